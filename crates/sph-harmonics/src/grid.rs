//! Ring grids on the sphere: Gauss–Legendre × equiangular quadrature grids,
//! the threshold grid of Radvilaitė 2016 §3.1.2, and general rings of
//! equally spaced azimuths.
//!
//! A ring is a set of `n_phi` directions at one polar angle θ with azimuths
//! `φ_j = phi0 + 2πj/n_phi`. Ring structure makes evaluation O(L) per point and
//! makes least squares separable in the azimuthal order m (see [`crate::fit`]).

use crate::error::Error;
use std::f64::consts::PI;

/// One ring of equally spaced azimuths at a fixed polar angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ring {
    /// Polar angle θ ∈ [0, π] (radians, from +z).
    pub theta: f64,
    /// Number of azimuths on the ring (1 for a single pole point).
    pub n_phi: usize,
    /// Azimuth of the first point (radians, from +x).
    pub phi0: f64,
    /// Quadrature (or least-squares) weight of every point of the ring.
    pub weight: f64,
}

impl Ring {
    /// Azimuth of point `j`.
    #[must_use]
    pub fn phi(&self, j: usize) -> f64 {
        self.phi0 + 2.0 * PI * j as f64 / self.n_phi as f64
    }

    /// Whether the ring sits on a pole (sin θ = 0 to rounding).
    #[must_use]
    pub fn is_pole(&self) -> bool {
        self.theta.sin().abs() < 1e-14
    }
}

/// A grid made of rings; points are ordered ring by ring, azimuth by azimuth.
#[derive(Debug, Clone, PartialEq)]
pub struct RingGrid {
    rings: Vec<Ring>,
}

impl RingGrid {
    /// A grid from explicit rings.
    ///
    /// # Errors
    /// [`Error::AngleOutOfRange`] for θ ∉ [0, π] or non-finite φ0,
    /// [`Error::InvalidGrid`] for an empty ring or a negative / non-finite weight.
    pub fn new(rings: Vec<Ring>) -> Result<Self, Error> {
        if rings.is_empty() {
            return Err(Error::InvalidGrid {
                what: "ring count",
                value: 0.0,
            });
        }
        for r in &rings {
            crate::error::check_angles(r.theta, r.phi0)?;
            if r.n_phi == 0 {
                return Err(Error::InvalidGrid {
                    what: "n_phi",
                    value: 0.0,
                });
            }
            if !(r.weight.is_finite() && r.weight >= 0.0) {
                return Err(Error::InvalidGrid {
                    what: "ring weight",
                    value: r.weight,
                });
            }
        }
        Ok(Self { rings })
    }

    /// Gauss–Legendre × equiangular grid exact for products of two functions of degree ≤ `degree`:
    /// `degree + 1` Gauss nodes in cos θ and `2·degree + 2` azimuths. Weights are the
    /// quadrature weights of ∫ f dΩ.
    ///
    /// # Errors
    /// [`Error::DegreeOutOfRange`] above [`crate::basis::MAX_DEGREE`].
    pub fn gauss_legendre(degree: usize) -> Result<Self, Error> {
        Self::gauss_legendre_sized(degree + 1, 2 * degree + 2)
    }

    /// Gauss–Legendre grid with `n_theta` nodes in cos θ and `n_phi` equally spaced azimuths.
    ///
    /// # Errors
    /// [`Error::InvalidGrid`] for zero sizes, [`Error::DegreeOutOfRange`] for huge sizes.
    pub fn gauss_legendre_sized(n_theta: usize, n_phi: usize) -> Result<Self, Error> {
        if n_theta == 0 || n_phi == 0 {
            return Err(Error::InvalidGrid {
                what: "gauss grid size",
                value: 0.0,
            });
        }
        if n_theta > 4 * crate::basis::MAX_DEGREE {
            return Err(Error::DegreeOutOfRange {
                degree: n_theta,
                max: 4 * crate::basis::MAX_DEGREE,
            });
        }
        let (x, w) = gauss_legendre_nodes(n_theta);
        let dphi = 2.0 * PI / n_phi as f64;
        let rings = x
            .iter()
            .zip(&w)
            .rev()
            .map(|(&xi, &wi)| Ring {
                theta: xi.clamp(-1.0, 1.0).acos(),
                n_phi,
                phi0: 0.0,
                weight: wi * dphi,
            })
            .collect();
        Ok(Self { rings })
    }

    /// Equiangular grid with `n_theta` polar intervals over [0, π] (n_theta − 1 interior rings)
    /// and `n_phi` azimuths per ring, plus one point at each pole:
    /// `(n_theta − 1)·n_phi + 2` points (Radvilaitė 2016, §3.1.2). Weights are 1.
    ///
    /// # Errors
    /// [`Error::InvalidGrid`] for `n_theta < 2` or `n_phi == 0`.
    pub fn equiangular_with_poles(n_theta: usize, n_phi: usize) -> Result<Self, Error> {
        if n_theta < 2 || n_phi == 0 {
            return Err(Error::InvalidGrid {
                what: "equiangular grid size",
                value: n_theta.min(n_phi) as f64,
            });
        }
        let mut rings = Vec::with_capacity(n_theta + 1);
        rings.push(Ring {
            theta: 0.0,
            n_phi: 1,
            phi0: 0.0,
            weight: 1.0,
        });
        for i in 1..n_theta {
            rings.push(Ring {
                theta: PI * i as f64 / n_theta as f64,
                n_phi,
                phi0: 0.0,
                weight: 1.0,
            });
        }
        rings.push(Ring {
            theta: PI,
            n_phi: 1,
            phi0: 0.0,
            weight: 1.0,
        });
        Ok(Self { rings })
    }

    /// The threshold grid of Radvilaitė 2016 §3.1.2: 128 polar intervals × 128 azimuths
    /// with single poles, 16,258 points.
    #[must_use]
    pub fn threshold() -> Self {
        // Sizes are constants: construction cannot fail.
        let mut rings = Vec::with_capacity(129);
        for i in 0..=128 {
            let pole = i == 0 || i == 128;
            rings.push(Ring {
                theta: PI * i as f64 / 128.0,
                n_phi: if pole { 1 } else { 128 },
                phi0: 0.0,
                weight: 1.0,
            });
        }
        Self { rings }
    }

    /// The rings.
    #[must_use]
    pub fn rings(&self) -> &[Ring] {
        &self.rings
    }

    /// Total number of points.
    #[must_use]
    pub fn len(&self) -> usize {
        self.rings.iter().map(|r| r.n_phi).sum()
    }

    /// Whether the grid has no points (never true for a constructed grid).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// All points as (θ, φ), ring by ring.
    #[must_use]
    pub fn points(&self) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(self.len());
        for r in &self.rings {
            for j in 0..r.n_phi {
                out.push((r.theta, r.phi(j)));
            }
        }
        out
    }

    /// Per-point weights, ring by ring.
    #[must_use]
    pub fn weights(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.len());
        for r in &self.rings {
            out.extend(std::iter::repeat_n(r.weight, r.n_phi));
        }
        out
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1], nodes ascending.
///
/// Newton iteration on the three-term recurrence from Tricomi's initial guesses;
/// accurate to a few ulp for n up to several thousand.
#[must_use]
pub fn gauss_legendre_nodes(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let k = i as f64 + 1.0;
        let mut z =
            (PI * (k - 0.25) / (nf + 0.5)).cos() * (1.0 - (nf - 1.0) / (8.0 * nf * nf * nf));
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre_p_and_derivative(n, z);
            dp = d;
            let dz = p / d;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre_p_and_derivative(n, z);
        if d.is_finite() {
            dp = d;
        }
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        x[n - 1 - i] = z;
        w[n - 1 - i] = wi;
        x[i] = -z;
        w[i] = wi;
    }
    (x, w)
}

/// Legendre polynomial P_n(x) and its derivative by the three-term recurrence.
fn legendre_p_and_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let nf = n as f64;
    let d = nf * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn threshold_grid_has_16258_points() {
        assert_eq!(RingGrid::threshold().len(), 16_258);
        assert_eq!(
            RingGrid::equiangular_with_poles(128, 128)
                .expect("grid")
                .len(),
            16_258
        );
    }

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        for n in [1, 2, 5, 31, 200] {
            let (x, w) = gauss_legendre_nodes(n);
            let total: f64 = w.iter().sum();
            assert_relative_eq!(total, 2.0, epsilon = 1e-13);
            // ∫ x^(2n−2) dx = 2/(2n−1), exact for an n-point rule.
            let k = 2 * n - 2;
            let integral: f64 = x
                .iter()
                .zip(&w)
                .map(|(xi, wi)| wi * xi.powi(k as i32))
                .sum();
            assert_relative_eq!(integral, 2.0 / (k as f64 + 1.0), epsilon = 1e-12);
        }
    }

    #[test]
    fn sphere_area_by_quadrature() {
        let g = RingGrid::gauss_legendre(10).expect("grid");
        let total: f64 = g.weights().iter().sum();
        assert_relative_eq!(total, 4.0 * PI, epsilon = 1e-13);
    }

    #[test]
    fn rejects_bad_rings() {
        let bad = Ring {
            theta: 4.0,
            n_phi: 3,
            phi0: 0.0,
            weight: 1.0,
        };
        assert!(RingGrid::new(vec![bad]).is_err());
        assert!(RingGrid::new(vec![]).is_err());
        assert!(RingGrid::equiangular_with_poles(1, 4).is_err());
    }
}
