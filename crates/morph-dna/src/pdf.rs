//! Continuous bivariate densities built from data: the seed's bicubic
//! interpolation of a 2D histogram (Medina 2018, §2.1, Fig. 2), a Gaussian
//! kernel density estimate as the smoother alternative, and the
//! piecewise-constant [`TabulatedPdf2d`] every sampler can draw from exactly.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::histogram::{BinAxis, Histogram2d, checked_cells};
use crate::stats::{check_len, check_sample, constant_value, mean_unchecked};

/// A piecewise-constant bivariate density on the cells of two [`BinAxis`]es,
/// normalised to integrate to one. Zero outside its rectangle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TabulatedPdf2d {
    /// Cells of the first variable.
    pub x: BinAxis,
    /// Cells of the second variable.
    pub y: BinAxis,
    /// Density per cell, `density[ix * y.bins + iy]`.
    pub density: Vec<f64>,
}

impl TabulatedPdf2d {
    /// A table from non-negative cell weights (any scale; normalised here).
    ///
    /// # Errors
    /// Axis errors, [`Error::RaggedTable`] if `weights` is not
    /// `x.bins · y.bins` long, [`Error::NonPositive`] for a negative or NaN
    /// weight (message "weight"), [`Error::ZeroMass`] if every weight is zero.
    pub fn new(x: BinAxis, y: BinAxis, weights: Vec<f64>) -> Result<Self> {
        x.validate()?;
        y.validate()?;
        let n = checked_cells("cells", x.bins, y.bins)?;
        if weights.len() != n {
            return Err(Error::RaggedTable {
                what: "density table",
                index: 0,
                expected: n,
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
                context: "in the table".into(),
            });
        }
        let norm = 1.0 / (total * x.width() * y.width());
        let density = weights.into_iter().map(|w| w * norm).collect();
        Ok(Self { x, y, density })
    }

    /// Re-checks a table whose public fields may have been edited: valid
    /// axes, one finite non-negative density per cell, positive mass.
    ///
    /// # Errors
    /// As [`TabulatedPdf2d::new`].
    pub fn validate(&self) -> Result<()> {
        Self::new(self.x, self.y, self.density.clone()).map(|_| ())
    }

    /// The histogram itself as a density (constant in each bin).
    ///
    /// # Errors
    /// As [`TabulatedPdf2d::new`] (cannot fail for a histogram built by
    /// [`Histogram2d::new`]).
    pub fn from_histogram(h: &Histogram2d) -> Result<Self> {
        Self::new(h.x, h.y, h.counts.iter().map(|c| *c as f64).collect())
    }

    /// Density at `(x, y)`, zero outside the rectangle.
    pub fn density_at(&self, x: f64, y: f64) -> f64 {
        match (self.x.bin_of(x), self.y.bin_of(y)) {
            (Some(i), Some(j)) => self
                .density
                .get(i * self.y.bins + j)
                .copied()
                .unwrap_or(0.0),
            _ => 0.0,
        }
    }

    /// Largest cell density.
    pub fn max_density(&self) -> f64 {
        self.density.iter().fold(0.0, |m: f64, v| m.max(*v))
    }
}

/// Catmull-Rom weights (Keys 1981 cubic convolution, a = −½) for the four
/// nodes around fractional position `s ∈ [0, 1)`.
fn catmull_rom(s: f64) -> [f64; 4] {
    let s2 = s * s;
    let s3 = s2 * s;
    [
        0.5 * (-s3 + 2.0 * s2 - s),
        0.5 * (3.0 * s3 - 5.0 * s2 + 2.0),
        0.5 * (-3.0 * s3 + 4.0 * s2 + s),
        0.5 * (s3 - s2),
    ]
}

/// Bound of `Σ|w|` for the Catmull-Rom weights: `1 + s(1 − s) ≤ 5/4`.
const CATMULL_ROM_ABS_SUM: f64 = 1.25;

/// The seed's PDF: bicubic interpolation of a 2D histogram's bin densities
/// (Medina 2018, §2.1: "cubic interpolation ... showed a better
/// representation of the histograms").
///
/// Construction (choices the seed leaves open):
/// * nodes are the bin centres, valued at the bin density `count/(N wx wy)`;
/// * the interpolant is the tensor-product cubic convolution of Keys (1981,
///   doi:10.1109/TASSP.1981.1163711) with a = −½ (Catmull-Rom), MATLAB's
///   `interp2(..., 'cubic')` kernel on uniform grids;
/// * to cover the outer half bins (MATLAB returns NaN beyond the outer
///   centres) the grid is extended by replicating the edge nodes;
/// * cubic interpolation overshoots near empty bins, so negative values are
///   clamped to zero, and the result is renormalised to unit mass over the
///   histogram rectangle by the midpoint rule on `refine × refine` points per
///   bin (the normaliser's quadrature error is O((w/refine)²)).
#[derive(Debug, Clone, PartialEq)]
pub struct BicubicPdf {
    x: BinAxis,
    y: BinAxis,
    nodes: Vec<f64>,
    scale: f64,
    max_node: f64,
}

impl BicubicPdf {
    /// Interpolates `h`, normalising with `refine ≥ 1` quadrature points per
    /// bin and axis (8 is plenty).
    ///
    /// # Errors
    /// Errors of [`Histogram2d::validate`], [`Error::CountTooLarge`],
    /// [`Error::CountTooSmall`] if `refine = 0`, [`Error::ZeroMass`] if the
    /// clamped interpolant has no mass (cannot happen for a non-empty
    /// histogram, kept as a guard).
    pub fn from_histogram(h: &Histogram2d, refine: usize) -> Result<Self> {
        if refine == 0 {
            return Err(Error::CountTooSmall {
                what: "refine",
                min: 1,
                value: 0,
            });
        }
        h.validate()?;
        let nodes = h.density();
        let max_node = nodes.iter().fold(0.0, |m: f64, v| m.max(*v));
        let mut pdf = Self {
            x: h.x,
            y: h.y,
            nodes,
            scale: 1.0,
            max_node,
        };
        let (fx, fy) = (
            BinAxis::new(h.x.min, h.x.max, checked_cells("bins", h.x.bins, refine)?)?,
            BinAxis::new(h.y.min, h.y.max, checked_cells("bins", h.y.bins, refine)?)?,
        );
        checked_cells("cells", fx.bins, fy.bins)?;
        let mut mass = 0.0;
        for i in 0..fx.bins {
            for j in 0..fy.bins {
                mass += pdf.raw(fx.center(i), fy.center(j));
            }
        }
        mass *= fx.width() * fy.width();
        if !(mass > 0.0 && mass.is_finite()) {
            return Err(Error::ZeroMass {
                context: "after clamping the bicubic interpolant".into(),
            });
        }
        pdf.scale = 1.0 / mass;
        Ok(pdf)
    }

    /// The binning of the first variable (the PDF's support).
    pub fn x_axis(&self) -> BinAxis {
        self.x
    }

    /// The binning of the second variable.
    pub fn y_axis(&self) -> BinAxis {
        self.y
    }

    /// Clamped, unnormalised interpolant.
    fn raw(&self, x: f64, y: f64) -> f64 {
        let (ix, wx) = stencil(&self.x, x);
        let (iy, wy) = stencil(&self.y, y);
        let ny = self.y.bins;
        let mut v = 0.0;
        for a in 0..4 {
            let row = ix[a] * ny;
            let mut r = 0.0;
            for b in 0..4 {
                r += wy[b] * self.nodes[row + iy[b]];
            }
            v += wx[a] * r;
        }
        v.max(0.0)
    }

    /// Normalised density at `(x, y)`; zero outside the histogram rectangle.
    pub fn density(&self, x: f64, y: f64) -> f64 {
        if !(x >= self.x.min && x <= self.x.max && y >= self.y.min && y <= self.y.max) {
            return 0.0;
        }
        self.raw(x, y) * self.scale
    }

    /// A rigorous upper bound of [`BicubicPdf::density`]:
    /// `(5/4)² · max node · scale` (the Catmull-Rom weights' absolute sum is
    /// at most 5/4 per axis).
    pub fn upper_bound(&self) -> f64 {
        CATMULL_ROM_ABS_SUM * CATMULL_ROM_ABS_SUM * self.max_node * self.scale
    }

    /// Rigorous upper bound of the density on each histogram bin, in the
    /// layout of [`Histogram2d::counts`]: `(5/4)² · scale ·` the largest node
    /// of the 5 × 5 block the bin's interpolation stencils can reach.
    pub fn cell_upper_bounds(&self) -> Vec<f64> {
        let (nx, ny) = (self.x.bins, self.y.bins);
        // Running maxima over ±2 nodes, first along y then along x.
        let mut along_y = vec![0.0f64; nx * ny];
        for i in 0..nx {
            for j in 0..ny {
                let (lo, hi) = (j.saturating_sub(2), (j + 2).min(ny - 1));
                along_y[i * ny + j] =
                    (lo..=hi).fold(0.0, |m: f64, q| m.max(self.nodes[i * ny + q]));
            }
        }
        let factor = CATMULL_ROM_ABS_SUM * CATMULL_ROM_ABS_SUM * self.scale;
        let mut out = vec![0.0; nx * ny];
        for i in 0..nx {
            let (lo, hi) = (i.saturating_sub(2), (i + 2).min(nx - 1));
            for j in 0..ny {
                out[i * ny + j] =
                    factor * (lo..=hi).fold(0.0, |m: f64, p| m.max(along_y[p * ny + j]));
            }
        }
        out
    }

    /// Tabulates the density at the centres of `refine × refine` sub-cells
    /// per histogram bin, for the exact inverse-CDF sampler.
    ///
    /// # Errors
    /// [`Error::CountTooSmall`] if `refine = 0`; [`Error::ZeroMass`] guard.
    pub fn tabulate(&self, refine: usize) -> Result<TabulatedPdf2d> {
        if refine == 0 {
            return Err(Error::CountTooSmall {
                what: "refine",
                min: 1,
                value: 0,
            });
        }
        let fx = BinAxis::new(
            self.x.min,
            self.x.max,
            checked_cells("bins", self.x.bins, refine)?,
        )?;
        let fy = BinAxis::new(
            self.y.min,
            self.y.max,
            checked_cells("bins", self.y.bins, refine)?,
        )?;
        let mut w = Vec::with_capacity(checked_cells("cells", fx.bins, fy.bins)?);
        for i in 0..fx.bins {
            for j in 0..fy.bins {
                w.push(self.raw(fx.center(i), fy.center(j)));
            }
        }
        TabulatedPdf2d::new(fx, fy, w)
    }
}

/// Indices (edge-replicated) and Catmull-Rom weights of the 4 nodes around `x`.
fn stencil(axis: &BinAxis, x: f64) -> ([usize; 4], [f64; 4]) {
    let t = ((x - axis.min) / axis.width() - 0.5).clamp(-0.5, axis.bins as f64 - 0.5);
    let f = t.floor();
    let s = t - f;
    let i0 = f as i64;
    let last = axis.bins as i64 - 1;
    let idx = [i0 - 1, i0, i0 + 1, i0 + 2].map(|k| k.clamp(0, last) as usize);
    (idx, catmull_rom(s))
}

/// Bandwidth rule of a Gaussian kernel density estimate.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum Bandwidth {
    /// Scott's rule: kernel covariance `n^(−2/(d+4)) Σ` (Scott 1992, Eq. 6.42).
    #[default]
    Scott,
    /// Silverman's rule `(n (d + 2)/4)^(−2/(d+4)) Σ`; identical to Scott's in
    /// two dimensions, kept so callers can name it.
    Silverman,
    /// Kernel covariance `factor² Σ` with a caller-chosen `factor > 0`.
    Factor(f64),
}

/// Bivariate Gaussian kernel density estimate with a full covariance kernel
/// `H = h² Σ` (Σ the sample covariance, divisor n − 1), the smoother
/// alternative to [`BicubicPdf`]: no binning, no negative lobes, exact
/// sampling by the smoothed bootstrap (pick a datum, add kernel noise).
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianKde2d {
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// Cholesky factor of H: `[[l11, 0], [l21, l22]]`.
    l11: f64,
    l21: f64,
    l22: f64,
}

impl GaussianKde2d {
    /// Fits the estimate to paired samples.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`], [`Error::TooFewSamples`] (below 3 pairs),
    /// [`Error::NonFiniteSample`], [`Error::ConstantSample`],
    /// [`Error::InvalidParameter`] for a non-positive factor,
    /// [`Error::SingularCovariance`] for perfectly correlated samples.
    pub fn fit(xs: &[f64], ys: &[f64], bandwidth: Bandwidth) -> Result<Self> {
        if xs.len() != ys.len() {
            return Err(Error::LengthMismatch {
                left: xs.len(),
                right: ys.len(),
            });
        }
        check_len(xs, 3)?;
        check_sample(xs)?;
        check_sample(ys)?;
        for s in [xs, ys] {
            if let Some(value) = constant_value(s) {
                return Err(Error::ConstantSample { value });
            }
        }
        let n = xs.len() as f64;
        let h = match bandwidth {
            Bandwidth::Scott => n.powf(-1.0 / 6.0),
            Bandwidth::Silverman => (n * 4.0 / 4.0).powf(-1.0 / 6.0),
            Bandwidth::Factor(f) => {
                if !(f.is_finite() && f > 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "bandwidth factor",
                        value: f,
                        reason: "must be finite and positive",
                    });
                }
                f
            }
        };
        let (mx, my) = (mean_unchecked(xs), mean_unchecked(ys));
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for (x, y) in xs.iter().zip(ys) {
            sxx += (x - mx) * (x - mx);
            sxy += (x - mx) * (y - my);
            syy += (y - my) * (y - my);
        }
        let d = n - 1.0;
        let (cxx, cxy, cyy) = (sxx / d * h * h, sxy / d * h * h, syy / d * h * h);
        let l11 = cxx.sqrt();
        let l21 = cxy / l11;
        let r = cyy - l21 * l21;
        // Relative test: 1 − ρ² below 1e-12 is numerically singular.
        if r.is_nan() || r <= 1e-12 * cyy {
            return Err(Error::SingularCovariance {
                determinant: cxx * cyy - cxy * cxy,
            });
        }
        Ok(Self {
            xs: xs.to_vec(),
            ys: ys.to_vec(),
            l11,
            l21,
            l22: r.sqrt(),
        })
    }

    /// Kernel covariance `[h_xx, h_xy, h_yy]`.
    pub fn kernel_covariance(&self) -> [f64; 3] {
        [
            self.l11 * self.l11,
            self.l11 * self.l21,
            self.l21 * self.l21 + self.l22 * self.l22,
        ]
    }

    /// Density at `(x, y)` (cost O(n)).
    pub fn density(&self, x: f64, y: f64) -> f64 {
        let norm = 1.0 / (std::f64::consts::TAU * self.l11 * self.l22 * self.xs.len() as f64);
        let mut s = 0.0;
        for (a, b) in self.xs.iter().zip(&self.ys) {
            let u = (x - a) / self.l11;
            let v = (y - b - self.l21 * u) / self.l22;
            s += (-0.5 * (u * u + v * v)).exp();
        }
        s * norm
    }

    /// One draw by the smoothed bootstrap (exact for the estimate).
    pub fn sample(&self, rng: &mut impl Rng) -> (f64, f64) {
        let k = rng.random_range(0..self.xs.len());
        let z1: f64 = StandardNormal.sample(rng);
        let z2: f64 = StandardNormal.sample(rng);
        (
            self.xs[k] + self.l11 * z1,
            self.ys[k] + self.l21 * z1 + self.l22 * z2,
        )
    }

    /// Tabulates the density at cell centres of the given axes (cost
    /// O(cells · n)), for the inverse-CDF sampler or plotting. The table is
    /// renormalised over the rectangle, i.e. conditioned on it.
    ///
    /// # Errors
    /// Axis errors; [`Error::ZeroMass`] if the rectangle misses the data.
    pub fn tabulate(&self, x: BinAxis, y: BinAxis) -> Result<TabulatedPdf2d> {
        x.validate()?;
        y.validate()?;
        let mut w = Vec::with_capacity(checked_cells("cells", x.bins, y.bins)?);
        for i in 0..x.bins {
            for j in 0..y.bins {
                w.push(self.density(x.center(i), y.center(j)));
            }
        }
        TabulatedPdf2d::new(x, y, w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn catmull_rom_reproduces_quadratics_and_bound() {
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            let w = catmull_rom(s);
            assert_relative_eq!(w.iter().sum::<f64>(), 1.0, epsilon = 1e-15);
            assert!(w.iter().map(|v| v.abs()).sum::<f64>() <= CATMULL_ROM_ABS_SUM + 1e-15);
            // Nodes at −1, 0, 1, 2: quadratics are reproduced exactly.
            let f = |t: f64| 3.0 - 2.0 * t + 0.5 * t * t;
            let v: f64 = w
                .iter()
                .zip([-1.0, 0.0, 1.0, 2.0])
                .map(|(a, t)| a * f(t))
                .sum();
            assert_relative_eq!(v, f(s), epsilon = 1e-14);
        }
    }

    #[test]
    fn bicubic_of_flat_histogram_is_uniform() {
        // One sample per cell of a 4 × 5 grid: density is 1 / area everywhere.
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        for i in 0..4 {
            for j in 0..5 {
                xs.push(0.5 * (i as f64 + 0.5));
                ys.push(3.0 + j as f64 + 0.5);
            }
        }
        let h = Histogram2d::new(&xs, &ys, (4, 5), Some((0.0, 2.0)), Some((3.0, 8.0))).expect("ok");
        let p = BicubicPdf::from_histogram(&h, 4).expect("ok");
        for (x, y) in [(0.0, 3.0), (1.3, 4.7), (2.0, 8.0), (0.77, 7.99)] {
            assert_relative_eq!(p.density(x, y), 0.1, epsilon = 1e-12);
        }
        assert_relative_eq!(p.density(2.1, 5.0), 0.0);
        assert!(p.upper_bound() >= 0.1);
        let t = p.tabulate(3).expect("ok");
        assert_eq!(t.density.len(), 12 * 15);
        assert_relative_eq!(t.density_at(1.0, 5.0), 0.1, epsilon = 1e-12);
    }

    #[test]
    fn bicubic_interpolates_node_values_and_clamps_overshoot() {
        // Counts 0 next to a spike overshoot below zero before clamping.
        let xs = [0.5, 1.5, 1.5, 1.5, 1.5, 1.5, 1.5, 1.5, 1.5, 2.5];
        let ys = [0.5; 10];
        let h = Histogram2d::new(&xs, &ys, (5, 1), Some((0.0, 5.0)), Some((0.0, 1.0))).expect("ok");
        let p = BicubicPdf::from_histogram(&h, 64).expect("ok");
        let mut mass = 0.0;
        let m = 5000;
        for k in 0..m {
            let x = 5.0 * (k as f64 + 0.5) / m as f64;
            let d = p.density(x, 0.5);
            assert!(d >= 0.0 && d.is_finite());
            assert!(d <= p.upper_bound());
            mass += d * 5.0 / m as f64;
        }
        assert_relative_eq!(mass, 1.0, epsilon = 1e-4);
        // At the centre of the spike bin the interpolant equals the node up to
        // the renormalisation scale, which is close to 1 here.
        let ratio = p.density(1.5, 0.5) / (0.8 * p.scale);
        assert_relative_eq!(ratio, 1.0, epsilon = 1e-12);
        // Between two empty bins far from data the density is exactly zero.
        assert_relative_eq!(p.density(4.5, 0.5), 0.0);
        // At x = 3.5 the raw interpolant is −0.0625 · 0.1 < 0: clamped.
        assert_relative_eq!(p.density(3.5, 0.5), 0.0);
    }

    #[test]
    fn cell_bounds_dominate_the_density() {
        let xs = [0.5, 1.5, 1.5, 1.5, 2.5, 2.5, 4.5, 0.2];
        let ys = [0.5, 0.5, 1.5, 1.7, 0.1, 2.9, 2.5, 2.2];
        let h = Histogram2d::new(&xs, &ys, (5, 3), Some((0.0, 5.0)), Some((0.0, 3.0))).expect("ok");
        let p = BicubicPdf::from_histogram(&h, 8).expect("ok");
        let b = p.cell_upper_bounds();
        let m = 40;
        for i in 0..5 {
            for j in 0..3 {
                for a in 0..=m {
                    for c in 0..=m {
                        let x = i as f64 + a as f64 / m as f64;
                        let y = j as f64 + c as f64 / m as f64;
                        assert!(p.density(x, y) <= b[i * 3 + j] * (1.0 + 1e-12));
                    }
                }
                assert!(b[i * 3 + j] <= p.upper_bound());
            }
        }
    }

    #[test]
    fn kde_matches_closed_form_for_two_points() {
        let xs = [0.0, 1.0, 0.0];
        let ys = [0.0, 0.0, 1.0];
        let k = GaussianKde2d::fit(&xs, &ys, Bandwidth::Factor(0.5)).expect("ok");
        let [hxx, hxy, hyy] = k.kernel_covariance();
        // Sample covariance: var = 1/3, cov = −1/6; times 0.25.
        assert_relative_eq!(hxx, 1.0 / 12.0, epsilon = 1e-15);
        assert_relative_eq!(hxy, -1.0 / 24.0, epsilon = 1e-15);
        assert_relative_eq!(hyy, 1.0 / 12.0, epsilon = 1e-15);
        let det = hxx * hyy - hxy * hxy;
        let g = |dx: f64, dy: f64| {
            let q = (hyy * dx * dx - 2.0 * hxy * dx * dy + hxx * dy * dy) / det;
            (-0.5 * q).exp() / (std::f64::consts::TAU * det.sqrt())
        };
        let (x, y) = (0.3, 0.2);
        let expected = (g(x, y) + g(x - 1.0, y) + g(x, y - 1.0)) / 3.0;
        assert_relative_eq!(k.density(x, y), expected, epsilon = 1e-14);
    }

    #[test]
    fn kde_rejects_degenerate_data() {
        assert!(matches!(
            GaussianKde2d::fit(&[1.0, 2.0, 3.0], &[2.0, 4.0, 6.0], Bandwidth::Scott),
            Err(Error::SingularCovariance { .. })
        ));
        assert!(matches!(
            GaussianKde2d::fit(&[1.0, 1.0, 1.0], &[2.0, 4.0, 6.0], Bandwidth::Scott),
            Err(Error::ConstantSample { .. })
        ));
        assert!(matches!(
            GaussianKde2d::fit(&[1.0, 2.0], &[2.0, 4.0], Bandwidth::Scott),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            GaussianKde2d::fit(&[1.0, 2.0, 0.0], &[2.0, 4.0, 1.0], Bandwidth::Factor(-1.0)),
            Err(Error::InvalidParameter { .. })
        ));
        let x = BinAxis::new(0.0, 1.0, 2).expect("ok");
        assert!(matches!(
            TabulatedPdf2d::new(x, x, vec![0.0; 4]),
            Err(Error::ZeroMass { .. })
        ));
        assert!(matches!(
            TabulatedPdf2d::new(x, x, vec![1.0, -1.0, 0.0, 0.0]),
            Err(Error::NonPositive { index: 1, .. })
        ));
        assert!(matches!(
            TabulatedPdf2d::new(x, x, vec![1.0; 3]),
            Err(Error::RaggedTable { .. })
        ));
    }
}
