//! 1D and 2D histograms with configurable bin counts (Medina 2018, §2.1 and
//! Table 3: 50 bins in GSC 2.0).
//!
//! Bins are equal-width on a closed range `[min, max]`; bin `k` is
//! `[min + k w, min + (k + 1) w)`, the last bin also takes `max`. Samples
//! outside the range are counted in `outside` and otherwise ignored. When no
//! range is given it is the sample's `[min, max]`. Empty bins are legal and
//! have density zero; a histogram with no sample inside its range is an error.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::stats::{check_sample, constant_value};

/// Largest number of bins of an axis and of cells of a 2D grid or table
/// (2²⁶ ≈ 6.7 × 10⁷): larger requests are an [`Error::CountTooLarge`]
/// rather than an allocation failure.
pub const MAX_CELLS: usize = 1 << 26;

/// `a · b` if it does not exceed [`MAX_CELLS`].
pub(crate) fn checked_cells(what: &'static str, a: usize, b: usize) -> Result<usize> {
    match a.checked_mul(b) {
        Some(n) if n <= MAX_CELLS => Ok(n),
        other => Err(Error::CountTooLarge {
            what,
            max: MAX_CELLS,
            value: other.unwrap_or(usize::MAX),
        }),
    }
}

/// An equal-width binning of a closed interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BinAxis {
    /// Lower edge.
    pub min: f64,
    /// Upper edge.
    pub max: f64,
    /// Number of bins (≥ 1).
    pub bins: usize,
}

impl BinAxis {
    /// A validated axis.
    ///
    /// # Errors
    /// [`Error::CountTooSmall`] for zero bins, [`Error::InvalidRange`] unless
    /// `min < max`, both finite.
    pub fn new(min: f64, max: f64, bins: usize) -> Result<Self> {
        let a = Self { min, max, bins };
        a.validate()?;
        Ok(a)
    }

    /// Checks the axis (see [`BinAxis::new`]).
    ///
    /// # Errors
    /// As [`BinAxis::new`].
    pub fn validate(&self) -> Result<()> {
        if self.bins == 0 {
            return Err(Error::CountTooSmall {
                what: "bins",
                min: 1,
                value: 0,
            });
        }
        checked_cells("bins", self.bins, 1)?;
        let ordered = self.min.is_finite() && self.max.is_finite() && self.min < self.max;
        let width = (self.max - self.min) / self.bins as f64;
        if !ordered || !width.is_normal() {
            return Err(Error::InvalidRange {
                min: self.min,
                max: self.max,
            });
        }
        Ok(())
    }

    /// The axis spanning a sample's range.
    ///
    /// # Errors
    /// [`Error::TooFewSamples`] for an empty sample, [`Error::NonFiniteSample`],
    /// [`Error::ConstantSample`] (no range to bin), plus [`BinAxis::new`]'s.
    pub fn spanning(x: &[f64], bins: usize) -> Result<Self> {
        crate::stats::check_len(x, 1)?;
        check_sample(x)?;
        if let Some(value) = constant_value(x) {
            return Err(Error::ConstantSample { value });
        }
        let (lo, hi) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        Self::new(lo, hi, bins)
    }

    /// Bin width.
    pub fn width(&self) -> f64 {
        (self.max - self.min) / self.bins as f64
    }

    /// Centre of bin `k`.
    pub fn center(&self, k: usize) -> f64 {
        self.min + (k as f64 + 0.5) * self.width()
    }

    /// Lower edge of bin `k` (`k = bins` gives `max`).
    pub fn edge(&self, k: usize) -> f64 {
        if k >= self.bins {
            self.max
        } else {
            self.min + k as f64 * self.width()
        }
    }

    /// Bin holding `x`, `None` outside `[min, max]` (or NaN).
    pub fn bin_of(&self, x: f64) -> Option<usize> {
        if !(x >= self.min && x <= self.max) {
            return None;
        }
        let k = ((x - self.min) / self.width()) as usize;
        Some(k.min(self.bins - 1))
    }
}

/// Counts of a sample in the bins of one [`BinAxis`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Histogram1d {
    /// The binning.
    pub axis: BinAxis,
    /// Count per bin.
    pub counts: Vec<u64>,
    /// Samples outside the axis range.
    pub outside: u64,
}

impl Histogram1d {
    /// Histogram of `x` with `bins` bins over `range` (or the sample's range).
    ///
    /// # Errors
    /// [`Error::NonFiniteSample`], axis errors of [`BinAxis::new`] /
    /// [`BinAxis::spanning`], [`Error::EmptyHistogram`] if no sample falls
    /// inside the range.
    pub fn new(x: &[f64], bins: usize, range: Option<(f64, f64)>) -> Result<Self> {
        check_sample(x)?;
        let axis = match range {
            Some((a, b)) => BinAxis::new(a, b, bins)?,
            None => BinAxis::spanning(x, bins)?,
        };
        let mut counts = vec![0u64; bins];
        let mut outside = 0;
        for v in x {
            match axis.bin_of(*v) {
                Some(k) => counts[k] += 1,
                None => outside += 1,
            }
        }
        if counts.iter().all(|c| *c == 0) {
            return Err(Error::EmptyHistogram);
        }
        Ok(Self {
            axis,
            counts,
            outside,
        })
    }

    /// Number of samples inside the range (> 0).
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// Probability density per bin, `count / (total · width)`, normalised over
    /// the samples inside the range.
    ///
    /// A histogram whose public fields were edited to hold no count gives
    /// zeros rather than NaN.
    pub fn density(&self) -> Vec<f64> {
        let total = self.total() as f64 * self.axis.width();
        let norm = if total > 0.0 { 1.0 / total } else { 0.0 };
        self.counts.iter().map(|c| *c as f64 * norm).collect()
    }

    /// Re-checks a histogram whose public fields may have been edited.
    ///
    /// # Errors
    /// Axis errors, [`Error::RaggedTable`], [`Error::EmptyHistogram`].
    pub fn validate(&self) -> Result<()> {
        self.axis.validate()?;
        if self.counts.len() != self.axis.bins {
            return Err(Error::RaggedTable {
                what: "histogram",
                index: 0,
                expected: self.axis.bins,
                found: self.counts.len(),
            });
        }
        if self.total() == 0 {
            return Err(Error::EmptyHistogram);
        }
        Ok(())
    }
}

/// Joint counts of paired samples on an `x.bins × y.bins` grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Histogram2d {
    /// Binning of the first variable.
    pub x: BinAxis,
    /// Binning of the second variable.
    pub y: BinAxis,
    /// Counts, `counts[ix * y.bins + iy]`.
    pub counts: Vec<u64>,
    /// Pairs with at least one coordinate outside its range.
    pub outside: u64,
}

impl Histogram2d {
    /// Histogram of the pairs `(x[k], y[k])`.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`], [`Error::NonFiniteSample`], axis errors,
    /// [`Error::EmptyHistogram`].
    pub fn new(
        x: &[f64],
        y: &[f64],
        bins: (usize, usize),
        x_range: Option<(f64, f64)>,
        y_range: Option<(f64, f64)>,
    ) -> Result<Self> {
        if x.len() != y.len() {
            return Err(Error::LengthMismatch {
                left: x.len(),
                right: y.len(),
            });
        }
        check_sample(x)?;
        check_sample(y)?;
        let ax = match x_range {
            Some((a, b)) => BinAxis::new(a, b, bins.0)?,
            None => BinAxis::spanning(x, bins.0)?,
        };
        let ay = match y_range {
            Some((a, b)) => BinAxis::new(a, b, bins.1)?,
            None => BinAxis::spanning(y, bins.1)?,
        };
        let mut counts = vec![0u64; checked_cells("cells", ax.bins, ay.bins)?];
        let mut outside = 0;
        for (u, v) in x.iter().zip(y) {
            match (ax.bin_of(*u), ay.bin_of(*v)) {
                (Some(i), Some(j)) => counts[i * ay.bins + j] += 1,
                _ => outside += 1,
            }
        }
        if counts.iter().all(|c| *c == 0) {
            return Err(Error::EmptyHistogram);
        }
        Ok(Self {
            x: ax,
            y: ay,
            counts,
            outside,
        })
    }

    /// Count of cell `(ix, iy)`, `None` out of range.
    pub fn count(&self, ix: usize, iy: usize) -> Option<u64> {
        (ix < self.x.bins && iy < self.y.bins).then(|| self.counts[ix * self.y.bins + iy])
    }

    /// Number of pairs inside the grid (> 0).
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// Density per cell, `count / (total · wx · wy)`, in the layout of `counts`.
    ///
    /// A histogram whose public fields were edited to hold no count gives
    /// zeros rather than NaN.
    pub fn density(&self) -> Vec<f64> {
        let total = self.total() as f64 * self.x.width() * self.y.width();
        let norm = if total > 0.0 { 1.0 / total } else { 0.0 };
        self.counts.iter().map(|c| *c as f64 * norm).collect()
    }

    /// Re-checks a histogram whose public fields may have been edited.
    ///
    /// # Errors
    /// Axis errors, [`Error::CountTooLarge`], [`Error::RaggedTable`],
    /// [`Error::EmptyHistogram`].
    pub fn validate(&self) -> Result<()> {
        self.x.validate()?;
        self.y.validate()?;
        let n = checked_cells("cells", self.x.bins, self.y.bins)?;
        if self.counts.len() != n {
            return Err(Error::RaggedTable {
                what: "histogram",
                index: 0,
                expected: n,
                found: self.counts.len(),
            });
        }
        if self.total() == 0 {
            return Err(Error::EmptyHistogram);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn one_dimensional_counts_and_density() {
        let x = [0.0, 0.1, 0.25, 0.5, 0.99, 1.0, 2.0, -1.0];
        let h = Histogram1d::new(&x, 4, Some((0.0, 1.0))).expect("ok");
        assert_eq!(h.counts, vec![2, 1, 1, 2]);
        assert_eq!(h.outside, 2);
        let d = h.density();
        assert_relative_eq!(d.iter().sum::<f64>() * h.axis.width(), 1.0);
        assert_relative_eq!(d[0], 2.0 / 6.0 / 0.25);
        // Data range: min and max land in the first and last bins.
        let h = Histogram1d::new(&[1.0, 2.0, 3.0], 2, None).expect("ok");
        assert_eq!(h.counts, vec![1, 2]);
        assert_eq!(h.outside, 0);
        assert_relative_eq!(h.axis.center(1), 2.5);
    }

    #[test]
    fn two_dimensional_counts_with_empty_bins() {
        let x = [0.1, 0.9, 0.9, 0.5];
        let y = [0.1, 0.9, 0.8, 5.0];
        let h = Histogram2d::new(&x, &y, (2, 3), Some((0.0, 1.0)), Some((0.0, 1.0))).expect("ok");
        assert_eq!(h.count(0, 0), Some(1));
        assert_eq!(h.count(1, 2), Some(2));
        assert_eq!(h.count(2, 0), None);
        assert_eq!(h.outside, 1);
        assert_eq!(h.counts.iter().filter(|c| **c == 0).count(), 4);
        let d = h.density();
        assert_relative_eq!(d.iter().sum::<f64>() * h.x.width() * h.y.width(), 1.0);
    }

    #[test]
    fn oversized_grids_are_errors_not_allocation_failures() {
        assert!(matches!(
            Histogram1d::new(&[0.5], usize::MAX, Some((0.0, 1.0))),
            Err(Error::CountTooLarge { what: "bins", .. })
        ));
        assert!(matches!(
            Histogram2d::new(&[0.5, 0.7], &[0.5, 0.6], (1 << 20, 1 << 20), None, None),
            Err(Error::CountTooLarge { what: "cells", .. })
        ));
        let h = Histogram2d::new(&[0.5, 0.7], &[0.5, 0.6], (4, 4), None, None).expect("ok");
        assert!(matches!(
            crate::pdf::BicubicPdf::from_histogram(&h, usize::MAX),
            Err(Error::CountTooLarge { .. })
        ));
        let p = crate::pdf::BicubicPdf::from_histogram(&h, 2).expect("ok");
        let mut emptied = h.clone();
        emptied.counts.iter_mut().for_each(|c| *c = 0);
        assert!(emptied.density().iter().all(|d| d.to_bits() == 0));
        assert_eq!(
            crate::pdf::BicubicPdf::from_histogram(&emptied, 2),
            Err(Error::EmptyHistogram)
        );
        assert!(matches!(
            p.tabulate(1 << 13),
            Err(Error::CountTooLarge { .. })
        ));
    }

    #[test]
    fn degenerate_histograms_are_errors() {
        assert!(matches!(
            Histogram1d::new(&[1.0, 1.0], 3, None),
            Err(Error::ConstantSample { .. })
        ));
        assert!(matches!(
            Histogram1d::new(&[], 3, None),
            Err(Error::TooFewSamples { .. })
        ));
        assert_eq!(
            Histogram1d::new(&[5.0], 3, Some((0.0, 1.0))),
            Err(Error::EmptyHistogram)
        );
        assert!(matches!(
            Histogram1d::new(&[0.5], 0, Some((0.0, 1.0))),
            Err(Error::CountTooSmall { .. })
        ));
        assert!(matches!(
            Histogram1d::new(&[0.5], 2, Some((1.0, 0.0))),
            Err(Error::InvalidRange { .. })
        ));
        assert!(matches!(
            Histogram1d::new(&[0.5], 2, Some((0.0, f64::NAN))),
            Err(Error::InvalidRange { .. })
        ));
        assert!(matches!(
            Histogram1d::new(&[0.5, f64::NAN], 2, None),
            Err(Error::NonFiniteSample { index: 1, .. })
        ));
        assert!(matches!(
            Histogram2d::new(&[0.5], &[0.5, 0.6], (2, 2), None, None),
            Err(Error::LengthMismatch { .. })
        ));
        assert_eq!(
            Histogram2d::new(&[0.5], &[3.0], (2, 2), Some((0.0, 1.0)), Some((0.0, 1.0))),
            Err(Error::EmptyHistogram)
        );
    }
}
