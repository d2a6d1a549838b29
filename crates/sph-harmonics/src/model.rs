//! Spherical-harmonic shape models `r(θ, φ) = Σ a_lm Y_lm(θ, φ)`
//! (Radvilaitė 2016, Eq. 2.8) and their evaluation.

use crate::basis::{Legendre, LegendreValues, coefficient_count, index, tri};
use crate::error::{Error, check_angles, check_finite};
use crate::grid::RingGrid;
use nalgebra::{Matrix3, Point3, Vector3};

/// Radius and its first and second derivatives in θ and φ at one direction.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RadiusDerivatives {
    /// r(θ, φ).
    pub r: f64,
    /// ∂r/∂θ.
    pub r_theta: f64,
    /// ∂r/∂φ.
    pub r_phi: f64,
    /// ∂²r/∂θ².
    pub r_theta_theta: f64,
    /// ∂²r/∂θ∂φ.
    pub r_theta_phi: f64,
    /// ∂²r/∂φ².
    pub r_phi_phi: f64,
}

/// A real spherical-harmonic expansion of a star-shaped surface about its origin.
///
/// Coefficients follow the convention of [`crate::basis`] and are stored at
/// index `l² + l + m`.
#[derive(Debug, Clone, PartialEq)]
pub struct ShModel {
    degree: usize,
    coefficients: Vec<f64>,
}

/// Per-ring azimuthal sums `C_m^(k)(θ) = Σ_l a_{l,m} √2 d^k p̄_l^m/dθ^k`, `S_m^(k)` likewise.
pub(crate) struct RingSums {
    pub(crate) c: Vec<[f64; 3]>,
    pub(crate) s: Vec<[f64; 3]>,
}

impl ShModel {
    /// A model of degree `degree` from `(degree+1)²` real coefficients.
    ///
    /// # Errors
    /// [`Error::CoefficientCount`], [`Error::NonFinite`], [`Error::DegreeOutOfRange`].
    pub fn new(degree: usize, coefficients: Vec<f64>) -> Result<Self, Error> {
        if degree > crate::basis::MAX_DEGREE {
            return Err(Error::DegreeOutOfRange {
                degree,
                max: crate::basis::MAX_DEGREE,
            });
        }
        let expected = coefficient_count(degree);
        if coefficients.len() != expected {
            return Err(Error::CoefficientCount {
                degree,
                expected,
                got: coefficients.len(),
            });
        }
        check_finite("coefficient", &coefficients)?;
        Ok(Self {
            degree,
            coefficients,
        })
    }

    /// A sphere of radius `radius` (only `a_00 = radius·√(4π)`).
    ///
    /// # Errors
    /// [`Error::NonPositiveRadius`] for `radius ≤ 0` or non-finite.
    pub fn sphere(radius: f64) -> Result<Self, Error> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::NonPositiveRadius {
                index: 0,
                value: radius,
            });
        }
        Self::new(0, vec![radius * (4.0 * std::f64::consts::PI).sqrt()])
    }

    /// Converts complex coefficients `a_nm` of `r = Σ a_nm Y_n^m` with the complex orthonormal
    /// `Y_n^m` including the Condon–Shortley phase (SciPy `sph_harm_y`, NIST/VCCTL convention).
    ///
    /// `complex[l² + l + m] = (Re a_lm, Im a_lm)`. The real part of the expansion is kept: for
    /// m > 0, `c_{l,m} = ((−1)^m Re a_lm + Re a_{l,−m})/√2` and
    /// `c_{l,−m} = (Im a_{l,−m} − (−1)^m Im a_lm)/√2`, which equals `√2 (−1)^m Re a_lm` and
    /// `−√2 (−1)^m Im a_lm` when `a_{l,−m} = (−1)^m conj(a_lm)` holds.
    ///
    /// # Errors
    /// As [`ShModel::new`].
    pub fn from_complex(degree: usize, complex: &[(f64, f64)]) -> Result<Self, Error> {
        let expected = coefficient_count(degree);
        if complex.len() != expected {
            return Err(Error::CoefficientCount {
                degree,
                expected,
                got: complex.len(),
            });
        }
        let sqrt2 = std::f64::consts::SQRT_2;
        let mut c = vec![0.0; expected];
        for l in 0..=degree {
            c[index(l, 0)] = complex[index(l, 0)].0;
            for m in 1..=l as i64 {
                let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
                let (ar, ai) = complex[index(l, m)];
                let (br, bi) = complex[index(l, -m)];
                c[index(l, m)] = (sign * ar + br) / sqrt2;
                c[index(l, -m)] = (bi - sign * ai) / sqrt2;
            }
        }
        Self::new(degree, c)
    }

    /// Inverse of [`ShModel::from_complex`]: complex coefficients obeying `a_{l,−m} = (−1)^m conj(a_lm)`.
    #[must_use]
    pub fn to_complex(&self) -> Vec<(f64, f64)> {
        let sqrt2 = std::f64::consts::SQRT_2;
        let mut out = vec![(0.0, 0.0); self.coefficients.len()];
        for l in 0..=self.degree {
            out[index(l, 0)] = (self.coefficients[index(l, 0)], 0.0);
            for m in 1..=l as i64 {
                let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
                let cp = self.coefficients[index(l, m)];
                let cm = self.coefficients[index(l, -m)];
                let a = (sign * cp / sqrt2, -sign * cm / sqrt2);
                out[index(l, m)] = a;
                out[index(l, -m)] = (sign * a.0, -sign * a.1);
            }
        }
        out
    }

    /// Expansion degree L.
    #[must_use]
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Real coefficients at index `l² + l + m`.
    #[must_use]
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// Coefficient (l, m), or 0 beyond the degree.
    #[must_use]
    pub fn coefficient(&self, l: usize, m: i64) -> f64 {
        if l > self.degree || m.unsigned_abs() as usize > l {
            0.0
        } else {
            self.coefficients[index(l, m)]
        }
    }

    /// The same surface truncated to degree `degree` (coefficients above it dropped).
    ///
    /// # Errors
    /// [`Error::DegreeOutOfRange`] when `degree` exceeds the model's degree.
    pub fn truncated(&self, degree: usize) -> Result<Self, Error> {
        if degree > self.degree {
            return Err(Error::DegreeOutOfRange {
                degree,
                max: self.degree,
            });
        }
        Ok(Self {
            degree,
            coefficients: self.coefficients[..coefficient_count(degree)].to_vec(),
        })
    }

    /// Radius r(θ, φ).
    ///
    /// # Errors
    /// [`Error::AngleOutOfRange`].
    pub fn radius(&self, theta: f64, phi: f64) -> Result<f64, Error> {
        check_angles(theta, phi)?;
        let leg = Legendre::new(self.degree)?;
        let mut v = leg.buffer(0);
        Ok(self.radius_with_buffer(&leg, &mut v, theta, phi))
    }

    /// Radius and derivatives at (θ, φ). At the poles the φ-derivatives vanish and the
    /// θ-derivatives are the one-sided limits along the meridian φ.
    ///
    /// # Errors
    /// [`Error::AngleOutOfRange`].
    pub fn derivatives(&self, theta: f64, phi: f64) -> Result<RadiusDerivatives, Error> {
        check_angles(theta, phi)?;
        let leg = Legendre::new(self.degree)?;
        let mut v = leg.buffer(2);
        leg.compute(theta, &mut v);
        let sums = self.ring_sums(&v, 2);
        Ok(sums.at(phi))
    }

    /// Radii at arbitrary directions (θ, φ).
    ///
    /// # Errors
    /// [`Error::AngleOutOfRange`] for any invalid direction.
    pub fn evaluate(&self, directions: &[(f64, f64)]) -> Result<Vec<f64>, Error> {
        for &(t, p) in directions {
            check_angles(t, p)?;
        }
        let leg = Legendre::new(self.degree)?;
        let mut v = leg.buffer(0);
        Ok(directions
            .iter()
            .map(|&(t, p)| self.radius_with_buffer(&leg, &mut v, t, p))
            .collect())
    }

    /// Radii at every point of a ring grid (ring by ring): O(L²) per ring and O(L) per point.
    ///
    /// # Errors
    /// [`Error::DegreeOutOfRange`] (never for a constructed model).
    pub fn evaluate_grid(&self, grid: &RingGrid) -> Result<Vec<f64>, Error> {
        let leg = Legendre::new(self.degree)?;
        let mut v = leg.buffer(0);
        let mut out = Vec::with_capacity(grid.len());
        let n = self.degree + 1;
        // Trigonometric table (cos mφ_j, sin mφ_j) shared by consecutive rings with the same
        // azimuths, so the per-point work is a vectorisable dot product.
        let mut key: Option<(usize, u64)> = None;
        let mut table: Vec<f64> = Vec::new();
        let mut cm = vec![0.0; 2 * n];
        for ring in grid.rings() {
            leg.compute(ring.theta, &mut v);
            let sums = self.ring_sums(&v, 0);
            let this = (ring.n_phi, ring.phi0.to_bits());
            if key != Some(this) {
                key = Some(this);
                table.clear();
                for j in 0..ring.n_phi {
                    let phi = ring.phi(j);
                    for m in 0..n {
                        let (sm, cmv) = (m as f64 * phi).sin_cos();
                        table.push(cmv);
                        table.push(sm);
                    }
                }
            }
            for m in 0..n {
                cm[2 * m] = sums.c[m][0];
                cm[2 * m + 1] = sums.s[m][0];
            }
            for row in table.chunks_exact(2 * n) {
                out.push(row.iter().zip(&cm).map(|(a, b)| a * b).sum());
            }
        }
        Ok(out)
    }

    /// Radius and derivatives at every point of a ring grid (ring by ring).
    ///
    /// # Errors
    /// [`Error::DegreeOutOfRange`] (never for a constructed model).
    pub fn derivatives_grid(&self, grid: &RingGrid) -> Result<Vec<RadiusDerivatives>, Error> {
        let leg = Legendre::new(self.degree)?;
        let mut v = leg.buffer(2);
        let mut out = Vec::with_capacity(grid.len());
        for ring in grid.rings() {
            leg.compute(ring.theta, &mut v);
            let sums = self.ring_sums(&v, 2);
            for j in 0..ring.n_phi {
                out.push(sums.at(ring.phi(j)));
            }
        }
        Ok(out)
    }

    /// Surface point `r(θ, φ)·u(θ, φ)` (Radvilaitė 2016, Eq. 2.42).
    ///
    /// # Errors
    /// [`Error::AngleOutOfRange`].
    pub fn surface_point(&self, theta: f64, phi: f64) -> Result<Point3<f64>, Error> {
        let r = self.radius(theta, phi)?;
        Ok(Point3::from(direction(theta, phi) * r))
    }

    /// The model of the rotated surface: `r'(u) = r(Rᵀ u)` for a rotation matrix `R`.
    ///
    /// Exact for band-limited models: the rotated function is sampled on a Gauss–Legendre grid
    /// of the same degree and transformed by quadrature.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `rotation` is not orthonormal with determinant +1.
    pub fn rotated(&self, rotation: &Matrix3<f64>) -> Result<Self, Error> {
        let should_be_identity = rotation.transpose() * rotation - Matrix3::identity();
        let det = rotation.determinant();
        if !(should_be_identity.norm() < 1e-10 && (det - 1.0).abs() < 1e-10) {
            return Err(Error::InvalidParameter {
                what: "rotation matrix (not a proper rotation)",
                value: det,
            });
        }
        let grid = RingGrid::gauss_legendre(self.degree)?;
        let rt = rotation.transpose();
        let dirs: Vec<(f64, f64)> = grid
            .points()
            .into_iter()
            .map(|(t, p)| to_angles(&(rt * direction(t, p))))
            .collect();
        let values = self.evaluate(&dirs)?;
        crate::fit::quadrature_transform(&grid, &values, self.degree)
    }

    pub(crate) fn radius_with_buffer(
        &self,
        leg: &Legendre,
        v: &mut LegendreValues,
        theta: f64,
        phi: f64,
    ) -> f64 {
        leg.compute(theta, v);
        let sqrt2 = std::f64::consts::SQRT_2;
        let (s1, c1) = phi.sin_cos();
        let (mut sm, mut cm) = (0.0_f64, 1.0_f64);
        let mut total = 0.0;
        for m in 0..=self.degree {
            if m > 0 {
                let c_next = cm * c1 - sm * s1;
                sm = sm * c1 + cm * s1;
                cm = c_next;
            }
            let (mut cs, mut ss) = (0.0, 0.0);
            for l in m..=self.degree {
                let p = v.p[tri(l, m)];
                cs += self.coefficients[index(l, m as i64)] * p;
                if m > 0 {
                    ss += self.coefficients[index(l, -(m as i64))] * p;
                }
            }
            total += if m == 0 {
                cs
            } else {
                sqrt2 * (cs * cm + ss * sm)
            };
        }
        total
    }

    pub(crate) fn ring_sums(&self, v: &LegendreValues, derivatives: usize) -> RingSums {
        let sqrt2 = std::f64::consts::SQRT_2;
        let n = self.degree + 1;
        let mut c = vec![[0.0; 3]; n];
        let mut s = vec![[0.0; 3]; n];
        if derivatives == 0 {
            for m in 0..=self.degree {
                let f = if m == 0 { 1.0 } else { sqrt2 };
                let base = tri(m, m);
                let (mut cs, mut ss) = (0.0, 0.0);
                for l in m..=self.degree {
                    // tri(l, m) = tri(l, 0) + m; consecutive l differ by l.
                    let p = v.p[base + (l * (l + 1) - m * (m + 1)) / 2];
                    cs += self.coefficients[l * l + l + m] * p;
                    if m > 0 {
                        ss += self.coefficients[l * l + l - m] * p;
                    }
                }
                c[m][0] = f * cs;
                s[m][0] = f * ss;
            }
            return RingSums { c, s };
        }
        for m in 0..=self.degree {
            let f = if m == 0 { 1.0 } else { sqrt2 };
            for l in m..=self.degree {
                let t = tri(l, m);
                let a = self.coefficients[index(l, m as i64)] * f;
                let b = if m > 0 {
                    self.coefficients[index(l, -(m as i64))] * f
                } else {
                    0.0
                };
                let tables: [&[f64]; 3] = [&v.p, &v.dp, &v.d2p];
                for (k, tab) in tables.iter().enumerate().take(derivatives + 1) {
                    c[m][k] += a * tab[t];
                    s[m][k] += b * tab[t];
                }
            }
        }
        RingSums { c, s }
    }
}

impl RingSums {
    /// r and all derivatives (requires sums computed with derivatives = 2).
    pub(crate) fn at(&self, phi: f64) -> RadiusDerivatives {
        let (s1, c1) = phi.sin_cos();
        let (mut sm, mut cm) = (0.0_f64, 1.0_f64);
        let mut d = RadiusDerivatives {
            r: self.c[0][0],
            r_theta: self.c[0][1],
            r_theta_theta: self.c[0][2],
            ..RadiusDerivatives::default()
        };
        for m in 1..self.c.len() {
            let c_next = cm * c1 - sm * s1;
            sm = sm * c1 + cm * s1;
            cm = c_next;
            let mf = m as f64;
            let (c, s) = (self.c[m], self.s[m]);
            d.r += c[0] * cm + s[0] * sm;
            d.r_theta += c[1] * cm + s[1] * sm;
            d.r_theta_theta += c[2] * cm + s[2] * sm;
            d.r_phi += mf * (-c[0] * sm + s[0] * cm);
            d.r_theta_phi += mf * (-c[1] * sm + s[1] * cm);
            d.r_phi_phi -= mf * mf * (c[0] * cm + s[0] * sm);
        }
        d
    }
}

/// Unit vector of direction (θ, φ) (Radvilaitė 2016, Eq. 2.1 with r = 1).
#[must_use]
pub fn direction(theta: f64, phi: f64) -> Vector3<f64> {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vector3::new(st * cp, st * sp, ct)
}

/// (θ, φ) of a non-zero vector, θ ∈ [0, π], φ ∈ (−π, π] (Radvilaitė 2016, Eq. 2.2).
#[must_use]
pub fn to_angles(v: &Vector3<f64>) -> (f64, f64) {
    let rho = (v.x * v.x + v.y * v.y).sqrt();
    (rho.atan2(v.z), v.y.atan2(v.x))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::{assert_abs_diff_eq, assert_relative_eq};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    pub(crate) fn random_model(degree: usize, seed: u64) -> ShModel {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut c: Vec<f64> = (0..coefficient_count(degree))
            .map(|i| rng.random_range(-1.0..1.0) / (1.0 + (i as f64).sqrt()))
            .collect();
        c[0] = 20.0;
        ShModel::new(degree, c).expect("model")
    }

    #[test]
    fn sphere_has_constant_radius() {
        let s = ShModel::sphere(2.5).expect("sphere");
        assert_relative_eq!(s.radius(0.3, 1.0).expect("r"), 2.5, epsilon = 1e-14);
        assert_relative_eq!(s.radius(PI, 0.0).expect("r"), 2.5, epsilon = 1e-14);
    }

    #[test]
    fn complex_conversion_matches_closed_form_condon_shortley() {
        // a_11 = 1, a_1,-1 = (−1)^1 conj(a_11) = −1:
        // r = Y_1^1 − Y_1^{−1} = 2 Re Y_1^1 = −√(3/(2π)) sin θ cos φ (SciPy sph_harm_y convention).
        let mut cx = vec![(0.0, 0.0); 4];
        cx[index(1, 1)] = (1.0, 0.0);
        cx[index(1, -1)] = (-1.0, 0.0);
        let model = ShModel::from_complex(1, &cx).expect("model");
        let (t, p) = (0.8_f64, 0.4_f64);
        let expected = -(3.0 / (2.0 * PI)).sqrt() * t.sin() * p.cos();
        assert_abs_diff_eq!(model.radius(t, p).expect("r"), expected, epsilon = 1e-14);
        // a_22 = i, a_2,-2 = conj(i) = −i: r = 2 Re(i Y_2^2) = −2 Im Y_2^2
        //   = −2 · ¼√(15/(2π)) sin²θ sin 2φ.
        let mut cx = vec![(0.0, 0.0); 9];
        cx[index(2, 2)] = (0.0, 1.0);
        cx[index(2, -2)] = (0.0, -1.0);
        let model = ShModel::from_complex(2, &cx).expect("model");
        let expected = -0.5 * (15.0 / (2.0 * PI)).sqrt() * t.sin().powi(2) * (2.0 * p).sin();
        assert_abs_diff_eq!(model.radius(t, p).expect("r"), expected, epsilon = 1e-14);
        let back = model.to_complex();
        for (a, b) in back.iter().zip(&cx) {
            assert_abs_diff_eq!(a.0, b.0, epsilon = 1e-15);
            assert_abs_diff_eq!(a.1, b.1, epsilon = 1e-15);
        }
    }

    #[test]
    fn grid_and_scattered_evaluation_agree() {
        let model = random_model(12, 7);
        let grid = RingGrid::threshold();
        let a = model.evaluate_grid(&grid).expect("grid");
        let b = model.evaluate(&grid.points()).expect("points");
        for (x, y) in a.iter().zip(&b) {
            assert_abs_diff_eq!(x, y, epsilon = 1e-12);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let model = random_model(10, 3);
        let h = 1e-5;
        for &(t, p) in &[(0.4, 0.3), (1.6, 4.0), (2.8, 5.5)] {
            let d = model.derivatives(t, p).expect("d");
            let r = |t: f64, p: f64| model.radius(t, p).expect("r");
            let dt = model.derivatives(t + h, p).expect("d");
            let dtm = model.derivatives(t - h, p).expect("d");
            let dp = model.derivatives(t, p + h).expect("d");
            let dpm = model.derivatives(t, p - h).expect("d");
            assert_abs_diff_eq!(d.r, r(t, p), epsilon = 1e-12);
            assert_abs_diff_eq!(d.r_theta, (dt.r - dtm.r) / (2.0 * h), epsilon = 1e-6);
            assert_abs_diff_eq!(d.r_phi, (dp.r - dpm.r) / (2.0 * h), epsilon = 1e-6);
            assert_abs_diff_eq!(
                d.r_theta_theta,
                (dt.r_theta - dtm.r_theta) / (2.0 * h),
                epsilon = 1e-5
            );
            assert_abs_diff_eq!(
                d.r_theta_phi,
                (dp.r_theta - dpm.r_theta) / (2.0 * h),
                epsilon = 1e-5
            );
            assert_abs_diff_eq!(
                d.r_phi_phi,
                (dp.r_phi - dpm.r_phi) / (2.0 * h),
                epsilon = 1e-5
            );
        }
    }

    #[test]
    fn rotation_is_exact_for_band_limited_models() {
        let model = random_model(8, 11);
        let rot = *nalgebra::Rotation3::from_euler_angles(0.3, -1.1, 2.0).matrix();
        let rotated = model.rotated(&rot).expect("rotated");
        for &(t, p) in &[(0.2, 0.1), (1.0, 2.0), (2.5, -1.0)] {
            let u = direction(t, p);
            let (t0, p0) = to_angles(&(rot.transpose() * u));
            assert_relative_eq!(
                rotated.radius(t, p).expect("r"),
                model.radius(t0, p0).expect("r"),
                epsilon = 1e-12
            );
        }
    }

    #[test]
    fn truncation_and_bad_input() {
        let model = random_model(6, 1);
        let t = model.truncated(3).expect("truncated");
        assert_eq!(t.coefficients().len(), 16);
        assert!(matches!(
            model.truncated(7),
            Err(Error::DegreeOutOfRange { .. })
        ));
        assert!(matches!(
            ShModel::new(2, vec![1.0; 8]),
            Err(Error::CoefficientCount { .. })
        ));
        assert!(matches!(
            ShModel::new(1, vec![1.0, f64::NAN, 0.0, 0.0]),
            Err(Error::NonFinite { .. })
        ));
        assert!(ShModel::sphere(-1.0).is_err());
        assert!(model.radius(f64::NAN, 0.0).is_err());
    }
}
