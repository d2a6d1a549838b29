//! Labelled images → level sets: per-grain extraction cost on synthetic watershed-like
//! images (rotated ellipsoids painted on a jittered lattice), EDT and smoothed, and reading
//! a u16 `.npy`. Divide the extraction times by the grain count for the per-grain cost.
//!
//! * `extract_160_64grains_*`: 160³ voxels, 64 ellipsoids of ~20–26 voxels across.
//! * `extract_512_2744grains_*`: the acceptance case, 512³ voxels (u16), 14³ = 2744
//!   ellipsoids of ~26–32 voxels across (10 samples; about two minutes with the setup).
//!   Measured on 2 cores (quiet machine): EDT 2.3 s, σ = 1 5.5 s; `read_npy_u16_512`
//!   0.3–0.4 s with a peak of 528 MB (the labels plus a 1 MiB chunk).

use criterion::{Criterion, criterion_group, criterion_main};
use levelset::io::{Dtype, read_npy, write_npy};
use levelset::{Ellipsoid, ExtractParams, Grid, GridSpec, LabelImage};
use nalgebra::{Isometry3, Point3, Vector3};
use std::hint::black_box;

/// Deterministic uniform numbers in [0, 1) from (seed, index) (splitmix64).
fn unit(seed: u64, i: u64) -> f64 {
    let mut z = seed
        .wrapping_add(i.wrapping_mul(0x9E37_79B9_7F4A_7C15))
        .wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// `n³` image with `sites³` ellipsoids of largest diameter `diameter` voxels on a lattice
/// of pitch `n / sites`, jittered by ±`jitter` voxels; 8 distinct shapes (sizes 0.8–1 of
/// `diameter`, aspect 1 : 0.8 : 0.65, random rotations) painted with offsets.
fn synthetic(n: usize, sites: usize, diameter: f64, jitter: f64) -> LabelImage {
    let mut img = LabelImage::zeros([n; 3], 1.0).expect("image");
    let grids: Vec<Grid> = (0..8u64)
        .map(|s| {
            let a = 0.5 * diameter * (0.8 + 0.2 * unit(s, 0));
            let semi = Vector3::new(a, 0.8 * a, 0.65 * a);
            let rot = Vector3::new(unit(s, 1), unit(s, 2), unit(s, 3)) * 3.0;
            let m = a + 2.0;
            let spec = GridSpec::covering(Point3::new(-m, -m, -m), Point3::new(m, m, m), 0.5, 0.0)
                .expect("spec");
            Grid::from_shape(
                spec,
                &Ellipsoid::new(semi).expect("e"),
                &Isometry3::new(Vector3::zeros(), rot),
            )
            .expect("grid")
        })
        .collect();
    let pitch = n as f64 / sites as f64;
    let mut label = 0u32;
    for k in 0..sites {
        for j in 0..sites {
            for i in 0..sites {
                label += 1;
                let l = u64::from(label);
                let c = Vector3::new(
                    (i as f64 + 0.5) * pitch + jitter * (2.0 * unit(l, 10) - 1.0),
                    (j as f64 + 0.5) * pitch + jitter * (2.0 * unit(l, 11) - 1.0),
                    (k as f64 + 0.5) * pitch + jitter * (2.0 * unit(l, 12) - 1.0),
                );
                img.paint(label, &grids[(l % 8) as usize], c)
                    .expect("paint");
            }
        }
    }
    img
}

fn benches(c: &mut Criterion) {
    let img = synthetic(160, 4, 26.0, 3.0);
    let edt = ExtractParams {
        smoothing: None,
        ..ExtractParams::default()
    };
    let smooth = ExtractParams {
        smoothing: Some(1.0),
        ..ExtractParams::default()
    };
    assert_eq!(img.extract(&edt).expect("extract").grains.len(), 64);
    c.bench_function("extract_160_64grains_edt", |b| {
        b.iter(|| img.extract(black_box(&edt)).expect("extract"))
    });
    c.bench_function("extract_160_64grains_smoothed", |b| {
        b.iter(|| img.extract(black_box(&smooth)).expect("extract"))
    });
    let serial = ExtractParams {
        parallel: false,
        ..smooth
    };
    c.bench_function("extract_160_64grains_smoothed_serial", |b| {
        b.iter(|| img.extract(black_box(&serial)).expect("extract"))
    });
    // issue 31: σ = 0.7 then the minimal-bending refinement (ExtractParams::minimal_bending)
    let bending = ExtractParams::minimal_bending();
    c.bench_function("extract_160_64grains_minimal_bending", |b| {
        b.iter(|| img.extract(black_box(&bending)).expect("extract"))
    });
    let mut npy = Vec::new();
    write_npy(&mut npy, &img, Dtype::U16).expect("npy");
    c.bench_function("read_npy_u16_160", |b| {
        b.iter(|| read_npy(black_box(&npy[..]), 1.0).expect("read"))
    });
}

fn acceptance(c: &mut Criterion) {
    let img = synthetic(512, 14, 32.0, 2.0);
    let mut npy = Vec::new();
    write_npy(&mut npy, &img, Dtype::U16).expect("npy");
    let mut g = c.benchmark_group("acceptance");
    g.sample_size(10);
    g.bench_function("read_npy_u16_512", |b| {
        b.iter(|| read_npy(black_box(&npy[..]), 1.0).expect("read"))
    });
    for (name, smoothing) in [
        ("extract_512_2744grains_edt", None),
        ("extract_512_2744grains_smoothed", Some(1.0)),
    ] {
        let p = ExtractParams {
            smoothing,
            ..ExtractParams::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| img.extract(black_box(&p)).expect("extract"))
        });
    }
    g.finish();
}

criterion_group!(labels, benches, acceptance);
criterion_main!(labels);
