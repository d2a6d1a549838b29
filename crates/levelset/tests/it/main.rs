//! Acceptance oracles of issue 3 that cross modules (mesh path, gradient norm, builds).

use levelset::{
    Body, Cylinder, Grid, GridSpec, MeshDistance, Redistance, Sphere, StarParams, Superellipsoid,
    contact,
};
use nalgebra::{Isometry3, Point3, Vector3};

fn sphere45() -> Grid {
    let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
    Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity()).expect("grid")
}

/// Max | |∇φ| − 1 | over interior nodes with |φ| < 3h (central differences).
fn gradient_norm_error(g: &Grid) -> f64 {
    g.eikonal_error(3.0 * g.spacing())
}

#[test]
fn sphere_gradient_norm_is_one_in_the_band() {
    let g = sphere45();
    let e = gradient_norm_error(&g);
    assert!(e < 0.02, "analytic sphere: {e}");
    let (star, _) = Grid::from_star(
        *g.spec(),
        &Point3::origin(),
        |_| 1.0,
        &StarParams::default(),
    )
    .expect("star");
    // The default (band) star build meets the acceptance bound too (measured 0.0004: the
    // second-order band estimate is exact for a sphere about the centre).
    let e = gradient_norm_error(&star);
    assert!(e < 0.02, "star-built sphere: {e}");
    // The seed method (first-order fast sweeping over the whole grid) errs in |∇φ| away from
    // the fixed interface nodes (measured 0.037).
    let (full, _) = Grid::from_star(
        *g.spec(),
        &Point3::origin(),
        |_| 1.0,
        &StarParams {
            redistance: Redistance::FullSweep,
            ..StarParams::default()
        },
    )
    .expect("star");
    let e = gradient_norm_error(&full);
    assert!(e < 0.05, "star-built sphere, full sweep: {e}");
}

#[test]
fn mesh_path_signed_distance_matches_analytic_within_tenth_of_h() {
    let g = sphere45();
    let h = g.spacing();
    let mesh = g.marching_cubes();
    let from_mesh = Grid::from_mesh(*g.spec(), &mesh).expect("closed mesh");
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
    assert!(
        worst < 0.1 * h,
        "mesh path error {worst} vs h/10 = {}",
        0.1 * h
    );
    // Spot check away from nodes and far away.
    let md = MeshDistance::new(&mesh).expect("closed");
    let p = Point3::new(3.0, -2.0, 1.0);
    assert!((md.signed_distance(&p) - (p.coords.norm() - 1.0)).abs() < 0.1 * h);
}

#[test]
fn superellipsoid_and_cylinder_volumes() {
    use std::f64::consts::PI;
    let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
    // ε1 = ε2 = 1 is the ellipsoid: volume 4/3 π abc.
    let s = Superellipsoid::new(Vector3::new(1.0, 0.8, 0.6), 1.0, 1.0).expect("s");
    let g = Grid::from_superellipsoid(spec, &s, &Isometry3::identity(), &StarParams::default())
        .expect("g");
    let v = 4.0 / 3.0 * PI * 0.48;
    assert!(
        (g.volume() / v - 1.0).abs() < 0.005,
        "superellipsoid volume {}",
        g.volume()
    );
    let c = Cylinder::new(0.5, 0.9).expect("c");
    let g =
        Grid::from_shape(spec, &c, &Isometry3::rotation(Vector3::new(0.3, 0.2, 0.1))).expect("g");
    let v = PI * 0.25 * 1.8;
    assert!(
        (g.volume() / v - 1.0).abs() < 0.01,
        "cylinder volume {}",
        g.volume()
    );
}

#[test]
fn contact_in_generic_direction_and_symmetry() {
    let g = sphere45();
    let h = g.spacing();
    let nodes = g.surface_nodes(4000).expect("nodes");
    let body = Body::new(g, nodes).expect("body");
    // Generic direction: the deepest node is off-axis by at most the node spacing α, which
    // costs R·α²/… of penetration; 4000 nodes give α ≲ 0.03.
    let axis = Vector3::new(0.3, -0.5, 0.81).normalize();
    for delta in [0.01, 0.1, 0.3] {
        let pb = Isometry3::new(axis * (2.0 - delta), Vector3::zeros());
        let a_in_b = contact(&body, &Isometry3::identity(), &body, &pb);
        let b_in_a = contact(&body, &pb, &body, &Isometry3::identity());
        let max_ab = a_in_b.iter().map(|c| c.penetration).fold(0.0, f64::max);
        let max_ba = b_in_a.iter().map(|c| c.penetration).fold(0.0, f64::max);
        assert!((max_ab - delta).abs() < 0.05 * h, "delta {delta}: {max_ab}");
        assert!((max_ab - max_ba).abs() < 0.05 * h);
        for c in &a_in_b {
            assert!(
                c.normal.dot(&(-axis)) > 0.0,
                "normal points out of B towards A"
            );
        }
    }
}
