//! Packing speed: the uniform cell grid against the seed's MX quadtree on
//! the same packing, and the 1000 × 1000 mm square of Pinto 2009, Table 3.13
//! with the Table 3.4 grading.

use criterion::{Criterion, criterion_group, criterion_main};
use packer_quadtree::{CellGrid, Domain, Grading, MxQuadtree, PackParams, pack_with_index};
use rand::SeedableRng;
use std::hint::black_box;

fn run<I: packer_quadtree::SpatialIndex>(side: f64) -> usize {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let domain = Domain::Rectangle {
        width: side,
        height: side,
    };
    let p = pack_with_index::<I>(
        &domain,
        &Grading::pinto_table_3_4(),
        &PackParams::default(),
        &mut rng,
    );
    p.map_or(0, |p| p.disks.len())
}

fn index_comparison(c: &mut Criterion) {
    let mut g = c.benchmark_group("index_100mm_square");
    g.sample_size(10);
    g.bench_function("cell_grid", |b| {
        b.iter(|| black_box(run::<CellGrid>(100.0)))
    });
    g.bench_function("mx_quadtree", |b| {
        b.iter(|| black_box(run::<MxQuadtree>(100.0)))
    });
    g.finish();
}

fn big_square(c: &mut Criterion) {
    let mut g = c.benchmark_group("table_3_13_1000mm_square");
    g.sample_size(10);
    g.bench_function("cell_grid", |b| {
        b.iter(|| black_box(run::<CellGrid>(1000.0)))
    });
    g.finish();
}

criterion_group!(benches, index_comparison, big_square);
criterion_main!(benches);
