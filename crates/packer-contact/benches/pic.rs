//! Particles per second of the Pérez Morales et al. 2016 rows
//! (`PicParams::perezmorales2016`), seed 1: criterion's throughput is the
//! placed grain count, so it reports grains/s directly. The seed's speeds:
//! P2 1.05, P3 0.0094, P4 3.90, P5 172.30 particles/s. P5's preset uses
//! the approximate wrappers; `P5-newton` times the exact clusters.
//!
//! `cargo bench -p packer-contact --bench pic` (P4/P5 take seconds per
//! packing; `-- P2` selects one row).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use packer_contact::{ContactMethod, PicParams, pack_pic};
use std::hint::black_box;
use std::time::Duration;

fn rows(c: &mut Criterion) {
    let mut group = c.benchmark_group("perezmorales2016");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    let mut rows: Vec<(String, usize, PicParams)> = Vec::new();
    for id in ["P1", "P2", "P3", "P4", "P5"] {
        if let Ok((dim, p)) = PicParams::perezmorales2016(id) {
            rows.push((id.to_owned(), dim, p));
        }
    }
    // The seed's own method for P3, for comparison.
    if let Ok((dim, p)) = PicParams::perezmorales2016("P3") {
        rows.push((
            "P3-nelder-mead".to_owned(),
            dim,
            PicParams {
                method: ContactMethod::NelderMead,
                ..p
            },
        ));
    }
    // P5 with exact Newton clusters, for comparison.
    if let Ok((dim, p)) = PicParams::perezmorales2016("P5") {
        rows.push((
            "P5-newton".to_owned(),
            dim,
            PicParams {
                method: ContactMethod::Newton,
                neighbours: 10,
                ..p
            },
        ));
    }
    for (id, dim, p) in rows {
        let n = if dim == 2 {
            pack_pic::<2>(&p, 1).map(|k| k.grains.len())
        } else {
            pack_pic::<3>(&p, 1).map(|k| k.grains.len())
        };
        let Ok(n) = n else { continue };
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(&id, |b| {
            b.iter(|| {
                if dim == 2 {
                    black_box(pack_pic::<2>(black_box(&p), 1).map(|k| k.grains.len()))
                } else {
                    black_box(pack_pic::<3>(black_box(&p), 1).map(|k| k.grains.len()))
                }
            });
        });
    }
    group.finish();
}

criterion_group!(benches, rows);
criterion_main!(benches);
