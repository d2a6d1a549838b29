//! Criterion benches of the cloner at the seed's trial-4 configuration
//! (mesh 28 × (18 + 2), 45³): one accepted clone end to end (targets, radii,
//! polishing, quality control, rasterisation, DNA), and the surface DNA of
//! one candidate. Parents are 40 synthetic bumpy ellipsoids (the real
//! Ottawa-sand throughput is reported by `cargo xtask calibrate`, which has
//! the embedded grains).

use std::hint::black_box;

use cloner::{CloneModel, NoClock, Params, Parents};
use criterion::{Criterion, criterion_group, criterion_main};
use levelset::nalgebra::{Point3, Unit, Vector3};
use levelset::{Grid, GridSpec, StarParams};
use morph_dna::MeasureParams;

fn parent(k: usize) -> Grid {
    let kf = k as f64;
    let (a, b, c) = (
        1.0 + 0.03 * kf,
        0.7 + 0.015 * (k % 9) as f64,
        0.45 + 0.02 * (k % 7) as f64,
    );
    let amp = 0.03 + 0.003 * (k % 8) as f64;
    let radius = move |u: Unit<Vector3<f64>>| {
        let e = 1.0 / ((u.x / a).powi(2) + (u.y / b).powi(2) + (u.z / c).powi(2)).sqrt();
        e * (1.0
            + amp * (4.0 * u.x + kf).sin() * (3.0 * u.y + 0.7 * kf).cos()
            + 0.5 * amp * (6.0 * u.z - kf).sin())
    };
    let half = 1.1 * a * (1.0 + 2.0 * amp);
    let spec = GridSpec::cube(45, -half, half).expect("spec");
    Grid::from_star(spec, &Point3::origin(), radius, &StarParams::default())
        .expect("parent")
        .0
}

fn bench(c: &mut Criterion) {
    let grids = (0..40).map(parent).collect();
    let parents = Parents::from_grids(grids, &MeasureParams::default()).expect("parents");
    let params = Params {
        bins: 20,
        tolerance: 0.02,
        ..Params::default()
    };
    let model = CloneModel::fit(&parents, &params).expect("model");
    let mut i = 0u64;
    c.bench_function("clone_one trial4 28x18 45^3 (accepted, with DNA)", |b| {
        b.iter(|| {
            i += 1;
            black_box(model.clone_one(i, &NoClock).expect("clone"))
        })
    });
    let radii = &model.parent_profiles()[0];
    let geom = model.geometry();
    c.bench_function("surface_dna 28x18", |b| {
        b.iter(|| black_box(geom.surface_dna(black_box(radii), 45, 1.1)))
    });
    c.bench_function("rasterise 28x18 -> 45^3", |b| {
        b.iter(|| black_box(model.rasterise(black_box(radii)).expect("grid")))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
