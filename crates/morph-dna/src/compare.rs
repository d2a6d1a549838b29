//! Comparison statistics between two populations (parents and clones):
//! relative errors of means and standard deviations in the format of
//! Medina 2018, Tables 4–5, two-sample Kolmogorov–Smirnov distance,
//! Wasserstein-1 distance and correlation-matrix differences.

use serde::{Deserialize, Serialize};

use crate::correlation::{CorrelationMethod, correlation_matrix};
use crate::error::{Error, Moment, Result};
use crate::stats::{check_len, check_sample, mean_unchecked, std_unchecked};
use crate::table::{Descriptor, DnaTable};

/// One row of Medina 2018, Tables 4 (mean) and 5 (standard deviation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MomentErrors {
    /// The descriptor.
    pub descriptor: Descriptor,
    /// `100 |mean_c − mean_r| / |mean_r|`, in percent.
    pub mean_error_pct: f64,
    /// `100 |std_c − std_r| / std_r` (sample std, divisor n − 1), in percent.
    pub std_error_pct: f64,
}

/// Medina 2018, Tables 4–5 for one candidate population: one row per
/// descriptor and the "Average error" row (arithmetic mean of the rows).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorTable {
    /// Per-descriptor errors.
    pub rows: Vec<MomentErrors>,
    /// Mean of `rows[..].mean_error_pct` (Table 4, "Average error").
    pub average_mean_error_pct: f64,
    /// Mean of `rows[..].std_error_pct` (Table 5, "Average error").
    pub average_std_error_pct: f64,
}

impl ErrorTable {
    /// Writes the table as CSV: header
    /// `morphological_parameter,mean_error_pct,std_error_pct`, one line per
    /// descriptor, then `average_error` (the layout of the reference tables).
    ///
    /// # Errors
    /// [`Error::Io`].
    pub fn write_csv(&self, mut w: impl std::io::Write) -> Result<()> {
        writeln!(w, "morphological_parameter,mean_error_pct,std_error_pct")?;
        for r in &self.rows {
            writeln!(
                w,
                "{},{},{}",
                r.descriptor, r.mean_error_pct, r.std_error_pct
            )?;
        }
        writeln!(
            w,
            "average_error,{},{}",
            self.average_mean_error_pct, self.average_std_error_pct
        )?;
        Ok(())
    }
}

/// Relative errors (percent) of the candidate's mean and standard deviation
/// with respect to the reference's, for `descriptors` (Medina 2018, §4.1).
///
/// # Errors
/// [`Error::NoDescriptors`] for an empty list, [`Error::MissingDescriptor`],
/// [`Error::TooFewSamples`] (either table below 2 grains),
/// [`Error::ZeroReference`] if a reference mean or std is zero.
pub fn moment_errors(
    reference: &DnaTable,
    candidate: &DnaTable,
    descriptors: &[Descriptor],
) -> Result<ErrorTable> {
    if descriptors.is_empty() {
        return Err(Error::NoDescriptors);
    }
    reference.require_grains(2)?;
    candidate.require_grains(2)?;
    let mut rows = Vec::with_capacity(descriptors.len());
    for d in descriptors {
        let (r, c) = (reference.column(*d)?, candidate.column(*d)?);
        let (mr, mc) = (mean_unchecked(r), mean_unchecked(c));
        let (sr, sc) = (std_unchecked(r), std_unchecked(c));
        if mr == 0.0 {
            return Err(Error::ZeroReference {
                descriptor: *d,
                moment: Moment::Mean,
            });
        }
        if sr == 0.0 {
            return Err(Error::ZeroReference {
                descriptor: *d,
                moment: Moment::StandardDeviation,
            });
        }
        rows.push(MomentErrors {
            descriptor: *d,
            mean_error_pct: 100.0 * (mc - mr).abs() / mr.abs(),
            std_error_pct: 100.0 * (sc - sr).abs() / sr,
        });
    }
    let n = rows.len() as f64;
    Ok(ErrorTable {
        average_mean_error_pct: rows.iter().map(|r| r.mean_error_pct).sum::<f64>() / n,
        average_std_error_pct: rows.iter().map(|r| r.std_error_pct).sum::<f64>() / n,
        rows,
    })
}

fn sorted(x: &[f64]) -> Result<Vec<f64>> {
    check_len(x, 1)?;
    check_sample(x)?;
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    Ok(s)
}

/// Two-sample Kolmogorov–Smirnov distance `sup_x |F_a(x) − F_b(x)|` of the
/// empirical CDFs (exact, ties handled by stepping past equal values).
///
/// # Errors
/// [`Error::TooFewSamples`] for an empty sample, [`Error::NonFiniteSample`].
pub fn ks_distance(a: &[f64], b: &[f64]) -> Result<f64> {
    let (a, b) = (sorted(a)?, sorted(b)?);
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (mut i, mut j, mut d) = (0usize, 0usize, 0.0f64);
    while i < a.len() && j < b.len() {
        let x = a[i].min(b[j]);
        while i < a.len() && a[i] <= x {
            i += 1;
        }
        while j < b.len() && b[j] <= x {
            j += 1;
        }
        d = d.max((i as f64 / na - j as f64 / nb).abs());
    }
    Ok(d)
}

/// One-sample Kolmogorov–Smirnov distance `sup_x |F_n(x) − F(x)|` against a
/// continuous CDF `cdf`.
///
/// # Errors
/// As [`ks_distance`].
pub fn ks_distance_to_cdf(x: &[f64], cdf: impl Fn(f64) -> f64) -> Result<f64> {
    let s = sorted(x)?;
    let n = s.len() as f64;
    Ok(s.iter().enumerate().fold(0.0f64, |d, (k, v)| {
        let f = cdf(*v);
        d.max((f - k as f64 / n).abs())
            .max((f - (k + 1) as f64 / n).abs())
    }))
}

/// Wasserstein-1 (earth mover's) distance `∫ |F_a − F_b| dx` between the
/// empirical distributions, exact.
///
/// # Errors
/// As [`ks_distance`].
pub fn wasserstein1(a: &[f64], b: &[f64]) -> Result<f64> {
    let (a, b) = (sorted(a)?, sorted(b)?);
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (mut i, mut j) = (0usize, 0usize);
    let mut x = a[0].min(b[0]);
    let mut w = 0.0;
    while i < a.len() || j < b.len() {
        let next = match (a.get(i), b.get(j)) {
            (Some(p), Some(q)) => p.min(*q),
            (Some(p), None) => *p,
            (None, Some(q)) => *q,
            (None, None) => break,
        };
        w += (i as f64 / na - j as f64 / nb).abs() * (next - x);
        x = next;
        while i < a.len() && a[i] <= x {
            i += 1;
        }
        while j < b.len() && b[j] <= x {
            j += 1;
        }
    }
    Ok(w)
}

/// Distribution distances of one descriptor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DistributionDistance {
    /// The descriptor.
    pub descriptor: Descriptor,
    /// Two-sample Kolmogorov–Smirnov distance.
    pub ks: f64,
    /// Wasserstein-1 distance (descriptor units).
    pub wasserstein1: f64,
}

/// Everything [`compare_populations`] measures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PopulationComparison {
    /// Medina 2018, Tables 4–5.
    pub errors: ErrorTable,
    /// KS and W1 per descriptor.
    pub distances: Vec<DistributionDistance>,
    /// Largest absolute difference of the correlation matrices.
    pub correlation_max_abs_difference: f64,
    /// Frobenius norm of the difference of the correlation matrices.
    pub correlation_frobenius_difference: f64,
}

/// Compares a candidate population (clones) with a reference (parents) on
/// the given descriptors.
///
/// # Errors
/// Those of [`moment_errors`], and [`Error::ConstantDescriptor`] from the
/// correlation matrices.
pub fn compare_populations(
    reference: &DnaTable,
    candidate: &DnaTable,
    descriptors: &[Descriptor],
    method: CorrelationMethod,
) -> Result<PopulationComparison> {
    let errors = moment_errors(reference, candidate, descriptors)?;
    let distances = descriptors
        .iter()
        .map(|d| {
            let (r, c) = (reference.column(*d)?, candidate.column(*d)?);
            Ok(DistributionDistance {
                descriptor: *d,
                ks: ks_distance(r, c)?,
                wasserstein1: wasserstein1(r, c)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let cr = correlation_matrix(&reference.select(descriptors)?, method)?;
    let cc = correlation_matrix(&candidate.select(descriptors)?, method)?;
    Ok(PopulationComparison {
        errors,
        distances,
        correlation_max_abs_difference: cr.max_abs_difference(&cc)?,
        correlation_frobenius_difference: cr.frobenius_difference(&cc)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use Descriptor::*;
    use approx::assert_relative_eq;

    #[test]
    fn moment_errors_by_hand() {
        let r = DnaTable::from_columns(
            vec![AspectRatio, Roundness],
            vec![vec![1.0, 3.0], vec![2.0, 4.0]],
        )
        .expect("ok");
        // AspectRatio: mean 2 → 2.2 (10 %), std √2 → 1.1·√2 (10 %).
        // Roundness: mean 3 → 2.4 (20 %), std √2 → 0.5·√2 (50 %).
        let c = DnaTable::from_columns(
            vec![Roundness, AspectRatio],
            vec![vec![1.9, 2.9], vec![1.1, 3.3]],
        )
        .expect("ok");
        let t = moment_errors(&r, &c, &[AspectRatio, Roundness]).expect("ok");
        assert_relative_eq!(t.rows[0].mean_error_pct, 10.0, epsilon = 1e-12);
        assert_relative_eq!(t.rows[0].std_error_pct, 10.0, epsilon = 1e-12);
        assert_relative_eq!(t.rows[1].mean_error_pct, 20.0, epsilon = 1e-12);
        assert_relative_eq!(t.rows[1].std_error_pct, 50.0, epsilon = 1e-12);
        assert_relative_eq!(t.average_mean_error_pct, 15.0, epsilon = 1e-12);
        assert_relative_eq!(t.average_std_error_pct, 30.0, epsilon = 1e-12);
        let mut buf = Vec::new();
        t.write_csv(&mut buf).expect("write");
        let s = String::from_utf8(buf).expect("utf8");
        assert!(
            s.starts_with("morphological_parameter,mean_error_pct,std_error_pct\naspect_ratio,")
        );
        assert!(s.contains("\naverage_error,"));
    }

    #[test]
    fn moment_errors_degenerate() {
        let r = DnaTable::from_columns(vec![Volume], vec![vec![1.0, 1.0]]).expect("ok");
        assert_eq!(
            moment_errors(&r, &r, &[Volume]),
            Err(Error::ZeroReference {
                descriptor: Volume,
                moment: Moment::StandardDeviation
            })
        );
        let z = DnaTable::from_columns(vec![Volume], vec![vec![-1.0, 1.0]]).expect("ok");
        assert!(matches!(
            moment_errors(&z, &z, &[Volume]),
            Err(Error::ZeroReference {
                moment: Moment::Mean,
                ..
            })
        ));
        let one = DnaTable::from_columns(vec![Volume], vec![vec![1.0]]).expect("ok");
        assert!(matches!(
            moment_errors(&r, &one, &[Volume]),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            moment_errors(&r, &r, &[Roundness]),
            Err(Error::MissingDescriptor { .. })
        ));
        assert_eq!(moment_errors(&r, &r, &[]), Err(Error::NoDescriptors));
    }

    #[test]
    fn ks_and_wasserstein_oracles() {
        assert_relative_eq!(
            ks_distance(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0]).expect("ok"),
            0.0
        );
        assert_relative_eq!(ks_distance(&[1.0, 2.0], &[3.0, 4.0]).expect("ok"), 1.0);
        // F_a jumps to 1/2 at 1, F_b to 1/3 at 1 (ties across samples).
        assert_relative_eq!(ks_distance(&[1.0, 5.0], &[1.0, 2.0, 3.0]).expect("ok"), 0.5);
        assert_relative_eq!(wasserstein1(&[0.0], &[2.5]).expect("ok"), 2.5);
        // Shift of every point by 0.3.
        let a = [0.1, 0.7, 0.2, 3.0];
        let b: Vec<f64> = a.iter().map(|v| v + 0.3).collect();
        assert_relative_eq!(wasserstein1(&a, &b).expect("ok"), 0.3, epsilon = 1e-12);
        // Uniform mass at {0, 1} vs a point at 0.5: W1 = 0.5.
        assert_relative_eq!(wasserstein1(&[0.0, 1.0], &[0.5]).expect("ok"), 0.5);
        assert_relative_eq!(ks_distance_to_cdf(&[0.5], |x| x).expect("ok"), 0.5);
        assert!(matches!(
            ks_distance(&[], &[1.0]),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            wasserstein1(&[1.0], &[f64::NAN]),
            Err(Error::NonFiniteSample { .. })
        ));
    }

    #[test]
    fn identical_populations_compare_to_zero() {
        let t = DnaTable::from_columns(
            vec![AspectRatio, Roundness],
            vec![vec![0.5, 0.6, 0.9, 0.7], vec![0.3, 0.2, 0.5, 0.4]],
        )
        .expect("ok");
        let c = compare_populations(
            &t,
            &t,
            &[Roundness, AspectRatio],
            CorrelationMethod::Spearman,
        )
        .expect("ok");
        assert_relative_eq!(c.errors.average_mean_error_pct, 0.0);
        assert_relative_eq!(c.correlation_frobenius_difference, 0.0);
        assert!(
            c.distances
                .iter()
                .all(|d| d.ks == 0.0 && d.wasserstein1 == 0.0)
        );
    }
}
