//! Measures `morph-dna`'s hand-written Quickhull against parry's
//! `convex_hull` on the same point clouds (bumpy ellipsoidal grains of 500
//! and 5000 surface points, 5 grains each) and prints the mean time per
//! hull and the hull volumes. `morph-dna` (layer 1) may not depend on
//! parry, so the faster one cannot replace the other there; this example
//! only reports the numbers.
//! `cargo run --release -p xtask --example hull_parry_vs_quickhull`
#![allow(clippy::print_stdout)]

use nalgebra::Point3;
use std::time::Instant;

fn grain(n: usize, k: usize) -> Vec<Point3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            let bump = 1.0 + 0.15 * ((3 + k) as f64 * t).sin() * (2.0 * z * (k + 1) as f64).cos();
            Point3::new(2.0 * s * t.cos() * bump, 1.3 * s * t.sin() * bump, z * bump)
        })
        .collect()
}

fn main() {
    for n in [500, 5000] {
        let (mut t_qh, mut t_parry, mut dv) = (0.0, 0.0, 0.0f64);
        let reps = 10;
        for k in 0..5 {
            let pts = grain(n, k);
            let pv: Vec<parry3d_f64::math::Vector> = pts
                .iter()
                .map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z))
                .collect();
            let t = Instant::now();
            let mut v1 = 0.0;
            for _ in 0..reps {
                v1 = morph_dna::convex_hull_volume(&pts).unwrap_or(f64::NAN);
            }
            t_qh += t.elapsed().as_secs_f64() / reps as f64;
            let t = Instant::now();
            let mut v2 = 0.0;
            for _ in 0..reps {
                let (v, idx) = parry3d_f64::transformation::convex_hull(&pv);
                v2 = idx
                    .iter()
                    .map(|f| {
                        let [a, b, c] = f.map(|i| v[i as usize]);
                        a.dot(b.cross(c)) / 6.0
                    })
                    .sum::<f64>()
                    .abs();
            }
            t_parry += t.elapsed().as_secs_f64() / reps as f64;
            dv = dv.max((v1 - v2).abs() / v1);
        }
        println!(
            "{n} points: morph-dna Quickhull {:.3} ms, parry {:.3} ms per hull (mean of 5 grains), \
             max relative volume difference {dv:.1e}",
            1e3 * t_qh / 5.0,
            1e3 * t_parry / 5.0
        );
    }
}
