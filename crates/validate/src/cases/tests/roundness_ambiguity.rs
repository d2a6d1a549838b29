//! How much of a clone's own roundness its labelled image determines (issue 31).
//!
//! For a clone of the round trips, search radii r′ on the clone's own spherical mesh whose
//! painted image is **identical** to the clone's, voxel for voxel, and whose own roundness
//! (rasterised by `CloneModel::rasterise` and measured as the clone's: the corner rule on
//! its 45³ grid) is as far from the clone's as possible, in both directions. No method that
//! reads the image can tell r from r′, so on at least one of the clone and its two
//! alternatives it errs by at least `(hi − lo)/(hi + lo)` (the relative error of the best
//! single reading for an interval [lo, hi]).
//!
//! Search: sequential linear programs. At the current radii, every voxel centre within
//! 1.5 voxels of the surface gives a linearised constraint "keeps its side, with a margin of
//! min(0.02 voxel, half its current margin)" (Jacobian of the painted level-set value by
//! finite differences of the clone rasterisation); the objective is the finite-difference
//! gradient of the own roundness; every node moves by at most 0.5 voxel per program. Each
//! program is solved by a log-barrier Newton method (Boyd & Vandenberghe 2004, §11.3). Its
//! step is then checked exactly: the radii are rasterised and repainted and the step is
//! taken only if the image is unchanged (halving it up to 8 times otherwise) and the own
//! roundness moved the right way. Three programs per direction.

use cloner::CloneModel;
use levelset::nalgebra::{DMatrix, DVector, Vector3};
use levelset::{Grid, LabelImage};
use morph_dna::{Descriptor, MeasureParams};

fn paint(g: &Grid, shape: [usize; 3], h: f64, offset: Vector3<f64>) -> LabelImage {
    let mut im = LabelImage::zeros(shape, h).expect("image");
    im.paint(1, g, offset).expect("paint");
    im
}

fn own(g: &Grid) -> f64 {
    morph_dna::measure(g, &[Descriptor::Roundness], &MeasureParams::default()).expect("measure")[0]
}

/// Maximises `u·δ` subject to `sphi_c + rows_c·δ ≥ floor_c` and `|δ_k| < dmax` by a
/// log barrier (duality gap below 1e-3 `h`).
fn barrier_lp(
    rows: &[Vec<(usize, f64)>],
    sphi: &[f64],
    floor: &[f64],
    u: &DVector<f64>,
    dmax: f64,
    h: f64,
) -> DVector<f64> {
    let n = u.len();
    let slack = |delta: &DVector<f64>| -> Vec<f64> {
        rows.iter()
            .zip(sphi.iter().zip(floor))
            .map(|(row, (s, f))| s + row.iter().map(|&(k, w)| w * delta[k]).sum::<f64>() - f)
            .collect()
    };
    let objective = |delta: &DVector<f64>, t: f64| -> f64 {
        let sl = slack(delta);
        if sl.iter().any(|x| *x <= 0.0) || delta.iter().any(|x| x.abs() >= dmax) {
            return f64::INFINITY;
        }
        -t * u.dot(delta)
            - sl.iter().map(|x| x.ln()).sum::<f64>()
            - delta
                .iter()
                .map(|x| (dmax - x).ln() + (dmax + x).ln())
                .sum::<f64>()
    };
    let mut delta = DVector::<f64>::zeros(n);
    let mut t = 1.0 / h;
    while (rows.len() + 2 * n) as f64 / t > 1e-3 * h {
        for _ in 0..50 {
            let sl = slack(&delta);
            let mut grad = u * (-t);
            let mut hess = DMatrix::<f64>::zeros(n, n);
            for (row, s) in rows.iter().zip(&sl) {
                let w = 1.0 / s;
                for &(a, wa) in row {
                    grad[a] -= w * wa;
                    for &(b, wb) in row {
                        hess[(a, b)] += w * w * wa * wb;
                    }
                }
            }
            for k in 0..n {
                let (p, m) = (dmax - delta[k], dmax + delta[k]);
                grad[k] += 1.0 / p - 1.0 / m;
                hess[(k, k)] += 1.0 / (p * p) + 1.0 / (m * m);
            }
            let step = -hess.cholesky().expect("barrier Hessian").solve(&grad);
            let decrement = -grad.dot(&step);
            if decrement < 1e-8 {
                break;
            }
            let f0 = objective(&delta, t);
            let mut a = 1.0;
            while a >= 1e-10 {
                let cand = &delta + &step * a;
                if objective(&cand, t) <= f0 - 0.25 * a * decrement {
                    delta = cand;
                    break;
                }
                a *= 0.5;
            }
            if a < 1e-10 {
                break;
            }
        }
        t *= 8.0;
    }
    delta
}

/// The clone's own roundness and the lowest and highest own roundness found among radii
/// whose image at `h` is identical to the clone's.
fn identical_image_interval(model: &CloneModel, r0: &[f64], h: f64) -> (f64, f64, f64) {
    let n = r0.len();
    let g0 = model.rasterise(r0).expect("rasterise");
    let own0 = own(&g0);
    let r_max = r0.iter().fold(0.0f64, |a, b| a.max(*b));
    let side = (2.0 * 1.6 * r_max / h).ceil() as usize + 6;
    let shape = [side; 3];
    // off the lattice, as the round trips' painting is
    let offset = Vector3::repeat(0.5 * side as f64 * h) + Vector3::new(0.31, 0.17, 0.43) * h;
    let image = paint(&g0, shape, h, offset);
    let mut centres: Vec<(Vector3<f64>, f64)> = Vec::new();
    for k in 0..side {
        for j in 0..side {
            for i in 0..side {
                let q = image.voxel_centre(i, j, k).coords - offset;
                let v = g0.value(&q.into());
                if v.abs() < 1.5 * h {
                    centres.push((q, if v < 0.0 { -1.0 } else { 1.0 }));
                }
            }
        }
    }
    let mean_r = r0.iter().sum::<f64>() / n as f64;
    let (eps, eps_r) = (1e-5 * mean_r, 2e-3 * mean_r);
    let mut ends = [own0; 2];
    for (end, dir) in ends.iter_mut().zip([-1.0f64, 1.0]) {
        let mut r = r0.to_vec();
        for _ in 0..3 {
            let g = model.rasterise(&r).expect("rasterise");
            let here: Vec<f64> = centres.iter().map(|(q, _)| g.value(&(*q).into())).collect();
            let sphi: Vec<f64> = centres.iter().zip(&here).map(|((_, s), v)| s * v).collect();
            let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); centres.len()];
            let mut grad = DVector::<f64>::zeros(n);
            for k in 0..n {
                let mut rp = r.clone();
                rp[k] += eps;
                let gp = model.rasterise(&rp).expect("rasterise");
                for (row, ((q, s), v)) in rows.iter_mut().zip(centres.iter().zip(&here)) {
                    let d = s * (gp.value(&(*q).into()) - v) / eps;
                    if d.abs() > 1e-9 {
                        row.push((k, d));
                    }
                }
                let (mut up, mut down) = (r.clone(), r.clone());
                up[k] += eps_r;
                down[k] -= eps_r;
                grad[k] = (own(&model.rasterise(&up).expect("rasterise"))
                    - own(&model.rasterise(&down).expect("rasterise")))
                    / (2.0 * eps_r);
            }
            let floor: Vec<f64> = sphi.iter().map(|x| (0.02 * h).min(0.5 * x)).collect();
            let u = &grad * (dir / grad.norm());
            let delta = barrier_lp(&rows, &sphi, &floor, &u, 0.5 * h, h);
            let mut taken = false;
            let mut scale = 1.0;
            for _ in 0..8 {
                let rn: Vec<f64> = r
                    .iter()
                    .zip(delta.iter())
                    .map(|(a, b)| a + scale * b)
                    .collect();
                let gn = model.rasterise(&rn).expect("rasterise");
                if paint(&gn, shape, h, offset).labels == image.labels {
                    let v = own(&gn);
                    if dir * (v - *end) > 0.0 {
                        r = rn;
                        *end = v;
                        taken = true;
                    }
                    break;
                }
                scale *= 0.5;
            }
            if !taken {
                break;
            }
        }
    }
    (own0, ends[0], ends[1])
}

/// The round trips' clone model, their clones and the voxel size at 30 voxels per median
/// diameter.
fn roundtrip_setup() -> (CloneModel, Vec<Vec<f64>>, f64) {
    let (model, run) = crate::cases::parents::roundtrip_model().expect("round-trip clones");
    let k = cloner::DNA
        .iter()
        .position(|d| *d == Descriptor::EquivalentDiameter)
        .expect("diameter");
    let diameters: Vec<f64> = run
        .clones
        .iter()
        .map(|c| c.dna.as_ref().expect("dna")[k])
        .collect();
    let h = crate::cases::parents::median(&diameters)
        / crate::cases::parents::ROUNDTRIP_VOXELS_PER_DIAMETER;
    let radii = run.clones.into_iter().map(|c| c.radii).collect();
    (model, radii, h)
}

/// The least worst errors `(hi − lo)/(hi + lo)` of clones `which`, printed.
#[allow(clippy::print_stdout, reason = "the intervals")]
fn least_worst_errors(which: std::ops::Range<usize>) -> Vec<f64> {
    let (model, radii, h) = roundtrip_setup();
    which
        .map(|i| {
            let (own0, lo, hi) = identical_image_interval(&model, &radii[i], h);
            assert!(lo <= own0 && own0 <= hi);
            let bound = (hi - lo) / (hi + lo);
            println!(
                "clone {i}: own {own0:.3}, identical images {lo:.3} – {hi:.3}: least worst error {:.1} %",
                100.0 * bound
            );
            bound
        })
        .collect()
}

/// Clones 0 and 1 of the round trips at 30 voxels per median diameter: radii with an
/// identical image span own roundness 0.416–0.500 and 0.412–0.522 (clones' own 0.472 and
/// 0.494), so any reading of those images errs by at least 9.2 % and 11.8 % on one of the
/// three grains; the issue asks for 5 % on average. Slow in the test profile:
/// `cargo test --release -p validate -- --ignored roundtrip_ambiguity --nocapture`
/// (about 2 minutes).
#[test]
#[ignore = "search over radii: run in release with --ignored"]
fn roundtrip_ambiguity() {
    for (i, bound) in least_worst_errors(0..2).into_iter().enumerate() {
        assert!(bound > 0.05, "clone {i}: {bound}");
    }
}

/// All 40 clones of the round trips (about 40 minutes on one core in release): least
/// worst error 11.5 % on average (median 9.0 %, 2.0–38 %), above 5 % for 34 clones and
/// above 20 % for 5, so neither "≤ 5 % mean" nor "≤ 20 % worst" can hold for every set of
/// grains consistent with the images.
#[test]
#[ignore = "search over radii, about 40 minutes: run in release with --ignored"]
#[allow(clippy::print_stdout, reason = "the summary")]
fn roundtrip_ambiguity_all() {
    let bounds = least_worst_errors(0..crate::cases::parents::ROUNDTRIP_CLONES as usize);
    let mean = bounds.iter().sum::<f64>() / bounds.len() as f64;
    let worst = bounds.iter().fold(0.0f64, |a, b| a.max(*b));
    println!(
        "least worst error: mean {:.2} %, worst {:.1} %, above 5 %: {}, above 20 %: {}",
        100.0 * mean,
        100.0 * worst,
        bounds.iter().filter(|b| **b > 0.05).count(),
        bounds.iter().filter(|b| **b > 0.2).count()
    );
    assert!(mean > 0.05 && worst > 0.2, "{mean} {worst}");
}
