//! Criterion benchmarks of the acceptance targets of issue 4 (degree 30, threshold grid).

use criterion::{Criterion, criterion_group, criterion_main};
use sph_harmonics::ShModel;
use sph_harmonics::basis::coefficient_count;
use sph_harmonics::fit::{least_squares, least_squares_rings, quadrature_transform};
use sph_harmonics::grid::RingGrid;
use std::hint::black_box;

fn model(degree: usize) -> ShModel {
    // Deterministic pseudo-random coefficients decaying with degree.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let c: Vec<f64> = (0..coefficient_count(degree))
        .map(|i| {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let u = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            if i == 0 {
                100.0
            } else {
                u / (1.0 + i as f64).sqrt()
            }
        })
        .collect();
    ShModel::new(degree, c).expect("valid coefficients")
}

fn benches(c: &mut Criterion) {
    let m = model(30);
    let grid = RingGrid::threshold();
    let points = grid.points();
    let radii = m.evaluate_grid(&grid).expect("evaluate");
    c.bench_function("evaluate_deg30_threshold_grid_rings", |b| {
        b.iter(|| m.evaluate_grid(black_box(&grid)).expect("evaluate"))
    });
    c.bench_function("evaluate_deg30_threshold_points_scattered", |b| {
        b.iter(|| m.evaluate(black_box(&points)).expect("evaluate"))
    });
    c.bench_function("lsq_fit_deg30_threshold_grid_ring_blocks", |b| {
        b.iter(|| least_squares_rings(black_box(&grid), black_box(&radii), 30).expect("fit"))
    });
    let gl = RingGrid::gauss_legendre(30).expect("grid");
    let gl_values = m.evaluate_grid(&gl).expect("evaluate");
    c.bench_function("quadrature_transform_deg30", |b| {
        b.iter(|| quadrature_transform(black_box(&gl), black_box(&gl_values), 30).expect("fit"))
    });
    let mut slow = c.benchmark_group("general_qr");
    slow.sample_size(10);
    slow.bench_function("lsq_fit_deg30_threshold_points_general_qr", |b| {
        b.iter(|| least_squares(black_box(&points), black_box(&radii), None, 30).expect("fit"))
    });
    slow.finish();
}

criterion_group!(sph, benches);
criterion_main!(sph);
