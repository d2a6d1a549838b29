//! Grain packing speed: 500 ellipsoids (semi-axes 0.6:0.5:0.4, sizes
//! ×U[0.8, 1.2], 12-cell cube maps) in a triaxial cylinder at a solid
//! fraction of 0.45, and the independent check of the result (32³ level
//! sets, 1000 nodes per grain, 16 raster pairs); densification (issue 28):
//! the same grains at 0.55 by the seed's method (skeleton of the grains'
//! sizes, growth by the gap minimisation alone) against the default
//! (equal-sphere skeleton, compaction of sphere proxies by FIRE, then the
//! gap minimisation), and the default at 0.60.

use criterion::{Criterion, criterion_group, criterion_main};
use packer_grains::{
    CheckParams, GrainPackParams, StarGrain, check_grain_overlaps, container_for, pack_grains,
};
use packer_spheres::Container;
use rand::{Rng, SeedableRng};
use std::hint::black_box;

fn grains() -> Vec<StarGrain> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    (0..500)
        .filter_map(|_| {
            let s = rng.random_range(0.8..1.2);
            StarGrain::ellipsoid(0.6 * s, 0.5 * s, 0.4 * s, 12).ok()
        })
        .collect()
}

fn grains3d_500(c: &mut Criterion) {
    let g = grains();
    let Ok(cont) = container_for(&Container::triaxial(1.0), &g, 0.45) else {
        return;
    };
    let params = GrainPackParams::default();
    let mut group = c.benchmark_group("grains3d_500");
    group.sample_size(10);
    group.bench_function("pack", |b| {
        b.iter(|| black_box(pack_grains(&g, &cont, &params).map(|p| p.stats.fine_sweeps)))
    });
    if let Ok(p) = pack_grains(&g, &cont, &params) {
        group.bench_function("check", |b| {
            b.iter(|| {
                black_box(
                    check_grain_overlaps(&g, &p.poses, &cont, &CheckParams::default())
                        .map(|r| r.nodes_checked),
                )
            })
        });
    }
    group.finish();
}

fn grains3d_dense(c: &mut Criterion) {
    let g = grains();
    let seed = GrainPackParams {
        proxy_spheres: 0,
        skeleton_spread: 1.0,
        ..GrainPackParams::default()
    };
    let compaction = GrainPackParams::default();
    let mut group = c.benchmark_group("grains3d_500_dense");
    group.sample_size(10);
    for (name, fraction, params) in [
        ("0.55/seed", 0.55, &seed),
        ("0.55/compaction", 0.55, &compaction),
        ("0.60/compaction", 0.60, &compaction),
    ] {
        let Ok(cont) = container_for(&Container::triaxial(1.0), &g, fraction) else {
            continue;
        };
        group.bench_function(name, |b| {
            b.iter(|| black_box(pack_grains(&g, &cont, params).map(|p| p.stats.fine_sweeps)))
        });
    }
    group.finish();
}

criterion_group!(benches, grains3d_500, grains3d_dense);
criterion_main!(benches);
