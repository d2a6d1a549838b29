//! cloner reproductions: GSC 2.0 clones of the default Ottawa-sand parents
//! (71 grains drawn at random from NIST's population) at the calibrated
//! configuration (`fixtures/calibrated/gsc2-ottawa.ron`, written by `cargo
//! xtask calibrate`) against Medina 2018, Tables 4–5, trial 4 (the seed's
//! best), and against the targets (average mean error ≤ 2 %, average
//! standard-deviation error ≤ 10 %, every KS ≤ 0.10: 71 parents against 500
//! clones, whose two-sample 5 % critical value is ≈ 0.17).
//! The run is deterministic, so it must also reproduce the committed scores.

use cloner::{Calibrated, CloneModel, Hooks, TABLES_4_5, score};

use crate::fixtures::{self, Table};
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

const CALIBRATED: &str = "gsc2-ottawa.ron";

pub(crate) fn cases() -> Vec<Case> {
    vec![Case {
        name: "cloner/gsc2018-trial4-calibrated",
        description: "GSC 2.0 clones of the 71 default Ottawa parents at the calibrated configuration: Tables 4–5 errors ≤ the seed's trial 4; issue targets; committed scores reproduced",
        fast: false,
        heavy: false,
        run: calibrated,
    }]
}

pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[];

fn err(e: impl std::fmt::Display) -> Error {
    Error::Computation {
        message: e.to_string(),
    }
}

/// Re-runs the committed calibration `fixtures/calibrated/<name>` on
/// `parents`: the configuration, its scores, and the run's accepted clones
/// and candidates drawn.
pub(crate) fn rerun_calibration(
    name: &str,
    parents: &cloner::Parents,
) -> Result<(Calibrated, cloner::Scores, usize, u64), Error> {
    let cal = Calibrated::from_ron(fixtures::calibrated(name)?).map_err(err)?;
    // as `cargo xtask calibrate` does: cloned without outputs, then scored
    // on the clones' level sets (the DNA output, bit for bit)
    let params = cloner::Params {
        outputs: cloner::Outputs {
            level_set: false,
            dna: false,
        },
        ..cal.params
    };
    let model = CloneModel::fit(parents, &params).map_err(err)?;
    let run = model.run(0..cal.clones, Hooks::default()).map_err(err)?;
    let s = score(parents.dna(), &model.measure_dna(&run.clones).map_err(err)?).map_err(err)?;
    Ok((cal, s, run.clones.len(), run.stats.attempts))
}

fn calibrated() -> Result<Vec<Check>, Error> {
    let parents = crate::grains::ottawa_parents()?;
    let (cal, s, clones, attempts) = rerun_calibration(CALIBRATED, &parents)?;
    let t4 = Table::reference("gsc2018_table4_mean_error_pct.csv")?;
    let t5 = Table::reference("gsc2018_table5_std_error_pct.csv")?;
    let mut out = Vec::new();
    for (k, d) in TABLES_4_5.iter().enumerate() {
        out.push(Check::new(
            format!("{d} mean error % <= seed trial 4"),
            t4.number(k, "trial_4")?,
            s.mean_error_pct[k],
            Tolerance::AtMost(0.0),
        ));
        out.push(Check::new(
            format!("{d} std error % <= seed trial 4"),
            t5.number(k, "trial_4")?,
            s.std_error_pct[k],
            Tolerance::AtMost(0.0),
        ));
        out.push(Check::new(
            format!("{d} KS <= 0.10 (target)"),
            0.10,
            s.ks[k],
            Tolerance::AtMost(0.0),
        ));
    }
    out.push(Check::new(
        "average mean error % <= seed trial 4",
        t4.number(4, "trial_4")?,
        s.mean_error_avg_pct,
        Tolerance::AtMost(0.0),
    ));
    out.push(Check::new(
        "average std error % <= seed trial 4",
        t5.number(4, "trial_4")?,
        s.std_error_avg_pct,
        Tolerance::AtMost(0.0),
    ));
    out.push(Check::new(
        "average mean error % <= 2 (target)",
        2.0,
        s.mean_error_avg_pct,
        Tolerance::AtMost(0.0),
    ));
    out.push(Check::new(
        "average std error % <= 10 (target)",
        10.0,
        s.std_error_avg_pct,
        Tolerance::AtMost(0.0),
    ));
    out.push(Check::new(
        "clones >= 500",
        500.0,
        clones as f64,
        Tolerance::AtLeast(0.0),
    ));
    out.push(Check::new(
        "average mean error reproduces the committed calibration",
        cal.scores.mean_error_avg_pct,
        s.mean_error_avg_pct,
        Tolerance::Relative(1e-6),
    ));
    out.push(Check::new(
        "candidates drawn reproduce the committed calibration",
        cal.attempts as f64,
        attempts as f64,
        Tolerance::Within(0.0),
    ));
    Ok(out)
}
