//! A joint model of all descriptors: a Gaussian copula over the empirical
//! marginals. It keeps every pairwise dependence (as normal-score
//! correlations) and every marginal exactly, which the seed's pairwise PDFs
//! (Medina 2018, §2.1) cannot do for more than two descriptors at once.
//!
//! Fit (Genest, Ghoudi & Rivest 1995, doi:10.1093/biomet/82.3.543, the
//! rank-based pseudo-likelihood setting): each column is turned into
//! van der Waerden normal scores `z = Φ⁻¹(r / (n + 1))` with average ranks
//! `r`; the copula correlation is the Pearson matrix of the scores.
//! Sampling: `z ~ N(0, R)` through a semidefinite Cholesky factor,
//! `u = Φ(z)`, then each marginal's empirical quantile function: linear
//! interpolation between the order statistics placed at plotting positions
//! `(k − ½)/n` (Hazen), clamped to `[min, max]` outside them — draws never
//! leave the observed range.
//!
//! Degenerate input: a constant descriptor is kept and always drawn at its
//! value (its score column is independent of the others); perfectly
//! dependent descriptors (e.g. volume and equivalent diameter) give a
//! singular but valid correlation, handled by the semidefinite factor.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::correlation::{CorrelationMatrix, CorrelationMethod};
use crate::error::{Error, Result};
use crate::stats::{average_ranks, constant_value, normal_cdf, normal_quantile, pearson_unchecked};
use crate::table::{Descriptor, DnaTable};

/// Gaussian copula with empirical marginals, fitted to a [`DnaTable`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GaussianCopula {
    descriptors: Vec<Descriptor>,
    /// Sorted values per descriptor.
    sorted: Vec<Vec<f64>>,
    /// Normal-score correlation, row-major `k × k`.
    correlation: Vec<f64>,
    /// Lower-triangular semidefinite Cholesky factor, row-major.
    factor: Vec<f64>,
}

/// Pivots below this (relative to the unit diagonal) are treated as zero.
const PIVOT_TOL: f64 = 1e-10;

/// Cholesky factor of a symmetric positive semidefinite matrix: columns with
/// a (numerically) zero pivot are set to zero, which still reproduces
/// `L Lᵀ = A` for semidefinite `A`.
fn semidefinite_cholesky(a: &[f64], k: usize) -> Result<Vec<f64>> {
    let mut l = vec![0.0; k * k];
    for j in 0..k {
        let mut d = a[j * k + j];
        for p in 0..j {
            d -= l[j * k + p] * l[j * k + p];
        }
        if d < -1e-8 {
            return Err(Error::NotPositiveSemidefinite { index: j, pivot: d });
        }
        if d <= PIVOT_TOL {
            continue;
        }
        let djj = d.sqrt();
        l[j * k + j] = djj;
        for i in (j + 1)..k {
            let mut s = a[i * k + j];
            for p in 0..j {
                s -= l[i * k + p] * l[j * k + p];
            }
            l[i * k + j] = s / djj;
        }
    }
    Ok(l)
}

impl GaussianCopula {
    /// Fits the copula to every descriptor of `table`.
    ///
    /// # Errors
    /// [`Error::TooFewSamples`] below 2 grains;
    /// [`Error::NotPositiveSemidefinite`] only on numerical breakdown.
    pub fn fit(table: &DnaTable) -> Result<Self> {
        table.require_grains(2)?;
        let n = table.n_grains() as f64;
        let k = table.descriptors().len();
        let mut scores = Vec::with_capacity(k);
        let mut constant = Vec::with_capacity(k);
        for col in table.columns() {
            constant.push(constant_value(col).is_some());
            scores.push(
                average_ranks(col)
                    .into_iter()
                    .map(|r| normal_quantile(r / (n + 1.0)))
                    .collect::<Vec<f64>>(),
            );
        }
        let mut correlation = vec![0.0; k * k];
        for i in 0..k {
            correlation[i * k + i] = 1.0;
            for j in (i + 1)..k {
                let r = if constant[i] || constant[j] {
                    0.0
                } else {
                    pearson_unchecked(&scores[i], &scores[j])
                };
                correlation[i * k + j] = r;
                correlation[j * k + i] = r;
            }
        }
        let factor = semidefinite_cholesky(&correlation, k)?;
        let sorted = table
            .columns()
            .iter()
            .map(|c| {
                let mut s = c.clone();
                s.sort_by(f64::total_cmp);
                s
            })
            .collect();
        Ok(Self {
            descriptors: table.descriptors().to_vec(),
            sorted,
            correlation,
            factor,
        })
    }

    /// The modelled descriptors, in the order of every draw.
    pub fn descriptors(&self) -> &[Descriptor] {
        &self.descriptors
    }

    /// The copula's normal-score correlation matrix.
    pub fn correlation(&self) -> CorrelationMatrix {
        CorrelationMatrix {
            descriptors: self.descriptors.clone(),
            method: CorrelationMethod::Pearson,
            values: self.correlation.clone(),
        }
    }

    /// Empirical quantile of descriptor number `d` at `u ∈ (0, 1)`.
    fn quantile(&self, d: usize, u: f64) -> f64 {
        let s = &self.sorted[d];
        let n = s.len();
        let t = u * n as f64 - 0.5;
        if t <= 0.0 {
            return s[0];
        }
        let i = t.floor() as usize;
        if i + 1 >= n {
            return s[n - 1];
        }
        let f = t - i as f64;
        s[i] + f * (s[i + 1] - s[i])
    }

    /// One draw: a value per descriptor, in [`GaussianCopula::descriptors`] order.
    pub fn sample(&self, rng: &mut impl Rng) -> Vec<f64> {
        let k = self.descriptors.len();
        let e: Vec<f64> = (0..k).map(|_| StandardNormal.sample(rng)).collect();
        (0..k)
            .map(|i| {
                let z: f64 = (0..=i).map(|p| self.factor[i * k + p] * e[p]).sum();
                self.quantile(i, normal_cdf(z))
            })
            .collect()
    }

    /// `n` draws as a new table.
    ///
    /// # Errors
    /// None in practice (draws are finite by construction); the `Result` is
    /// the table validation's.
    pub fn sample_table(&self, n: usize, rng: &mut impl Rng) -> Result<DnaTable> {
        let mut t = DnaTable::new(self.descriptors.clone())?;
        for _ in 0..n {
            t.push_row(&self.sample(rng))?;
        }
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Descriptor::*;
    use approx::assert_relative_eq;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn semidefinite_cholesky_handles_rank_deficiency() {
        // Rank-2 matrix: third variable equals the first.
        let a = [1.0, 0.5, 1.0, 0.5, 1.0, 0.5, 1.0, 0.5, 1.0];
        let l = semidefinite_cholesky(&a, 3).expect("semidefinite");
        for i in 0..3 {
            for j in 0..3 {
                let v: f64 = (0..3).map(|p| l[i * 3 + p] * l[j * 3 + p]).sum();
                assert_relative_eq!(v, a[i * 3 + j], epsilon = 1e-12);
            }
        }
        let bad = [1.0, 2.0, 2.0, 1.0];
        assert!(matches!(
            semidefinite_cholesky(&bad, 2),
            Err(Error::NotPositiveSemidefinite { index: 1, .. })
        ));
    }

    #[test]
    fn degenerate_tables_sample_in_range() {
        // Volume and equivalent diameter are perfectly dependent; roundness constant.
        let d: Vec<f64> = (1..=20).map(|k| k as f64 * 0.1).collect();
        let v: Vec<f64> = d
            .iter()
            .map(|x| std::f64::consts::PI / 6.0 * x * x * x)
            .collect();
        let r = vec![0.4; 20];
        let t = DnaTable::from_columns(vec![EquivalentDiameter, Volume, Roundness], vec![d, v, r])
            .expect("ok");
        let c = GaussianCopula::fit(&t).expect("fit");
        assert_relative_eq!(
            c.correlation().get(EquivalentDiameter, Volume).expect("ok"),
            1.0,
            epsilon = 1e-12
        );
        let seed = 11;
        #[expect(clippy::print_stdout, reason = "seeded tests print their seed")]
        {
            println!("seed {seed}");
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let s = c.sample_table(500, &mut rng).expect("ok");
        for row in 0..s.n_grains() {
            let x = s.row(row).expect("in range");
            assert!((0.1..=2.0).contains(&x[0]));
            assert_relative_eq!(x[2], 0.4);
            // Comonotone: both draws sit at the same fractional position
            // between the same order statistics.
            let vol = |d: f64| std::f64::consts::PI / 6.0 * d * d * d;
            let i = (((x[0] - 0.1) / 0.1).floor() as usize).min(18);
            let (d0, d1) = (0.1 * (i + 1) as f64, 0.1 * (i + 2) as f64);
            let f = (x[0] - d0) / (d1 - d0);
            let expected = vol(d0) + f * (vol(d1) - vol(d0));
            assert_relative_eq!(x[1], expected, max_relative = 1e-9);
        }
        let one = DnaTable::from_rows(vec![Volume], &[vec![1.0]]).expect("ok");
        assert!(matches!(
            GaussianCopula::fit(&one),
            Err(Error::TooFewSamples { .. })
        ));
    }

    #[test]
    fn quantile_interpolates_order_statistics() {
        let t = DnaTable::from_columns(vec![Volume], vec![vec![4.0, 1.0, 3.0, 2.0]]).expect("ok");
        let c = GaussianCopula::fit(&t).expect("fit");
        assert_relative_eq!(c.quantile(0, 0.01), 1.0);
        assert_relative_eq!(c.quantile(0, 0.125), 1.0);
        assert_relative_eq!(c.quantile(0, 0.25), 1.5);
        assert_relative_eq!(c.quantile(0, 0.5), 2.5);
        assert_relative_eq!(c.quantile(0, 0.99), 4.0);
    }
}
