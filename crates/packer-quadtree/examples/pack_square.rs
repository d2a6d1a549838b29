//! Packs one square (or rectangle) with the Table 3.4 grading of Pinto 2009
//! and prints count, porosity and wall time: used to measure peak memory
//! with `/usr/bin/time -v` (e.g. `cargo run --release -p packer-quadtree
//! --example pack_square -- 3873 3873` for about 10⁷ disks; append `1` for
//! the default best-of front order instead of the stack order).
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use packer_quadtree::{Domain, FrontOrder, Grading, PackParams, pack, porosity};
use rand::SeedableRng;

fn main() -> Result<(), packer_quadtree::Error> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let w = args.first().copied().unwrap_or(1000.0);
    let h = args.get(1).copied().unwrap_or(w);
    let domain = Domain::Rectangle {
        width: w,
        height: h,
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    // A third argument `1` selects the default (best-of) front order.
    let params = if args.get(2) == Some(&1.0) {
        PackParams::default()
    } else {
        PackParams {
            front_order: FrontOrder::Stack,
            ..PackParams::default()
        }
    };
    let t = std::time::Instant::now();
    let p = pack(&domain, &Grading::pinto_table_3_4(), &params, &mut rng)?;
    let dt = t.elapsed().as_secs_f64();
    // FNV-1a over the bit patterns of every centre and radius (as the
    // golden test): equal digests mean bit-identical packings.
    let mut digest = 0xcbf2_9ce4_8422_2325_u64;
    for d in &p.disks {
        for v in [d.center.x, d.center.y, d.radius] {
            for b in v.to_bits().to_le_bytes() {
                digest = (digest ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    println!(
        "{w} x {h}: {} disks, porosity {:.4}, {dt:.3} s, {} front visits, digest {digest:#018x}",
        p.disks.len(),
        porosity(&domain, &p.disks)?,
        p.stats.front_visits
    );
    Ok(())
}
