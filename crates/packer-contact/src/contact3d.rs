//! Closed-form wrappers in 3D (Pérez Morales et al. 2016, §3.1): a sphere
//! tangent to three spheres, to spheres and wall planes, and a sphere
//! cluster touching three sphere clusters.
//!
//! Wrappers are spheres `|x − c| = r_fix + r` and planes `n·x = o + r`.
//! With `k ≥ 1` spheres, subtracting the first sphere's equation from the
//! others leaves two linear equations `a_i·y = b_i` (`y = x − c_0`), whose
//! solution line `y_0 + t (a_1 × a_2)` has `y_0 ⟂ a_1 × a_2`, so the
//! quadratic reduces to `t² = (ρ_0² − |y_0|²)/|a_1 × a_2|²`. Three planes
//! are a 3×3 linear solve. Collinear or coincident centres and parallel
//! planes make `a_1 × a_2` vanish: no solution, never NaN. Convex
//! polyhedra have no closed form here: their wrappers (faces, edges and
//! vertices of the Minkowski difference, seed §3.1) are replaced by the
//! gap minimisation of [`crate::gap`] on parry's exact distances.

use nalgebra::{Matrix3, Point3, Unit, Vector3};

use crate::contact2d::Solutions;

/// A wrapper surface in 3D.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wrapper3 {
    /// `|x − centre| = radius`.
    Sphere {
        /// Centre of the fixed sphere.
        centre: Point3<f64>,
        /// Wrapper radius, fixed radius plus mobile radius.
        radius: f64,
    },
    /// `normal · x = offset`.
    Plane {
        /// Unit normal, pointing to the side of the mobile.
        normal: Unit<Vector3<f64>>,
        /// Offset along the normal.
        offset: f64,
    },
}

const TANGENCY: f64 = 64.0 * f64::EPSILON;

/// Common points of three wrappers: 0, 1 or 2 centres of a mobile sphere
/// touching the three fixed objects.
#[must_use]
pub fn intersect(w: &[Wrapper3; 3]) -> Solutions<Point3<f64>> {
    let mut sph = [(Point3::origin(), 0.0); 3];
    let mut pl = [(Vector3::zeros(), 0.0); 3];
    let (mut ns, mut np) = (0, 0);
    for x in w {
        match *x {
            Wrapper3::Sphere { centre, radius } => {
                if !radius.gt(&0.0) || !radius.is_finite() {
                    return Solutions::none();
                }
                sph[ns] = (centre, radius);
                ns += 1;
            }
            Wrapper3::Plane { normal, offset } => {
                pl[np] = (normal.into_inner(), offset);
                np += 1;
            }
        }
    }
    let spheres = &sph[..ns];
    let planes = &pl[..np];
    if spheres.is_empty() {
        let m = Matrix3::from_rows(&[
            planes[0].0.transpose(),
            planes[1].0.transpose(),
            planes[2].0.transpose(),
        ]);
        if m.determinant().abs() <= 1e-12 {
            return Solutions::none();
        }
        return match m.try_inverse() {
            Some(inv) => {
                let x = inv * Vector3::new(planes[0].1, planes[1].1, planes[2].1);
                Solutions::one(Point3::from(x))
            }
            None => Solutions::none(),
        };
    }
    let (c0, rho0) = spheres[0];
    let scale = spheres.iter().map(|s| s.1).fold(0.0, f64::max);
    let mut lin = [(Vector3::zeros(), 0.0); 2];
    let mut nl = 0;
    for &(c, rho) in &spheres[1..] {
        let a = c - c0;
        let d2 = a.norm_squared();
        if d2 <= (1e-12 * scale).powi(2) {
            return Solutions::none();
        }
        lin[nl] = (a, 0.5 * (rho0 * rho0 - rho * rho + d2));
        nl += 1;
    }
    for &(n, o) in planes {
        lin[nl] = (n, o - n.dot(&c0.coords));
        nl += 1;
    }
    let (a1, b1) = lin[0];
    let (a2, b2) = lin[1];
    let u = a1.cross(&a2);
    let uu = u.norm_squared();
    if !uu.gt(&(1e-12 * a1.norm() * a2.norm()).powi(2)) || !uu.is_finite() {
        return Solutions::none();
    }
    let y0 = (a2.cross(&u) * b1 + u.cross(&a1) * b2) / uu;
    let y0n = y0.norm_squared();
    let disc = rho0 * rho0 - y0n;
    if !disc.is_finite() || disc < -TANGENCY * (rho0 * rho0 + y0n) {
        return Solutions::none();
    }
    if disc <= TANGENCY * (rho0 * rho0 + y0n) {
        return Solutions::one(c0 + y0);
    }
    let t = (disc / uu).sqrt();
    Solutions::two(c0 + y0 + u * t, c0 + y0 - u * t)
}

/// Centres of a sphere of radius `r` tangent to three spheres `(c_i, r_i)`
/// from outside. Collinear or coincident centres give none.
#[must_use]
pub fn sphere_three_spheres(fixed: &[(Point3<f64>, f64); 3], r: f64) -> Solutions<Point3<f64>> {
    if !r.gt(&0.0) || fixed.iter().any(|f| !f.1.gt(&0.0)) {
        return Solutions::none();
    }
    intersect(&fixed.map(|(c, rf)| Wrapper3::Sphere {
        centre: c,
        radius: rf + r,
    }))
}

/// Centres of a sphere of radius `r` tangent to the given spheres and wall
/// planes (`(point, unit normal towards the mobile)`), three objects in
/// all. Returns none for a wrong count.
#[must_use]
pub fn sphere_spheres_planes(
    spheres: &[(Point3<f64>, f64)],
    planes: &[(Point3<f64>, Unit<Vector3<f64>>)],
    r: f64,
) -> Solutions<Point3<f64>> {
    if spheres.len() + planes.len() != 3 || !r.gt(&0.0) || spheres.iter().any(|s| !s.1.gt(&0.0)) {
        return Solutions::none();
    }
    let mut w = [Wrapper3::Plane {
        normal: Vector3::z_axis(),
        offset: 0.0,
    }; 3];
    for (k, &(c, rf)) in spheres.iter().enumerate() {
        w[k] = Wrapper3::Sphere {
            centre: c,
            radius: rf + r,
        };
    }
    for (k, &(p, n)) in planes.iter().enumerate() {
        w[spheres.len() + k] = Wrapper3::Plane {
            normal: n,
            offset: n.dot(&p.coords) + r,
        };
    }
    intersect(&w)
}

/// Smallest signed gap between a fixed sphere cluster and a mobile cluster
/// (offsets and radii) placed at `x`.
#[must_use]
pub fn cluster_gap(
    fixed: &[(Point3<f64>, f64)],
    mobile: &[(Vector3<f64>, f64)],
    x: Point3<f64>,
) -> f64 {
    let mut g = f64::INFINITY;
    for &(c, r) in fixed {
        for &(m, s) in mobile {
            g = g.min((x + m - c).norm() - r - s);
        }
    }
    g
}

/// Positions of a mobile sphere cluster touching three fixed clusters
/// (the 3D analogue of [`crate::contact2d::cluster_two_clusters`], seed
/// §3.1 "clusters of spheres"): every combination of one sphere of each
/// fixed cluster with one sphere of the mobile one, filtered by
/// non-overlap with tolerance `tol`. Cost `O(n1·n2·n3·m³)`.
#[must_use]
pub fn cluster_three_clusters(
    fixed: [&[(Point3<f64>, f64)]; 3],
    mobile: &[(Vector3<f64>, f64)],
    tol: f64,
) -> Vec<Point3<f64>> {
    let mut out: Vec<Point3<f64>> = Vec::new();
    let scale = mobile.iter().map(|m| m.1).fold(0.0, f64::max);
    for &(c1, r1) in fixed[0] {
        for &(c2, r2) in fixed[1] {
            for &(c3, r3) in fixed[2] {
                for &(m1, s1) in mobile {
                    for &(m2, s2) in mobile {
                        for &(m3, s3) in mobile {
                            let w = [
                                Wrapper3::Sphere {
                                    centre: c1 - m1,
                                    radius: r1 + s1,
                                },
                                Wrapper3::Sphere {
                                    centre: c2 - m2,
                                    radius: r2 + s2,
                                },
                                Wrapper3::Sphere {
                                    centre: c3 - m3,
                                    radius: r3 + s3,
                                },
                            ];
                            for x in intersect(&w).iter() {
                                let ok = fixed.iter().all(|f| cluster_gap(f, mobile, x) >= -tol);
                                if ok && !out.iter().any(|q| (q - x).norm() <= 1e-9 * scale) {
                                    out.push(x);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests;
