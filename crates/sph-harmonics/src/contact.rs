//! Hertz normal contact with the curvature correction (Radvilaitė 2016, Eqs. 2.48–2.52;
//! Johnson 1987, *Contact Mechanics*, §4.2).
//!
//! Printed-form corrections, checked against Table 3.6:
//! * Eq. 2.50 prints `ρ_eff = √(A·B/2)`; Table 3.6 (ρ_e = 0.5 for ρ_n = 0.25, ρ_t = 1, i.e.
//!   A = 0.5, B = 2) requires Johnson's `ρ_eff = 1/(2√(AB))` (= √(ρ₁ρ₂) against a plane),
//!   which is what [`hertz`] uses.
//! * Eq. 2.52 prints `(1/ρ_j1 − 1/ρ_j2 cos 2α)`; the bracket is `(1/ρ_j1 − 1/ρ_j2) cos 2α`.

use crate::error::Error;

/// Result of the curvature-corrected Hertz contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzContact {
    /// A of Eq. 2.52 (A ≤ B), 1/length.
    pub a: f64,
    /// B of Eq. 2.52, 1/length.
    pub b: f64,
    /// Effective radius of curvature `1/(2√(AB))`, length.
    pub rho_eff: f64,
    /// Correction factor of Eq. 2.51.
    pub c_cor: f64,
}

impl HertzContact {
    /// Normal force of Eq. 2.48 for overlap `u` and effective modulus `e_eff`.
    #[must_use]
    pub fn force(&self, e_eff: f64, u: f64) -> f64 {
        4.0 / 3.0 * self.c_cor * e_eff * self.rho_eff.sqrt() * u.max(0.0).powf(1.5)
    }
}

/// Effective modulus `1/E_eff = (1 − ν_i²)/E_i + (1 − ν_j²)/E_j` (Eq. 2.49).
///
/// # Errors
/// [`Error::InvalidParameter`] for non-positive moduli or ν ∉ (−1, 0.5].
pub fn effective_modulus(e_i: f64, nu_i: f64, e_j: f64, nu_j: f64) -> Result<f64, Error> {
    for (what, v) in [("e_i", e_i), ("e_j", e_j)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::InvalidParameter { what, value: v });
        }
    }
    for (what, v) in [("nu_i", nu_i), ("nu_j", nu_j)] {
        if !(v.is_finite() && v > -1.0 && v <= 0.5) {
            return Err(Error::InvalidParameter { what, value: v });
        }
    }
    Ok(1.0 / ((1.0 - nu_i * nu_i) / e_i + (1.0 - nu_j * nu_j) / e_j))
}

/// Correction factor `c_cor = (1 − [(B/A)^0.0684 − 1]^1.531)^(−3/2)` (Eq. 2.51), B ≥ A > 0.
#[must_use]
pub fn correction_factor(a: f64, b: f64) -> f64 {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    let t = ((hi / lo).powf(0.0684) - 1.0).powf(1.531);
    (1.0 - t).powf(-1.5)
}

/// A, B, effective radius and correction for two bodies with principal radii of curvature
/// `rho_i`, `rho_j` (use `f64::INFINITY` for a plane) and angle `alpha` between their
/// principal axes (Eqs. 2.50–2.52).
///
/// # Errors
/// [`Error::InvalidParameter`] for non-positive or NaN radii, non-finite α, both bodies flat,
/// or a geometry outside the validity of Eq. 2.51 (`(B/A)^0.0684 − 1 ≥ 1`).
pub fn hertz(rho_i: [f64; 2], rho_j: [f64; 2], alpha: f64) -> Result<HertzContact, Error> {
    for (what, v) in [
        ("rho_i1", rho_i[0]),
        ("rho_i2", rho_i[1]),
        ("rho_j1", rho_j[0]),
        ("rho_j2", rho_j[1]),
    ] {
        if v.is_nan() || v <= 0.0 {
            return Err(Error::InvalidParameter { what, value: v });
        }
    }
    if !alpha.is_finite() {
        return Err(Error::InvalidParameter {
            what: "alpha",
            value: alpha,
        });
    }
    let k = |r: f64| if r.is_infinite() { 0.0 } else { 1.0 / r };
    let (ki1, ki2, kj1, kj2) = (k(rho_i[0]), k(rho_i[1]), k(rho_j[0]), k(rho_j[1]));
    let sum = 0.5 * (ki1 + ki2 + kj1 + kj2);
    let di = ki1 - ki2;
    let dj = kj1 - kj2;
    let diff = 0.5
        * (di * di + dj * dj + 2.0 * di * dj * (2.0 * alpha).cos())
            .max(0.0)
            .sqrt();
    let a = 0.5 * (sum - diff);
    let b = 0.5 * (sum + diff);
    if a <= 0.0 {
        return Err(Error::InvalidParameter {
            what: "curvature sum (flat or cylindrical contact)",
            value: a,
        });
    }
    let ratio_term = (b / a).powf(0.0684) - 1.0;
    if ratio_term >= 1.0 {
        return Err(Error::InvalidParameter {
            what: "curvature ratio B/A outside Eq. 2.51",
            value: b / a,
        });
    }
    Ok(HertzContact {
        a,
        b,
        rho_eff: 1.0 / (2.0 * (a * b).sqrt()),
        c_cor: correction_factor(a, b),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn table_3_6_analytic_rows() {
        // (ρ_n, ρ_t) → (c_cor, ρ_e, F̄ ×1e3) as printed; ellipsoid against a plane, u_rel = 0.01.
        let rows = [
            (0.25, 1.0, 1.0455, 0.5, 0.9857),
            (0.05, 1.0, 1.1782, 0.2236, 0.7429),
            (2.0, 2.0, 1.0, 2.0, 1.885),
            (2.005, 2.005, 1.0, 2.005, 1.888),
        ];
        for (rn, rt, c, re, f) in rows {
            let h = hertz([rn, rt], [f64::INFINITY; 2], 0.0).expect("contact");
            assert!((h.c_cor - c).abs() < 0.5e-4, "c_cor {} vs {c}", h.c_cor);
            assert!(
                (h.rho_eff - re).abs() < 0.5e-4,
                "rho_e {} vs {re}",
                h.rho_eff
            );
            let force = h.force(1.0, 0.01) * 1e3;
            // Printed with 4 significant digits (row 3 recomputes to 1.8856, printed 1.885).
            assert!((force - f).abs() < 1e-3, "F {force} vs {f}");
        }
    }

    #[test]
    fn spheres_reduce_to_classic_hertz() {
        let h = hertz([1.0, 1.0], [3.0, 3.0], 0.4).expect("contact");
        assert_relative_eq!(h.c_cor, 1.0, epsilon = 1e-14);
        assert_relative_eq!(h.rho_eff, 0.75, epsilon = 1e-14);
        let e = effective_modulus(1.0, 0.0, 1.0, 0.0).expect("modulus");
        assert_relative_eq!(e, 0.5, epsilon = 1e-15);
    }

    #[test]
    fn bad_input() {
        assert!(hertz([0.0, 1.0], [1.0, 1.0], 0.0).is_err());
        assert!(hertz([f64::NAN, 1.0], [1.0, 1.0], 0.0).is_err());
        assert!(hertz([f64::INFINITY; 2], [f64::INFINITY; 2], 0.0).is_err());
        assert!(hertz([1e-6, 1.0], [f64::INFINITY; 2], 0.0).is_err());
        assert!(effective_modulus(-1.0, 0.3, 1.0, 0.3).is_err());
        assert!(effective_modulus(1.0, 0.7, 1.0, 0.3).is_err());
    }
}
