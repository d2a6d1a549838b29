//! Runs the porosity-control tests AP-1..AP-5 of Pinto 2009, Table 4.2
//! (20 × 20 mm square, target porosity 0.5) and prints before/after
//! porosities and wall time.
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use packer_quadtree::{Domain, GaParams, Grading, HaloMode, PackParams, optimise_porosity};

fn main() -> Result<(), packer_quadtree::Error> {
    let domain = Domain::Rectangle {
        width: 20.0,
        height: 20.0,
    };
    let tests = [
        ("AP-1", Grading::Constant { diameter: 1.2 }),
        ("AP-2", Grading::Uniform { min: 1.2, max: 1.3 }),
        ("AP-3", Grading::Uniform { min: 1.2, max: 2.4 }),
        ("AP-4", Grading::Uniform { min: 1.2, max: 4.8 }),
        ("AP-5", Grading::pinto_ap5()),
    ];
    for (label, params) in [
        ("contact halo", PackParams::default()),
        (
            "seed halo d_max",
            PackParams {
                halo: HaloMode::MaxDiameter,
                ..PackParams::default()
            },
        ),
    ] {
        for (name, g) in &tests {
            let t = std::time::Instant::now();
            let r = optimise_porosity(&domain, g, &params, &GaParams::default(), 1)?;
            println!(
                "{label:16} {name}: porosity {:.3} -> {:.3}, {} packings, {:.2} s",
                r.initial_porosity,
                r.porosity,
                r.evaluations,
                t.elapsed().as_secs_f64()
            );
        }
    }
    Ok(())
}
