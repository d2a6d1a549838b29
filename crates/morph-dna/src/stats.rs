//! Scalar statistics on raw samples: moments, average ranks, Pearson and
//! Spearman correlation, and the standard normal distribution.

use crate::error::{Error, Result};

/// Fails on NaN/infinite values.
pub(crate) fn check_sample(x: &[f64]) -> Result<()> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(Error::NonFiniteSample {
            index,
            value: x[index],
        }),
        None => Ok(()),
    }
}

/// Fails unless `x` has at least `needed` values.
pub(crate) fn check_len(x: &[f64], needed: usize) -> Result<()> {
    if x.len() < needed {
        return Err(Error::TooFewSamples {
            needed,
            found: x.len(),
        });
    }
    Ok(())
}

/// Arithmetic mean of a non-empty slice.
pub(crate) fn mean_unchecked(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// Sample standard deviation (divisor `n − 1`) of a slice of length ≥ 2, two-pass.
pub(crate) fn std_unchecked(x: &[f64]) -> f64 {
    let m = mean_unchecked(x);
    let ss: f64 = x.iter().map(|v| (v - m) * (v - m)).sum();
    (ss / (x.len() - 1) as f64).sqrt()
}

/// Arithmetic mean.
///
/// # Errors
/// [`Error::TooFewSamples`] for an empty slice, [`Error::NonFiniteSample`].
pub fn mean(x: &[f64]) -> Result<f64> {
    check_len(x, 1)?;
    check_sample(x)?;
    Ok(mean_unchecked(x))
}

/// Sample standard deviation with divisor `n − 1` (MATLAB's `std`, which the
/// seed's statistics were computed with).
///
/// # Errors
/// [`Error::TooFewSamples`] below two values, [`Error::NonFiniteSample`].
pub fn sample_std(x: &[f64]) -> Result<f64> {
    check_len(x, 2)?;
    check_sample(x)?;
    Ok(std_unchecked(x))
}

/// 1-based ranks with ties replaced by their average rank (the "fractional"
/// ranking used by Spearman's coefficient). Input must be NaN-free.
pub(crate) fn average_ranks(x: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut ranks = vec![0.0; x.len()];
    let mut start = 0;
    while start < idx.len() {
        let mut end = start + 1;
        while end < idx.len() && x[idx[end]] == x[idx[start]] {
            end += 1;
        }
        // Positions start..end (0-based) share the ranks start+1 ..= end.
        let r = (start + 1 + end) as f64 / 2.0;
        for &k in &idx[start..end] {
            ranks[k] = r;
        }
        start = end;
    }
    ranks
}

/// Pearson correlation of two validated, non-constant samples of equal length ≥ 2.
pub(crate) fn pearson_unchecked(x: &[f64], y: &[f64]) -> f64 {
    let mx = mean_unchecked(x);
    let my = mean_unchecked(y);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        let (dx, dy) = (a - mx, b - my);
        sxy += dx * dy;
        sxx += dx * dx;
        syy += dy * dy;
    }
    (sxy / (sxx.sqrt() * syy.sqrt())).clamp(-1.0, 1.0)
}

/// Returns the common value if the slice is constant.
pub(crate) fn constant_value(x: &[f64]) -> Option<f64> {
    let first = *x.first()?;
    x.iter().all(|v| *v == first).then_some(first)
}

fn check_pair(x: &[f64], y: &[f64]) -> Result<()> {
    if x.len() != y.len() {
        return Err(Error::LengthMismatch {
            left: x.len(),
            right: y.len(),
        });
    }
    check_len(x, 2)?;
    check_sample(x)?;
    check_sample(y)?;
    for s in [x, y] {
        if let Some(value) = constant_value(s) {
            return Err(Error::ConstantSample { value });
        }
    }
    Ok(())
}

/// Pearson's linear correlation coefficient of paired samples, in [−1, 1].
///
/// # Errors
/// [`Error::LengthMismatch`], [`Error::TooFewSamples`] (fewer than 2 pairs),
/// [`Error::NonFiniteSample`], [`Error::ConstantSample`] (correlation undefined).
pub fn pearson(x: &[f64], y: &[f64]) -> Result<f64> {
    check_pair(x, y)?;
    Ok(pearson_unchecked(x, y))
}

/// Spearman's rank correlation: Pearson's coefficient of the average ranks
/// (ties share the mean of the ranks they span).
///
/// # Errors
/// As [`pearson`].
pub fn spearman(x: &[f64], y: &[f64]) -> Result<f64> {
    check_pair(x, y)?;
    Ok(pearson_unchecked(&average_ranks(x), &average_ranks(y)))
}

/// Complementary error function, Chebyshev fit of Press et al., *Numerical
/// Recipes* (2nd ed.) §6.2 `erfcc`: fractional error below 1.2 × 10⁻⁷ everywhere.
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// Standard normal CDF Φ(x) (relative error below 1.2 × 10⁻⁷).
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Standard normal quantile Φ⁻¹(p) for p in (0, 1), by Acklam's rational
/// approximation (relative error below 1.15 × 10⁻⁹). Returns ∓∞ at p = 0, 1
/// and NaN outside [0, 1]; callers in this crate only pass p in (0, 1).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.024_25;
    if !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    if p == 0.0 {
        return f64::NEG_INFINITY;
    }
    if p == 1.0 {
        return f64::INFINITY;
    }
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - P_LOW {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn moments_of_known_sample() {
        let x = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0];
        assert_relative_eq!(mean(&x).expect("ok"), 5.0);
        // Σ(x−5)² = 32, n − 1 = 7.
        assert_relative_eq!(sample_std(&x).expect("ok"), (32.0f64 / 7.0).sqrt());
        assert!(matches!(
            sample_std(&[1.0]),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(mean(&[]), Err(Error::TooFewSamples { .. })));
    }

    #[test]
    fn average_ranks_share_ties() {
        let r = average_ranks(&[10.0, 20.0, 10.0, 30.0, 20.0, 20.0]);
        assert_eq!(r, vec![1.5, 4.0, 1.5, 6.0, 4.0, 4.0]);
    }

    #[test]
    fn pearson_and_spearman_oracles() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        let y: Vec<f64> = x.iter().map(|v: &f64| v.powi(3)).collect();
        assert_relative_eq!(spearman(&x, &y).expect("ok"), 1.0);
        assert!(pearson(&x, &y).expect("ok") < 0.99);
        let neg: Vec<f64> = x.iter().map(|v| -2.0 * v + 1.0).collect();
        assert_relative_eq!(pearson(&x, &neg).expect("ok"), -1.0);
        // Hand-computed: x = 1..5, y = [2, 1, 4, 3, 5]: Σdxdy = 8, Σdx² = Σdy² = 10.
        assert_relative_eq!(pearson(&x, &[2.0, 1.0, 4.0, 3.0, 5.0]).expect("ok"), 0.8);
        // Ties: x = [1, 2, 2, 3], y = [1, 2, 3, 4] → ranks x = [1, 2.5, 2.5, 4];
        // Pearson of ranks: Σdxdy = 4.5, Σdx² = 4.5, Σdy² = 5 → 4.5/√22.5.
        assert_relative_eq!(
            spearman(&[1.0, 2.0, 2.0, 3.0], &[1.0, 2.0, 3.0, 4.0]).expect("ok"),
            4.5 / 22.5f64.sqrt(),
            epsilon = 1e-15
        );
    }

    #[test]
    fn correlation_rejects_degenerate_input() {
        assert_eq!(
            pearson(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0]),
            Err(Error::ConstantSample { value: 1.0 })
        );
        assert_eq!(
            spearman(&[1.0, 2.0], &[1.0]),
            Err(Error::LengthMismatch { left: 2, right: 1 })
        );
        assert!(matches!(
            pearson(&[1.0], &[1.0]),
            Err(Error::TooFewSamples {
                needed: 2,
                found: 1
            })
        ));
        assert!(matches!(
            pearson(&[1.0, f64::NAN], &[1.0, 2.0]),
            Err(Error::NonFiniteSample { index: 1, .. })
        ));
    }

    #[test]
    fn normal_functions_match_tabulated_values() {
        assert_relative_eq!(normal_cdf(0.0), 0.5, epsilon = 1e-7);
        assert_relative_eq!(normal_cdf(1.0), 0.841_344_746_068_542_9, epsilon = 2e-7);
        assert_relative_eq!(normal_cdf(-1.959_963_984_540_054), 0.025, epsilon = 1e-8);
        assert_relative_eq!(
            normal_quantile(0.975),
            1.959_963_984_540_054,
            epsilon = 1e-8
        );
        assert_relative_eq!(
            normal_quantile(1e-10),
            -6.361_340_902_404_056,
            max_relative = 1e-8
        );
        for k in 1..1000 {
            let p = k as f64 / 1000.0;
            assert_relative_eq!(normal_cdf(normal_quantile(p)), p, max_relative = 3e-7);
        }
        assert!(normal_quantile(1.5).is_nan());
    }
}
