//! Correlation matrices of all descriptors of a population (Medina 2018,
//! Table 1), Pearson or Spearman.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::stats::{average_ranks, constant_value, pearson_unchecked};
use crate::table::{Descriptor, DnaTable};

/// Which correlation coefficient to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum CorrelationMethod {
    /// Pearson's linear coefficient (the seed's Table 1 "linear correlation").
    #[default]
    Pearson,
    /// Spearman's rank coefficient, ties by average ranks: invariant under
    /// monotone transforms of each descriptor, so it does not depend on
    /// whether a size is expressed as a diameter or a volume.
    Spearman,
}

/// A symmetric matrix of correlation coefficients between descriptors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CorrelationMatrix {
    /// Row/column labels.
    pub descriptors: Vec<Descriptor>,
    /// Coefficient used.
    pub method: CorrelationMethod,
    /// Row-major `k × k` values, unit diagonal, each in [−1, 1].
    pub values: Vec<f64>,
}

impl CorrelationMatrix {
    /// Number of descriptors `k`.
    pub fn len(&self) -> usize {
        self.descriptors.len()
    }

    /// True if the matrix has no descriptor (never for a computed matrix).
    pub fn is_empty(&self) -> bool {
        self.descriptors.is_empty()
    }

    /// Entry `(i, j)` by position, `None` out of range.
    pub fn at(&self, i: usize, j: usize) -> Option<f64> {
        let k = self.len();
        if i < k && j < k {
            self.values.get(i * k + j).copied()
        } else {
            None
        }
    }

    /// Entry between two descriptors, `None` if either is absent.
    pub fn get(&self, a: Descriptor, b: Descriptor) -> Option<f64> {
        let i = self.descriptors.iter().position(|d| *d == a)?;
        let j = self.descriptors.iter().position(|d| *d == b)?;
        self.at(i, j)
    }

    /// Entry-wise difference `self − other` over the descriptors of `self`,
    /// looked up by name in `other`, as a row-major matrix.
    ///
    /// # Errors
    /// [`Error::DescriptorMismatch`] if `other` lacks a descriptor of `self`
    /// or has a different size.
    pub fn difference(&self, other: &Self) -> Result<Vec<f64>> {
        if other.len() != self.len() {
            return Err(Error::DescriptorMismatch);
        }
        let mut out = Vec::with_capacity(self.values.len());
        for a in &self.descriptors {
            for b in &self.descriptors {
                let o = other.get(*a, *b).ok_or(Error::DescriptorMismatch)?;
                let s = self.get(*a, *b).ok_or(Error::DescriptorMismatch)?;
                out.push(s - o);
            }
        }
        Ok(out)
    }

    /// Largest absolute entry-wise difference with `other`.
    ///
    /// # Errors
    /// As [`CorrelationMatrix::difference`].
    pub fn max_abs_difference(&self, other: &Self) -> Result<f64> {
        Ok(self
            .difference(other)?
            .iter()
            .fold(0.0, |m: f64, d| m.max(d.abs())))
    }

    /// Frobenius norm of the difference with `other` (diagonal included; it
    /// is zero there).
    ///
    /// # Errors
    /// As [`CorrelationMatrix::difference`].
    pub fn frobenius_difference(&self, other: &Self) -> Result<f64> {
        Ok(self
            .difference(other)?
            .iter()
            .map(|d| d * d)
            .sum::<f64>()
            .sqrt())
    }
}

/// Correlation matrix of every descriptor of `table`.
///
/// A constant descriptor has no defined correlation: rather than NaN this
/// returns [`Error::ConstantDescriptor`] naming it, so the caller can drop it
/// with [`DnaTable::select`] and retry.
///
/// # Errors
/// [`Error::TooFewSamples`] below 2 grains, [`Error::ConstantDescriptor`].
pub fn correlation_matrix(
    table: &DnaTable,
    method: CorrelationMethod,
) -> Result<CorrelationMatrix> {
    table.require_grains(2)?;
    for (d, col) in table.descriptors().iter().zip(table.columns()) {
        if let Some(value) = constant_value(col) {
            return Err(Error::ConstantDescriptor {
                descriptor: *d,
                value,
            });
        }
    }
    let cols: Vec<Vec<f64>> = match method {
        CorrelationMethod::Pearson => table.columns().to_vec(),
        CorrelationMethod::Spearman => table.columns().iter().map(|c| average_ranks(c)).collect(),
    };
    let k = cols.len();
    let mut values = vec![0.0; k * k];
    for i in 0..k {
        values[i * k + i] = 1.0;
        for j in (i + 1)..k {
            let r = pearson_unchecked(&cols[i], &cols[j]);
            values[i * k + j] = r;
            values[j * k + i] = r;
        }
    }
    Ok(CorrelationMatrix {
        descriptors: table.descriptors().to_vec(),
        method,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use Descriptor::*;
    use approx::assert_relative_eq;

    fn table() -> DnaTable {
        // y = x², z = −x, w an independent-looking sequence.
        let x: Vec<f64> = (1..=6).map(f64::from).collect();
        let y = x.iter().map(|v| v * v).collect();
        let z = x.iter().map(|v| -v).collect();
        let w = vec![3.0, 1.0, 4.0, 1.0, 5.0, 9.0];
        DnaTable::from_columns(
            vec![AspectRatio, Roundness, Volume, Convexity],
            vec![x, y, z, w],
        )
        .expect("valid")
    }

    #[test]
    fn spearman_sees_monotone_relations_pearson_does_not() {
        let t = table();
        let p = correlation_matrix(&t, CorrelationMethod::Pearson).expect("ok");
        let s = correlation_matrix(&t, CorrelationMethod::Spearman).expect("ok");
        assert_relative_eq!(s.get(AspectRatio, Roundness).expect("present"), 1.0);
        assert!(p.get(AspectRatio, Roundness).expect("present") < 0.99);
        assert_relative_eq!(p.get(AspectRatio, Volume).expect("present"), -1.0);
        assert_relative_eq!(s.get(Roundness, Volume).expect("present"), -1.0);
        for m in [&p, &s] {
            for i in 0..4 {
                assert_relative_eq!(m.at(i, i).expect("in range"), 1.0);
                for j in 0..4 {
                    assert_relative_eq!(m.at(i, j).expect("in"), m.at(j, i).expect("in"));
                }
            }
        }
        // x vs w by hand: ranks of w are [3, 1.5, 4, 1.5, 5, 6].
        let rw = [3.0, 1.5, 4.0, 1.5, 5.0, 6.0];
        let rx = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let expected = crate::stats::pearson(&rx, &rw).expect("ok");
        assert_relative_eq!(s.get(AspectRatio, Convexity).expect("present"), expected);
    }

    #[test]
    fn differences_of_matrices() {
        let t = table();
        let p = correlation_matrix(&t, CorrelationMethod::Pearson).expect("ok");
        assert_relative_eq!(p.max_abs_difference(&p).expect("same"), 0.0);
        let s = correlation_matrix(&t, CorrelationMethod::Spearman).expect("ok");
        let d = s.difference(&p).expect("same descriptors");
        let max = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let fro = d.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert_relative_eq!(s.max_abs_difference(&p).expect("ok"), max);
        assert_relative_eq!(s.frobenius_difference(&p).expect("ok"), fro);
        // Reordered descriptors are matched by name.
        let q = correlation_matrix(
            &t.select(&[Convexity, Volume, Roundness, AspectRatio])
                .expect("ok"),
            CorrelationMethod::Pearson,
        )
        .expect("ok");
        assert_relative_eq!(q.max_abs_difference(&p).expect("ok"), 0.0, epsilon = 1e-15);
        let small = correlation_matrix(
            &t.select(&[Volume, Roundness]).expect("ok"),
            CorrelationMethod::Pearson,
        )
        .expect("ok");
        assert_eq!(small.max_abs_difference(&p), Err(Error::DescriptorMismatch));
        let mut edited = small.clone();
        edited.values.truncate(3);
        assert_eq!(edited.at(1, 1), None);
        assert_eq!(
            edited.max_abs_difference(&small),
            Err(Error::DescriptorMismatch)
        );
    }

    #[test]
    fn degenerate_populations_are_errors() {
        let one = DnaTable::from_rows(vec![AspectRatio, Roundness], &[vec![0.5, 0.5]]).expect("ok");
        assert!(matches!(
            correlation_matrix(&one, CorrelationMethod::Pearson),
            Err(Error::TooFewSamples {
                needed: 2,
                found: 1
            })
        ));
        let constant = DnaTable::from_columns(
            vec![AspectRatio, Roundness],
            vec![vec![0.1, 0.2, 0.3], vec![0.7, 0.7, 0.7]],
        )
        .expect("ok");
        for m in [CorrelationMethod::Pearson, CorrelationMethod::Spearman] {
            assert_eq!(
                correlation_matrix(&constant, m),
                Err(Error::ConstantDescriptor {
                    descriptor: Roundness,
                    value: 0.7
                })
            );
        }
    }
}
