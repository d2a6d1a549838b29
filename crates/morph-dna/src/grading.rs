//! Grading (particle-size distribution) curves and the coefficients of
//! uniformity and curvature (Medina 2018, §4, Fig. 12).
//!
//! # Conventions
//!
//! * The passing percentage at diameter `d` is the share of the population,
//!   **by volume** (mass at uniform density, as a sieve analysis measures;
//!   ASTM D6913) or **by count** (what Medina 2018's per-grain histograms
//!   show), of grains whose diameter is `≤ d`. Volume weights are `d³` of the
//!   given (equivalent-sphere) diameters, or caller-supplied volumes/masses.
//! * The curve's points are `(d_k, P_k)` for the distinct sorted diameters,
//!   `P_k` the cumulative percentage through `d_k` (ties merged), as a sieve
//!   curve joins its measured points.
//! * `D_p` is read off the curve by interpolating between neighbouring
//!   points, **linearly in log d** by default (grading curves are drawn on a
//!   semi-log chart, Medina 2018 Fig. 12) or linearly in `d`. Below the first
//!   point `P_1` it is `d_min`; `P_n = 100` so above it cannot occur.
//! * `Cu = D60 / D10`, `Cc = D30² / (D60 · D10)` (standard; ASTM D2487).
//!   Medina 2018 prints `Cc = D30 / (D60 × D10)` (reference NOTES G5); that
//!   dimensional variant is kept as
//!   [`GradingCoefficients::cc_as_printed_medina2018`] for comparison only.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::stats::check_sample;

/// How grains are weighted in the passing percentage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum GradingWeight {
    /// By volume ∝ d³ (mass at uniform density): the sieve convention.
    #[default]
    Volume,
    /// By number of grains.
    Count,
}

/// How `D_p` is interpolated between curve points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum GradingInterpolation {
    /// Linear in `log d` (semi-log grading chart).
    #[default]
    LogDiameter,
    /// Linear in `d`.
    Linear,
}

/// A passing-percentage curve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GradingCurve {
    /// Distinct diameters, increasing.
    pub diameters: Vec<f64>,
    /// Cumulative passing percentage at each diameter, increasing to 100.
    pub passing_percent: Vec<f64>,
}

/// Characteristic diameters and coefficients of a [`GradingCurve`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GradingCoefficients {
    /// Diameter with 10 % passing.
    pub d10: f64,
    /// Diameter with 30 % passing.
    pub d30: f64,
    /// Diameter with 60 % passing.
    pub d60: f64,
    /// Coefficient of uniformity `D60 / D10`.
    pub cu: f64,
    /// Coefficient of curvature `D30² / (D60 D10)` (standard definition).
    pub cc: f64,
    /// `D30 / (D60 D10)` as printed in Medina 2018, §4 (not dimensionless;
    /// for comparison with the seed's numbers only).
    pub cc_as_printed_medina2018: f64,
}

fn check_positive(what: &'static str, x: &[f64]) -> Result<()> {
    check_sample(x)?;
    match x.iter().position(|v| *v <= 0.0) {
        Some(index) => Err(Error::NonPositive {
            what,
            index,
            value: x[index],
        }),
        None => Ok(()),
    }
}

impl GradingCurve {
    /// Curve of equivalent diameters with the given weighting.
    ///
    /// # Errors
    /// [`Error::TooFewSamples`] for no grain, [`Error::NonFiniteSample`],
    /// [`Error::NonPositive`] for a diameter ≤ 0.
    pub fn from_diameters(diameters: &[f64], weight: GradingWeight) -> Result<Self> {
        check_positive("diameter", diameters)?;
        let w: Vec<f64> = match weight {
            GradingWeight::Count => vec![1.0; diameters.len()],
            GradingWeight::Volume => diameters.iter().map(|d| d * d * d).collect(),
        };
        Self::from_weighted(diameters, &w)
    }

    /// Curve of diameters with caller-supplied weights (volumes or masses).
    ///
    /// # Errors
    /// As [`GradingCurve::from_diameters`], plus [`Error::LengthMismatch`] and
    /// [`Error::NonPositive`] for a weight ≤ 0.
    pub fn from_weighted(diameters: &[f64], weights: &[f64]) -> Result<Self> {
        crate::stats::check_len(diameters, 1)?;
        if diameters.len() != weights.len() {
            return Err(Error::LengthMismatch {
                left: diameters.len(),
                right: weights.len(),
            });
        }
        check_positive("diameter", diameters)?;
        check_positive("weight", weights)?;
        let mut idx: Vec<usize> = (0..diameters.len()).collect();
        idx.sort_by(|&a, &b| diameters[a].total_cmp(&diameters[b]));
        let total: f64 = weights.iter().sum();
        if !total.is_finite() {
            return Err(Error::InvalidParameter {
                name: "total weight",
                value: total,
                reason: "must be finite",
            });
        }
        let mut ds: Vec<f64> = Vec::new();
        let mut ps: Vec<f64> = Vec::new();
        let mut acc = 0.0;
        for k in idx {
            acc += weights[k];
            let p = 100.0 * acc / total;
            match ds.last() {
                Some(last) if *last == diameters[k] => {
                    if let Some(lp) = ps.last_mut() {
                        *lp = p;
                    }
                }
                _ => {
                    ds.push(diameters[k]);
                    ps.push(p);
                }
            }
        }
        if let Some(lp) = ps.last_mut() {
            *lp = 100.0;
        }
        Ok(Self {
            diameters: ds,
            passing_percent: ps,
        })
    }

    /// Re-checks a curve whose public fields may have been edited: equal,
    /// non-zero lengths, positive increasing diameters, non-decreasing
    /// percentages in [0, 100].
    ///
    /// # Errors
    /// [`Error::TooFewSamples`], [`Error::LengthMismatch`],
    /// [`Error::NonPositive`], [`Error::InvalidParameter`].
    pub fn validate(&self) -> Result<()> {
        crate::stats::check_len(&self.diameters, 1)?;
        if self.diameters.len() != self.passing_percent.len() {
            return Err(Error::LengthMismatch {
                left: self.diameters.len(),
                right: self.passing_percent.len(),
            });
        }
        check_positive("diameter", &self.diameters)?;
        check_sample(&self.passing_percent)?;
        if self.diameters.windows(2).any(|w| w[1] <= w[0]) {
            return Err(Error::InvalidParameter {
                name: "diameters",
                value: f64::NAN,
                reason: "must be strictly increasing",
            });
        }
        if self.passing_percent.windows(2).any(|w| w[1] < w[0])
            || self
                .passing_percent
                .iter()
                .any(|p| !(0.0..=100.0).contains(p))
        {
            return Err(Error::InvalidParameter {
                name: "passing_percent",
                value: f64::NAN,
                reason: "must be non-decreasing within [0, 100]",
            });
        }
        Ok(())
    }

    /// Passing percentage at `d` (the step curve: share of grains ≤ d).
    pub fn passing_at(&self, d: f64) -> f64 {
        match self.diameters.partition_point(|x| *x <= d) {
            0 => 0.0,
            k => self.passing_percent.get(k - 1).copied().unwrap_or(100.0),
        }
    }

    /// Diameter `D_p` at `percent` passing, `0 < percent ≤ 100`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a percentage outside (0, 100], and
    /// [`GradingCurve::validate`]'s errors.
    pub fn diameter_at(&self, percent: f64, interpolation: GradingInterpolation) -> Result<f64> {
        self.validate()?;
        if !(percent > 0.0 && percent <= 100.0) {
            return Err(Error::InvalidParameter {
                name: "percent",
                value: percent,
                reason: "must be in (0, 100]",
            });
        }
        let k = self.passing_percent.partition_point(|p| *p < percent);
        if k == 0 {
            return Ok(self.diameters[0]);
        }
        let k = k.min(self.diameters.len() - 1);
        let (p0, p1) = (self.passing_percent[k - 1], self.passing_percent[k]);
        let (d0, d1) = (self.diameters[k - 1], self.diameters[k]);
        let t = (percent - p0) / (p1 - p0);
        Ok(match interpolation {
            GradingInterpolation::Linear => d0 + t * (d1 - d0),
            GradingInterpolation::LogDiameter => (d0.ln() + t * (d1.ln() - d0.ln())).exp(),
        })
    }

    /// D10, D30, D60, Cu and Cc (both variants).
    ///
    /// # Errors
    /// [`GradingCurve::validate`]'s errors (none for a curve built by this
    /// module).
    pub fn coefficients(&self, interpolation: GradingInterpolation) -> Result<GradingCoefficients> {
        let d10 = self.diameter_at(10.0, interpolation)?;
        let d30 = self.diameter_at(30.0, interpolation)?;
        let d60 = self.diameter_at(60.0, interpolation)?;
        Ok(GradingCoefficients {
            d10,
            d30,
            d60,
            cu: d60 / d10,
            cc: d30 * d30 / (d60 * d10),
            cc_as_printed_medina2018: d30 / (d60 * d10),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use GradingInterpolation::*;
    use approx::assert_relative_eq;

    #[test]
    fn count_curve_of_one_to_hundred() {
        let d: Vec<f64> = (1..=100).map(f64::from).collect();
        let c = GradingCurve::from_diameters(&d, GradingWeight::Count).expect("ok");
        for interp in [Linear, LogDiameter] {
            let g = c.coefficients(interp).expect("ok");
            assert_relative_eq!(g.d10, 10.0, epsilon = 1e-12);
            assert_relative_eq!(g.d30, 30.0, epsilon = 1e-12);
            assert_relative_eq!(g.d60, 60.0, epsilon = 1e-12);
            assert_relative_eq!(g.cu, 6.0, epsilon = 1e-12);
            assert_relative_eq!(g.cc, 1.5, epsilon = 1e-12);
            assert_relative_eq!(g.cc_as_printed_medina2018, 0.05, epsilon = 1e-12);
        }
        assert_relative_eq!(c.passing_at(0.5), 0.0);
        assert_relative_eq!(c.passing_at(42.5), 42.0);
        assert_relative_eq!(c.passing_at(1e9), 100.0);
    }

    #[test]
    fn interpolation_between_points_log_and_linear() {
        let c = GradingCurve::from_diameters(&[1.0, 10.0], GradingWeight::Count).expect("ok");
        assert_eq!(c.passing_percent, vec![50.0, 100.0]);
        assert_relative_eq!(
            c.diameter_at(60.0, Linear).expect("ok"),
            2.8,
            epsilon = 1e-12
        );
        assert_relative_eq!(
            c.diameter_at(60.0, LogDiameter).expect("ok"),
            10f64.powf(0.2),
            epsilon = 1e-12
        );
        // Below the first point: the smallest diameter.
        assert_relative_eq!(c.diameter_at(10.0, Linear).expect("ok"), 1.0);
        assert_relative_eq!(c.diameter_at(100.0, Linear).expect("ok"), 10.0);
        assert!(c.diameter_at(0.0, Linear).is_err());
        assert!(c.diameter_at(101.0, Linear).is_err());
        assert!(c.diameter_at(f64::NAN, Linear).is_err());
    }

    #[test]
    fn volume_weighting_and_ties() {
        // Diameters 1 and 2: volumes 1 and 8, so 1/9 of the volume passes at 1.
        let c = GradingCurve::from_diameters(&[2.0, 1.0, 1.0], GradingWeight::Volume).expect("ok");
        assert_eq!(c.diameters, vec![1.0, 2.0]);
        assert_relative_eq!(c.passing_percent[0], 200.0 / 10.0);
        assert_relative_eq!(c.passing_percent[1], 100.0);
        let w = GradingCurve::from_weighted(&[1.0, 2.0], &[3.0, 1.0]).expect("ok");
        assert_relative_eq!(w.passing_percent[0], 75.0);
    }

    #[test]
    fn bad_grading_input() {
        assert!(matches!(
            GradingCurve::from_diameters(&[], GradingWeight::Count),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            GradingCurve::from_diameters(&[1.0, 0.0], GradingWeight::Count),
            Err(Error::NonPositive { index: 1, .. })
        ));
        assert!(matches!(
            GradingCurve::from_diameters(&[1.0, f64::INFINITY], GradingWeight::Volume),
            Err(Error::NonFiniteSample { index: 1, .. })
        ));
        assert!(matches!(
            GradingCurve::from_weighted(&[1.0], &[1.0, 2.0]),
            Err(Error::LengthMismatch { .. })
        ));
        let edited = GradingCurve {
            diameters: vec![],
            passing_percent: vec![],
        };
        assert!(matches!(
            edited.coefficients(Linear),
            Err(Error::TooFewSamples { .. })
        ));
        let edited = GradingCurve {
            diameters: vec![1.0, 2.0],
            passing_percent: vec![100.0],
        };
        assert!(matches!(
            edited.diameter_at(50.0, Linear),
            Err(Error::LengthMismatch { .. })
        ));
        assert_relative_eq!(edited.passing_at(5.0), 100.0);
        let edited = GradingCurve {
            diameters: vec![2.0, 1.0],
            passing_percent: vec![50.0, 100.0],
        };
        assert!(matches!(
            edited.diameter_at(50.0, Linear),
            Err(Error::InvalidParameter { .. })
        ));
        // A single grain is a valid (degenerate) curve: every D_p is its diameter.
        let one = GradingCurve::from_diameters(&[2.0], GradingWeight::Volume).expect("ok");
        let g = one.coefficients(LogDiameter).expect("ok");
        assert_relative_eq!(g.cu, 1.0);
        assert_relative_eq!(g.cc, 1.0);
    }
}
