//! One accepted clone of the committed Ottawa calibration
//! (`fixtures/calibrated/gsc2-ottawa.ron`, parents: the 71 NIST/VCCTL grains
//! of `fixtures/grains/vcctl/ottawa-random` at 45³, as `cargo xtask
//! calibrate` builds them), stage by stage:
//!
//! * `clone_one` — one production clone end to end (no outputs: what a
//!   specimen's clone stage pays per shape);
//! * `1 targets`, `2 radii` — one candidate's draws;
//! * `3 polish step` — one umbrella-smoothing step and its surface roundness
//!   (polishing repeats it until the roundness target is met);
//! * `4 surface DNA` — moments, area, principal dimensions and the curvature
//!   roundness of the node radii (the quality control runs it without the
//!   curvature once per axis correction, and whole once for an accepted
//!   candidate);
//! * `5 roundness prediction` — the estimated inscribed radius and the
//!   surface roundness about it (`RoundnessCheck::Predicted`);
//! * `6 rasterise 45³`, `7 DNA` — the level set and its measured DNA, built
//!   only when an output asks for them (a calibration's scoring, a report).
//!
//! Before the benches it prints the stage composition of 200 accepted clones
//! (CPU per accepted clone by the pipeline's own clock, candidates, polishing
//! steps and level sets per clone), so the per-stage times above can be
//! weighted by how often a clone runs them.

use std::fs::File;
use std::hint::black_box;
use std::io::{BufReader, Write as _};
use std::path::PathBuf;
use std::time::Instant;

use cloner::{Calibrated, Clock, CloneModel, Hooks, Parents, clone_rng};
use criterion::{Criterion, criterion_group, criterion_main};
use morph_dna::{MeasureParams, measure};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn parents() -> Parents {
    let dir = root().join("fixtures/grains/vcctl/ottawa-random");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixtures/grains/vcctl/ottawa-random")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "dat"))
        .collect();
    files.sort();
    let grids = files
        .iter()
        .map(|f| {
            let sh = sph_harmonics::vcctl::read_anm(BufReader::new(File::open(f).expect("open")))
                .expect("anm");
            let model = sh.to_model(sh.degree).expect("model").0;
            cloner::grid_from_sh(&model, 45, 1.1).expect("grid")
        })
        .collect();
    Parents::from_grids(grids, &MeasureParams::default()).expect("parents")
}

struct Wall(Instant);

impl Clock for Wall {
    fn now_ns(&self) -> u64 {
        u64::try_from(self.0.elapsed().as_nanos()).unwrap_or(u64::MAX)
    }
}

fn composition(model: &CloneModel) {
    let clock = Wall(Instant::now());
    let run = model
        .run(
            0..200,
            Hooks {
                clock: &clock,
                progress: None,
            },
        )
        .expect("run");
    let st = &run.stats;
    let per = st.accepted as f64;
    let ms = |ns: u64| ns as f64 * 1e-6 / per;
    // (a bench's report to the terminal, beside criterion's own)
    let _ = writeln!(
        std::io::stderr(),
        "stage composition of {} accepted clones: {:.2} candidates, {:.1} polishing steps, {:.2} predicted-roundness passes, {:.2} level sets per clone; CPU ms per clone: targets {:.3}, radii {:.3}, polishing {:.3}, quality control {:.3}, rasterisation {:.3}, DNA {:.3}",
        st.accepted,
        st.attempts as f64 / per,
        st.polishing_steps as f64 / per,
        st.roundness_predictions as f64 / per,
        st.level_sets as f64 / per,
        ms(st.times.targets_ns),
        ms(st.times.radii_ns),
        ms(st.times.polishing_ns),
        ms(st.times.quality_ns),
        ms(st.times.rasterise_ns),
        ms(st.times.measure_ns),
    );
}

fn bench(c: &mut Criterion) {
    let text = std::fs::read_to_string(root().join("fixtures/calibrated/gsc2-ottawa.ron"))
        .expect("calibration");
    let mut params = Calibrated::from_ron(&text).expect("ron").params;
    params.outputs = cloner::Outputs {
        level_set: false,
        dna: false,
    };
    let model = CloneModel::fit(&parents(), &params).expect("model");
    composition(&model);
    let clone = model.clone_one(0, &cloner::NoClock).expect("clone").0;
    let geom = model.geometry();
    let (res, margin) = (params.level_set_resolution, params.grid_margin);
    let mut g = c.benchmark_group("accepted clone (Ottawa, calibrated)");
    let mut i = 0u64;
    g.bench_function("clone_one", |b| {
        b.iter(|| {
            i += 1;
            black_box(model.clone_one(i, &cloner::NoClock).expect("clone"))
        })
    });
    let mut rng = clone_rng(params.seed, 1);
    g.bench_function("1 targets", |b| {
        b.iter(|| black_box(model.draw_targets(&mut rng)))
    });
    let mut rho = Vec::new();
    g.bench_function("2 radii", |b| {
        b.iter(|| {
            model.draw_radii(&mut rng, &mut rho);
            black_box(rho.len())
        })
    });
    let mut next = vec![0.0; clone.radii.len()];
    g.bench_function("3 polish step", |b| {
        b.iter(|| {
            geom.smooth_into(black_box(&clone.radii), params.smoothing.lambda, &mut next);
            black_box(geom.roundness(&next, res, margin))
        })
    });
    g.bench_function("4 surface DNA", |b| {
        b.iter(|| black_box(geom.surface_dna(black_box(&clone.radii), res, margin)))
    });
    g.bench_function("5 roundness prediction", |b| {
        b.iter(|| {
            let ins = geom
                .inscribed_radius(black_box(&clone.radii))
                .expect("r_ins");
            black_box(geom.roundness_about(&clone.radii, res, margin, ins))
        })
    });
    g.bench_function("6 rasterise 45^3", |b| {
        b.iter(|| black_box(model.rasterise(black_box(&clone.radii)).expect("grid")))
    });
    let grid = model.rasterise(&clone.radii).expect("grid");
    g.bench_function("7 DNA", |b| {
        b.iter(|| {
            black_box(measure(
                black_box(&grid),
                &cloner::DNA,
                &MeasureParams::default(),
            ))
            .expect("dna")
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
