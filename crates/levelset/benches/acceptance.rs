//! Acceptance benchmarks of issue 3 on 45³ grids: star build (incl. redistancing; default
//! band build and the seed's full sweep),
//! marching cubes, volume + area + inertia, contact of 1,000 nodes; and the user-grain mesh
//! path (`mesh_grain` group): `prepare_closed`, `Grid::from_mesh` (exact everywhere) and
//! `Grid::from_mesh_banded` (exact in a band of `MESH_BAND_CELLS`, on the default pool and on
//! one thread) on a 45³ grid with margin 1.1 for lumpy grains of ≈ 5k and ≈ 50k triangles.

use criterion::{Criterion, criterion_group, criterion_main};
use levelset::{
    Body, Grid, GridSpec, MESH_BAND_CELLS, Orientation, Redistance, Sphere, StarParams, TriMesh,
    contact_into,
};
use nalgebra::{Isometry3, Point3, Unit, Vector3};
use std::hint::black_box;

/// A radius function with trigonometry (≈ 50 ns per call over the cube-map directions, see
/// `radius_call_trig`): a lumpy grain.
fn lumpy(u: Unit<Vector3<f64>>) -> f64 {
    let theta = u.z.clamp(-1.0, 1.0).acos();
    let phi = u.y.atan2(u.x);
    0.8 + 0.12 * (3.0 * theta).sin() * (2.0 * phi).cos() + 0.05 * (5.0 * phi).sin() * theta.sin()
}

/// The same lumpy grain without trigonometry (≈ 5 ns per call): `sin θ = ρ`, `sin 3θ =
/// 3ρ − 4ρ³`, `cos 2φ = (x² − y²)/ρ²`, `sin 5φ · sin θ = (5x⁴y − 10x²y³ + y⁵)/ρ⁴` with
/// `ρ² = x² + y²` (radii agree to 4e-16; the grids are identical).
fn lumpy_poly(u: Unit<Vector3<f64>>) -> f64 {
    let (x, y) = (u.x, u.y);
    let r2 = x * x + y * y;
    if r2 <= 0.0 {
        return 0.8;
    }
    let s = r2.sqrt();
    let (x2, y2) = (x * x, y * y);
    0.8 + 0.12 * (3.0 * s - 4.0 * s * r2) * ((x2 - y2) / r2)
        + 0.05 * (y * (5.0 * x2 * x2 - 10.0 * x2 * y2 + y2 * y2)) / (r2 * r2)
}

/// The 6534 directions of the default cube map (32 cells per face), where a build calls the
/// radius function.
fn table_directions() -> Vec<Unit<Vector3<f64>>> {
    let n = 32;
    let mut dirs = Vec::new();
    for f in 0..6 {
        let axis = f / 2;
        let (b, c) = [(1, 2), (2, 0), (0, 1)][axis];
        for q in 0..=n {
            for p in 0..=n {
                let mut d = Vector3::zeros();
                d[axis] = if f % 2 == 0 { 1.0 } else { -1.0 };
                d[b] = -1.0 + 2.0 * p as f64 / n as f64;
                d[c] = -1.0 + 2.0 * q as f64 / n as f64;
                dirs.push(Unit::new_normalize(d));
            }
        }
    }
    dirs
}

fn benches(c: &mut Criterion) {
    let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
    // Cost of the radius calls of one build (6534 calls over the table's directions; divide
    // by 6534 for the cost per call).
    let dirs = table_directions();
    c.bench_function("radius_calls_6534_trig", |b| {
        b.iter(|| dirs.iter().map(|&u| lumpy(black_box(u))).sum::<f64>())
    });
    c.bench_function("radius_calls_6534_poly", |b| {
        b.iter(|| dirs.iter().map(|&u| lumpy_poly(black_box(u))).sum::<f64>())
    });
    c.bench_function("star_build_45", |b| {
        b.iter(|| {
            Grid::from_star(spec, &Point3::origin(), lumpy, &StarParams::default()).expect("build")
        })
    });
    c.bench_function("star_build_45_poly", |b| {
        b.iter(|| {
            Grid::from_star(spec, &Point3::origin(), lumpy_poly, &StarParams::default())
                .expect("build")
        })
    });
    // Radius calls and per-node passes on the rayon pool in one crew pass (bit-identical
    // result).
    let par = StarParams {
        parallel: true,
        ..StarParams::default()
    };
    c.bench_function("star_build_45_parallel", |b| {
        b.iter(|| Grid::from_star_sync(spec, &Point3::origin(), lumpy, &par).expect("build"))
    });
    c.bench_function("star_build_45_poly_parallel", |b| {
        b.iter(|| Grid::from_star_sync(spec, &Point3::origin(), lumpy_poly, &par).expect("build"))
    });
    // The seed method, for comparison.
    let full = StarParams {
        redistance: Redistance::FullSweep,
        ..StarParams::default()
    };
    c.bench_function("star_build_45_full_sweep", |b| {
        b.iter(|| Grid::from_star(spec, &Point3::origin(), lumpy, &full).expect("build"))
    });
    let (star, _) =
        Grid::from_star(spec, &Point3::origin(), lumpy, &StarParams::default()).expect("build");
    c.bench_function("marching_cubes_45", |b| {
        b.iter(|| black_box(&star).marching_cubes())
    });
    c.bench_function("volume_area_inertia_45", |b| {
        b.iter(|| black_box(&star).mass_properties().expect("mp"))
    });
    let sphere =
        Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity()).expect("g");
    let nodes = sphere.surface_nodes(1000).expect("nodes");
    let body = Body::new(sphere, nodes).expect("body");
    let pa = Isometry3::identity();
    let pb = Isometry3::new(Vector3::new(1.9, 0.0, 0.0), Vector3::new(0.1, 0.2, 0.3));
    let mut out = Vec::with_capacity(1000);
    c.bench_function("contact_1000_nodes", |b| {
        b.iter(|| contact_into(black_box(&body), &pa, black_box(&body), &pb, &mut out))
    });
}

/// The lumpy grain as a latitude–longitude mesh with `m` rings: 4·m·(m − 1) triangles
/// (m = 36: 5040; m = 112: 49 728).
fn lumpy_mesh(m: usize) -> TriMesh {
    let seg = 2 * m;
    let point = |theta: f64, phi: f64| {
        let u = Vector3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        Point3::from(lumpy(Unit::new_unchecked(u)) * u)
    };
    let mut v = vec![point(0.0, 0.0)];
    for i in 1..m {
        let theta = std::f64::consts::PI * i as f64 / m as f64;
        for j in 0..seg {
            v.push(point(theta, std::f64::consts::TAU * j as f64 / seg as f64));
        }
    }
    let south = v.len();
    v.push(point(std::f64::consts::PI, 0.0));
    let at = |i: usize, j: usize| 1 + (i - 1) * seg + j % seg;
    let mut t = Vec::new();
    for j in 0..seg {
        t.push([0, at(1, j), at(1, j + 1)]);
        t.push([south, at(m - 1, j + 1), at(m - 1, j)]);
        for i in 1..m - 1 {
            t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let mesh = TriMesh::new(v, t).expect("mesh");
    let (mesh, repair) = mesh.prepare_closed(Orientation::Refuse).expect("closed");
    assert_eq!(repair, levelset::MeshRepair::default());
    mesh
}

fn mesh_grain(c: &mut Criterion) {
    let mut group = c.benchmark_group("mesh_grain");
    group.sample_size(10);
    for m in [36, 112] {
        let mesh = lumpy_mesh(m);
        let n = mesh.triangles().len();
        let centre = mesh.centroid().expect("centroid");
        let spec = GridSpec::around_points(mesh.vertices(), centre, 45, 1.1).expect("spec");
        group.bench_function(format!("prepare_closed_{n}"), |b| {
            b.iter(|| {
                black_box(&mesh)
                    .prepare_closed(Orientation::Repair)
                    .expect("ok")
            })
        });
        group.bench_function(format!("from_mesh_45_{n}"), |b| {
            b.iter(|| Grid::from_mesh(spec, black_box(&mesh)).expect("grid"))
        });
        // Exact in a band of MESH_BAND_CELLS, swept beyond: on the default pool (z-slabs of
        // the band in parallel) and on one thread (callers that parallelise over grains).
        group.bench_function(format!("from_mesh_banded_45_{n}"), |b| {
            b.iter(|| {
                Grid::from_mesh_banded(spec, black_box(&mesh), MESH_BAND_CELLS).expect("grid")
            })
        });
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("pool");
        group.bench_function(format!("from_mesh_banded_45_{n}_1thread"), |b| {
            b.iter(|| {
                one.install(|| {
                    Grid::from_mesh_banded(spec, black_box(&mesh), MESH_BAND_CELLS).expect("grid")
                })
            })
        });
    }
    group.finish();
}

criterion_group!(acceptance, benches, mesh_grain);
criterion_main!(acceptance);
