//! Densification speed (issue 28: `pack3d/jammed-periodic`): about 10⁴
//! spheres, d ~ U[1, 2], fully periodic cube, front + thinning + densify to
//! φ = 0.64 (`pack3d_dense`, what the validate case runs), and the densify
//! stage alone from the front's packing of a cube (x/y periodic, z walls,
//! treated as periodic) to 0.63 and 0.64. The peer, packing-generation
//! (force-biased then Lubachevsky–Stillinger, one core), takes 63–97 s for
//! 10⁴ spheres to φ 0.644 on the 2-core machine (its speed varies by up to
//! 2× within an hour: compare with the peer in the same minutes).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use packer_quadtree::Grading;
use packer_spheres::{
    Boundary, Container, DensifyParams, Pack3Params, Target, densify, pack3d_dense, pack3d_seeded,
};
use std::hint::black_box;

fn target(f: f64) -> DensifyParams {
    DensifyParams {
        target: Target::Fraction(f),
        ..DensifyParams::default()
    }
}

fn densify_1e4(c: &mut Criterion) {
    let g = Grading::Uniform { min: 1.0, max: 2.0 };
    let l = 32.0;
    let front = pack3d_seeded(
        &Container::Box {
            min: Point3::origin(),
            max: Point3::new(l, l, l),
            periodic: [true, true],
        },
        &g,
        &Pack3Params::default(),
        1,
    )
    .expect("front")
    .spheres;
    let cube = Boundary::Periodic {
        min: Point3::origin(),
        max: Point3::new(l, l, l),
    };
    let side = (1e4 * std::f64::consts::PI / 6.0 * 3.75 / 0.64).cbrt();
    let periodic = Boundary::Periodic {
        min: Point3::origin(),
        max: Point3::new(side, side, side),
    };
    let mut grp = c.benchmark_group("densify_1e4");
    grp.sample_size(10);
    for f in [0.63, 0.64] {
        grp.bench_function(format!("stage_to_{f}"), |b| {
            b.iter(|| black_box(densify(&front, &cube, &target(f)).map_or(0.0, |d| d.fraction)))
        });
    }
    grp.bench_function("pack3d_dense_periodic_0.64", |b| {
        b.iter(|| {
            black_box(
                pack3d_dense(&periodic, &g, &Pack3Params::default(), &target(0.64), 1)
                    .map_or(0.0, |d| d.fraction),
            )
        })
    });
    grp.finish();
}

criterion_group!(benches, densify_1e4);
criterion_main!(benches);
