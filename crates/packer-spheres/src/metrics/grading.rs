//! The geotechnical grading report: the packed grading by mass and by
//! number against the requested one.

use rayon::prelude::*;

use super::validate_spheres;
use crate::Sphere;
use crate::error::{Error, Result};
use packer_quadtree::{Grading, MassCurve};

/// Characteristic sizes and coefficients of one grading curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradingStats {
    /// Size at which 10 % of the mass passes.
    pub d10: f64,
    /// Size at which 30 % of the mass passes.
    pub d30: f64,
    /// Size at which 50 % of the mass passes.
    pub d50: f64,
    /// Size at which 60 % of the mass passes.
    pub d60: f64,
    /// Uniformity coefficient `Cu = D60 / D10` (by mass).
    pub cu: f64,
    /// Curvature coefficient `Cc = D30² / (D10 · D60)` (by mass).
    pub cc: f64,
    /// Size at which 10 % of the particles (by number) pass.
    pub d10_number: f64,
    /// Size at which 30 % of the particles pass.
    pub d30_number: f64,
    /// Size at which 50 % of the particles pass.
    pub d50_number: f64,
    /// Size at which 60 % of the particles pass.
    pub d60_number: f64,
}

impl GradingStats {
    fn new(mass: impl Fn(f64) -> f64, number: impl Fn(f64) -> f64) -> Self {
        let (d10, d30, d50, d60) = (mass(0.1), mass(0.3), mass(0.5), mass(0.6));
        Self {
            d10,
            d30,
            d50,
            d60,
            cu: d60 / d10,
            cc: d30 * d30 / (d10 * d60),
            d10_number: number(0.1),
            d30_number: number(0.3),
            d50_number: number(0.5),
            d60_number: number(0.6),
        }
    }
}

/// Requested against packed grading, by mass (geotechnical convention).
#[derive(Debug, Clone, PartialEq)]
pub struct GradingReport {
    /// Number of spheres.
    pub n_spheres: usize,
    /// Statistics of the requested distribution.
    pub requested: GradingStats,
    /// Statistics of the packed sample.
    pub packed: GradingStats,
    /// 201 log-spaced sizes (diameters) spanning both curves.
    pub sizes: Vec<f64>,
    /// Requested mass fraction passing each of [`GradingReport::sizes`].
    pub requested_passing: Vec<f64>,
    /// Packed mass fraction passing each size.
    pub packed_passing: Vec<f64>,
    /// Largest absolute difference of the packed and requested mass
    /// passing fractions (0–1) over a fine set of sizes: both sides of
    /// every packed diameter and 1024 log-spaced sizes.
    pub max_deviation: f64,
    /// Size at which [`GradingReport::max_deviation`] occurs.
    pub max_deviation_at: f64,
}

/// Grading report of a packing: the cumulative passing curves **by mass**
/// (volume ∝ `d³`) of the requested distribution and of the packed sample,
/// their `D10/D30/D50/D60`, `Cu = D60/D10` and `Cc = D30²/(D10·D60)` (by
/// mass; number-based `D`s too) and the largest deviation of the packed
/// mass curve from the requested one.
///
/// [`Grading`] curves are **number** distributions, as the packer samples
/// them (one diameter per particle). The requested mass curve is
/// `M(F(d))`, `M(u) = ∫₀ᵘ D(v)³ dv / ∫₀¹ D(v)³ dv` with `D` the inverse
/// number CDF — the integral of `d³ × number density` after the
/// substitution `d = D(v)`, which also covers constant sizes (atoms);
/// it is tabulated by Gauss–Legendre on `2¹⁴` cells of `u`. The packed
/// curve is the step function `Σ_{d_i ≤ d} d_i³ / Σ d_i³`; its `D_x` is the
/// smallest packed diameter at which at least the fraction `x` passes.
///
/// # Errors
/// Grading validation errors; [`Error::Empty`] without spheres;
/// [`Error::NonFinite`] / [`Error::NonPositive`] for a bad sphere.
pub fn grading_report(requested: &Grading, spheres: &[Sphere]) -> Result<GradingReport> {
    requested.validate()?;
    if spheres.is_empty() {
        return Err(Error::Empty { what: "spheres" });
    }
    validate_spheres(spheres)?;
    let n = spheres.len();
    let mut d: Vec<f64> = spheres.iter().map(|s| 2.0 * s.radius).collect();
    d.sort_by(f64::total_cmp);
    let mut cum = Vec::with_capacity(n);
    let mut acc = 0.0;
    for &x in &d {
        acc += x * x * x;
        cum.push(acc);
    }
    for c in &mut cum {
        *c /= acc;
    }
    // Packed passing (mass) at size `s`: spheres with d ≤ s.
    let packed_at = |s: f64| {
        let k = d.partition_point(|&x| x <= s);
        if k == 0 { 0.0 } else { cum[k - 1] }
    };
    let curve = MassCurve::new(requested);
    let requested_stats = GradingStats::new(|x| curve.quantile(x), |x| requested.diameter_at(x));
    let packed_stats = GradingStats::new(
        |x| {
            let k = cum.partition_point(|&c| c < x).min(n - 1);
            d[k]
        },
        |x| {
            let k = ((x * n as f64).ceil() as usize).clamp(1, n) - 1;
            d[k]
        },
    );

    let lo = requested.d_min().min(d[0]) * 0.999;
    let hi = requested.d_max().max(d[n - 1]) * 1.001;
    let log_size = |k: usize, m: usize| lo * (hi / lo).powf(k as f64 / m as f64);

    // Deviation at both sides of every distinct packed diameter (the jumps
    // of the step function) and on a fine log grid.
    let best = |a: (f64, f64), b: (f64, f64)| {
        if b.0.total_cmp(&a.0).then(a.1.total_cmp(&b.1)).is_gt() {
            b
        } else {
            a
        }
    };
    let at_jumps = (0..n)
        .into_par_iter()
        .with_min_len(1024)
        .filter(|&k| k + 1 == n || d[k + 1] > d[k])
        .map(|k| {
            let first = d.partition_point(|&x| x < d[k]);
            let left = if first == 0 { 0.0 } else { cum[first - 1] };
            let dl = (left - curve.passing(d[k] * (1.0 - 1e-12))).abs();
            let dr = (cum[k] - curve.passing(d[k])).abs();
            (dl.max(dr), d[k])
        })
        .reduce(|| (0.0, f64::INFINITY), best);
    let on_grid = (0..=1024)
        .map(|k| {
            let s = log_size(k, 1024);
            ((packed_at(s) - curve.passing(s)).abs(), s)
        })
        .fold((0.0, f64::INFINITY), best);
    let (max_deviation, max_deviation_at) = best(at_jumps, on_grid);

    let sizes: Vec<f64> = (0..=200).map(|k| log_size(k, 200)).collect();
    Ok(GradingReport {
        n_spheres: n,
        requested: requested_stats,
        packed: packed_stats,
        requested_passing: sizes.iter().map(|&s| curve.passing(s)).collect(),
        packed_passing: sizes.iter().map(|&s| packed_at(s)).collect(),
        sizes,
        max_deviation,
        max_deviation_at,
    })
}
