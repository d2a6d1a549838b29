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
//!
//! A [`Grading::LogNormal`] is truncated to `[min, max]`; its inverse CDF
//! uses an inverse normal accurate to double precision (Acklam's rational
//! approximation refined by Halley steps on a careful `erfc`). Every
//! curve is a **number** distribution (one draw per particle); the mass
//! curve of the geotechnical report is derived from it (`MassCurve`).

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
    /// Log-normal by number: `ln d` is normal with mean `ln median` and
    /// standard deviation `sigma`, truncated to `[min, max]` (the number
    /// distribution is renormalised on the interval, so `median` is the
    /// median of the untruncated law).
    LogNormal {
        /// Median diameter of the untruncated distribution.
        median: f64,
        /// Standard deviation of `ln d` (dimensionless).
        sigma: f64,
        /// Smallest diameter (truncation).
        min: f64,
        /// Largest diameter (truncation).
        max: f64,
    },
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

    /// A sieve curve given as cumulative passing **by mass** (what a
    /// laboratory reports), as the number distribution the packers draw
    /// from: a [`Grading::Sieve`] by number, exact at the sieve sizes and
    /// refined with 32 semi-log points per interval.
    ///
    /// Between two sieves the mass passing is interpolated semi-log (mass
    /// uniform in `ln d`, as the by-number curves), so the number density per
    /// `ln d` is proportional to `d⁻³` there: the interval `[a, b]` holding
    /// the mass fraction `Δm` holds the number weight
    /// `Δm · (a⁻³ − b⁻³) / (3 ln(b / a))`, spread inside it as
    /// `F(d) = (a⁻³ − d⁻³) / (a⁻³ − b⁻³)`. The sizes are whatever dimension
    /// the caller maps them to (for grains: the sieve opening that the
    /// intermediate dimension passes).
    ///
    /// # Errors
    /// As [`Grading::validate`] for the sieve curve.
    pub fn sieve_by_mass(sizes: Vec<f64>, passing: Vec<f64>) -> Result<Self> {
        const SUB: usize = 32;
        let mass = Self::Sieve { sizes, passing };
        mass.validate()?;
        let Self::Sieve { sizes, passing } = mass else {
            unreachable!("constructed above")
        };
        let n = sizes.len();
        let weight: Vec<f64> = (0..n - 1)
            .map(|i| {
                let (a, b) = (sizes[i], sizes[i + 1]);
                let dm = passing[i + 1] - passing[i];
                if dm > 0.0 {
                    dm * (a.powi(-3) - b.powi(-3)) / (3.0 * (b / a).ln())
                } else {
                    0.0
                }
            })
            .collect();
        let total: f64 = weight.iter().sum();
        let mut out_sizes = vec![sizes[0]];
        let mut out_pass = vec![0.0];
        let mut acc = 0.0;
        for i in 0..n - 1 {
            let (a, b) = (sizes[i], sizes[i + 1]);
            for j in 1..=SUB {
                let d = if j == SUB {
                    b
                } else {
                    a * (b / a).powf(j as f64 / SUB as f64)
                };
                let f = (a.powi(-3) - d.powi(-3)) / (a.powi(-3) - b.powi(-3));
                out_sizes.push(d);
                out_pass.push(100.0 * (acc + weight[i] * f) / total);
            }
            acc += weight[i];
        }
        // round-off: the curve ends at exactly 100
        if let Some(last) = out_pass.last_mut() {
            *last = 100.0;
        }
        for k in 1..out_pass.len() {
            out_pass[k] = out_pass[k].max(out_pass[k - 1]).min(100.0);
        }
        let g = Self::Sieve {
            sizes: out_sizes,
            passing: out_pass,
        };
        g.validate()?;
        Ok(g)
    }

    /// Checks every invariant of the variant.
    ///
    /// # Errors
    /// [`Error::NonFinite`], [`Error::NonPositive`], [`Error::InvertedRange`],
    /// [`Error::GradingTooShort`], [`Error::GradingLengthMismatch`],
    /// [`Error::GradingNotMonotone`], [`Error::GradingRange`],
    /// [`Error::MixtureNotTiling`] for the corresponding defect;
    /// [`Error::Parameter`] for a log-normal whose interval `[min, max]`
    /// has a probability below `1e-250` (too far in a tail to sample).
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
            Self::LogNormal {
                median,
                sigma,
                min,
                max,
            } => {
                positive("log-normal median", *median)?;
                positive("log-normal sigma", *sigma)?;
                positive("log-normal min", *min)?;
                positive("log-normal max", *max)?;
                if min >= max {
                    return Err(Error::InvertedRange {
                        min: *min,
                        max: *max,
                    });
                }
                let t = Truncated::new(*median, *sigma, *min, *max);
                if t.mass.is_nan() || t.mass < 1e-250 {
                    return Err(Error::Parameter {
                        what: "log-normal probability of [min, max]",
                        value: t.mass,
                        range: "[1e-250, 1]",
                    });
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
            Self::LogNormal { min, .. } => *min,
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
            Self::LogNormal { max, .. } => *max,
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
            Self::LogNormal {
                median,
                sigma,
                min,
                max,
            } => {
                if u <= 0.0 {
                    return *min;
                }
                if u >= 1.0 {
                    return *max;
                }
                let t = Truncated::new(*median, *sigma, *min, *max);
                (median * (sigma * t.quantile(u)).exp()).clamp(*min, *max)
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
            Self::LogNormal {
                median,
                sigma,
                min,
                max,
            } => {
                if d <= *min {
                    return 0.0;
                }
                if d >= *max {
                    return 1.0;
                }
                let t = Truncated::new(*median, *sigma, *min, *max);
                t.cdf((d / median).ln() / sigma)
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

/// The standard normal law truncated to `[za, zb]`. When the interval
/// leans into the upper half (`za + zb > 0`) every probability is an
/// upper-tail one, `Q(z) = Φ(−z)`, so that far tails keep full precision.
struct Truncated {
    za: f64,
    zb: f64,
    upper: bool,
    /// `Φ(za)` (or `Q(za)` when `upper`).
    pa: f64,
    /// Probability of `[za, zb]`.
    mass: f64,
}

impl Truncated {
    fn new(median: f64, sigma: f64, min: f64, max: f64) -> Self {
        let za = (min / median).ln() / sigma;
        let zb = (max / median).ln() / sigma;
        // The formulation of the tail the interval leans into.
        let upper = za + zb > 0.0;
        let (pa, pb) = if upper {
            (norm_cdf(-za), norm_cdf(-zb))
        } else {
            (norm_cdf(za), norm_cdf(zb))
        };
        Self {
            za,
            zb,
            upper,
            pa,
            mass: (pb - pa).abs(),
        }
    }

    /// Truncated CDF at the standard score `z`.
    fn cdf(&self, z: f64) -> f64 {
        if z <= self.za {
            return 0.0;
        }
        if z >= self.zb {
            return 1.0;
        }
        let f = if self.upper {
            (self.pa - norm_cdf(-z)) / self.mass
        } else {
            (norm_cdf(z) - self.pa) / self.mass
        };
        f.clamp(0.0, 1.0)
    }

    /// Standard score at truncated cumulative probability `u ∈ [0, 1]`.
    fn quantile(&self, u: f64) -> f64 {
        if u <= 0.0 {
            return self.za;
        }
        if u >= 1.0 {
            return self.zb;
        }
        let z = if self.upper {
            -norm_ppf(self.pa - u * self.mass)
        } else {
            norm_ppf(self.pa + u * self.mass)
        };
        z.clamp(self.za, self.zb)
    }
}

/// `2/√π`.
const TWO_OVER_SQRT_PI: f64 = std::f64::consts::FRAC_2_SQRT_PI;

/// Complementary error function, relative accuracy about `1e-15`
/// (`2e-14` near `x = 1.5`, where `1 − erf` cancels most).
///
/// For `|x| < 1.5`, `erf` from the series of positive terms
/// `erf x = 2/√π e^{−x²} Σ 2ⁿ x^{2n+1} / (1·3···(2n+1))`
/// (Abramowitz & Stegun 1964, Eq. 7.1.6); beyond, the continued fraction
/// `erfc x = e^{−x²}/√π · 1/(x + ½/(x + 1/(x + 3/2/(x + …))))`
/// (A&S Eq. 7.1.14), evaluated by the modified Lentz method;
/// `erfc(−x) = 2 − erfc(x)`.
pub fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    if x < 1.5 {
        return 1.0 - erf_series(x);
    }
    if x > 27.5 {
        return 0.0;
    }
    // Modified Lentz for F = x + a1/(x + a2/(x + …)), a_n = n/2.
    let tiny = 1e-300;
    let mut f = x;
    let mut c = f;
    let mut d = 0.0;
    for n in 1..5000 {
        let a = 0.5 * f64::from(n);
        d = x + a * d;
        if d.abs() < tiny {
            d = tiny;
        }
        c = x + a / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        let delta = c * d;
        f *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    0.5 * TWO_OVER_SQRT_PI * (-x * x).exp() / f
}

/// `erf x` by the series of positive terms (A&S Eq. 7.1.6), `x ≥ 0` small.
fn erf_series(x: f64) -> f64 {
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    for n in 1..200 {
        term *= 2.0 * x2 / f64::from(2 * n + 1);
        sum += term;
        if term < 1e-17 * sum {
            break;
        }
    }
    TWO_OVER_SQRT_PI * (-x2).exp() * sum
}

/// Standard normal CDF `Φ(z) = erfc(−z/√2)/2`.
pub fn norm_cdf(z: f64) -> f64 {
    0.5 * erfc(-z * std::f64::consts::FRAC_1_SQRT_2)
}

/// Inverse standard normal CDF: Acklam's rational approximation (relative
/// error `1.15e-9`) refined by Halley steps on [`norm_cdf`] to full double
/// precision. `p ≤ 0` gives `−∞`, `p ≥ 1` gives `+∞`; the upper half is
/// mirrored (`Φ⁻¹(p) = −Φ⁻¹(1 − p)`, `1 − p` exact there) so that every
/// Halley residual is a lower-tail probability.
pub fn norm_ppf(p: f64) -> f64 {
    if p.is_nan() {
        return f64::NAN;
    }
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    if p > 0.5 {
        return -norm_ppf(1.0 - p);
    }
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
    let mut x = if p < 0.02425 {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    };
    // Halley on Φ(x) − p: cubic convergence, so two steps from 1e-9 are
    // more than enough; stop when the step no longer changes x.
    let sqrt_2pi = (2.0 * std::f64::consts::PI).sqrt();
    for _ in 0..3 {
        let e = norm_cdf(x) - p;
        let u = e * sqrt_2pi * (0.5 * x * x).exp();
        if !u.is_finite() {
            break;
        }
        let step = u / (1.0 + 0.5 * x * u);
        x -= step;
        if step.abs() <= 1e-16 * x.abs() {
            break;
        }
    }
    x
}

/// Cumulative passing **by mass** of a number distribution, for the
/// geotechnical grading report.
///
/// [`Grading`] curves are number distributions: the packer draws one
/// diameter per particle with [`Grading::sample`]. With `D(u)` the inverse
/// number CDF ([`Grading::diameter_at`]) and mass ∝ `d³`, the mass fraction
/// passing `d` is `M(F(d))` with `M(u) = ∫₀ᵘ D(v)³ dv / ∫₀¹ D(v)³ dv`
/// (the substitution `d = D(v)` in `∫ s³ dF(s)`), which also handles atoms
/// (constant diameters) exactly. `M` is tabulated once by two-point
/// Gauss–Legendre on `2¹⁴` equal cells of `u`.
pub struct MassCurve<'a> {
    grading: &'a Grading,
    /// `M(k / N)`, `k = 0..=N`, normalised to end at 1.
    cum: Vec<f64>,
}

impl<'a> MassCurve<'a> {
    const CELLS: usize = 1 << 14;

    /// Tabulates `M` for a validated grading.
    pub fn new(grading: &'a Grading) -> Self {
        let n = Self::CELLS;
        let h = 1.0 / n as f64;
        let off = 0.5 / 3f64.sqrt();
        let mut cum = Vec::with_capacity(n + 1);
        let mut acc = 0.0;
        cum.push(0.0);
        for k in 0..n {
            let mid = (k as f64 + 0.5) * h;
            let d1 = grading.diameter_at(mid - off * h);
            let d2 = grading.diameter_at(mid + off * h);
            acc += 0.5 * h * (d1 * d1 * d1 + d2 * d2 * d2);
            cum.push(acc);
        }
        if acc > 0.0 {
            for c in &mut cum {
                *c /= acc;
            }
        }
        Self { grading, cum }
    }

    /// `M(u)`, linear between the tabulated nodes.
    fn at_u(&self, u: f64) -> f64 {
        let n = Self::CELLS;
        let s = u.clamp(0.0, 1.0) * n as f64;
        let k = (s.floor() as usize).min(n - 1);
        let t = s - k as f64;
        self.cum[k] + t * (self.cum[k + 1] - self.cum[k])
    }

    /// Mass fraction (0–1) passing the size `d`.
    pub fn passing(&self, d: f64) -> f64 {
        self.at_u(self.grading.passing_at(d))
    }

    /// Size at which the mass fraction `x ∈ [0, 1]` passes (`D_x` by mass).
    pub fn quantile(&self, x: f64) -> f64 {
        let n = Self::CELLS;
        let x = x.clamp(0.0, 1.0);
        // First node with cum > x: the cell [k, k + 1] holds x.
        let k = self.cum.partition_point(|&c| c <= x).clamp(1, n) - 1;
        let (c0, c1) = (self.cum[k], self.cum[k + 1]);
        let t = if c1 > c0 {
            ((x - c0) / (c1 - c0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.grading.diameter_at((k as f64 + t) / n as f64)
    }
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

    /// A lab's mass-passing curve turned into a number distribution gives the
    /// same mass passing back at every sieve (the report's mass curve of the
    /// number distribution), and far more small grains by number.
    #[test]
    fn sieve_by_mass_round_trips_the_mass_passing() {
        let sizes = vec![0.1, 0.15, 0.25, 0.425, 0.6];
        let passing = vec![0.0, 8.0, 45.0, 90.0, 100.0];
        let g = Grading::sieve_by_mass(sizes.clone(), passing.clone()).expect("valid");
        let m = MassCurve::new(&g);
        for (d, p) in sizes.iter().zip(&passing) {
            assert!(
                (100.0 * m.passing(*d) - p).abs() < 0.05,
                "{d}: {}",
                100.0 * m.passing(*d)
            );
        }
        // by number the finest interval holds 8 % of the mass but 39.4 % of the grains:
        // 8 (10³ − 0.15⁻³) / (3 ln 1.5) over the sum of the four intervals' weights
        let w = |a: f64, b: f64, dm: f64| dm * (a.powi(-3) - b.powi(-3)) / (3.0 * (b / a).ln());
        let first = w(0.1, 0.15, 8.0);
        let all = first + w(0.15, 0.25, 37.0) + w(0.25, 0.425, 45.0) + w(0.425, 0.6, 10.0);
        assert_relative_eq!(g.passing_at(0.15), first / all, epsilon = 1e-12);
        assert!(first / all > 0.39);
        assert_relative_eq!(g.d_min(), 0.1);
        assert_relative_eq!(g.d_max(), 0.6);
        // flat intervals (no mass) stay empty; bad curves are errors
        let flat = Grading::sieve_by_mass(vec![1.0, 2.0, 3.0, 4.0], vec![0.0, 50.0, 50.0, 100.0])
            .expect("flat middle");
        assert_relative_eq!(flat.passing_at(2.0), flat.passing_at(3.0), epsilon = 1e-12);
        assert!(Grading::sieve_by_mass(vec![1.0, 2.0], vec![0.0, 90.0]).is_err());
        assert!(Grading::sieve_by_mass(vec![2.0, 1.0], vec![0.0, 100.0]).is_err());
        assert!(Grading::sieve_by_mass(vec![1.0, f64::NAN], vec![0.0, 100.0]).is_err());
        assert!(Grading::sieve_by_mass(vec![1.0, 2.0, 3.0], vec![0.0, 100.0]).is_err());
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
