//! Analytic shapes and their exact signed distances.
//!
//! Sphere, box and capped cylinder have closed-form signed distances. The ellipsoid
//! distance has no closed form; it is computed to machine precision by Eberly's robust
//! bisection on the Lagrange-multiplier equation (Eberly 2011, "Distance from a point to
//! an ellipse, an ellipsoid, or a hyperellipsoid", Geometric Tools, Eq. 26–30). The
//! superellipsoid has no usable distance formula at all; it is star-shaped with a closed
//! form radius `r(u) = F(u)^(−ε₁/2)` (Barr 1981, doi:10.1109/MCG.1981.1673799) and is built
//! through the star path followed by reinitialisation.

use nalgebra::{Isometry3, Point3, Unit, Vector3};

use crate::error::{Error, Result};
use crate::grid::{Grid, GridSpec};
use crate::star::StarParams;

/// A solid with an exact signed distance (negative inside), in its own frame.
pub trait Shape {
    /// Signed distance from `p` (shape frame) to the surface.
    fn signed_distance(&self, p: &Point3<f64>) -> f64;
}

fn check_positive(name: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name,
            value,
            requirement: "finite and positive",
        })
    }
}

/// Sphere of the given radius centred at the origin.
#[derive(Debug, Clone, Copy)]
pub struct Sphere {
    radius: f64,
}

impl Sphere {
    /// # Errors
    /// [`Error::InvalidParameter`] unless the radius is finite and positive.
    pub fn new(radius: f64) -> Result<Self> {
        check_positive("radius", radius)?;
        Ok(Self { radius })
    }
}

impl Shape for Sphere {
    fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        p.coords.norm() - self.radius
    }
}

/// Axis-aligned box with the given half extents, centred at the origin.
#[derive(Debug, Clone, Copy)]
pub struct Cuboid {
    half: Vector3<f64>,
}

impl Cuboid {
    /// # Errors
    /// [`Error::InvalidParameter`] unless all half extents are finite and positive.
    pub fn new(half_extents: Vector3<f64>) -> Result<Self> {
        for a in 0..3 {
            check_positive("half extent", half_extents[a])?;
        }
        Ok(Self { half: half_extents })
    }
}

impl Shape for Cuboid {
    fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        let q = p.coords.abs() - self.half;
        let outside = q.map(|v| v.max(0.0)).norm();
        outside + q.max().min(0.0)
    }
}

/// Capped cylinder with axis z, centred at the origin.
#[derive(Debug, Clone, Copy)]
pub struct Cylinder {
    radius: f64,
    half_height: f64,
}

impl Cylinder {
    /// # Errors
    /// [`Error::InvalidParameter`] unless radius and half height are finite and positive.
    pub fn new(radius: f64, half_height: f64) -> Result<Self> {
        check_positive("radius", radius)?;
        check_positive("half height", half_height)?;
        Ok(Self {
            radius,
            half_height,
        })
    }
}

impl Shape for Cylinder {
    fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        let dr = p.x.hypot(p.y) - self.radius;
        let dz = p.z.abs() - self.half_height;
        dr.max(dz).min(0.0) + dr.max(0.0).hypot(dz.max(0.0))
    }
}

/// Ellipsoid with semi-axes along x, y, z, centred at the origin.
#[derive(Debug, Clone, Copy)]
pub struct Ellipsoid {
    semi_axes: Vector3<f64>,
}

impl Ellipsoid {
    /// # Errors
    /// [`Error::InvalidParameter`] unless all semi-axes are finite and positive.
    pub fn new(semi_axes: Vector3<f64>) -> Result<Self> {
        for a in 0..3 {
            check_positive("semi-axis", semi_axes[a])?;
        }
        Ok(Self { semi_axes })
    }

    /// Semi-axes.
    pub fn semi_axes(&self) -> Vector3<f64> {
        self.semi_axes
    }

    /// Radius along a unit direction (the ellipsoid is star-shaped about its centre).
    pub fn radius(&self, u: &Unit<Vector3<f64>>) -> f64 {
        let e = self.semi_axes;
        1.0 / ((u.x / e.x).powi(2) + (u.y / e.y).powi(2) + (u.z / e.z).powi(2)).sqrt()
    }
}

impl Shape for Ellipsoid {
    fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        // Sort axes descending, fold the point into the first octant.
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| self.semi_axes[b].total_cmp(&self.semi_axes[a]));
        let e = [
            self.semi_axes[order[0]],
            self.semi_axes[order[1]],
            self.semi_axes[order[2]],
        ];
        let y = [p[order[0]].abs(), p[order[1]].abs(), p[order[2]].abs()];
        let d = distance_point_ellipsoid(e, y);
        let g = (y[0] / e[0]).powi(2) + (y[1] / e[1]).powi(2) + (y[2] / e[2]).powi(2);
        if g < 1.0 { -d } else { d }
    }
}

fn robust_length(v: &[f64]) -> f64 {
    let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 {
        return 0.0;
    }
    m * v.iter().map(|x| (x / m).powi(2)).sum::<f64>().sqrt()
}

/// Eberly 2011, Listing 2 (`GetRoot`, 2D).
fn root2(r0: f64, z0: f64, z1: f64, g: f64) -> f64 {
    let n0 = r0 * z0;
    let mut s0 = z1 - 1.0;
    let mut s1 = if g < 0.0 {
        0.0
    } else {
        robust_length(&[n0, z1]) - 1.0
    };
    let mut s = 0.0;
    for _ in 0..200 {
        s = 0.5 * (s0 + s1);
        if s == s0 || s == s1 {
            break;
        }
        let g = (n0 / (s + r0)).powi(2) + (z1 / (s + 1.0)).powi(2) - 1.0;
        if g > 0.0 {
            s0 = s;
        } else if g < 0.0 {
            s1 = s;
        } else {
            break;
        }
    }
    s
}

/// Eberly 2011, Listing 4 (`GetRoot`, 3D).
fn root3(r0: f64, r1: f64, z: [f64; 3], g: f64) -> f64 {
    let n0 = r0 * z[0];
    let n1 = r1 * z[1];
    let mut s0 = z[2] - 1.0;
    let mut s1 = if g < 0.0 {
        0.0
    } else {
        robust_length(&[n0, n1, z[2]]) - 1.0
    };
    let mut s = 0.0;
    for _ in 0..200 {
        s = 0.5 * (s0 + s1);
        if s == s0 || s == s1 {
            break;
        }
        let g =
            (n0 / (s + r0)).powi(2) + (n1 / (s + r1)).powi(2) + (z[2] / (s + 1.0)).powi(2) - 1.0;
        if g > 0.0 {
            s0 = s;
        } else if g < 0.0 {
            s1 = s;
        } else {
            break;
        }
    }
    s
}

/// Unsigned distance from `y` (first quadrant) to the ellipse with `e0 ≥ e1` (Eberly Listing 3).
fn distance_point_ellipse(e0: f64, e1: f64, y0: f64, y1: f64) -> f64 {
    if y1 > 0.0 {
        if y0 > 0.0 {
            let z0 = y0 / e0;
            let z1 = y1 / e1;
            let g = z0 * z0 + z1 * z1 - 1.0;
            if g != 0.0 {
                let r0 = (e0 / e1).powi(2);
                let s = root2(r0, z0, z1, g);
                let x0 = r0 * y0 / (s + r0);
                let x1 = y1 / (s + 1.0);
                (x0 - y0).hypot(x1 - y1)
            } else {
                0.0
            }
        } else {
            (y1 - e1).abs()
        }
    } else {
        let numer0 = e0 * y0;
        let denom0 = e0 * e0 - e1 * e1;
        if numer0 < denom0 {
            let xde0 = numer0 / denom0;
            let x0 = e0 * xde0;
            let x1 = e1 * (1.0 - xde0 * xde0).max(0.0).sqrt();
            (x0 - y0).hypot(x1)
        } else {
            (y0 - e0).abs()
        }
    }
}

/// Unsigned distance from `y` (first octant) to the ellipsoid with `e0 ≥ e1 ≥ e2`
/// (Eberly Listing 5).
fn distance_point_ellipsoid(e: [f64; 3], y: [f64; 3]) -> f64 {
    if y[2] > 0.0 {
        if y[1] > 0.0 {
            if y[0] > 0.0 {
                let z = [y[0] / e[0], y[1] / e[1], y[2] / e[2]];
                let g = z[0] * z[0] + z[1] * z[1] + z[2] * z[2] - 1.0;
                if g != 0.0 {
                    let r0 = (e[0] / e[2]).powi(2);
                    let r1 = (e[1] / e[2]).powi(2);
                    let s = root3(r0, r1, z, g);
                    let x = [r0 * y[0] / (s + r0), r1 * y[1] / (s + r1), y[2] / (s + 1.0)];
                    robust_length(&[x[0] - y[0], x[1] - y[1], x[2] - y[2]])
                } else {
                    0.0
                }
            } else {
                distance_point_ellipse(e[1], e[2], y[1], y[2])
            }
        } else if y[0] > 0.0 {
            distance_point_ellipse(e[0], e[2], y[0], y[2])
        } else {
            (y[2] - e[2]).abs()
        }
    } else {
        let denom = [e[0] * e[0] - e[2] * e[2], e[1] * e[1] - e[2] * e[2]];
        let numer = [e[0] * y[0], e[1] * y[1]];
        if numer[0] < denom[0] && numer[1] < denom[1] {
            let xde = [numer[0] / denom[0], numer[1] / denom[1]];
            let discr = 1.0 - xde[0] * xde[0] - xde[1] * xde[1];
            if discr > 0.0 {
                let x = [e[0] * xde[0], e[1] * xde[1], e[2] * discr.sqrt()];
                return robust_length(&[x[0] - y[0], x[1] - y[1], x[2]]);
            }
        }
        distance_point_ellipse(e[0], e[1], y[0], y[1])
    }
}

/// Superellipsoid `(|x/a|^(2/ε₂) + |y/b|^(2/ε₂))^(ε₂/ε₁) + |z/c|^(2/ε₁) = 1` (Barr 1981).
#[derive(Debug, Clone, Copy)]
pub struct Superellipsoid {
    semi_axes: Vector3<f64>,
    e1: f64,
    e2: f64,
}

impl Superellipsoid {
    /// Semi-axes (a, b, c) and the two shape exponents ε₁ (north–south), ε₂ (east–west),
    /// each in (0, 4]; ε = 1 is the ellipsoid, ε → 0 the box.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for non-positive axes or exponents outside (0, 4].
    pub fn new(semi_axes: Vector3<f64>, e1: f64, e2: f64) -> Result<Self> {
        for a in 0..3 {
            check_positive("semi-axis", semi_axes[a])?;
        }
        for (name, e) in [("epsilon1", e1), ("epsilon2", e2)] {
            if !(e.is_finite() && e > 0.0 && e <= 4.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: e,
                    requirement: "in (0, 4]",
                });
            }
        }
        Ok(Self { semi_axes, e1, e2 })
    }

    /// Inside–outside function F (F < 1 inside), homogeneous of degree 2/ε₁.
    pub fn inside_outside(&self, p: &Point3<f64>) -> f64 {
        let a = self.semi_axes;
        let xy = (p.x / a.x).abs().powf(2.0 / self.e2) + (p.y / a.y).abs().powf(2.0 / self.e2);
        xy.powf(self.e2 / self.e1) + (p.z / a.z).abs().powf(2.0 / self.e1)
    }

    /// Radius along a unit direction: `F(u)^(−ε₁/2)`.
    pub fn radius(&self, u: &Unit<Vector3<f64>>) -> f64 {
        self.inside_outside(&Point3::from(u.into_inner()))
            .powf(-0.5 * self.e1)
    }
}

impl Grid {
    /// Samples an exact signed distance `shape` placed by `pose` (shape frame → grid frame).
    ///
    /// # Errors
    /// Invalid spec or a non-finite distance.
    pub fn from_shape(spec: GridSpec, shape: &impl Shape, pose: &Isometry3<f64>) -> Result<Self> {
        let inv = pose.inverse();
        Self::from_fn(spec, |p| shape.signed_distance(&(inv * p)))
    }

    /// Superellipsoid placed by `pose`: star build with the closed-form radius, then
    /// reinitialisation.
    ///
    /// # Errors
    /// As [`Grid::from_star`].
    pub fn from_superellipsoid(
        spec: GridSpec,
        shape: &Superellipsoid,
        pose: &Isometry3<f64>,
        params: &StarParams,
    ) -> Result<Self> {
        let rot = pose.rotation;
        let centre = Point3::from(pose.translation.vector);
        Self::from_star(
            spec,
            &centre,
            |u| shape.radius(&(rot.inverse() * u)),
            params,
        )
        .map(|(g, _)| g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn closed_forms_on_known_points() {
        let b = Cuboid::new(Vector3::new(1.0, 0.5, 0.25)).expect("box");
        assert_abs_diff_eq!(
            b.signed_distance(&Point3::new(2.0, 0.0, 0.0)),
            1.0,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(b.signed_distance(&Point3::origin()), -0.25, epsilon = 1e-15);
        assert_abs_diff_eq!(
            b.signed_distance(&Point3::new(2.0, 1.5, 0.0)),
            2.0f64.sqrt(),
            epsilon = 1e-15
        );
        let c = Cylinder::new(1.0, 2.0).expect("cyl");
        assert_abs_diff_eq!(
            c.signed_distance(&Point3::new(0.0, 0.0, 3.0)),
            1.0,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            c.signed_distance(&Point3::new(0.5, 0.0, 0.0)),
            -0.5,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            c.signed_distance(&Point3::new(4.0, 0.0, 6.0)),
            5.0,
            epsilon = 1e-15
        );
    }

    #[test]
    fn ellipsoid_distance_matches_sphere_and_brute_force() {
        let s = Ellipsoid::new(Vector3::new(1.0, 1.0, 1.0)).expect("e");
        let p = Point3::new(0.3, -0.4, 1.2);
        assert_abs_diff_eq!(
            s.signed_distance(&p),
            p.coords.norm() - 1.0,
            epsilon = 1e-12
        );
        let e = Ellipsoid::new(Vector3::new(1.5, 2.0, 1.0)).expect("e");
        // Brute force: minimise over a fine parametrisation of the surface.
        for p in [
            Point3::new(0.3, -0.4, 1.2),
            Point3::new(0.1, 0.2, 0.05),
            Point3::new(-3.0, 0.0, 0.0),
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
        ] {
            let mut best = f64::INFINITY;
            let n = 1200;
            for it in 0..=n {
                let th = std::f64::consts::PI * it as f64 / n as f64;
                for ip in 0..(2 * n) {
                    let ph = std::f64::consts::PI * ip as f64 / n as f64;
                    let q = Point3::new(
                        1.5 * th.sin() * ph.cos(),
                        2.0 * th.sin() * ph.sin(),
                        th.cos(),
                    );
                    best = best.min((q - p).norm());
                }
            }
            let d = e.signed_distance(&p);
            assert_abs_diff_eq!(d.abs(), best, epsilon = 1e-5);
        }
        assert!(e.signed_distance(&Point3::origin()) < 0.0);
        assert_abs_diff_eq!(e.signed_distance(&Point3::origin()), -1.0, epsilon = 1e-12);
    }

    #[test]
    fn superellipsoid_radius_is_on_surface() {
        let s = Superellipsoid::new(Vector3::new(1.0, 0.7, 0.5), 0.5, 1.5).expect("s");
        let u = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
        let r = s.radius(&u);
        let p = Point3::from(u.into_inner() * r);
        assert_abs_diff_eq!(s.inside_outside(&p), 1.0, epsilon = 1e-12);
        assert!(Superellipsoid::new(Vector3::new(1.0, 1.0, 1.0), 0.0, 1.0).is_err());
        assert!(Ellipsoid::new(Vector3::new(1.0, f64::NAN, 1.0)).is_err());
        assert!(Sphere::new(-1.0).is_err());
    }
}
