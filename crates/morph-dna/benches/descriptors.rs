//! Criterion bench: every descriptor of one grain on a 45³ level set
//! (issue 5 target ≤ 2 ms), the cheap volume-type subset, the cloner's
//! subset, and roundness and convexity alone.

use criterion::{Criterion, criterion_group, criterion_main};
use levelset::{Ellipsoid, Grid, GridSpec};
use morph_dna::{Descriptor, MeasureParams, measure, measure_with_frame};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use std::hint::black_box;

fn grain() -> Grid {
    let spec = GridSpec::cube(45, -3.3, 3.3).expect("spec");
    let e = Ellipsoid::new(Vector3::new(3.0, 2.0, 1.0)).expect("ellipsoid");
    let pose = Isometry3::from_parts(
        Default::default(),
        UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
    );
    Grid::from_shape(spec, &e, &pose).expect("grid")
}

fn bench(c: &mut Criterion) {
    let g = grain();
    let params = MeasureParams::default();
    c.bench_function("all 16 descriptors, 45^3 ellipsoid", |b| {
        b.iter(|| measure(black_box(&g), &Descriptor::ALL, &params).expect("measure"));
    });
    let cheap = [
        Descriptor::Volume,
        Descriptor::SurfaceArea,
        Descriptor::VolumeSurfaceRatio,
        Descriptor::EquivalentDiameter,
        Descriptor::AspectRatio,
        Descriptor::Sphericity,
    ];
    c.bench_function("volume-type descriptors, 45^3 ellipsoid", |b| {
        b.iter(|| measure(black_box(&g), &cheap, &params).expect("measure"));
    });
    // what the cloner asks of every clone (crates/cloner, surface DNA)
    let cloner = [
        Descriptor::AspectRatio,
        Descriptor::EquivalentDiameter,
        Descriptor::Roundness,
        Descriptor::VolumeSurfaceRatio,
        Descriptor::MajorPrincipalDimension,
        Descriptor::IntermediatePrincipalDimension,
        Descriptor::MinPrincipalDimension,
    ];
    c.bench_function("cloner subset, 45^3 ellipsoid", |b| {
        b.iter(|| measure(black_box(&g), &cloner, &params).expect("measure"));
    });
    c.bench_function("cloner subset with frame, 45^3 ellipsoid", |b| {
        b.iter(|| measure_with_frame(black_box(&g), &cloner, &params).expect("measure"));
    });
    c.bench_function("roundness only, 45^3 ellipsoid", |b| {
        b.iter(|| measure(black_box(&g), &[Descriptor::Roundness], &params).expect("measure"));
    });
    c.bench_function("convexity only, 45^3 ellipsoid", |b| {
        b.iter(|| measure(black_box(&g), &[Descriptor::Convexity], &params).expect("measure"));
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
