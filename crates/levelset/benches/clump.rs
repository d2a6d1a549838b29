//! Multi-sphere clumps of a cloned-size grain: `clump` at N = 50 on a 45³ grid with margin
//! 1.1 (the cloner's default) holding a lumpy star grain, as placed (CLUMP generator only)
//! and with the default offset volume correction; and `clump_quality` of the corrected clump.

use criterion::{Criterion, criterion_group, criterion_main};
use levelset::{ClumpParams, Grid, GridSpec, StarParams, VolumeCorrection, clump, clump_quality};
use nalgebra::{Point3, Unit, Vector3};
use std::hint::black_box;

/// The lumpy grain of the acceptance benches (radii 0.63 to 0.97).
fn lumpy(u: Unit<Vector3<f64>>) -> f64 {
    let theta = u.z.clamp(-1.0, 1.0).acos();
    let phi = u.y.atan2(u.x);
    0.8 + 0.12 * (3.0 * theta).sin() * (2.0 * phi).cos() + 0.05 * (5.0 * phi).sin() * theta.sin()
}

fn benches(c: &mut Criterion) {
    let half = 1.1 * 0.97;
    let spec = GridSpec::cube(45, -half, half).expect("spec");
    let (grid, _) =
        Grid::from_star(spec, &Point3::origin(), lumpy, &StarParams::default()).expect("grain");
    let mut group = c.benchmark_group("clump");
    group.sample_size(20);
    for (name, correction) in [
        ("n50_placed", VolumeCorrection::None),
        ("n50_offset", VolumeCorrection::Offset),
    ] {
        let params = ClumpParams {
            n_spheres: 50,
            volume_correction: correction,
            ..ClumpParams::default()
        };
        group.bench_function(name, |b| {
            b.iter(|| clump(black_box(&grid), black_box(&params)).expect("clump"))
        });
    }
    let corrected = clump(&grid, &ClumpParams::default()).expect("clump");
    group.bench_function("n50_quality", |b| {
        b.iter(|| clump_quality(black_box(&grid), black_box(&corrected)).expect("quality"))
    });
    group.finish();
}

criterion_group!(clump_benches, benches);
criterion_main!(clump_benches);
