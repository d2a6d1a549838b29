//! A timing report of the Pérez Morales et al. 2016 rows with our presets
//! (`PicParams::perezmorales2016`): grains, seconds, grains/s, fraction and
//! the independent checker's worst gap. `cargo run --release --example
//! pic_rows -- P4 P5` (no argument: every row; `SEED=2` another seed).
#![allow(clippy::print_stdout)]

use packer_quadtree::{PicParams, check_pic, pack_pic};
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
        let Ok((dim, p)) = PicParams::perezmorales2016(id) else {
            continue;
        };
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
                "{id}: {n} grains in {s:.3} s = {:.1} grains/s, fraction {f:.4}, coordination {:.2}, \
                 worst gap/d {:.2e} (walls {:.2e})",
                n as f64 / s,
                r.coordination,
                r.min_relative_gap,
                r.min_relative_wall_gap
            ),
            Err(e) => println!("{id}: error {e}"),
        }
    }
}
