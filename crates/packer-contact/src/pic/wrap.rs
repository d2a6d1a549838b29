//! Wrappers of either dimension (spheres and planes) and their closed-form
//! intersections, the first guesses and exact contacts of the placement.

use nalgebra::{Point2, Point3, SVector, Unit};

use crate::contact2d::{self, Solutions, Wrapper2};
use crate::contact3d::{self, Wrapper3};

/// Centres `x` with `|x − c_i| = ρ_i` for three spheres (3D only; the
/// closed form of [`contact3d::intersect`] without its conversions): none
/// for collinear centres or no intersection, one when tangent.
pub(super) fn tangent3<const D: usize>(
    c0: &SVector<f64, D>,
    rho0: f64,
    c1: &SVector<f64, D>,
    rho1: f64,
    c2: &SVector<f64, D>,
    rho2: f64,
    out: &mut Vec<SVector<f64, D>>,
) {
    out.clear();
    let cross = |a: &SVector<f64, D>, b: &SVector<f64, D>| {
        SVector::<f64, D>::from_fn(|i, _| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            a[j] * b[k] - a[k] * b[j]
        })
    };
    let a1 = c1 - c0;
    let a2 = c2 - c0;
    let b1 = 0.5 * (rho0 * rho0 - rho1 * rho1 + a1.norm_squared());
    let b2 = 0.5 * (rho0 * rho0 - rho2 * rho2 + a2.norm_squared());
    let u = cross(&a1, &a2);
    let uu = u.norm_squared();
    if !uu.gt(&(1e-24 * a1.norm_squared() * a2.norm_squared())) || !uu.is_finite() {
        return;
    }
    let y0 = (cross(&a2, &u) * b1 + cross(&u, &a1) * b2) / uu;
    let y0n = y0.norm_squared();
    let disc = rho0 * rho0 - y0n;
    let eps = 64.0 * f64::EPSILON * (rho0 * rho0 + y0n);
    if !disc.is_finite() || disc < -eps {
        return;
    }
    if disc <= eps {
        out.push(c0 + y0);
        return;
    }
    let t = (disc / uu).sqrt();
    out.push(c0 + y0 + u * t);
    out.push(c0 + y0 - u * t);
}

/// A wrapper of either dimension: sphere `|x − c| = ρ` or plane `n·x = o`.
#[derive(Debug, Clone, Copy)]
pub(super) enum Wrap<const D: usize> {
    Sphere(SVector<f64, D>, f64),
    Plane(SVector<f64, D>, f64),
}

/// Intersection of `D` wrappers by the closed forms of `contact2d` /
/// `contact3d`.
pub(super) fn intersect<const D: usize>(w: &[Wrap<D>], out: &mut Vec<SVector<f64, D>>) {
    out.clear();
    let back = |s: &[f64]| SVector::<f64, D>::from_fn(|i, _| s[i]);
    if D == 2 {
        let c = |x: &Wrap<D>| match *x {
            Wrap::Sphere(c, r) => Wrapper2::Circle {
                centre: Point2::new(c[0], c[1]),
                radius: r,
            },
            Wrap::Plane(n, o) => Wrapper2::Line {
                normal: Unit::new_unchecked(nalgebra::Vector2::new(n[0], n[1])),
                offset: o,
            },
        };
        let s: Solutions<Point2<f64>> = contact2d::intersect(&c(&w[0]), &c(&w[1]));
        out.extend(s.iter().map(|p| back(p.coords.as_slice())));
    } else {
        let c = |x: &Wrap<D>| match *x {
            Wrap::Sphere(c, r) => Wrapper3::Sphere {
                centre: Point3::new(c[0], c[1], c[2]),
                radius: r,
            },
            Wrap::Plane(n, o) => Wrapper3::Plane {
                normal: Unit::new_unchecked(nalgebra::Vector3::new(n[0], n[1], n[2])),
                offset: o,
            },
        };
        let s = contact3d::intersect(&[c(&w[0]), c(&w[1]), c(&w[2])]);
        out.extend(s.iter().map(|p| back(p.coords.as_slice())));
    }
}
