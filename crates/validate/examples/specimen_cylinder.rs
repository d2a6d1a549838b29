//! Times the stages of the `specimen/cylinder-10k` case (the validate crate
//! has no clock): `cargo run --release -p validate --example
//! specimen_cylinder -- [COUNT] [box]`; `FRACTIONS=0.56,0.53` (tried in
//! turn), `SWEEPS`, `SEED`, `COARSE` (coarse nodes), `OMEGA`, `ROT=0`
//! (translations only) override the packer's parameters.
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use levelset::nalgebra::Vector3;
use packer_grains::{CheckParams, StarGrain, check_grain_overlaps, orientation_fabric};
use packer_spheres::Container;
use std::time::Instant;
use validate::cases::specimen::{mass_cu_cc, ottawa_star_grains, pack_specimen};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: u64 = args.get(1).map_or(10_000, |s| s.parse().unwrap());
    let shape = if args.get(2).is_some_and(|s| s == "box") {
        Container::walled_box(Vector3::new(1.0, 1.0, 2.0))
    } else {
        Container::triaxial(1.0)
    };
    let t = Instant::now();
    let grains = ottawa_star_grains(n).unwrap();
    let t_clone = t.elapsed().as_secs_f64();
    println!(
        "clone + star tables: {t_clone:.2} s ({} grains)",
        grains.len()
    );
    let mut ratios: Vec<(f64, usize)> = grains
        .iter()
        .enumerate()
        .map(|(i, g)| (2.0 * g.r_max() / g.equivalent_diameter(), i))
        .collect();
    ratios.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!("largest 2 r_max / d_eq: {:?}", &ratios[..5]);
    println!(
        "d_eq range: {:?}",
        grains
            .iter()
            .map(StarGrain::equivalent_diameter)
            .fold((f64::INFINITY, 0.0_f64), |(a, b), d| (a.min(d), b.max(d)))
    );
    if std::env::var("STATS_ONLY").is_ok() {
        return;
    }
    let t = Instant::now();
    let fr: Vec<f64> = std::env::var("FRACTIONS").map_or(vec![], |s| {
        s.split(',').map(|x| x.parse().unwrap()).collect()
    });
    let sweeps: usize = std::env::var("SWEEPS").map_or(3000, |s| s.parse().unwrap());
    let (container, packing) = if fr.is_empty() {
        pack_specimen(&grains, &shape).unwrap()
    } else {
        let mut out = None;
        for f in fr {
            let c = packer_grains::container_for(&shape, &grains, f).unwrap();
            let t1 = Instant::now();
            let params = packer_grains::GrainPackParams {
                max_sweeps: sweeps,
                relaxation: std::env::var("OMEGA").map_or(1.8, |v| v.parse().unwrap()),
                rotations: std::env::var("ROT").map_or(true, |v| v != "0"),
                seed: std::env::var("SEED").map_or(1, |v| v.parse().unwrap()),
                coarse_nodes: std::env::var("COARSE").map_or(160, |v| v.parse().unwrap()),
                ..Default::default()
            };
            match packer_grains::pack_grains(&grains, &c, &params) {
                Ok(p) => {
                    println!("fraction {f}: ok in {:.2} s", t1.elapsed().as_secs_f64());
                    out = Some((c, p));
                    break;
                }
                Err(e) => println!("fraction {f}: {e} ({:.2} s)", t1.elapsed().as_secs_f64()),
            }
        }
        out.unwrap()
    };
    let t_pack = t.elapsed().as_secs_f64();
    println!(
        "pack: {t_pack:.2} s\n{:#?}\ncontainer {container:?}",
        packing.stats
    );
    let t = Instant::now();
    let report =
        check_grain_overlaps(&grains, &packing.poses, &container, &CheckParams::default()).unwrap();
    let t_check = t.elapsed().as_secs_f64();
    println!("check: {t_check:.2} s\n{report:#?}");
    let fabric = orientation_fabric(&packing.poses, &Vector3::x()).unwrap();
    let d: Vec<f64> = grains.iter().map(StarGrain::equivalent_diameter).collect();
    let (cu, cc) = mass_cu_cc(&d);
    println!(
        "fraction {:.4} | worst phi/d {:.3e} | raster overlap voxels {} of {} in {} pairs | Cu {cu:.4} Cc {cc:.4} | fabric {:.4} | total {:.1} s",
        packing.stats.solid_fraction,
        report.worst_phi_over_d,
        report.raster_overlap_voxels,
        report.raster_voxels,
        report.raster_pairs,
        fabric.deviatoric_norm,
        t_clone + t_pack + t_check
    );
}
