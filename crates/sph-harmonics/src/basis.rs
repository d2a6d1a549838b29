//! The real orthonormal spherical-harmonic basis and its fully normalised
//! associated Legendre functions.
//!
//! # Convention
//!
//! θ is the polar angle from +z, φ the azimuth from +x. With
//! `p̄_l^m(θ) = √((2l+1)/(4π) · (l−m)!/(l+m)!) · P_l^m(cos θ)` **without** the
//! Condon–Shortley phase (so `p̄_m^m(θ) > 0` for 0 < θ < π), the real basis is
//!
//! * `Y_{l,0} = p̄_l^0(θ)`,
//! * `Y_{l,m} = √2 · p̄_l^m(θ) · cos(mφ)` for m > 0,
//! * `Y_{l,−m} = √2 · p̄_l^m(θ) · sin(mφ)` for m > 0,
//!
//! orthonormal on the unit sphere (Radvilaitė 2016, Eqs. 2.13–2.15). The
//! thesis' Eq. 2.16 includes the Condon–Shortley factor (−1)^m in P_l^m, so its
//! basis equals ours times (−1)^m; the coefficients differ by the same sign.
//!
//! Coefficients are stored flat at index `l² + l + m` ([`index`]).
//!
//! # Recurrences
//!
//! No factorials are evaluated: `p̄_0^0 = 1/√(4π)`, the sectoral terms
//! `p̄_m^m = √((2m+1)/(2m)) · sin θ · p̄_{m−1}^{m−1}`, then
//! `p̄_{m+1}^m = √(2m+3) cos θ p̄_m^m` and the three-term recurrence
//! `p̄_l^m = a_lm (cos θ p̄_{l−1}^m − b_lm p̄_{l−2}^m)` with
//! `a_lm = √((4l²−1)/(l²−m²))`, `b_lm = √(((l−1)²−m²)/(4(l−1)²−1))`
//! (Holmes & Featherstone 2002, doi:10.1007/s00190-002-0216-2). Derivatives use
//! the pole-regular identity
//! `dp̄_l^m/dθ = ½ (√((l+m)(l−m+1)) p̄_l^{m−1} − √((l−m)(l+m+1)) p̄_l^{m+1})`
//! with `p̄_l^{−1} ≡ −p̄_l^1`, applied twice for the second derivative, so no
//! `1/sin θ` appears anywhere. In f64 the functions are accurate to degree
//! ≥ 1000 away from the poles; close to the poles `sin^m θ` underflows for very
//! large m, which only affects values below 1e-290.

use crate::error::Error;

/// Largest degree the crate accepts (memory bound, not an accuracy bound).
pub const MAX_DEGREE: usize = 2000;

/// Flat index of the real coefficient (l, m), −l ≤ m ≤ l: `l² + l + m`.
#[must_use]
pub fn index(l: usize, m: i64) -> usize {
    // l ≤ MAX_DEGREE, |m| ≤ l: the sum is never negative.
    (l * l + l).saturating_add_signed(m as isize)
}

/// Number of real coefficients up to degree `degree`: `(degree + 1)²` (Radvilaitė 2016, Eq. 2.9).
#[must_use]
pub fn coefficient_count(degree: usize) -> usize {
    (degree + 1) * (degree + 1)
}

/// Index into the triangular (l, m ≥ 0) Legendre tables.
#[inline]
pub(crate) fn tri(l: usize, m: usize) -> usize {
    l * (l + 1) / 2 + m
}

/// Precomputed recurrence coefficients for the normalised Legendre functions up to a degree.
#[derive(Debug, Clone)]
pub struct Legendre {
    degree: usize,
    a: Vec<f64>,
    b: Vec<f64>,
    sect: Vec<f64>,
    diag1: Vec<f64>,
    cminus: Vec<f64>,
    cplus: Vec<f64>,
}

/// Values (and optionally θ-derivatives) of `p̄_l^m(θ)` for 0 ≤ m ≤ l ≤ degree.
#[derive(Debug, Clone)]
pub struct LegendreValues {
    /// `p̄_l^m` at `tri(l, m) = l(l+1)/2 + m`.
    pub p: Vec<f64>,
    /// `dp̄_l^m/dθ` (empty when not requested).
    pub dp: Vec<f64>,
    /// `d²p̄_l^m/dθ²` (empty when not requested).
    pub d2p: Vec<f64>,
}

impl Legendre {
    /// Tables of recurrence coefficients for degrees up to `degree`.
    ///
    /// # Errors
    /// [`Error::DegreeOutOfRange`] when `degree > MAX_DEGREE`.
    pub fn new(degree: usize) -> Result<Self, Error> {
        if degree > MAX_DEGREE {
            return Err(Error::DegreeOutOfRange {
                degree,
                max: MAX_DEGREE,
            });
        }
        let n = tri(degree, degree) + 1;
        let mut a = vec![0.0; n];
        let mut b = vec![0.0; n];
        let mut cminus = vec![0.0; n];
        let mut cplus = vec![0.0; n];
        for l in 0..=degree {
            for m in 0..=l {
                let (lf, mf) = (l as f64, m as f64);
                if l >= m + 2 {
                    a[tri(l, m)] = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                    let l1 = lf - 1.0;
                    b[tri(l, m)] = ((l1 * l1 - mf * mf) / (4.0 * l1 * l1 - 1.0)).sqrt();
                }
                cminus[tri(l, m)] = ((lf + mf) * (lf - mf + 1.0)).sqrt();
                cplus[tri(l, m)] = ((lf - mf) * (lf + mf + 1.0)).sqrt();
            }
        }
        let sect = (0..=degree)
            .map(|m| {
                if m == 0 {
                    1.0 / (4.0 * std::f64::consts::PI).sqrt()
                } else {
                    let mf = m as f64;
                    ((2.0 * mf + 1.0) / (2.0 * mf)).sqrt()
                }
            })
            .collect();
        let diag1 = (0..=degree)
            .map(|m| (2.0 * m as f64 + 3.0).sqrt())
            .collect();
        Ok(Self {
            degree,
            a,
            b,
            sect,
            diag1,
            cminus,
            cplus,
        })
    }

    /// The degree of the tables.
    #[must_use]
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Allocates a value buffer; `derivatives` = 0, 1 or 2 selects how many θ-derivatives are kept.
    #[must_use]
    pub fn buffer(&self, derivatives: usize) -> LegendreValues {
        let n = tri(self.degree, self.degree) + 1;
        LegendreValues {
            p: vec![0.0; n],
            dp: if derivatives >= 1 {
                vec![0.0; n]
            } else {
                Vec::new()
            },
            d2p: if derivatives >= 2 {
                vec![0.0; n]
            } else {
                Vec::new()
            },
        }
    }

    /// Fills `out.p` (and `out.dp`, `out.d2p` if allocated) at polar angle θ.
    pub fn compute(&self, theta: f64, out: &mut LegendreValues) {
        let (s, c) = theta.sin_cos();
        let lmax = self.degree;
        let p = &mut out.p;
        let mut pmm = 0.0;
        for m in 0..=lmax {
            pmm = if m == 0 {
                self.sect[0]
            } else {
                pmm * self.sect[m] * s
            };
            p[tri(m, m)] = pmm;
            if m < lmax {
                let mut pm2 = pmm;
                let mut pm1 = self.diag1[m] * c * pmm;
                p[tri(m + 1, m)] = pm1;
                for l in (m + 2)..=lmax {
                    let t = tri(l, m);
                    let v = self.a[t] * (c * pm1 - self.b[t] * pm2);
                    p[t] = v;
                    pm2 = pm1;
                    pm1 = v;
                }
            }
        }
        if !out.dp.is_empty() {
            derivative(&self.cminus, &self.cplus, lmax, &out.p, &mut out.dp);
        }
        if !out.d2p.is_empty() {
            derivative(&self.cminus, &self.cplus, lmax, &out.dp, &mut out.d2p);
        }
    }
}

/// θ-derivative of a table of (l, m) functions that obey the same ladder identity as `p̄`.
fn derivative(cminus: &[f64], cplus: &[f64], lmax: usize, f: &[f64], df: &mut [f64]) {
    for l in 0..=lmax {
        for m in 0..=l {
            let t = tri(l, m);
            let lower = if m > 0 {
                f[t - 1]
            } else if l > 0 {
                -f[t + 1]
            } else {
                0.0
            };
            let upper = if m < l { f[t + 1] } else { 0.0 };
            df[t] = 0.5 * (cminus[t] * lower - cplus[t] * upper);
        }
    }
}

/// All real orthonormal harmonics `Y_{l,m}(θ, φ)` up to `degree`, at index `l² + l + m`.
///
/// Convenience for tests and small problems; models evaluate without building this vector.
///
/// # Errors
/// [`Error::DegreeOutOfRange`] for `degree > MAX_DEGREE`, [`Error::AngleOutOfRange`] for
/// θ ∉ [0, π] or non-finite φ.
pub fn real_harmonics(degree: usize, theta: f64, phi: f64) -> Result<Vec<f64>, Error> {
    crate::error::check_angles(theta, phi)?;
    let leg = Legendre::new(degree)?;
    let mut vals = leg.buffer(0);
    leg.compute(theta, &mut vals);
    let mut out = vec![0.0; coefficient_count(degree)];
    fill_row(degree, &vals.p, phi, &mut out);
    Ok(out)
}

/// Fills one row of real harmonics from a Legendre table.
pub(crate) fn fill_row(degree: usize, p: &[f64], phi: f64, out: &mut [f64]) {
    let sqrt2 = std::f64::consts::SQRT_2;
    let (s1, c1) = phi.sin_cos();
    let (mut sm, mut cm) = (0.0_f64, 1.0_f64);
    for m in 0..=degree {
        if m > 0 {
            let c_next = cm * c1 - sm * s1;
            sm = sm * c1 + cm * s1;
            cm = c_next;
        }
        for l in m..=degree {
            let v = p[tri(l, m)];
            if m == 0 {
                out[index(l, 0)] = v;
            } else {
                out[index(l, m as i64)] = sqrt2 * v * cm;
                out[index(l, -(m as i64))] = sqrt2 * v * sm;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::{PI, SQRT_2};

    /// Max |<Y_lm, Y_l'm'> − δ| by Gauss–Legendre × equiangular quadrature of degree `degree`.
    ///
    /// The grid is a tensor product, so every inner product factorises exactly into a θ-sum
    /// (Σ_i w_i p̄_l^m p̄_l'^m') and a φ-sum (Σ_j trig_m trig_m'). Same-m θ-sums are computed for
    /// all (l, l'); for m ≠ m' the θ-sum is bounded by Cauchy–Schwarz, so the returned value is
    /// an upper bound on the true maximum error over all pairs.
    fn orthonormality_error(degree: usize) -> f64 {
        let grid = crate::grid::RingGrid::gauss_legendre(degree).expect("grid");
        let leg = Legendre::new(degree).expect("legendre");
        let mut vals = leg.buffer(0);
        let n = tri(degree, degree) + 1;
        let rings = grid.rings();
        let n_phi = rings[0].n_phi;
        let dphi = 2.0 * PI / n_phi as f64;
        let mut table = Vec::with_capacity(rings.len());
        for ring in rings {
            leg.compute(ring.theta, &mut vals);
            // ring.weight = w_i · 2π/n_phi; the θ weight alone:
            table.push((ring.weight / dphi, vals.p.clone()));
        }
        // φ-sums (times 2π normalisation of the basis: √2 factors, 1/2π → dphi).
        let trig = |m: usize, cos_m: bool, mp: usize, cos_mp: bool| -> f64 {
            let mut s = 0.0;
            for j in 0..n_phi {
                let phi = j as f64 * dphi;
                let a = if m == 0 {
                    1.0
                } else if cos_m {
                    (m as f64 * phi).cos() * SQRT_2
                } else {
                    (m as f64 * phi).sin() * SQRT_2
                };
                let b = if mp == 0 {
                    1.0
                } else if cos_mp {
                    (mp as f64 * phi).cos() * SQRT_2
                } else {
                    (mp as f64 * phi).sin() * SQRT_2
                };
                s += a * b;
            }
            s * dphi
        };
        let mut worst: f64 = 0.0;
        let mut diag = vec![0.0; n];
        for m in 0..=degree {
            let same = [
                trig(m, true, m, true),
                trig(m, false, m, false),
                trig(m, true, m, false),
            ];
            for l in m..=degree {
                for lp in l..=degree {
                    let th: f64 = table
                        .iter()
                        .map(|(w, p)| w * p[tri(l, m)] * p[tri(lp, m)])
                        .sum();
                    if l == lp {
                        diag[tri(l, m)] = th;
                    }
                    for (k, &(c1, c2)) in [(true, true), (false, false), (true, false)]
                        .iter()
                        .enumerate()
                    {
                        if m == 0 && !(c1 && c2) {
                            continue;
                        }
                        let target = if l == lp && c1 == c2 { 1.0 } else { 0.0 };
                        worst = worst.max((th * same[k] - target).abs());
                    }
                }
            }
        }
        let dmax = diag.iter().copied().fold(0.0, f64::max);
        for m in 0..=degree {
            for mp in (m + 1)..=degree {
                for &(c1, c2) in &[(true, true), (false, false), (true, false), (false, true)] {
                    worst = worst.max(trig(m, c1, mp, c2).abs() * dmax);
                }
            }
        }
        worst
    }

    #[test]
    fn orthonormal_to_degree_100_by_quadrature() {
        let err = orthonormality_error(100);
        assert!(err < 1e-12, "max |<Y,Y'> - delta| = {err:e}");
    }

    #[test]
    fn low_degrees_match_closed_forms() {
        // Closed forms of the real orthonormal harmonics (thesis Annex A lists l ≤ 3;
        // written here without the Condon–Shortley phase, see the module docs).
        let (theta, phi) = (0.7_f64, 2.1_f64);
        let (x, y, z) = (
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        let y_all = real_harmonics(3, theta, phi).expect("values");
        let sq = |v: f64| v.sqrt();
        let expected = [
            (0, 0, 0.5 * sq(1.0 / PI)),
            (1, -1, sq(3.0 / (4.0 * PI)) * y),
            (1, 0, sq(3.0 / (4.0 * PI)) * z),
            (1, 1, sq(3.0 / (4.0 * PI)) * x),
            (2, -2, 0.5 * sq(15.0 / PI) * x * y),
            (2, -1, 0.5 * sq(15.0 / PI) * y * z),
            (2, 0, 0.25 * sq(5.0 / PI) * (3.0 * z * z - 1.0)),
            (2, 1, 0.5 * sq(15.0 / PI) * x * z),
            (2, 2, 0.25 * sq(15.0 / PI) * (x * x - y * y)),
            (
                3,
                -3,
                0.25 * sq(35.0 / (2.0 * PI)) * (3.0 * x * x - y * y) * y,
            ),
            (3, -2, 0.5 * sq(105.0 / PI) * x * y * z),
            (
                3,
                -1,
                0.25 * sq(21.0 / (2.0 * PI)) * y * (5.0 * z * z - 1.0),
            ),
            (3, 0, 0.25 * sq(7.0 / PI) * (5.0 * z * z * z - 3.0 * z)),
            (3, 1, 0.25 * sq(21.0 / (2.0 * PI)) * x * (5.0 * z * z - 1.0)),
            (3, 2, 0.25 * sq(105.0 / PI) * (x * x - y * y) * z),
            (
                3,
                3,
                0.25 * sq(35.0 / (2.0 * PI)) * (x * x - 3.0 * y * y) * x,
            ),
        ];
        for (l, m, v) in expected {
            assert_abs_diff_eq!(y_all[index(l, m)], v, epsilon = 1e-14);
        }
    }

    #[test]
    fn derivatives_match_finite_differences_including_poles() {
        let degree = 40;
        let leg = Legendre::new(degree).expect("legendre");
        let mut v0 = leg.buffer(2);
        let mut vp = leg.buffer(1);
        let mut vm = leg.buffer(1);
        let h = 1e-6;
        for &theta in &[1e-9, 0.3, 1.2, PI / 2.0, 2.9, PI - 1e-9] {
            leg.compute(theta, &mut v0);
            leg.compute(theta + h, &mut vp);
            leg.compute(theta - h, &mut vm);
            for t in 0..v0.p.len() {
                let fd1 = (vp.p[t] - vm.p[t]) / (2.0 * h);
                let fd2 = (vp.dp[t] - vm.dp[t]) / (2.0 * h);
                assert_abs_diff_eq!(v0.dp[t], fd1, epsilon = 1e-5 * (1.0 + fd1.abs()));
                assert_abs_diff_eq!(v0.d2p[t], fd2, epsilon = 1e-4 * (1.0 + fd2.abs()));
            }
        }
    }

    #[test]
    fn legendre_ode_holds_at_high_degree() {
        // p'' + cot θ p' + (l(l+1) − m²/sin²θ) p = 0, checked at degree 150.
        let degree = 150;
        let leg = Legendre::new(degree).expect("legendre");
        let mut v = leg.buffer(2);
        let theta = 1.1_f64;
        leg.compute(theta, &mut v);
        let (s, c) = theta.sin_cos();
        for l in 0..=degree {
            for m in 0..=l {
                let t = tri(l, m);
                let (lf, mf) = (l as f64, m as f64);
                let res =
                    v.d2p[t] + c / s * v.dp[t] + (lf * (lf + 1.0) - mf * mf / (s * s)) * v.p[t];
                let scale = lf * lf + 1.0;
                assert!(res.abs() < 1e-10 * scale, "l={l} m={m} residual {res:e}");
            }
        }
    }

    #[test]
    fn rejects_bad_input() {
        assert!(matches!(
            real_harmonics(2, -0.1, 0.0),
            Err(Error::AngleOutOfRange { .. })
        ));
        assert!(matches!(
            real_harmonics(2, 0.1, f64::NAN),
            Err(Error::AngleOutOfRange { .. })
        ));
        assert!(matches!(
            Legendre::new(MAX_DEGREE + 1),
            Err(Error::DegreeOutOfRange { .. })
        ));
    }
}
