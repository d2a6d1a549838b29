//! 3D sphere packing speed: about 10⁵ spheres, d ~ U[1, 2] (uniform in
//! diameter), walled box of side 70 (the target: ≤ 1 s on the
//! 2-core machine; packing-generation's Lubachevsky–Stillinger / force-
//! biased generators take 149–168 s per 10⁵). The default preset packs 4
//! slabs, two at a time; `sequential` is the default preset on one front
//! (site generation on the second thread); `dense` runs its portfolio of
//! three sequential fronts in parallel.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use packer_quadtree::Grading;
use packer_spheres::{Container, Pack3Params, pack3d_seeded};
use std::hint::black_box;

fn run(side: f64, params: &Pack3Params) -> usize {
    let c = Container::walled_box(Vector3::new(side, side, side));
    let g = Grading::Uniform { min: 1.0, max: 2.0 };
    pack3d_seeded(&c, &g, params, 1).map_or(0, |p| p.spheres.len())
}

fn pack3d_1e5(c: &mut Criterion) {
    let mut g = c.benchmark_group("pack3d_1e5");
    g.sample_size(10);
    g.bench_function("default", |b| {
        b.iter(|| black_box(run(70.0, &Pack3Params::default())))
    });
    g.bench_function("sequential", |b| {
        b.iter(|| {
            black_box(run(
                70.0,
                &Pack3Params {
                    slabs: 0,
                    ..Pack3Params::default()
                },
            ))
        })
    });
    g.bench_function("dense", |b| {
        b.iter(|| black_box(run(70.0, &Pack3Params::dense())))
    });
    g.finish();
}

criterion_group!(benches, pack3d_1e5);
criterion_main!(benches);
