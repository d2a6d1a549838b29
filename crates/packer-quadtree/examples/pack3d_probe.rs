//! Probe of the 3D packer: density (centre-in-core estimate) and time.
//! `cargo run --release --example pack3d_probe -- SIDE ORDER [mono]`;
//! env: `LA` look-ahead, `SLABS` slab count, `CYL` a triaxial cylinder of
//! diameter SIDE, `CHECK` the independent checker, `XPROF=W` the solid
//! fraction in x-bins of width W.
#![allow(clippy::print_stdout)]
use nalgebra::{Point3, Vector3};
use packer_quadtree::{Container, FrontOrder, Grading, Pack3Params, pack3d_seeded};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let side: f64 = args.get(1).map_or(Ok(80.0), |s| s.parse())?;
    let order = match args.get(2).map_or("lc", String::as_str) {
        "stack" => FrontOrder::Stack,
        "lf" => FrontOrder::LowestFirst,
        "best" => FrontOrder::Best,
        _ => FrontOrder::LowestCandidate,
    };
    let mono = args.get(3).is_some_and(|s| s == "mono");
    let grading = if mono {
        Grading::Constant { diameter: 1.0 }
    } else {
        Grading::Uniform { min: 1.0, max: 2.0 }
    };
    let dmax = grading.d_max();
    let c = if std::env::var("CYL").is_ok() {
        Container::triaxial(side)
    } else {
        Container::walled_box(Vector3::new(side, side, side))
    };
    let params = Pack3Params {
        lookahead: std::env::var("LA")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(8),
        front_order: order,
        slab_cylinders: true,
        slabs: std::env::var("SLABS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(Pack3Params::default().slabs),
        ..Pack3Params::default()
    };
    let t = std::time::Instant::now();
    let p = pack3d_seeded(&c, &grading, &params, 1)?;
    let el = t.elapsed().as_secs_f64();
    if std::env::var("CHECK").is_ok() {
        let rep = packer_quadtree::check_spheres(&c, &p.spheres, 1e-9)?;
        println!(
            "check: worst gap {:.3e} wall {:.3e}",
            rep.worst_normalised_gap, rep.worst_normalised_wall_gap
        );
    }
    let m = 2.0 * dmax;
    let lo = Point3::new(m, m, m);
    let hi = Point3::new(side - m, side - m, side - m);
    let mut v = 0.0;
    let mut tot = 0.0;
    for s in &p.spheres {
        let vol = std::f64::consts::PI * 4.0 / 3.0 * s.radius.powi(3);
        tot += vol;
        if (0..3).all(|k| s.center[k] >= lo[k] && s.center[k] <= hi[k]) {
            v += vol;
        }
    }
    let core = (side - 2.0 * m).powi(3);
    if let Ok(w) = std::env::var("XPROF") {
        // Solid fraction in x-bins of width w over the core in y and z
        // (centre-in-core spheres only, exact slab volumes in x).
        let w: f64 = w.parse()?;
        let nb = (side / w).ceil() as usize;
        let mut bins = vec![0.0; nb];
        for s in &p.spheres {
            if !(1..3).all(|k| s.center[k] >= lo[k] && s.center[k] <= hi[k]) {
                continue;
            }
            let r = s.radius;
            let cum = |x: f64| {
                let t = x.clamp(-r, r);
                std::f64::consts::PI * (r * r * t - t * t * t / 3.0)
            };
            let b0 = ((s.center.x - r) / w).floor().max(0.0) as usize;
            let b1 = (((s.center.x + r) / w).floor() as usize).min(nb - 1);
            for (b, v) in bins.iter_mut().enumerate().take(b1 + 1).skip(b0) {
                let (a, c) = (b as f64 * w - s.center.x, (b + 1) as f64 * w - s.center.x);
                *v += cum(c) - cum(a);
            }
        }
        let area = (side - 2.0 * m) * (side - 2.0 * m);
        let line: Vec<String> = bins
            .iter()
            .map(|v| format!("{:.3}", v / (area * w)))
            .collect();
        println!("xprof {}", line.join(" "));
    }
    println!(
        "n {} time {:.3}s  overall {:.4} core(centre) {:.4} order {:?} stats {:?}",
        p.spheres.len(),
        el,
        tot / c.volume(),
        v / core,
        p.front_order,
        p.stats
    );
    Ok(())
}
