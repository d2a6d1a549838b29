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

use crate::correlation::{CorrelationMatrix, CorrelationMethod};
use crate::error::{Error, Result};
use crate::stats::{average_ranks, constant_value, normal_cdf, normal_quantile, pearson_unchecked};
use crate::table::{Descriptor, DnaTable};

/// Gaussian copula with empirical marginals, fitted to a [`DnaTable`].
#[derive(Debug, Clone, PartialEq)]
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

    /// Empirical CDF of descriptor number `d` at `x`: the inverse of
    /// [`GaussianCopula::quantile`], clamped to the plotting positions
    /// `[1/(2n), 1 − 1/(2n)]`; tied order statistics map to the middle of
    /// their span.
    fn cdf(&self, d: usize, x: f64) -> f64 {
        let s = &self.sorted[d];
        let n = s.len() as f64;
        let lo = s.partition_point(|v| *v < x);
        let hi = s.partition_point(|v| *v <= x);
        if hi > lo {
            // x equals order statistics lo..hi (0-based): middle of their positions.
            return ((lo + hi) as f64 / 2.0) / n;
        }
        if lo == 0 {
            return 0.5 / n;
        }
        if lo == s.len() {
            return 1.0 - 0.5 / n;
        }
        let (a, b) = (s[lo - 1], s[lo]);
        (lo as f64 - 0.5 + (x - a) / (b - a)) / n
    }

    /// One draw of every descriptor conditional on the values of some of
    /// them, in [`GaussianCopula::descriptors`] order (the given descriptors
    /// are returned at their given values).
    ///
    /// The given values are mapped to normal scores through the empirical
    /// CDFs (values beyond the observed range count as the extremes), and
    /// the remaining scores are drawn from the conditional normal
    /// `N(R_BA R_AA⁻ z_A, R_BB − R_BA R_AA⁻ R_AB)`. If the given descriptors
    /// are themselves perfectly dependent (e.g. volume and equivalent
    /// diameter), `R_AA⁻` is the generalised inverse of the semidefinite
    /// factor and the redundant given value is ignored.
    ///
    /// # Errors
    /// [`Error::MissingDescriptor`], [`Error::DuplicateDescriptor`],
    /// [`Error::NonFiniteSample`] for a NaN or infinite given value.
    pub fn sample_conditional(
        &self,
        given: &[(Descriptor, f64)],
        rng: &mut impl Rng,
    ) -> Result<Vec<f64>> {
        let k = self.descriptors.len();
        let mut is_given = vec![None; k];
        for (index, (d, v)) in given.iter().enumerate() {
            let p = self
                .descriptors
                .iter()
                .position(|x| x == d)
                .ok_or(Error::MissingDescriptor { descriptor: *d })?;
            if is_given[p].is_some() {
                return Err(Error::DuplicateDescriptor { descriptor: *d });
            }
            if !v.is_finite() {
                return Err(Error::NonFiniteSample { index, value: *v });
            }
            is_given[p] = Some(*v);
        }
        let a: Vec<usize> = (0..k).filter(|i| is_given[*i].is_some()).collect();
        let b: Vec<usize> = (0..k).filter(|i| is_given[*i].is_none()).collect();
        let r = |i: usize, j: usize| self.correlation[i * k + j];
        let za: Vec<f64> = a
            .iter()
            .map(|&i| normal_quantile(self.cdf(i, is_given[i].unwrap_or(0.0))))
            .collect();
        // Generalised solve with the semidefinite factor of R_AA.
        let na = a.len();
        let raa: Vec<f64> = a
            .iter()
            .flat_map(|&i| a.iter().map(move |&j| r(i, j)))
            .collect();
        let laa = semidefinite_cholesky(&raa, na)?;
        let solve = |rhs: &[f64]| -> Vec<f64> {
            let mut y = vec![0.0; na];
            for i in 0..na {
                let d = laa[i * na + i];
                if d > 0.0 {
                    let s: f64 = (0..i).map(|p| laa[i * na + p] * y[p]).sum();
                    y[i] = (rhs[i] - s) / d;
                }
            }
            let mut x = vec![0.0; na];
            for i in (0..na).rev() {
                let d = laa[i * na + i];
                if d > 0.0 {
                    let s: f64 = ((i + 1)..na).map(|p| laa[p * na + i] * x[p]).sum();
                    x[i] = (y[i] - s) / d;
                }
            }
            x
        };
        let w = solve(&za);
        let nb = b.len();
        let mut mean = vec![0.0; nb];
        let mut cov = vec![0.0; nb * nb];
        let cols: Vec<Vec<f64>> = b
            .iter()
            .map(|&j| solve(&a.iter().map(|&i| r(i, j)).collect::<Vec<_>>()))
            .collect();
        for (p, &i) in b.iter().enumerate() {
            mean[p] = a.iter().zip(&w).map(|(&q, wq)| r(i, q) * wq).sum();
            for (q, &j) in b.iter().enumerate() {
                let reduce: f64 = a.iter().zip(&cols[q]).map(|(&m, c)| r(i, m) * c).sum();
                cov[p * nb + q] = r(i, j) - reduce;
            }
        }
        // Symmetrise against rounding before factorising.
        for p in 0..nb {
            for q in 0..p {
                let v = 0.5 * (cov[p * nb + q] + cov[q * nb + p]);
                cov[p * nb + q] = v;
                cov[q * nb + p] = v;
            }
        }
        let lb = semidefinite_cholesky(&cov, nb)?;
        let e: Vec<f64> = (0..nb).map(|_| StandardNormal.sample(rng)).collect();
        let mut out: Vec<f64> = is_given.iter().map(|g| g.unwrap_or(0.0)).collect();
        for (p, &i) in b.iter().enumerate() {
            let z = mean[p] + (0..=p).map(|q| lb[p * nb + q] * e[q]).sum::<f64>();
            out[i] = self.quantile(i, normal_cdf(z));
        }
        Ok(out)
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
    fn empirical_cdf_inverts_the_quantile() {
        let t =
            DnaTable::from_columns(vec![Volume], vec![vec![4.0, 1.0, 3.0, 2.0, 2.0]]).expect("ok");
        let c = GaussianCopula::fit(&t).expect("fit");
        for u in [0.1, 0.15, 0.55, 0.7, 0.85, 0.9] {
            assert_relative_eq!(c.cdf(0, c.quantile(0, u)), u, epsilon = 1e-12);
        }
        // The tie at 2 holds plotting positions 0.3 and 0.5: middle 0.4.
        assert_relative_eq!(c.cdf(0, 2.0), 0.4);
        assert_relative_eq!(c.cdf(0, -5.0), 0.1);
        assert_relative_eq!(c.cdf(0, 50.0), 0.9);
    }

    #[test]
    fn conditional_sampling_validates_and_keeps_given_values() {
        let t = DnaTable::from_columns(
            vec![Volume, Roundness, AspectRatio],
            vec![
                vec![1.0, 2.0, 3.0, 4.0, 5.0],
                vec![0.2, 0.1, 0.4, 0.3, 0.5],
                vec![0.5, 0.6, 0.6, 0.9, 0.7],
            ],
        )
        .expect("ok");
        let c = GaussianCopula::fit(&t).expect("fit");
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let v = c
            .sample_conditional(&[(Roundness, 0.33)], &mut rng)
            .expect("valid");
        assert_relative_eq!(v[1], 0.33);
        assert!((1.0..=5.0).contains(&v[0]) && (0.5..=0.9).contains(&v[2]));
        // Everything given: returned as is.
        let all = [(Volume, 2.5), (Roundness, 0.3), (AspectRatio, 0.8)];
        let got = c.sample_conditional(&all, &mut rng).expect("ok");
        for (g, (_, v)) in got.iter().zip(&all) {
            assert_relative_eq!(*g, *v);
        }
        assert!(matches!(
            c.sample_conditional(&[(Sphericity, 0.3)], &mut rng),
            Err(Error::MissingDescriptor { .. })
        ));
        assert!(matches!(
            c.sample_conditional(&[(Volume, 1.0), (Volume, 2.0)], &mut rng),
            Err(Error::DuplicateDescriptor { .. })
        ));
        assert!(matches!(
            c.sample_conditional(&[(Volume, f64::NAN)], &mut rng),
            Err(Error::NonFiniteSample { .. })
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
