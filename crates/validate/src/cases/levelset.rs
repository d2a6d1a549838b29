//! levelset analytic acceptance cases (issue 3): sphere, ellipsoid and box on 45³ grids,
//! the mesh path (signed distance from the marching-cubes mesh) and LS-DEM sphere–sphere
//! contact. References are closed forms, not fixtures.

use std::f64::consts::PI;

use levelset::nalgebra::{Isometry3, UnitQuaternion, Vector3};
use levelset::{Body, Cuboid, Ellipsoid, Grid, GridSpec, Sphere, contact};

use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "levelset/sphere-45",
            description: "sphere R = 1 on 45³ over [−1.2, 1.2]³: volume ±0.3 %, area ±0.5 %, ||∇φ| − 1| ≤ 0.02 where |φ| < 3h",
            fast: true,
            heavy: false,
            run: sphere,
        },
        Case {
            name: "levelset/ellipsoid-45",
            description: "rotated ellipsoid (2, 1.5, 1) on 45³ over [−2.4, 2.4]³: volume ±0.5 %, principal moments ±1 %, axes ≤ 1°",
            fast: true,
            heavy: false,
            run: ellipsoid,
        },
        Case {
            name: "levelset/box-45",
            description: "box 2 × 1 × 0.5 on 45³ over [−1.2, 1.2]³: volume ±0.5 %",
            fast: true,
            heavy: false,
            run: cuboid,
        },
        Case {
            name: "levelset/mesh-path",
            description: "signed distance of the sphere's marching-cubes mesh vs the analytic distance, |φ| < 3h: ≤ h/10",
            fast: true,
            heavy: false,
            run: mesh_path,
        },
        Case {
            name: "levelset/contact-spheres",
            description: "two R = 1 spheres overlapping by δ ∈ {0.01, 0.1, 0.3}: max node penetration within 0.02·h of δ, normals ≤ 1°",
            fast: true,
            heavy: false,
            run: contact_spheres,
        },
    ]
}

// The box's convex edges were cut by the piecewise-linear zero set (−0.70 %); the
// sharp-feature correction of `Grid::volume` restores them (−0.04 %).
pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[];

fn err(e: levelset::Error) -> Error {
    Error::computation(e)
}

fn sphere_grid() -> Result<Grid, Error> {
    let spec = GridSpec::cube(45, -1.2, 1.2).map_err(err)?;
    Grid::from_shape(
        spec,
        &Sphere::new(1.0).map_err(err)?,
        &Isometry3::identity(),
    )
    .map_err(err)
}

fn sphere() -> Result<Vec<Check>, Error> {
    let g = sphere_grid()?;
    let worst = g.eikonal_error(3.0 * g.spacing());
    Ok(vec![
        Check::new(
            "volume",
            4.0 * PI / 3.0,
            g.volume(),
            Tolerance::Relative(0.003),
        ),
        Check::new("area", 4.0 * PI, g.area(), Tolerance::Relative(0.005)),
        Check::new(
            "max ||grad phi| - 1| (|phi| < 3h)",
            0.0,
            worst,
            Tolerance::AtMost(0.02),
        ),
    ])
}

fn ellipsoid() -> Result<Vec<Check>, Error> {
    let axes = Vector3::new(2.0, 1.5, 1.0);
    let e = Ellipsoid::new(axes).map_err(err)?;
    let rot = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7);
    let pose = Isometry3::from_parts(Vector3::new(0.05, -0.1, 0.02).into(), rot);
    let spec = GridSpec::cube(45, -2.4, 2.4).map_err(err)?;
    let g = Grid::from_shape(spec, &e, &pose).map_err(err)?;
    let mp = g.mass_properties().map_err(err)?;
    let p = mp.principal();
    let v = 4.0 / 3.0 * PI * axes.x * axes.y * axes.z;
    let m = v / 5.0;
    let (a2, b2, c2) = (axes.x * axes.x, axes.y * axes.y, axes.z * axes.z);
    // Ascending: the smallest moment is about the longest axis.
    let exact = [m * (b2 + c2), m * (a2 + c2), m * (a2 + b2)];
    let mut checks = vec![Check::new(
        "volume",
        v,
        mp.volume,
        Tolerance::Relative(0.005),
    )];
    for (i, ex) in exact.iter().enumerate() {
        checks.push(Check::new(
            format!("principal moment {}", i + 1),
            *ex,
            p.moments[i],
            Tolerance::Relative(0.01),
        ));
        let axis = rot * Vector3::ith(i, 1.0);
        let cos = p.axes.column(i).dot(&axis).abs().min(1.0);
        checks.push(Check::new(
            format!("principal axis {} angle (deg)", i + 1),
            0.0,
            cos.acos().to_degrees(),
            Tolerance::AtMost(1.0),
        ));
    }
    Ok(checks)
}

fn cuboid() -> Result<Vec<Check>, Error> {
    let spec = GridSpec::cube(45, -1.2, 1.2).map_err(err)?;
    let b = Cuboid::new(Vector3::new(1.0, 0.5, 0.25)).map_err(err)?;
    let g = Grid::from_shape(spec, &b, &Isometry3::identity()).map_err(err)?;
    Ok(vec![Check::new(
        "volume",
        1.0,
        g.volume(),
        Tolerance::Relative(0.005),
    )])
}

fn mesh_path() -> Result<Vec<Check>, Error> {
    let g = sphere_grid()?;
    let h = g.spacing();
    let mesh = g.marching_cubes();
    let from_mesh = Grid::from_mesh(*g.spec(), &mesh).map_err(err)?;
    let [nx, ny, nz] = g.dims();
    let mut worst = 0.0f64;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let exact = g.spec().node(i, j, k).coords.norm() - 1.0;
                if exact.abs() < 3.0 * h {
                    worst = worst.max((from_mesh.at(i, j, k) - exact).abs());
                }
            }
        }
    }
    Ok(vec![Check::new(
        "max |phi_mesh - phi_exact| / h (|phi| < 3h)",
        0.0,
        worst / h,
        Tolerance::AtMost(0.1),
    )])
}

fn contact_spheres() -> Result<Vec<Check>, Error> {
    let g = sphere_grid()?;
    let h = g.spacing();
    let nodes = g.surface_nodes(1000).map_err(err)?;
    let body = Body::new(g, nodes).map_err(err)?;
    // The line of centres passes through a node of A, so the deepest node sits on the axis
    // and the check measures the level-set accuracy, not the node spacing.
    let axis = body.nodes()[17].coords.normalize();
    let mut checks = Vec::new();
    for delta in [0.01, 0.1, 0.3] {
        let cb = axis * (2.0 - delta);
        let pb = Isometry3::new(cb, Vector3::new(0.4, -0.3, 0.2));
        let cs = contact(&body, &Isometry3::identity(), &body, &pb);
        let max_pen = cs.iter().map(|c| c.penetration).fold(0.0, f64::max);
        let mut worst = 0.0f64;
        for c in &cs {
            let exact = (c.point.coords - cb).normalize();
            worst = worst.max(c.normal.dot(&exact).clamp(-1.0, 1.0).acos().to_degrees());
        }
        checks.push(Check::new(
            format!("delta {delta}: max penetration"),
            delta,
            max_pen,
            Tolerance::Within(0.02 * h),
        ));
        checks.push(Check::new(
            format!("delta {delta}: max normal error (deg)"),
            0.0,
            worst,
            Tolerance::AtMost(1.0),
        ));
    }
    Ok(checks)
}
