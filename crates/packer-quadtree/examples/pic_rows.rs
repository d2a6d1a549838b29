//! A timing report of the Pérez Morales et al. 2016 rows with our presets
//! (`PicParams::perezmorales2016`): grains, seconds, grains/s, fraction and
//! the independent checker's worst gap. `cargo run --release --example
//! pic_rows -- P4 P5` (no argument: every row; `SEED=2` another seed;
//! `METHOD=newton|wrappers|nelder-mead|approx` overrides the preset's
//! contact method, e.g. `METHOD=newton` for P5's exact clusters;
//! `NEIGHBOURS=k` its partner count).
#![allow(clippy::print_stdout)]

use packer_quadtree::{ContactMethod, PicParams, check_pic, pack_pic};
use std::time::Instant;

fn main() {
    let which: Vec<String> = std::env::args().skip(1).collect();
    let seed = std::env::var("SEED")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        .unwrap_or(1);
    for id in ["P1", "P2", "P3", "P4", "P5"] {
        if !which.is_empty() && !which.iter().any(|w| w == id) {
            continue;
        }
        let Ok((dim, mut p)) = PicParams::perezmorales2016(id) else {
            continue;
        };
        match std::env::var("METHOD").as_deref() {
            Ok("newton") => p.method = ContactMethod::Newton,
            Ok("wrappers") => p.method = ContactMethod::Wrappers,
            Ok("nelder-mead") => p.method = ContactMethod::NelderMead,
            Ok("approx") => p.method = ContactMethod::ApproxWrappers,
            _ => {}
        }
        if let Some(k) = std::env::var("NEIGHBOURS")
            .ok()
            .and_then(|v| v.parse::<usize>().ok())
        {
            p.neighbours = k;
        }
        let t = Instant::now();
        let row = if dim == 2 {
            pack_pic::<2>(&p, seed).and_then(|k| {
                let s = t.elapsed().as_secs_f64();
                let r = check_pic(&k, 1e-9)?;
                Ok((k.grains.len(), s, k.fraction(), r))
            })
        } else {
            pack_pic::<3>(&p, seed).and_then(|k| {
                let s = t.elapsed().as_secs_f64();
                let r = check_pic(&k, 1e-9)?;
                Ok((k.grains.len(), s, k.fraction(), r))
            })
        };
        match row {
            Ok((n, s, f, r)) => println!(
                "{id} ({:?}, {} partners): {n} grains in {s:.3} s = {:.1} grains/s, fraction {f:.4}, coordination {:.2}, \
                 worst gap/d {:.2e} (walls {:.2e})",
                p.method,
                p.neighbours,
                n as f64 / s,
                r.coordination,
                r.min_relative_gap,
                r.min_relative_wall_gap
            ),
            Err(e) => println!("{id}: error {e}"),
        }
    }
}
