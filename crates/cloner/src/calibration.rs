//! Scoring clones against their parents in the format of Medina 2018,
//! Tables 4–5, and the calibrated configuration written by
//! `cargo xtask calibrate` (`fixtures/calibrated/*.ron`).

use morph_dna::{
    CorrelationMethod, Descriptor, DnaTable, GradingCurve, GradingInterpolation, GradingWeight,
    compare_populations,
};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::TABLES_4_5;
use crate::params::Params;

/// Clone-vs-parent scores of one configuration ([`TABLES_4_5`] order:
/// aspect ratio, grain diameter, roundness, volume/surface ratio).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// Mean errors `100 |mean_c − mean_p| / mean_p` (Table 4).
    pub mean_error_pct: [f64; 4],
    /// Standard-deviation errors (Table 5, divisor n − 1).
    pub std_error_pct: [f64; 4],
    /// Two-sample Kolmogorov–Smirnov distances.
    pub ks: [f64; 4],
    /// Average of the mean errors ("Average error" of Table 4).
    pub mean_error_avg_pct: f64,
    /// Average of the standard-deviation errors (Table 5).
    pub std_error_avg_pct: f64,
    /// Largest KS distance.
    pub ks_max: f64,
    /// Parents' `(Cu, Cc)` of the volume-weighted grading curve.
    pub cu_cc_parents: [f64; 2],
    /// Clones' `(Cu, Cc)`.
    pub cu_cc_clones: [f64; 2],
}

fn grading(dna: &DnaTable) -> Result<[f64; 2]> {
    let d = dna.column(Descriptor::EquivalentDiameter)?;
    let g = GradingCurve::from_diameters(d, GradingWeight::Volume)?;
    let c = g.coefficients(GradingInterpolation::LogDiameter)?;
    Ok([c.cu, c.cc])
}

/// Scores `clones` against `parents` (both with the [`TABLES_4_5`]
/// descriptors and the equivalent diameter).
///
/// # Errors
/// `morph-dna` errors ([`Error::MorphDna`]): missing descriptors, fewer than
/// two grains, a zero reference mean or deviation.
pub fn score(parents: &DnaTable, clones: &DnaTable) -> Result<Scores> {
    let cmp = compare_populations(parents, clones, &TABLES_4_5, CorrelationMethod::Pearson)?;
    let mut mean = [0.0; 4];
    let mut std = [0.0; 4];
    let mut ks = [0.0; 4];
    for (k, d) in TABLES_4_5.iter().enumerate() {
        let missing = || Error::MorphDna {
            message: format!("comparison lacks {d}"),
        };
        let e = cmp
            .errors
            .rows
            .iter()
            .find(|r| r.descriptor == *d)
            .ok_or_else(missing)?;
        mean[k] = e.mean_error_pct;
        std[k] = e.std_error_pct;
        ks[k] = cmp
            .distances
            .iter()
            .find(|x| x.descriptor == *d)
            .ok_or_else(missing)?
            .ks;
    }
    Ok(Scores {
        mean_error_avg_pct: mean.iter().sum::<f64>() / 4.0,
        std_error_avg_pct: std.iter().sum::<f64>() / 4.0,
        ks_max: ks.iter().fold(0.0f64, |a, b| a.max(*b)),
        mean_error_pct: mean,
        std_error_pct: std,
        ks,
        cu_cc_parents: grading(parents)?,
        cu_cc_clones: grading(clones)?,
    })
}

/// The calibrated configuration (`fixtures/calibrated/*.ron`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibrated {
    /// Name of the chosen configuration in the sweep.
    pub name: String,
    /// Its parameters.
    pub params: Params,
    /// Clones it was scored with (indices `0..clones`).
    pub clones: u64,
    /// Number of parents.
    pub parents: usize,
    /// Its scores.
    pub scores: Scores,
    /// Candidates drawn for those clones (a digest of the run: runs are
    /// deterministic).
    pub attempts: u64,
}

impl Calibrated {
    /// Pretty RON.
    ///
    /// # Errors
    /// [`Error::Ron`].
    pub fn to_ron(&self) -> Result<String> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).map_err(|e| {
            Error::Ron {
                message: e.to_string(),
            }
        })
    }

    /// Parses and validates.
    ///
    /// # Errors
    /// [`Error::Ron`] (with the position) and [`Params::validate`]'s errors.
    pub fn from_ron(text: &str) -> Result<Self> {
        let c: Self = ron::from_str(text).map_err(|e| Error::Ron {
            message: e.to_string(),
        })?;
        c.params.validate()?;
        Ok(c)
    }
}
