//! Curvature of a spherical-harmonic surface (Radvilaitė 2016, Eqs. 2.42–2.47).
//!
//! The surface `X(θ, φ) = r(θ, φ) u(θ, φ)` is differentiated analytically; with the first
//! (E, F, G) and second (L, M, N) fundamental forms, the mean curvature
//! `H = −(EN + GL − 2FM) / (2(EG − F²))` and Gaussian curvature `K = (LN − M²)/(EG − F²)`.
//! The normal is the outward one, so a sphere of radius R has H = 1/R (the thesis' Eq. 2.47
//! has the opposite sign with the same normal). Principal curvatures `κ = H ± √(H² − K)`,
//! principal radii `1/κ`.
//!
//! **Poles.** (θ, φ) is singular at sin θ = 0. Within `sin θ < 0.1` the evaluator uses a
//! model of the surface rotated by 90° about y (exact for band-limited models, see
//! [`ShModel::rotated`]), where the same point lies on the equator, and rotates normal and
//! principal directions back. Results are therefore well defined and smooth at the poles.

use crate::basis::Legendre;
use crate::error::{Error, check_angles};
use crate::grid::RingGrid;
use crate::model::{RadiusDerivatives, ShModel, direction, to_angles};
use nalgebra::{Matrix3, Unit, Vector3};

/// Curvature at one surface point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curvature {
    /// Outward unit normal (Eq. 2.45).
    pub normal: Unit<Vector3<f64>>,
    /// Mean curvature H (positive for convex).
    pub mean: f64,
    /// Gaussian curvature K.
    pub gaussian: f64,
    /// Principal curvatures κ₁ ≥ κ₂.
    pub principal: [f64; 2],
    /// Unit tangent directions of κ₁ and κ₂.
    pub principal_directions: [Unit<Vector3<f64>>; 2],
}

impl Curvature {
    /// Principal radii of curvature 1/κ (infinite for κ = 0), ordered as `principal`.
    #[must_use]
    pub fn principal_radii(&self) -> [f64; 2] {
        self.principal.map(|k| 1.0 / k)
    }
}

/// Curvature evaluator for one model (holds the rotated model used near the poles).
#[derive(Debug, Clone)]
pub struct CurvatureEvaluator {
    model: ShModel,
    rotated: ShModel,
    rotation: Matrix3<f64>,
}

/// Surface derivatives at one (θ, φ): X_θ, X_φ, X_θθ, X_θφ, X_φφ.
fn surface_derivatives(d: &RadiusDerivatives, theta: f64, phi: f64) -> [Vector3<f64>; 5] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    let u = Vector3::new(st * cp, st * sp, ct);
    let ut = Vector3::new(ct * cp, ct * sp, -st);
    let up = Vector3::new(-st * sp, st * cp, 0.0);
    let utp = Vector3::new(-ct * sp, ct * cp, 0.0);
    let upp = Vector3::new(-st * cp, -st * sp, 0.0);
    let xt = u * d.r_theta + ut * d.r;
    let xp = u * d.r_phi + up * d.r;
    let xtt = u * d.r_theta_theta + ut * (2.0 * d.r_theta) - u * d.r;
    let xtp = u * d.r_theta_phi + up * d.r_theta + ut * d.r_phi + utp * d.r;
    let xpp = u * d.r_phi_phi + up * (2.0 * d.r_phi) + upp * d.r;
    [xt, xp, xtt, xtp, xpp]
}

/// Curvature from derivatives at a regular point (sin θ not tiny).
fn curvature_regular(d: &RadiusDerivatives, theta: f64, phi: f64) -> Result<Curvature, Error> {
    let [xt, xp, xtt, xtp, xpp] = surface_derivatives(d, theta, phi);
    let cross = xt.cross(&xp);
    let norm = cross.norm();
    let e = xt.dot(&xt);
    let f = xt.dot(&xp);
    let g = xp.dot(&xp);
    let det = e * g - f * f;
    if !(norm > 0.0 && det > 0.0 && norm.is_finite()) {
        return Err(Error::DegenerateMetric { theta, phi });
    }
    let n = cross / norm;
    // Second form with the inward sign so that convex surfaces have positive curvature.
    let l = -xtt.dot(&n);
    let m = -xtp.dot(&n);
    let nn = -xpp.dot(&n);
    let mean = (e * nn + g * l - 2.0 * f * m) / (2.0 * det);
    let gaussian = (l * nn - m * m) / det;
    let disc = (mean * mean - gaussian).max(0.0).sqrt();
    let principal = [mean + disc, mean - disc];
    let dirs = principal.map(|k| {
        // (II − κ I) (a, b)ᵀ = 0 in the basis (X_θ, X_φ).
        let c1 = Vector3::new(m - k * f, -(l - k * e), 0.0);
        let c2 = Vector3::new(nn - k * g, -(m - k * f), 0.0);
        let c = if c1.norm() >= c2.norm() { c1 } else { c2 };
        let v = if c.norm() > 1e-12 * (e + g) * (l.abs() + nn.abs() + m.abs() + 1.0) {
            xt * c.x + xp * c.y
        } else {
            xt
        };
        Unit::new_normalize(v)
    });
    // For umbilics make the second direction orthogonal to the first.
    let d0 = dirs[0];
    let d1 = if disc < 1e-12 * mean.abs().max(1e-300) {
        Unit::new_normalize(n.cross(&d0))
    } else {
        dirs[1]
    };
    Ok(Curvature {
        normal: Unit::new_unchecked(n),
        mean,
        gaussian,
        principal,
        principal_directions: [d0, d1],
    })
}

impl CurvatureEvaluator {
    /// Prepares the evaluator (computes the model rotated by 90° about y, exact).
    ///
    /// # Errors
    /// From [`ShModel::rotated`] (not expected for a valid model).
    pub fn new(model: &ShModel) -> Result<Self, Error> {
        // Rotation by +90° about y: maps +z to +x.
        let rotation = Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0);
        let rotated = model.rotated(&rotation)?;
        Ok(Self {
            model: model.clone(),
            rotated,
            rotation,
        })
    }

    /// Curvature at direction (θ, φ), well defined also at the poles.
    ///
    /// # Errors
    /// [`Error::AngleOutOfRange`], [`Error::ModelNotStarShaped`] if r ≤ 0 there,
    /// [`Error::DegenerateMetric`].
    pub fn at(&self, theta: f64, phi: f64) -> Result<Curvature, Error> {
        check_angles(theta, phi)?;
        if theta.sin() >= 0.1 {
            let d = self.model.derivatives(theta, phi)?;
            if d.r <= 0.0 {
                return Err(Error::ModelNotStarShaped {
                    theta,
                    phi,
                    value: d.r,
                });
            }
            return curvature_regular(&d, theta, phi);
        }
        let u = self.rotation * direction(theta, phi);
        let (t2, p2) = to_angles(&u);
        let d = self.rotated.derivatives(t2, p2)?;
        if d.r <= 0.0 {
            return Err(Error::ModelNotStarShaped {
                theta,
                phi,
                value: d.r,
            });
        }
        let c = curvature_regular(&d, t2, p2)?;
        let back = self.rotation.transpose();
        Ok(Curvature {
            normal: Unit::new_normalize(back * c.normal.into_inner()),
            principal_directions: c
                .principal_directions
                .map(|v| Unit::new_normalize(back * v.into_inner())),
            ..c
        })
    }
}

/// Curvature at (θ, φ) of a model (builds a [`CurvatureEvaluator`]; reuse one for many points).
///
/// # Errors
/// As [`CurvatureEvaluator::at`].
pub fn curvature(model: &ShModel, theta: f64, phi: f64) -> Result<Curvature, Error> {
    CurvatureEvaluator::new(model)?.at(theta, phi)
}

/// Total Gaussian curvature ∫ K dA by Gauss–Legendre × equiangular quadrature with `n_theta`
/// nodes in cos θ and `2·n_theta` azimuths; equals 4π for any closed smooth star-shaped
/// surface (Gauss–Bonnet). Returns (∫K dA, area).
///
/// # Errors
/// [`Error::InvalidGrid`], [`Error::ModelNotStarShaped`], [`Error::DegenerateMetric`].
pub fn gauss_bonnet(model: &ShModel, n_theta: usize) -> Result<(f64, f64), Error> {
    let grid = RingGrid::gauss_legendre_sized(n_theta, 2 * n_theta)?;
    let leg = Legendre::new(model.degree())?;
    let mut v = leg.buffer(2);
    let mut total = 0.0;
    let mut area = 0.0;
    for ring in grid.rings() {
        leg.compute(ring.theta, &mut v);
        let sums = model.ring_sums(&v, 2);
        let s = ring.theta.sin();
        for j in 0..ring.n_phi {
            let phi = ring.phi(j);
            let d = sums.at(phi);
            if d.r <= 0.0 {
                return Err(Error::ModelNotStarShaped {
                    theta: ring.theta,
                    phi,
                    value: d.r,
                });
            }
            let c = curvature_regular(&d, ring.theta, phi)?;
            let [xt, xp, ..] = surface_derivatives(&d, ring.theta, phi);
            // Quadrature weight is for dΩ = sin θ dθ dφ; dA = |X_θ × X_φ| dθ dφ.
            let da = xt.cross(&xp).norm() / s * ring.weight;
            total += c.gaussian * da;
            area += da;
        }
    }
    Ok((total, area))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::quadrature_transform;
    use crate::shapes::Shape;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn spheroid(degree: usize) -> ShModel {
        let shape = Shape::Ellipsoid {
            a: 2.0,
            b: 2.0,
            c: 1.0,
        };
        let grid = RingGrid::gauss_legendre(degree).expect("grid");
        let values: Vec<f64> = grid
            .points()
            .iter()
            .map(|&(t, p)| shape.radius(t, p))
            .collect();
        quadrature_transform(&grid, &values, degree).expect("fit")
    }

    #[test]
    fn sphere_curvature_everywhere_including_poles() {
        let s = ShModel::sphere(2.0).expect("sphere");
        let ev = CurvatureEvaluator::new(&s).expect("evaluator");
        for &(t, p) in &[(0.0, 0.0), (PI, 1.0), (1e-9, 0.3), (1.0, 2.0)] {
            let c = ev.at(t, p).expect("curvature");
            assert_relative_eq!(c.mean, 0.5, epsilon = 1e-12);
            assert_relative_eq!(c.gaussian, 0.25, epsilon = 1e-12);
            assert_relative_eq!(c.normal.dot(&direction(t, p)), 1.0, epsilon = 1e-12);
        }
    }

    #[test]
    fn oblate_spheroid_principal_radii_at_equator_and_pole() {
        // Exact: equator ρ_meridian = c²/a = 0.5, ρ_parallel = a = 2; pole ρ = a²/c = 4.
        let model = spheroid(60);
        let ev = CurvatureEvaluator::new(&model).expect("evaluator");
        let eq = ev.at(PI / 2.0, 0.3).expect("equator");
        let [r1, r2] = eq.principal_radii();
        assert_relative_eq!(r1, 0.5, max_relative = 1e-3);
        assert_relative_eq!(r2, 2.0, max_relative = 1e-4);
        let pole = ev.at(0.0, 0.0).expect("pole");
        let [p1, p2] = pole.principal_radii();
        assert_relative_eq!(p1, 4.0, max_relative = 1e-4);
        assert_relative_eq!(p2, 4.0, max_relative = 1e-4);
        // Pole value is continuous with nearby points.
        let near = ev.at(1e-4, 1.0).expect("near pole");
        assert_relative_eq!(near.mean, pole.mean, max_relative = 1e-6);
    }

    #[test]
    fn gauss_bonnet_spheroid() {
        let model = spheroid(30);
        let (k, _) = gauss_bonnet(&model, 160).expect("gb");
        assert_relative_eq!(k, 4.0 * PI, epsilon = 1e-8);
    }

    #[test]
    fn bad_input() {
        let s = ShModel::sphere(1.0).expect("sphere");
        assert!(curvature(&s, -1.0, 0.0).is_err());
        let neg = ShModel::new(0, vec![-1.0]).expect("model");
        assert!(matches!(
            curvature(&neg, 1.0, 0.0),
            Err(Error::ModelNotStarShaped { .. })
        ));
    }
}
