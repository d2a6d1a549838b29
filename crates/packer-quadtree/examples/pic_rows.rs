//! Packs the rows of Pérez Morales et al. 2016 and prints fraction, speed
//! and the independent checker's worst gap (`cargo run --release --example
//! pic_rows -- P4`).
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use packer_quadtree::{ContactMethod, GrainShape, PicParams, check_pic, pack_pic};
use std::time::Instant;

fn main() {
    let which: Vec<String> = std::env::args().skip(1).collect();
    let want = |s: &str| which.is_empty() || which.iter().any(|w| w == s);
    let base = PicParams::default();
    let rows: Vec<(&str, usize, PicParams)> = vec![
        (
            "P1",
            2,
            PicParams {
                shape: GrainShape::Mix {
                    polygon_share: 0.5,
                    sides_min: 4,
                    sides_max: 8,
                },
                ..base.clone()
            },
        ),
        (
            "P2",
            2,
            PicParams {
                shape: GrainShape::Cluster {
                    aspect: 0.5,
                    spheres: 4,
                },
                method: ContactMethod::Wrappers,
                ..base.clone()
            },
        ),
        ("P3", 2, PicParams { ..base.clone() }),
        (
            "P3o",
            2,
            PicParams {
                orientations: 8,
                ..base.clone()
            },
        ),
        (
            "P2o",
            2,
            PicParams {
                orientations: 8,
                shape: GrainShape::Cluster {
                    aspect: 0.5,
                    spheres: 4,
                },
                method: ContactMethod::Wrappers,
                ..base.clone()
            },
        ),
        (
            "P4o",
            3,
            PicParams {
                orientations: 4,
                side: 40.0,
                ..base.clone()
            },
        ),
        (
            "P3nm",
            2,
            PicParams {
                method: ContactMethod::NelderMead,
                ..base.clone()
            },
        ),
        (
            "P4",
            3,
            PicParams {
                side: 40.0,
                ..base.clone()
            },
        ),
        (
            "P5",
            3,
            PicParams {
                side: 40.0,
                shape: GrainShape::Cluster {
                    aspect: 0.5,
                    spheres: 4,
                },
                ..base.clone()
            },
        ),
        (
            "S3",
            3,
            PicParams {
                side: 40.0,
                shape: GrainShape::Ball,
                ..base.clone()
            },
        ),
    ];
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<usize>().ok());
    for (name, dim, mut p) in rows {
        if !want(name) {
            continue;
        }
        if let Some(o) = env("ORI") {
            p.orientations = o;
        }
        if let Some(o) = env("NB") {
            p.neighbours = o;
        }
        let seed = env("SEED").unwrap_or(1) as u64;
        let t = Instant::now();
        let (n, frac, rej, rep) = if dim == 2 {
            let k = pack_pic::<2>(&p, seed).unwrap();
            let dt = t.elapsed();
            let rep = check_pic(&k, 1e-9).unwrap();
            println!(
                "{name}: {} grains in {:.3} s = {:.1} p/s",
                k.grains.len(),
                dt.as_secs_f64(),
                k.grains.len() as f64 / dt.as_secs_f64()
            );
            (k.grains.len(), k.fraction(), k.rejected, rep)
        } else {
            let k = pack_pic::<3>(&p, seed).unwrap();
            let dt = t.elapsed();
            let rep = check_pic(&k, 1e-9).unwrap();
            println!(
                "{name}: {} grains in {:.3} s = {:.1} p/s",
                k.grains.len(),
                dt.as_secs_f64(),
                k.grains.len() as f64 / dt.as_secs_f64()
            );
            (k.grains.len(), k.fraction(), k.rejected, rep)
        };
        println!(
            "   n {n} fraction {frac:.4} rejected {rej} min gap/d {:.3e} wall {:.3e} Z {:.2}",
            rep.min_relative_gap, rep.min_relative_wall_gap, rep.coordination
        );
    }
}
