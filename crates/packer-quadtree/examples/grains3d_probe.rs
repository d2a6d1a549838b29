//! Probe of the grain packer on random ellipsoids in a triaxial cylinder:
//! `cargo run --release -p packer-quadtree --example grains3d_probe -- N FRACTION`.
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use packer_quadtree::{
    CheckParams, Container, GrainPackParams, StarGrain, check_grain_overlaps, container_for,
    orientation_fabric, pack_grains,
};
use rand::{Rng, SeedableRng};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(2000, |s| s.parse().unwrap());
    let f: f64 = args.get(2).map_or(0.56, |s| s.parse().unwrap());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let t = Instant::now();
    let grains: Vec<StarGrain> = (0..n)
        .map(|_| {
            let s = rng.random_range(0.8..1.2);
            let a = s * rng.random_range(1.0..1.3);
            let b = s * rng.random_range(0.85..1.0);
            let c = s * rng.random_range(0.7..0.85);
            StarGrain::ellipsoid(a, b, c, 16).unwrap()
        })
        .collect();
    println!("grains {:.2}s", t.elapsed().as_secs_f64());
    let c = container_for(&Container::triaxial(1.0), &grains, f).unwrap();
    let t = Instant::now();
    // ROT=0: translations only (the seed's moves), for comparison.
    let params = GrainPackParams {
        rotations: std::env::var("ROT").map_or(true, |v| v != "0"),
        ..GrainPackParams::default()
    };
    let p = pack_grains(&grains, &c, &params);
    println!("pack {:.2}s", t.elapsed().as_secs_f64());
    let p = match p {
        Ok(p) => p,
        Err(e) => {
            println!("error: {e}");
            return;
        }
    };
    println!("{:#?}", p.stats);
    let fab = orientation_fabric(&p.poses, &nalgebra::Vector3::x()).unwrap();
    println!("fabric {:.4}", fab.deviatoric_norm);
    let t = Instant::now();
    let r = check_grain_overlaps(&grains, &p.poses, &c, &CheckParams::default()).unwrap();
    println!("check {:.2}s {:#?}", t.elapsed().as_secs_f64(), r);
}
