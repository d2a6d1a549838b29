//! Oracles of the banded mesh build: [`Grid::from_mesh`] (exact everywhere) on grains with
//! curved, sharp, thin and grid-crossing surfaces.

use super::*;
use crate::mesh::tests::{cube_mesh, icosphere, lumpy_mesh};
use approx::assert_relative_eq;
use nalgebra::{Point3, Rotation3, Vector3};

/// `mesh` with every vertex mapped by `f`.
fn mapped(mesh: &TriMesh, f: impl Fn(&Point3<f64>) -> Point3<f64>) -> TriMesh {
    TriMesh::new(
        mesh.vertices().iter().map(f).collect(),
        mesh.triangles().to_vec(),
    )
    .expect("mesh")
}

/// Test grains and their grids: (name, mesh, spec).
fn cases() -> Vec<(&'static str, TriMesh, GridSpec)> {
    let around = |m: &TriMesh, n: usize| {
        let c = m.centroid().expect("centroid");
        GridSpec::around_points(m.vertices(), c, n, 1.1).expect("spec")
    };
    let lumpy = lumpy_mesh(24);
    let sphere = icosphere(3);
    let rot = Rotation3::from_euler_angles(0.3, 0.5, 0.7);
    // A rotated box 1.6 × 1.0 × 0.6: sharp edges and corners off the grid axes.
    let brick = mapped(&cube_mesh(), |p| {
        rot * Point3::new(1.6 * p.x, 1.0 * p.y, 0.6 * p.z)
    });
    // A rotated plate 0.04 thick: thinner than a grid spacing (h ≈ 0.05).
    let plate = mapped(&cube_mesh(), |p| {
        rot * Point3::new(2.0 * p.x, 1.5 * p.y, 0.04 * p.z)
    });
    // The lumpy grain on a grid that cuts it: the surface crosses the grid boundary and
    // part of the boundary is inside.
    let cut = GridSpec::cube(33, -0.5, 0.9).expect("spec");
    vec![
        ("lumpy", lumpy.clone(), around(&lumpy, 37)),
        ("sphere", sphere.clone(), around(&sphere, 31)),
        ("brick", brick.clone(), around(&brick, 33)),
        ("plate", plate.clone(), around(&plate, 41)),
        ("cut lumpy", lumpy, cut),
    ]
}

/// Band nodes equal `from_mesh` to 1e-12; every node within `band_cells·h` of the surface is
/// a band node; elsewhere the sign is exact, |φ| ≥ band_cells·h and |φ − exact| ≤
/// FAR_ERROR_CELLS·h.
#[test]
fn band_is_exact_and_far_field_is_bounded() {
    for (name, mesh, spec) in cases() {
        let exact = Grid::from_mesh(spec, &mesh).expect("exact");
        let md = MeshDistance::new(&mesh).expect("distance");
        let h = spec.spacing;
        let [nx, ny, nz] = spec.dims;
        for band_cells in [1, 2, 3, 4] {
            let g = Grid::from_mesh_banded(spec, &mesh, band_cells).expect("banded");
            let (band, _) = md.band(&spec, band_cells);
            let floor = band_cells as f64 * h;
            let (mut in_band, mut worst_far, mut far) = (0usize, 0.0f64, 0usize);
            let mut signs = [0usize; 2];
            for k in 0..nz {
                for j in 0..ny {
                    for i in 0..nx {
                        let (v, e) = (g.at(i, j, k), exact.at(i, j, k));
                        if band.has(i, j + ny * k) {
                            in_band += 1;
                            assert!((v - e).abs() <= 1e-12, "{name} B{band_cells}: {v} {e}");
                            continue;
                        }
                        far += 1;
                        assert!(
                            e.abs() > floor,
                            "{name}: node within the band width left out"
                        );
                        assert_eq!(v < 0.0, e < 0.0, "{name} B{band_cells} sign at {i} {j} {k}");
                        signs[usize::from(v < 0.0)] += 1;
                        assert!(v.abs() >= floor, "{name}: far value below the band width");
                        worst_far = worst_far.max((v - e).abs() / h);
                    }
                }
            }
            assert!(
                worst_far <= FAR_ERROR_CELLS,
                "{name} B{band_cells}: {worst_far}·h"
            );
            assert!(in_band > 0 && far > 0, "{name}");
        }
    }
}

/// With band_cells ≥ 3 (MESH_BAND_CELLS) the surface integrals read only band nodes: volume,
/// area and mass properties equal `from_mesh`'s to 1e-12 (relative). (With 2 they do not for
/// the brick: the sharp-feature correction reads gradients at the corners of crossed cells,
/// up to (√3 + 1)·h from the surface.)
#[test]
fn surface_integrals_equal_the_exact_grid() {
    for (name, mesh, spec) in cases() {
        let exact = Grid::from_mesh(spec, &mesh).expect("exact");
        let (ve, ae) = (exact.volume(), exact.area());
        let me = exact.mass_properties().expect("mass");
        for band_cells in [MESH_BAND_CELLS, MESH_BAND_CELLS + 1] {
            let g = Grid::from_mesh_banded(spec, &mesh, band_cells).expect("banded");
            assert_relative_eq!(g.volume(), ve, max_relative = 1e-12);
            assert_relative_eq!(g.area(), ae, max_relative = 1e-12);
            let m = g.mass_properties().expect("mass");
            assert_relative_eq!(m.volume, me.volume, max_relative = 1e-12);
            assert_relative_eq!(m.area, me.area, max_relative = 1e-12);
            let scale = me.volume.abs().max(me.inertia.norm());
            assert!(
                (m.centroid - me.centroid).norm() <= 1e-12 * spec.spacing * 45.0,
                "{name} centroid"
            );
            assert!(
                (m.inertia - me.inertia).norm() <= 1e-12 * scale,
                "{name} inertia"
            );
        }
    }
}

/// The build is bit-identical on pools of 1 and 2 threads.
#[test]
fn banded_build_does_not_depend_on_the_thread_count() {
    let mesh = lumpy_mesh(24);
    let c = mesh.centroid().expect("centroid");
    let spec = GridSpec::around_points(mesh.vertices(), c, 37, 1.1).expect("spec");
    let build = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| Grid::from_mesh_banded(spec, &mesh, MESH_BAND_CELLS).expect("grid"))
    };
    let (one, two) = (build(1), build(2));
    let bits = |g: &Grid| g.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert!(bits(&one) == bits(&two));
}

/// Bad input is an `Err` as for `from_mesh`; a grid the band does not reach is exact.
#[test]
fn bad_input_and_empty_band() {
    let mesh = icosphere(2);
    let spec = GridSpec::cube(21, -1.2, 1.2).expect("spec");
    assert!(matches!(
        Grid::from_mesh_banded(spec, &mesh, 0),
        Err(Error::InvalidParameter {
            name: "band_cells",
            ..
        })
    ));
    let bad = GridSpec {
        spacing: -1.0,
        ..spec
    };
    assert!(matches!(
        Grid::from_mesh_banded(bad, &mesh, 2),
        Err(Error::NonPositiveSpacing { .. })
    ));
    let open =
        TriMesh::new(mesh.vertices().to_vec(), mesh.triangles()[1..].to_vec()).expect("mesh");
    assert!(matches!(
        Grid::from_mesh_banded(spec, &open, 2),
        Err(Error::NonClosedMesh { .. })
    ));
    assert!(matches!(
        Grid::from_mesh_banded(spec, &TriMesh::default(), 2),
        Err(Error::EmptyMesh)
    ));
    // Grid far from the grain: no band, built exactly.
    let away = GridSpec::cube(9, 3.0, 4.0).expect("spec");
    let g = Grid::from_mesh_banded(away, &mesh, 2).expect("grid");
    assert_eq!(g, Grid::from_mesh(away, &mesh).expect("grid"));
    // Grid inside the grain, the band not reaching it: exact, all negative.
    let inner = GridSpec::cube(9, -0.3, 0.3).expect("spec");
    let g = Grid::from_mesh_banded(inner, &mesh, 2).expect("grid");
    assert!(g.values().iter().all(|&v| v < 0.0));
    let _ = Vector3::<f64>::zeros();
}
