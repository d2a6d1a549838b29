//! Throughput of the independent 3D overlap checker (`check_spheres`) and
//! of the exact core solid fraction on 10⁶ non-overlapping spheres: a
//! jittered 100³ cubic lattice (spacing 1, centres jittered by ±0.05,
//! radii uniform in [0.4, 0.45]) in a walled box and in a box periodic in x
//! and y. Criterion's throughput is the sphere count (spheres/s).
//!
//! `cargo bench -p packer-spheres --bench metrics3d`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Point3, Vector3};
use packer_spheres::{Container, Sphere, check_spheres, core_solid_fraction};
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Duration;

fn lattice(n: usize, seed: u64) -> Vec<Sphere> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let mut c = |v: usize| v as f64 + 0.5 + rng.random_range(-0.05..0.05);
                let center = Point3::new(c(i), c(j), c(k));
                out.push(Sphere {
                    center,
                    radius: rng.random_range(0.4..0.45),
                });
            }
        }
    }
    out
}

fn metrics3d(c: &mut Criterion) {
    let n = 100;
    let spheres = lattice(n, 1);
    let side = n as f64;
    let walled = Container::walled_box(Vector3::new(side, side, side));
    let periodic = Container::Box {
        min: Point3::origin(),
        max: Point3::new(side, side, side),
        periodic: [true, true],
    };
    let mut group = c.benchmark_group("metrics3d");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.throughput(Throughput::Elements(spheres.len() as u64));
    group.bench_function("check_spheres/1e6/walled", |b| {
        b.iter(|| check_spheres(black_box(&walled), black_box(&spheres), 1e-9))
    });
    group.bench_function("check_spheres/1e6/periodic-xy", |b| {
        b.iter(|| check_spheres(black_box(&periodic), black_box(&spheres), 1e-9))
    });
    group.bench_function("core_solid_fraction/1e6/walled", |b| {
        b.iter(|| core_solid_fraction(black_box(&walled), black_box(&spheres), 2.3))
    });
    group.finish();
}

criterion_group!(benches, metrics3d);
criterion_main!(benches);
