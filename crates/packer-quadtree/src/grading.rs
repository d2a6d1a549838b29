//! Grading curves (particle-size distributions) and inverse-transform
//! sampling of diameters (Pinto 2009, §4.2.1).
//!
//! A sieve curve gives cumulative passing percentages at increasing sieve
//! sizes. Between two sieves the curve is a straight line on the usual
//! semi-logarithmic grading chart (passing linear in `ln d`), so the inverse
//! of the cumulative distribution on a segment is
//! `d = d_i (d_{i+1}/d_i)^t` with `t = (P − P_i)/(P_{i+1} − P_i)`
//! (Pinto 2009, §4.2.1: "a regra de três … tratado devido ao gráfico ser
//! semilogarítmico").

use crate::error::{Error, Result, finite, positive};
use rand::Rng;

/// One component of a [`Grading::Mixture`]: the passing range it covers and
/// the distribution of diameters inside that range.
#[derive(Debug, Clone, PartialEq)]
pub struct MixtureComponent {
    /// Lower end of the passing range, in percent.
    pub passing_from: f64,
    /// Upper end of the passing range, in percent.
    pub passing_to: f64,
    /// Distribution of diameters inside the range (not itself a mixture).
    pub grading: Grading,
}

/// A particle-size distribution. Diameters are in the caller's length unit
/// (the seed and the tests use mm).
#[derive(Debug, Clone, PartialEq)]
pub enum Grading {
    /// Every particle has the same diameter.
    Constant {
        /// The diameter.
        diameter: f64,
    },
    /// Diameters uniformly distributed (linear in `d`) in `[min, max]`.
    Uniform {
        /// Smallest diameter.
        min: f64,
        /// Largest diameter.
        max: f64,
    },
    /// A sieve curve: strictly increasing sizes with non-decreasing
    /// cumulative passing percentages from 0 to 100, semi-log interpolated.
    Sieve {
        /// Sieve sizes, strictly increasing.
        sizes: Vec<f64>,
        /// Cumulative passing in percent at each size, 0 first, 100 last.
        passing: Vec<f64>,
    },
    /// A piecewise mixture over passing ranges that tile 0–100 %
    /// (Pinto 2009, Table 4.1).
    Mixture(Vec<MixtureComponent>),
}

impl Grading {
    /// The sieve curve of Pinto 2009, Table 3.4 (1.200–1.295 mm), used in
    /// Tables 3.5, 3.6, 3.13, 3.14 and 3.16.
    pub fn pinto_table_3_4() -> Self {
        Self::Sieve {
            sizes: vec![
                1.200, 1.215, 1.225, 1.235, 1.245, 1.255, 1.265, 1.275, 1.285, 1.295,
            ],
            passing: vec![0.0, 11.0, 21.0, 31.0, 43.0, 54.0, 65.0, 77.0, 89.0, 100.0],
        }
    }

    /// The AP-5 mixture of Pinto 2009, Table 4.1: 0–10 % uniform in
    /// 1.2–2.4 mm, 10–90 % constant 2.4 mm, 90–100 % uniform in 2.4–6.0 mm.
    pub fn pinto_ap5() -> Self {
        Self::Mixture(vec![
            MixtureComponent {
                passing_from: 0.0,
                passing_to: 10.0,
                grading: Self::Uniform { min: 1.2, max: 2.4 },
            },
            MixtureComponent {
                passing_from: 10.0,
                passing_to: 90.0,
                grading: Self::Constant { diameter: 2.4 },
            },
            MixtureComponent {
                passing_from: 90.0,
                passing_to: 100.0,
                grading: Self::Uniform { min: 2.4, max: 6.0 },
            },
        ])
    }

    /// Checks every invariant of the variant.
    ///
    /// # Errors
    /// [`Error::NonFinite`], [`Error::NonPositive`], [`Error::InvertedRange`],
    /// [`Error::GradingTooShort`], [`Error::GradingLengthMismatch`],
    /// [`Error::GradingNotMonotone`], [`Error::GradingRange`],
    /// [`Error::MixtureNotTiling`] for the corresponding defect.
    pub fn validate(&self) -> Result<()> {
        match self {
            Self::Constant { diameter } => {
                positive("diameter", *diameter)?;
            }
            Self::Uniform { min, max } => {
                positive("uniform min", *min)?;
                positive("uniform max", *max)?;
                if min > max {
                    return Err(Error::InvertedRange {
                        min: *min,
                        max: *max,
                    });
                }
            }
            Self::Sieve { sizes, passing } => {
                if sizes.len() != passing.len() {
                    return Err(Error::GradingLengthMismatch {
                        sizes: sizes.len(),
                        passing: passing.len(),
                    });
                }
                if sizes.len() < 2 {
                    return Err(Error::GradingTooShort {
                        needed: 2,
                        got: sizes.len(),
                    });
                }
                for (i, (&s, &p)) in sizes.iter().zip(passing).enumerate() {
                    positive("sieve size", s)?;
                    finite("passing", p)?;
                    if i > 0 && (s <= sizes[i - 1] || p < passing[i - 1]) {
                        return Err(Error::GradingNotMonotone {
                            index: i,
                            size: s,
                            passing: p,
                        });
                    }
                }
                let (first, last) = (passing[0], passing[passing.len() - 1]);
                if first.abs() > 1e-9 || (last - 100.0).abs() > 1e-9 {
                    return Err(Error::GradingRange { first, last });
                }
            }
            Self::Mixture(components) => {
                if components.is_empty() {
                    return Err(Error::GradingTooShort { needed: 1, got: 0 });
                }
                let mut at = 0.0;
                for c in components {
                    finite("mixture passing_from", c.passing_from)?;
                    finite("mixture passing_to", c.passing_to)?;
                    if (c.passing_from - at).abs() > 1e-9 || c.passing_to <= c.passing_from {
                        return Err(Error::MixtureNotTiling { at });
                    }
                    if matches!(c.grading, Self::Mixture(_)) {
                        return Err(Error::MixtureNotTiling { at });
                    }
                    c.grading.validate()?;
                    at = c.passing_to;
                }
                if (at - 100.0).abs() > 1e-9 {
                    return Err(Error::MixtureNotTiling { at });
                }
            }
        }
        Ok(())
    }

    /// Smallest diameter the grading can produce.
    pub fn d_min(&self) -> f64 {
        match self {
            Self::Constant { diameter } => *diameter,
            Self::Uniform { min, .. } => *min,
            Self::Sieve { sizes, passing } => {
                // First size after which passing becomes positive.
                let i = passing.iter().rposition(|&p| p <= 0.0).unwrap_or(0);
                sizes[i]
            }
            Self::Mixture(c) => c.iter().map(|c| c.grading.d_min()).fold(f64::MAX, f64::min),
        }
    }

    /// Largest diameter the grading can produce.
    pub fn d_max(&self) -> f64 {
        match self {
            Self::Constant { diameter } => *diameter,
            Self::Uniform { max, .. } => *max,
            Self::Sieve { sizes, passing } => {
                let i = passing
                    .iter()
                    .position(|&p| p >= 100.0)
                    .unwrap_or(sizes.len() - 1);
                sizes[i]
            }
            Self::Mixture(c) => c.iter().map(|c| c.grading.d_max()).fold(0.0, f64::max),
        }
    }

    /// Inverse cumulative distribution: the diameter at cumulative passing
    /// fraction `u ∈ [0, 1]` (clamped). Assumes a validated grading.
    pub fn diameter_at(&self, u: f64) -> f64 {
        let u = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        match self {
            Self::Constant { diameter } => *diameter,
            Self::Uniform { min, max } => min + u * (max - min),
            Self::Sieve { sizes, passing } => {
                let p = 100.0 * u;
                let n = sizes.len();
                for i in 0..n - 1 {
                    let (p0, p1) = (passing[i], passing[i + 1]);
                    if p1 > p0 && p <= p1 {
                        let t = ((p - p0) / (p1 - p0)).clamp(0.0, 1.0);
                        return sizes[i] * (sizes[i + 1] / sizes[i]).powf(t);
                    }
                }
                sizes[n - 1]
            }
            Self::Mixture(components) => {
                let p = 100.0 * u;
                for c in components {
                    if p <= c.passing_to {
                        let t = (p - c.passing_from) / (c.passing_to - c.passing_from);
                        return c.grading.diameter_at(t);
                    }
                }
                components
                    .last()
                    .map_or(0.0, |c| c.grading.diameter_at(1.0))
            }
        }
    }

    /// Cumulative passing fraction (0–1) at diameter `d`; the inverse of
    /// [`Grading::diameter_at`] on its support.
    pub fn passing_at(&self, d: f64) -> f64 {
        match self {
            Self::Constant { diameter } => f64::from(u8::from(d >= *diameter)),
            Self::Uniform { min, max } => {
                if max > min {
                    ((d - min) / (max - min)).clamp(0.0, 1.0)
                } else {
                    f64::from(u8::from(d >= *min))
                }
            }
            Self::Sieve { sizes, passing } => {
                let n = sizes.len();
                if d <= sizes[0] {
                    return passing[0] / 100.0;
                }
                for i in 0..n - 1 {
                    if d <= sizes[i + 1] {
                        let t = (d / sizes[i]).ln() / (sizes[i + 1] / sizes[i]).ln();
                        return (passing[i] + t * (passing[i + 1] - passing[i])) / 100.0;
                    }
                }
                1.0
            }
            Self::Mixture(components) => {
                let mut best = 0.0_f64;
                for c in components {
                    let f = c.grading.passing_at(d);
                    if f > 0.0 {
                        let p = c.passing_from + f * (c.passing_to - c.passing_from);
                        best = best.max(p / 100.0);
                    }
                }
                best
            }
        }
    }

    /// Draws one diameter by inverse-transform sampling (Devroye; Pinto
    /// 2009, §4.2.1).
    pub fn sample(&self, rng: &mut impl Rng) -> f64 {
        self.diameter_at(rng.random::<f64>())
    }
}

/// Particle-count estimate of Pinto 2009, Eq. 3-1:
/// `n_est = ⌈a_c / a_p,min⌉` with `a_p,min = π d_min² / 4`.
pub fn estimate_count(domain_area: f64, d_min: f64) -> f64 {
    (domain_area / (std::f64::consts::PI * d_min * d_min / 4.0)).ceil()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn sieve_inverse_is_semi_log_and_round_trips() {
        let g = Grading::pinto_table_3_4();
        g.validate().expect("valid");
        // Midway in passing between two sieves is the geometric mean size.
        let d = g.diameter_at(0.16);
        assert_relative_eq!(d, (1.215_f64 * 1.225).sqrt(), max_relative = 1e-12);
        for k in 0..=100 {
            let u = f64::from(k) / 100.0;
            assert_relative_eq!(g.passing_at(g.diameter_at(u)), u, epsilon = 1e-12);
        }
        assert_relative_eq!(g.d_min(), 1.2);
        assert_relative_eq!(g.d_max(), 1.295);
    }

    #[test]
    fn ap5_mixture_pieces() {
        let g = Grading::pinto_ap5();
        g.validate().expect("valid");
        assert_relative_eq!(g.diameter_at(0.05), 1.8, epsilon = 1e-12);
        assert_relative_eq!(g.diameter_at(0.5), 2.4, epsilon = 1e-12);
        assert_relative_eq!(g.diameter_at(0.95), 4.2, epsilon = 1e-12);
        assert_relative_eq!(g.d_min(), 1.2);
        assert_relative_eq!(g.d_max(), 6.0);
    }

    #[test]
    fn uniform_sample_mean() {
        use rand::SeedableRng;
        let seed = 11;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let g = Grading::Uniform { min: 1.2, max: 2.4 };
        let n = 100_000;
        let mean = (0..n).map(|_| g.sample(&mut rng)).sum::<f64>() / f64::from(n);
        // Standard error 0.35/sqrt(1e5) ≈ 0.0011.
        assert!((mean - 1.8).abs() < 0.005, "mean {mean}");
    }

    #[test]
    fn bad_gradings_are_errors() {
        let bad = [
            Grading::Sieve {
                sizes: vec![],
                passing: vec![],
            },
            Grading::Sieve {
                sizes: vec![1.0, 0.9],
                passing: vec![0.0, 100.0],
            },
            Grading::Sieve {
                sizes: vec![1.0, 2.0],
                passing: vec![0.0, 90.0],
            },
            Grading::Sieve {
                sizes: vec![1.0, 2.0, 3.0],
                passing: vec![0.0, 60.0, 50.0],
            },
            Grading::Sieve {
                sizes: vec![-1.0, 2.0],
                passing: vec![0.0, 100.0],
            },
            Grading::Sieve {
                sizes: vec![f64::NAN, 2.0],
                passing: vec![0.0, 100.0],
            },
            Grading::Constant { diameter: 0.0 },
            Grading::Uniform { min: 2.0, max: 1.0 },
            Grading::Mixture(vec![]),
        ];
        for g in bad {
            assert!(g.validate().is_err(), "{g:?} accepted");
        }
    }

    #[test]
    fn eq_3_1_estimate() {
        // 8.6 × 62.5 mm with d_min = 1.2 mm: 537.5 / 1.1310 = 475.3 -> 476.
        assert_relative_eq!(estimate_count(537.5, 1.2), 476.0);
    }
}
