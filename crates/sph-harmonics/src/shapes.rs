//! Analytic reference shapes as radius functions r(θ, φ) about their centre, with exact
//! volume and surface area (the shapes of Radvilaitė 2016, Tables 3.7–3.9 and Annex B).
//!
//! All shapes are centred at the origin with their symmetry axes on x, y, z.

use crate::error::Error;
use crate::model::direction;
use std::f64::consts::PI;

/// An analytic star-shaped solid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Sphere of radius `r`.
    Sphere {
        /// Radius.
        r: f64,
    },
    /// Ellipsoid with semi-axes a (x), b (y), c (z); a = b gives the spheroids of §3.1.
    Ellipsoid {
        /// Semi-axis along x.
        a: f64,
        /// Semi-axis along y.
        b: f64,
        /// Semi-axis along z.
        c: f64,
    },
    /// Circular cylinder of radius `a` about z and height `2c` (§3.2).
    Cylinder {
        /// Radius.
        a: f64,
        /// Half height.
        c: f64,
    },
    /// Rectangular parallelepiped with half-sides a, b, c (§3.3).
    Box {
        /// Half side along x.
        a: f64,
        /// Half side along y.
        b: f64,
        /// Half side along z.
        c: f64,
    },
    /// Bicone: two cones of base radius `a` and height `c` joined at their bases in z = 0.
    Bicone {
        /// Base radius.
        a: f64,
        /// Height of each cone.
        c: f64,
    },
    /// Octahedron `|x|/a + |y|/b + |z|/c = 1`.
    Octahedron {
        /// Vertex distance along x.
        a: f64,
        /// Vertex distance along y.
        b: f64,
        /// Vertex distance along z.
        c: f64,
    },
}

impl Shape {
    /// Checks that every size parameter is finite and positive.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first bad parameter.
    pub fn validate(&self) -> Result<(), Error> {
        let params: Vec<(&'static str, f64)> = match *self {
            Shape::Sphere { r } => vec![("r", r)],
            Shape::Ellipsoid { a, b, c }
            | Shape::Box { a, b, c }
            | Shape::Octahedron { a, b, c } => {
                vec![("a", a), ("b", b), ("c", c)]
            }
            Shape::Cylinder { a, c } | Shape::Bicone { a, c } => vec![("a", a), ("c", c)],
        };
        for (what, value) in params {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidParameter { what, value });
            }
        }
        Ok(())
    }

    /// Radius of the surface in direction (θ, φ) (Annex B, Eqs. E2, C2, P2).
    #[must_use]
    pub fn radius(&self, theta: f64, phi: f64) -> f64 {
        let u = direction(theta, phi);
        let (x, y, z) = (u.x.abs(), u.y.abs(), u.z.abs());
        match *self {
            Shape::Sphere { r } => r,
            Shape::Ellipsoid { a, b, c } => {
                1.0 / ((x / a).powi(2) + (y / b).powi(2) + (z / c).powi(2)).sqrt()
            }
            Shape::Cylinder { a, c } => {
                let rho = (x * x + y * y).sqrt();
                1.0 / (rho / a).max(z / c)
            }
            Shape::Box { a, b, c } => 1.0 / (x / a).max(y / b).max(z / c),
            Shape::Bicone { a, c } => {
                let rho = (x * x + y * y).sqrt();
                1.0 / (rho / a + z / c)
            }
            Shape::Octahedron { a, b, c } => 1.0 / (x / a + y / b + z / c),
        }
    }

    /// Exact volume.
    #[must_use]
    pub fn volume(&self) -> f64 {
        match *self {
            Shape::Sphere { r } => 4.0 / 3.0 * PI * r * r * r,
            Shape::Ellipsoid { a, b, c } => 4.0 / 3.0 * PI * a * b * c,
            Shape::Cylinder { a, c } => 2.0 * PI * a * a * c,
            Shape::Box { a, b, c } => 8.0 * a * b * c,
            Shape::Bicone { a, c } => 2.0 / 3.0 * PI * a * a * c,
            Shape::Octahedron { a, b, c } => 4.0 / 3.0 * a * b * c,
        }
    }

    /// Exact surface area (ellipsoid through Carlson's symmetric elliptic integrals).
    #[must_use]
    pub fn area(&self) -> f64 {
        match *self {
            Shape::Sphere { r } => 4.0 * PI * r * r,
            Shape::Ellipsoid { a, b, c } => ellipsoid_area(a, b, c),
            Shape::Cylinder { a, c } => 2.0 * PI * a * a + 4.0 * PI * a * c,
            Shape::Box { a, b, c } => 8.0 * (a * b + b * c + c * a),
            Shape::Bicone { a, c } => 2.0 * PI * a * (a * a + c * c).sqrt(),
            Shape::Octahedron { a, b, c } => {
                4.0 * (a * a * b * b + b * b * c * c + c * c * a * a).sqrt()
            }
        }
    }
}

/// Surface area of an ellipsoid, any semi-axes: `S = 2π c² + 2π a b / sin φ ·
/// (E(φ,k) sin²φ + F(φ,k) cos²φ)` with a ≥ b ≥ c, cos φ = c/a,
/// k² = a²(b²−c²)/(b²(a²−c²)), F and E via Carlson's R_F and R_D.
#[must_use]
pub fn ellipsoid_area(a: f64, b: f64, c: f64) -> f64 {
    let mut s = [a, b, c];
    s.sort_by(|x, y| y.total_cmp(x));
    let [a, b, c] = s;
    if (a - c).abs() <= 1e-15 * a {
        return 4.0 * PI * a * a;
    }
    let cos_phi = c / a;
    let sin_phi = (1.0 - cos_phi * cos_phi).sqrt();
    let k2 = (a * a * (b * b - c * c)) / (b * b * (a * a - c * c));
    let x = cos_phi * cos_phi;
    let y = 1.0 - k2 * sin_phi * sin_phi;
    let rf = carlson_rf(x, y, 1.0);
    let rd = carlson_rd(x, y, 1.0);
    let f = sin_phi * rf;
    let e = f - k2 * sin_phi.powi(3) * rd / 3.0;
    2.0 * PI * c * c + 2.0 * PI * a * b / sin_phi * (e * sin_phi * sin_phi + f * cos_phi * cos_phi)
}

/// Carlson's R_F(x, y, z) by duplication (Carlson 1995, doi:10.1007/BF02198293).
fn carlson_rf(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    for _ in 0..100 {
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * sy + sy * sz + sz * sx;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        let mu = (x + y + z) / 3.0;
        let dev = ((x - mu).abs()).max((y - mu).abs()).max((z - mu).abs()) / mu;
        if dev < 1e-4 {
            let (dx, dy, dz) = (1.0 - x / mu, 1.0 - y / mu, 1.0 - z / mu);
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0)
                / mu.sqrt();
        }
    }
    let mu = (x + y + z) / 3.0;
    1.0 / mu.sqrt()
}

/// Carlson's R_D(x, y, z) by duplication.
fn carlson_rd(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    let mut sum = 0.0;
    let mut fac = 1.0;
    for _ in 0..100 {
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * sy + sy * sz + sz * sx;
        sum += fac / (sz * (z + lam));
        fac *= 0.25;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        let mu = (x + y + 3.0 * z) / 5.0;
        let dev = ((x - mu).abs()).max((y - mu).abs()).max((z - mu).abs()) / mu;
        if dev < 1e-4 {
            let (dx, dy, dz) = (1.0 - x / mu, 1.0 - y / mu, 1.0 - z / mu);
            let ea = dx * dy;
            let eb = dz * dz;
            let ec = ea - eb;
            let ed = ea - 6.0 * eb;
            let ee = ed + ec + ec;
            let s = 1.0
                + ed * (-3.0 / 14.0 + 9.0 / 88.0 * ed - 4.5 / 26.0 * dz * ee)
                + dz * (ee / 6.0 + dz * (-9.0 / 22.0 * ec + dz * 3.0 / 26.0 * ea));
            return 3.0 * sum + fac * s / (mu * mu.sqrt());
        }
    }
    let mu = (x + y + 3.0 * z) / 5.0;
    3.0 * sum + fac / (mu * mu.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrals::{CellDomain, cell_integration};
    use approx::assert_relative_eq;

    #[test]
    fn oblate_spheroid_area_matches_closed_form() {
        // 2πa² + (πc²/e) ln((1+e)/(1−e)), e = √(1 − c²/a²).
        let (a, c) = (2.0_f64, 1.0_f64);
        let e = (1.0 - c * c / (a * a)).sqrt();
        let exact = 2.0 * PI * a * a + PI * c * c / e * ((1.0 + e) / (1.0 - e)).ln();
        assert_relative_eq!(ellipsoid_area(a, a, c), exact, max_relative = 1e-13);
        assert_relative_eq!(exact, 34.6875, epsilon = 1e-4);
    }

    #[test]
    fn prolate_and_triaxial_areas() {
        let (a, c) = (1.0_f64, 2.0_f64);
        let e = (1.0 - a * a / (c * c)).sqrt();
        let exact = 2.0 * PI * a * a * (1.0 + c / (a * e) * e.asin());
        assert_relative_eq!(ellipsoid_area(a, a, c), exact, max_relative = 1e-13);
        // Triaxial against the cell integration on a fine grid.
        let s = Shape::Ellipsoid {
            a: 3.0,
            b: 2.0,
            c: 1.0,
        };
        let (area, vol) =
            cell_integration(|t, p| s.radius(t, p), 400, 800, CellDomain::Sphere).expect("cells");
        assert_relative_eq!(area, s.area(), max_relative = 1e-4);
        assert_relative_eq!(vol, s.volume(), max_relative = 1e-4);
    }

    #[test]
    fn polyhedral_shapes_match_their_formulas() {
        for s in [
            Shape::Cylinder { a: 2.0, c: 1.0 },
            Shape::Bicone { a: 2.0, c: 1.0 },
            Shape::Octahedron {
                a: 2.0,
                b: 1.5,
                c: 1.0,
            },
            Shape::Box {
                a: 2.0,
                b: 1.5,
                c: 1.0,
            },
        ] {
            let (area, vol) = cell_integration(|t, p| s.radius(t, p), 400, 800, CellDomain::Sphere)
                .expect("cells");
            assert_relative_eq!(vol, s.volume(), max_relative = 3e-3);
            assert_relative_eq!(area, s.area(), max_relative = 3e-3);
        }
        assert_relative_eq!(
            Shape::Cylinder { a: 2.0, c: 1.0 }.volume(),
            25.133,
            epsilon = 1e-3
        );
        assert_relative_eq!(
            Shape::Cylinder { a: 2.0, c: 1.0 }.area(),
            50.265,
            epsilon = 1e-3
        );
    }

    #[test]
    fn validation() {
        assert!(Shape::Sphere { r: 0.0 }.validate().is_err());
        assert!(
            Shape::Ellipsoid {
                a: 1.0,
                b: f64::NAN,
                c: 1.0
            }
            .validate()
            .is_err()
        );
        assert!(Shape::Cylinder { a: 1.0, c: 1.0 }.validate().is_ok());
    }
}
