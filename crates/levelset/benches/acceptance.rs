//! Acceptance benchmarks of issue 3 on 45³ grids: star build (incl. redistancing; default
//! band build and the seed's full sweep),
//! marching cubes, volume + area + inertia, contact of 1,000 nodes.

use criterion::{Criterion, criterion_group, criterion_main};
use levelset::{Body, Grid, GridSpec, Redistance, Sphere, StarParams, contact_into};
use nalgebra::{Isometry3, Point3, Unit, Vector3};
use std::hint::black_box;

/// A radius function with trigonometry (~40–50 ns per call): a lumpy grain.
fn lumpy(u: Unit<Vector3<f64>>) -> f64 {
    let theta = u.z.clamp(-1.0, 1.0).acos();
    let phi = u.y.atan2(u.x);
    0.8 + 0.12 * (3.0 * theta).sin() * (2.0 * phi).cos() + 0.05 * (5.0 * phi).sin() * theta.sin()
}

fn benches(c: &mut Criterion) {
    let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
    c.bench_function("radius_call", |b| {
        let u = Unit::new_normalize(Vector3::new(0.3, -0.2, 0.9));
        b.iter(|| lumpy(black_box(u)))
    });
    c.bench_function("star_build_45", |b| {
        b.iter(|| {
            Grid::from_star(spec, &Point3::origin(), lumpy, &StarParams::default()).expect("build")
        })
    });
    // Radius calls and per-node passes on the rayon pool (bit-identical result).
    let par = StarParams {
        parallel: true,
        ..StarParams::default()
    };
    c.bench_function("star_build_45_parallel", |b| {
        b.iter(|| Grid::from_star_sync(spec, &Point3::origin(), lumpy, &par).expect("build"))
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

criterion_group!(acceptance, benches);
criterion_main!(acceptance);
