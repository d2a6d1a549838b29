//! Samplers of univariate and bivariate densities: the seed's
//! acceptance–rejection (Medina 2018, §2.2) and an exact tabulated
//! inverse-CDF sampler with marginal and conditional draws.
//!
//! Every sampler takes the caller's `rng: &mut impl rand::Rng`; draws depend
//! only on the generator's stream.

use rand::Rng;

use crate::error::{Error, Result};
use crate::histogram::{BinAxis, Histogram1d};
use crate::pdf::{BicubicPdf, TabulatedPdf2d};

/// A bounded bivariate density on a rectangle, as needed by
/// [`AcceptanceRejection2d`].
pub trait Density2d {
    /// The rectangle `((x_min, x_max), (y_min, y_max))` outside which the
    /// density is zero.
    fn support(&self) -> ((f64, f64), (f64, f64));
    /// The density at `(x, y)` (non-negative).
    fn density(&self, x: f64, y: f64) -> f64;
    /// An upper bound of [`Density2d::density`] on the support.
    fn upper_bound(&self) -> f64;
    /// Checks the density's own invariants (default: none to check).
    ///
    /// # Errors
    /// Whatever the implementation finds.
    fn validate(&self) -> Result<()> {
        Ok(())
    }
}

impl Density2d for BicubicPdf {
    fn support(&self) -> ((f64, f64), (f64, f64)) {
        let (x, y) = (self.x_axis(), self.y_axis());
        ((x.min, x.max), (y.min, y.max))
    }
    fn density(&self, x: f64, y: f64) -> f64 {
        BicubicPdf::density(self, x, y)
    }
    fn upper_bound(&self) -> f64 {
        BicubicPdf::upper_bound(self)
    }
}

impl Density2d for TabulatedPdf2d {
    fn support(&self) -> ((f64, f64), (f64, f64)) {
        ((self.x.min, self.x.max), (self.y.min, self.y.max))
    }
    fn density(&self, x: f64, y: f64) -> f64 {
        self.density_at(x, y)
    }
    fn upper_bound(&self) -> f64 {
        self.max_density()
    }
    fn validate(&self) -> Result<()> {
        TabulatedPdf2d::validate(self)
    }
}

/// The seed's Monte Carlo sampler (Medina 2018, §2.2): propose `(x, y)`
/// uniformly on the support, accept with probability `f(x, y) / M`.
///
/// Exact for any density bounded by `M`; the expected number of proposals per
/// draw is `M · area` ([`AcceptanceRejection2d::expected_trials`]).
#[derive(Debug, Clone)]
pub struct AcceptanceRejection2d<D> {
    pdf: D,
    x: (f64, f64),
    y: (f64, f64),
    bound: f64,
}

impl<D: Density2d> AcceptanceRejection2d<D> {
    /// Wraps a density.
    ///
    /// # Errors
    /// [`Density2d::validate`]'s errors, [`Error::InvalidRange`] for an
    /// empty or non-finite support,
    /// [`Error::InvalidParameter`] for a bound that is not finite and positive.
    pub fn new(pdf: D) -> Result<Self> {
        pdf.validate()?;
        let (x, y) = pdf.support();
        for (a, b) in [x, y] {
            if !(a.is_finite() && b.is_finite() && a < b) {
                return Err(Error::InvalidRange { min: a, max: b });
            }
        }
        let bound = pdf.upper_bound();
        if !(bound.is_finite() && bound > 0.0) {
            return Err(Error::InvalidParameter {
                name: "upper bound",
                value: bound,
                reason: "must be finite and positive",
            });
        }
        Ok(Self { pdf, x, y, bound })
    }

    /// Expected proposals per accepted draw, `M · area`.
    pub fn expected_trials(&self) -> f64 {
        self.bound * (self.x.1 - self.x.0) * (self.y.1 - self.y.0)
    }

    /// The wrapped density.
    pub fn pdf(&self) -> &D {
        &self.pdf
    }

    /// One draw of `y` given `x` by rejection on the slice `f(x, ·)` (the
    /// seed's Monte Carlo applied to the quality control of Medina 2018,
    /// §2.4): propose `y` uniformly, accept with probability `f(x, y) / M`.
    /// The expected number of proposals is `M · height / ∫f(x, y) dy`, large
    /// where the slice carries little mass, hence the limit `max_trials`;
    /// [`InverseCdfSampler2d::sample_y_given_x`] has no such limit.
    ///
    /// # Errors
    /// [`Error::OutsideSupport`] for `x` outside the support,
    /// [`Error::TooManyRejections`] after `max_trials` rejected proposals.
    pub fn sample_y_given_x(&self, x: f64, max_trials: usize, rng: &mut impl Rng) -> Result<f64> {
        if !(x >= self.x.0 && x <= self.x.1) {
            return Err(Error::OutsideSupport {
                value: x,
                min: self.x.0,
                max: self.x.1,
            });
        }
        for _ in 0..max_trials {
            let y = self.y.0 + (self.y.1 - self.y.0) * rng.random::<f64>();
            if rng.random::<f64>() * self.bound < self.pdf.density(x, y) {
                return Ok(y);
            }
        }
        Err(Error::TooManyRejections { trials: max_trials })
    }

    /// One draw.
    pub fn sample(&self, rng: &mut impl Rng) -> (f64, f64) {
        loop {
            let x = self.x.0 + (self.x.1 - self.x.0) * rng.random::<f64>();
            let y = self.y.0 + (self.y.1 - self.y.0) * rng.random::<f64>();
            if rng.random::<f64>() * self.bound < self.pdf.density(x, y) {
                return (x, y);
            }
        }
    }
}

/// Acceptance–rejection for a [`BicubicPdf`] under a piecewise-constant
/// envelope: one rigorous bound per histogram bin
/// ([`BicubicPdf::cell_upper_bounds`]), a bin drawn in proportion to
/// `bound · area`, a uniform proposal inside it, acceptance with probability
/// `f / bound`. Exact like [`AcceptanceRejection2d`] (same target density)
/// but with far fewer rejections, because the envelope follows the density
/// instead of its global maximum.
#[derive(Debug, Clone)]
pub struct EnvelopeRejection2d {
    pdf: BicubicPdf,
    bounds: Vec<f64>,
    cells: GuidedCdf,
    expected_trials: f64,
}

impl EnvelopeRejection2d {
    /// Builds the envelope (O(bins)).
    ///
    /// # Errors
    /// [`Error::ZeroMass`] if every bound is zero (impossible for a PDF built
    /// from a non-empty histogram; kept as a guard).
    pub fn new(pdf: BicubicPdf) -> Result<Self> {
        let bounds = pdf.cell_upper_bounds();
        let area = pdf.x_axis().width() * pdf.y_axis().width();
        let total: f64 = bounds.iter().sum::<f64>() * area;
        if !(total.is_finite() && total > 0.0) {
            return Err(Error::ZeroMass {
                context: "in the envelope".into(),
            });
        }
        Ok(Self {
            cells: GuidedCdf::new(&bounds),
            pdf,
            bounds,
            expected_trials: total,
        })
    }

    /// Expected proposals per accepted draw (the envelope's mass).
    pub fn expected_trials(&self) -> f64 {
        self.expected_trials
    }

    /// One draw.
    pub fn sample(&self, rng: &mut impl Rng) -> (f64, f64) {
        let (ax, ay) = (self.pdf.x_axis(), self.pdf.y_axis());
        loop {
            let (c, _) = self.cells.locate(rng.random::<f64>());
            let (i, j) = (c / ay.bins, c % ay.bins);
            let x = (ax.edge(i) + ax.width() * rng.random::<f64>()).min(ax.max);
            let y = (ay.edge(j) + ay.width() * rng.random::<f64>()).min(ay.max);
            if rng.random::<f64>() * self.bounds[c] < self.pdf.density(x, y) {
                return (x, y);
            }
        }
    }
}

/// A discrete CDF over `n` cells with a guide table (Chen & Asau 1974) for
/// O(1) expected lookup.
#[derive(Debug, Clone, PartialEq)]
struct GuidedCdf {
    /// `cdf[0] = 0`, `cdf[n] = 1`, non-decreasing.
    cdf: Vec<f64>,
    /// `guide[g]`: first cell whose upper CDF exceeds `g / n`.
    guide: Vec<u32>,
}

impl GuidedCdf {
    /// From non-negative weights with positive finite sum.
    fn new(weights: &[f64]) -> Self {
        let mut out = Self {
            cdf: Vec::with_capacity(weights.len() + 1),
            guide: Vec::with_capacity(weights.len()),
        };
        build_guided(weights, &mut out.cdf, &mut out.guide);
        out
    }

    /// Cell `k` with `cdf[k] ≤ u < cdf[k+1]` and the fraction of the way
    /// through it, for `u ∈ [0, 1)`.
    #[inline]
    fn locate(&self, u: f64) -> (usize, f64) {
        locate_guided(&self.cdf, &self.guide, u)
    }
}

/// Appends the `n + 1` CDF values and `n` guide entries of `weights`
/// (non-negative, positive finite sum) to `cdf` and `guide`.
fn build_guided(weights: &[f64], cdf: &mut Vec<f64>, guide: &mut Vec<u32>) {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let base = cdf.len();
    cdf.push(0.0);
    let mut acc = 0.0;
    for w in weights {
        acc += w;
        cdf.push((acc / total).min(1.0));
    }
    // Trailing empty cells keep their exact 1.0; the last positive cell ends at 1.
    if let Some(last) = weights.iter().rposition(|w| *w > 0.0) {
        for c in &mut cdf[base + last + 1..] {
            *c = 1.0;
        }
    }
    let cdf = &cdf[base..];
    let mut k = 0usize;
    for g in 0..n {
        let t = g as f64 / n as f64;
        while k + 1 < n && cdf[k + 1] <= t {
            k += 1;
        }
        guide.push(k as u32);
    }
}

/// Cell `k` of a guided CDF (`cdf.len() = guide.len() + 1`) with
/// `cdf[k] ≤ u < cdf[k+1]`, and the fraction of the way through it.
#[inline]
fn locate_guided(cdf: &[f64], guide: &[u32], u: f64) -> (usize, f64) {
    let n = guide.len();
    let g = ((u * n as f64) as usize).min(n - 1);
    let mut k = guide[g] as usize;
    // One step back covers a rounding of `u · n` up across a guide boundary.
    while k > 0 && cdf[k] > u {
        k -= 1;
    }
    while k + 1 < n && cdf[k + 1] <= u {
        k += 1;
    }
    let (lo, hi) = (cdf[k], cdf[k + 1]);
    let frac = if hi > lo {
        ((u - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.5
    };
    (k, frac)
}

/// Exact inverse-CDF sampler of a piecewise-constant univariate density
/// (for example a [`Histogram1d`]).
#[derive(Debug, Clone, PartialEq)]
pub struct InverseCdfSampler1d {
    axis: BinAxis,
    cdf: GuidedCdf,
}

impl InverseCdfSampler1d {
    /// From non-negative bin weights on `axis`.
    ///
    /// # Errors
    /// Axis errors, [`Error::RaggedTable`] if `weights.len() != axis.bins`,
    /// [`Error::NonPositive`] for a negative or NaN weight, [`Error::ZeroMass`].
    pub fn new(axis: BinAxis, weights: &[f64]) -> Result<Self> {
        axis.validate()?;
        if weights.len() != axis.bins {
            return Err(Error::RaggedTable {
                what: "weights",
                index: 0,
                expected: axis.bins,
                found: weights.len(),
            });
        }
        if let Some(k) = weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(Error::NonPositive {
                what: "weight",
                index: k,
                value: weights[k],
            });
        }
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return Err(Error::ZeroMass {
                context: "in the weights".into(),
            });
        }
        Ok(Self {
            axis,
            cdf: GuidedCdf::new(weights),
        })
    }

    /// The histogram's piecewise-constant density.
    ///
    /// # Errors
    /// As [`InverseCdfSampler1d::new`] (cannot fail for a valid histogram).
    pub fn from_histogram(h: &Histogram1d) -> Result<Self> {
        let w: Vec<f64> = h.counts.iter().map(|c| *c as f64).collect();
        Self::new(h.axis, &w)
    }

    /// The quantile function at `u ∈ [0, 1)` (clamped into it).
    pub fn quantile(&self, u: f64) -> f64 {
        let u = if u.is_nan() {
            0.0
        } else {
            u.clamp(0.0, 1.0 - f64::EPSILON / 2.0)
        };
        let (k, f) = self.cdf.locate(u);
        (self.axis.edge(k) + f * self.axis.width()).min(self.axis.max)
    }

    /// One draw.
    pub fn sample(&self, rng: &mut impl Rng) -> f64 {
        self.quantile(rng.random::<f64>())
    }
}

/// Exact inverse-CDF sampler of a [`TabulatedPdf2d`]: `x` from the marginal
/// CDF over columns, then `y` from the conditional CDF of that column, each
/// uniform within its cell. Exact for the tabulated (piecewise-constant)
/// density; tabulate a [`BicubicPdf`] finely ([`BicubicPdf::tabulate`]) to
/// sample it to any accuracy.
#[derive(Debug, Clone, PartialEq)]
pub struct InverseCdfSampler2d {
    x: BinAxis,
    y: BinAxis,
    marginal: GuidedCdf,
    /// Conditional CDFs of every column, `y.bins + 1` values per column,
    /// contiguous (columns without mass hold zeros and are never located).
    cond_cdf: Vec<f64>,
    /// Guide tables of the conditional CDFs, `y.bins` entries per column.
    cond_guide: Vec<u32>,
    /// Whether each column has mass.
    has_mass: Vec<bool>,
}

impl InverseCdfSampler2d {
    /// Precomputes the marginal and conditional CDFs (O(cells)).
    ///
    /// # Errors
    /// Those of [`TabulatedPdf2d::validate`] (the table's fields are public).
    pub fn new(pdf: &TabulatedPdf2d) -> Result<Self> {
        pdf.validate()?;
        let (nx, ny) = (pdf.x.bins, pdf.y.bins);
        let mut marginal = Vec::with_capacity(nx);
        let mut cond_cdf = Vec::with_capacity(nx * (ny + 1));
        let mut cond_guide = Vec::with_capacity(nx * ny);
        let mut has_mass = Vec::with_capacity(nx);
        for col in pdf.density.chunks_exact(ny) {
            let m: f64 = col.iter().sum();
            marginal.push(m);
            has_mass.push(m > 0.0);
            if m > 0.0 {
                build_guided(col, &mut cond_cdf, &mut cond_guide);
            } else {
                cond_cdf.extend(std::iter::repeat_n(0.0, ny + 1));
                cond_guide.extend(std::iter::repeat_n(0, ny));
            }
        }
        Ok(Self {
            x: pdf.x,
            y: pdf.y,
            marginal: GuidedCdf::new(&marginal),
            cond_cdf,
            cond_guide,
            has_mass,
        })
    }

    /// `y` drawn from the conditional CDF of column `i` (which has mass).
    #[inline]
    fn y_in_column(&self, i: usize, u: f64) -> f64 {
        let ny = self.y.bins;
        let cdf = &self.cond_cdf[i * (ny + 1)..(i + 1) * (ny + 1)];
        let guide = &self.cond_guide[i * ny..(i + 1) * ny];
        let (j, f) = locate_guided(cdf, guide, u);
        (self.y.min + (j as f64 + f) * self.y.width()).min(self.y.max)
    }

    /// One joint draw `(x, y)`.
    #[inline]
    pub fn sample(&self, rng: &mut impl Rng) -> (f64, f64) {
        let (i, f) = self.marginal.locate(rng.random::<f64>());
        let x = (self.x.min + (i as f64 + f) * self.x.width()).min(self.x.max);
        // Columns picked by the marginal always have mass.
        (x, self.y_in_column(i, rng.random::<f64>()))
    }

    /// One draw of `x` from its marginal.
    pub fn sample_x(&self, rng: &mut impl Rng) -> f64 {
        let (i, f) = self.marginal.locate(rng.random::<f64>());
        (self.x.edge(i) + f * self.x.width()).min(self.x.max)
    }

    /// One draw of `y` conditional on `x` (the column holding `x`), as the
    /// cloner's quality control needs (Medina 2018, §2.4).
    ///
    /// # Errors
    /// [`Error::OutsideSupport`] if `x` is outside the table,
    /// [`Error::ZeroMass`] if its column has no mass.
    pub fn sample_y_given_x(&self, x: f64, rng: &mut impl Rng) -> Result<f64> {
        let i = self.x.bin_of(x).ok_or(Error::OutsideSupport {
            value: x,
            min: self.x.min,
            max: self.x.max,
        })?;
        if self.has_mass[i] {
            Ok(self.y_in_column(i, rng.random::<f64>()))
        } else {
            Err(Error::ZeroMass {
                context: format!("in the column holding x = {x}"),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn guided_cdf_locates_every_cell_and_skips_empty_ones() {
        let c = GuidedCdf::new(&[0.0, 1.0, 0.0, 0.0, 3.0, 0.0]);
        assert_eq!(c.locate(0.0).0, 1);
        assert_eq!(c.locate(0.2499).0, 1);
        assert_eq!(c.locate(0.25).0, 4);
        let (k, f) = c.locate(0.625);
        assert_eq!(k, 4);
        assert_relative_eq!(f, 0.5);
        assert_eq!(c.locate(1.0 - 1e-16).0, 4);
    }

    #[test]
    fn inverse_cdf_1d_quantiles_are_exact() {
        let axis = BinAxis::new(0.0, 4.0, 4).expect("ok");
        let s = InverseCdfSampler1d::new(axis, &[1.0, 0.0, 2.0, 1.0]).expect("ok");
        assert_relative_eq!(s.quantile(0.0), 0.0);
        assert_relative_eq!(s.quantile(0.125), 0.5);
        // Mass 1/4 in [0, 1), 0 in [1, 2), 1/2 in [2, 3): u = 0.5 → 2.5.
        assert_relative_eq!(s.quantile(0.5), 2.5);
        assert_relative_eq!(s.quantile(0.875), 3.5);
        assert!(s.quantile(1.0) <= 4.0);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..1000 {
            let v = s.sample(&mut rng);
            assert!((0.0..=4.0).contains(&v) && !(1.0..2.0).contains(&v));
        }
        assert!(matches!(
            InverseCdfSampler1d::new(axis, &[0.0; 4]),
            Err(Error::ZeroMass { .. })
        ));
        assert!(matches!(
            InverseCdfSampler1d::new(axis, &[1.0; 3]),
            Err(Error::RaggedTable { .. })
        ));
        assert!(matches!(
            InverseCdfSampler1d::new(axis, &[1.0, f64::NAN, 1.0, 1.0]),
            Err(Error::NonPositive { index: 1, .. })
        ));
    }

    #[test]
    fn conditional_sampling_respects_columns() {
        let x = BinAxis::new(0.0, 2.0, 2).expect("ok");
        let y = BinAxis::new(0.0, 2.0, 2).expect("ok");
        // Column 0: all mass in y ∈ [1, 2); column 1: no mass.
        let t = TabulatedPdf2d::new(x, y, vec![0.0, 1.0, 0.0, 0.0]).expect("ok");
        let s = InverseCdfSampler2d::new(&t).expect("valid");
        let seed = 7;
        #[expect(clippy::print_stdout, reason = "seeded tests print their seed")]
        {
            println!("seed {seed}");
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for _ in 0..200 {
            let (a, b) = s.sample(&mut rng);
            assert!((0.0..1.0).contains(&a) && (1.0..=2.0).contains(&b));
            let c = s
                .sample_y_given_x(0.3, &mut rng)
                .expect("column 0 has mass");
            assert!((1.0..=2.0).contains(&c));
        }
        assert!(matches!(
            s.sample_y_given_x(1.5, &mut rng),
            Err(Error::ZeroMass { .. })
        ));
        // Public fields edited into an inconsistent state are rejected.
        let mut bad = t.clone();
        bad.y.bins = 0;
        assert!(matches!(
            InverseCdfSampler2d::new(&bad),
            Err(Error::CountTooSmall { .. })
        ));
        let mut bad = t.clone();
        bad.density.pop();
        assert!(matches!(
            InverseCdfSampler2d::new(&bad),
            Err(Error::RaggedTable { .. })
        ));
        assert!(matches!(
            AcceptanceRejection2d::new(bad),
            Err(Error::RaggedTable { .. })
        ));
        assert!(matches!(
            s.sample_y_given_x(2.5, &mut rng),
            Err(Error::OutsideSupport { .. })
        ));
        let ar = AcceptanceRejection2d::new(t).expect("ok");
        assert_relative_eq!(ar.expected_trials(), 4.0);
        for _ in 0..50 {
            let c = ar
                .sample_y_given_x(0.3, 1000, &mut rng)
                .expect("column 0 has mass");
            assert!((1.0..=2.0).contains(&c));
        }
        assert_eq!(
            ar.sample_y_given_x(1.5, 100, &mut rng),
            Err(Error::TooManyRejections { trials: 100 })
        );
        assert!(matches!(
            ar.sample_y_given_x(-0.1, 100, &mut rng),
            Err(Error::OutsideSupport { .. })
        ));
        for _ in 0..200 {
            let (a, b) = ar.sample(&mut rng);
            assert!((0.0..1.0).contains(&a) && (1.0..=2.0).contains(&b));
        }
    }
}
