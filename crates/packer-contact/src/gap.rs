//! Gap functions and their minimisation (Pérez Morales et al. 2016, §3.2).
//!
//! The gap `g(p_fix, p_mob[x])` of a mobile grain translated to `x` is its
//! signed distance to a fixed grain or wall: `> 0` apart, `0` in outer
//! contact, `< 0` overlapping (seed Eq. 3). For disks and spheres it is
//! `|c_1 − c_2| − r_1 − r_2` (Eq. 5); for spherocylinders the segment
//! distance minus the radii (Eq. 6, segment distance after Eberly); for
//! clusters the smallest gap over element pairs; for convex polygons and
//! polyhedra parry's signed contact distance (GJK/EPA). The gradient with
//! respect to `x` is the unit vector between the closest points.
//!
//! Two solvers place the mobile in contact with `D` obstacles:
//! * [`newton`] (the fast one): Newton's method on `g_i(x) = 0`, with the
//!   exact gradients as Jacobian rows, from a closed-form first guess;
//!   quadratic convergence, contacts to `1e-13·R`;
//! * [`nelder_mead`] (the seed's): derivative-free Nelder–Mead (1965) on
//!   `Σ g_i²` with the seed's half-space restriction as a penalty. Our own
//!   ~60 lines instead of `argmin`: argmin's Nelder–Mead needs
//!   `argmin-math` with a vector backend and would add a dozen crates to a
//!   2-core build for one 2–3-parameter simplex.
//!
//! The segment–segment distance of the hot loop is written by hand
//! (Ericson 2005, §5.1.9) in nalgebra for any dimension: parry's version
//! works on glam vectors of one dimension per crate, and the packer's inner
//! loop is generic over `D`. The independent checker ([`crate::check_pic`]) uses
//! parry's own distances, so the two never share arithmetic.

use nalgebra::{SMatrix, SVector};

use crate::shapes::{Geometry, Grain, ParryConvex, Swept};

/// A fixed object the mobile grain must touch.
#[derive(Debug, Clone, Copy)]
pub enum Obstacle<'a, const D: usize> {
    /// A placed grain at `centre`.
    Grain {
        /// Position of the grain's reference point.
        centre: SVector<f64, D>,
        /// The grain.
        grain: &'a Grain<D>,
    },
    /// The wall `x[axis] = at`; `upper` says the free side is below.
    Wall {
        /// Axis normal to the wall.
        axis: usize,
        /// Position of the wall.
        at: f64,
        /// Whether the wall bounds from above.
        upper: bool,
    },
}

/// Closest points of segments `[p1, q1]` and `[p2, q2]` (Ericson 2005,
/// §5.1.9), robust for degenerate (point) and parallel segments.
#[must_use]
pub fn closest_segment_points<const D: usize>(
    p1: &SVector<f64, D>,
    q1: &SVector<f64, D>,
    p2: &SVector<f64, D>,
    q2: &SVector<f64, D>,
) -> (SVector<f64, D>, SVector<f64, D>) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let tiny = 1e-300;
    let (s, t);
    if a <= tiny && e <= tiny {
        return (*p1, *p2);
    }
    if a <= tiny {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 1e-14 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    (p1 + d1 * s, p2 + d2 * t)
}

fn swept_gap<const D: usize>(
    cf: &SVector<f64, D>,
    f: &Swept<D>,
    x: &SVector<f64, D>,
    m: &Swept<D>,
) -> (f64, SVector<f64, D>) {
    let (p, q) = if f.a == f.b && m.a == m.b {
        (cf + f.a, x + m.a)
    } else {
        closest_segment_points(&(cf + f.a), &(cf + f.b), &(x + m.a), &(x + m.b))
    };
    let d = q - p;
    let n = d.norm();
    let grad = if n > 0.0 {
        d / n
    } else {
        let v = x - cf;
        if v.norm() > 0.0 {
            v.normalize()
        } else {
            SVector::from_fn(|i, _| if i + 1 == D { 1.0 } else { 0.0 })
        }
    };
    (n - f.radius - m.radius, grad)
}

fn to_p2(v: &[f64]) -> parry2d_f64::math::Vector {
    parry2d_f64::math::Vector::new(v[0], v[1])
}

fn to_p3(v: &[f64]) -> parry3d_f64::math::Vector {
    parry3d_f64::math::Vector::new(v[0], v[1], v[2])
}

/// A parry shape of one element of a swept grain (ball or capsule).
fn swept_contact<const D: usize>(
    convex: &ParryConvex,
    at_convex: &SVector<f64, D>,
    e: &Swept<D>,
    at_e: &SVector<f64, D>,
    convex_first: bool,
) -> Option<(f64, SVector<f64, D>)> {
    // Returns the signed distance and the outward normal of the first shape
    // (fixed) pointing to the second (mobile).
    let pred = 1e6;
    match convex {
        ParryConvex::Polygon(poly) => {
            let p1 = parry2d_f64::math::Pose::translation(at_convex[0], at_convex[1]);
            let p2 = parry2d_f64::math::Pose::translation(at_e[0], at_e[1]);
            let cap = parry2d_f64::shape::Capsule::new(
                to_p2(e.a.as_slice()),
                to_p2(e.b.as_slice()),
                e.radius,
            );
            let ball = parry2d_f64::shape::Ball::new(e.radius);
            let s2: &dyn parry2d_f64::shape::Shape = if e.a == e.b { &ball } else { &cap };
            let pe = if e.a == e.b {
                parry2d_f64::math::Pose::translation(at_e[0] + e.a[0], at_e[1] + e.a[1])
            } else {
                p2
            };
            let c = if convex_first {
                parry2d_f64::query::contact(&p1, poly.as_ref(), &pe, s2, pred)
            } else {
                parry2d_f64::query::contact(&pe, s2, &p1, poly.as_ref(), pred)
            }
            .ok()??;
            Some((c.dist, SVector::from_fn(|i, _| c.normal1[i])))
        }
        ParryConvex::Polyhedron(poly) => {
            let p1 = parry3d_f64::math::Pose::translation(at_convex[0], at_convex[1], at_convex[2]);
            let cap = parry3d_f64::shape::Capsule::new(
                to_p3(e.a.as_slice()),
                to_p3(e.b.as_slice()),
                e.radius,
            );
            let ball = parry3d_f64::shape::Ball::new(e.radius);
            let s2: &dyn parry3d_f64::shape::Shape = if e.a == e.b { &ball } else { &cap };
            let pe = if e.a == e.b {
                parry3d_f64::math::Pose::translation(
                    at_e[0] + e.a[0],
                    at_e[1] + e.a[1],
                    at_e[2] + e.a[2],
                )
            } else {
                parry3d_f64::math::Pose::translation(at_e[0], at_e[1], at_e[2])
            };
            let c = if convex_first {
                parry3d_f64::query::contact(&p1, poly.as_ref(), &pe, s2, pred)
            } else {
                parry3d_f64::query::contact(&pe, s2, &p1, poly.as_ref(), pred)
            }
            .ok()??;
            Some((c.dist, SVector::from_fn(|i, _| c.normal1[i])))
        }
    }
}

fn convex_convex<const D: usize>(
    a: &ParryConvex,
    at_a: &SVector<f64, D>,
    b: &ParryConvex,
    at_b: &SVector<f64, D>,
) -> Option<(f64, SVector<f64, D>)> {
    let pred = 1e6;
    match (a, b) {
        (ParryConvex::Polygon(pa), ParryConvex::Polygon(pb)) => {
            let p1 = parry2d_f64::math::Pose::translation(at_a[0], at_a[1]);
            let p2 = parry2d_f64::math::Pose::translation(at_b[0], at_b[1]);
            let c =
                parry2d_f64::query::contact(&p1, pa.as_ref(), &p2, pb.as_ref(), pred).ok()??;
            Some((c.dist, SVector::from_fn(|i, _| c.normal1[i])))
        }
        (ParryConvex::Polyhedron(pa), ParryConvex::Polyhedron(pb)) => {
            let p1 = parry3d_f64::math::Pose::translation(at_a[0], at_a[1], at_a[2]);
            let p2 = parry3d_f64::math::Pose::translation(at_b[0], at_b[1], at_b[2]);
            let c =
                parry3d_f64::query::contact(&p1, pa.as_ref(), &p2, pb.as_ref(), pred).ok()??;
            Some((c.dist, SVector::from_fn(|i, _| c.normal1[i])))
        }
        _ => None,
    }
}

/// Signed gap of the mobile grain at `x` to an obstacle, and its gradient
/// with respect to `x`. `None` only if parry refuses a shape pair.
#[must_use]
pub fn gap<const D: usize>(
    obstacle: &Obstacle<'_, D>,
    mobile: &Grain<D>,
    x: &SVector<f64, D>,
) -> Option<(f64, SVector<f64, D>)> {
    match *obstacle {
        Obstacle::Wall { axis, at, upper } => {
            let mut grad = SVector::<f64, D>::zeros();
            if upper {
                grad[axis] = -1.0;
                Some((at - x[axis] - mobile.hi[axis], grad))
            } else {
                grad[axis] = 1.0;
                Some((x[axis] + mobile.lo[axis] - at, grad))
            }
        }
        Obstacle::Grain { centre, grain } => match (&grain.geometry, &mobile.geometry) {
            (Geometry::Swept(fe), Geometry::Swept(me)) => {
                let mut best = (f64::INFINITY, SVector::zeros());
                for f in fe {
                    for m in me {
                        let g = swept_gap(&centre, f, x, m);
                        if g.0 < best.0 {
                            best = g;
                        }
                    }
                }
                Some(best)
            }
            (Geometry::Convex { shape, .. }, Geometry::Swept(me)) => {
                let mut best: Option<(f64, SVector<f64, D>)> = None;
                for m in me {
                    let g = swept_contact(shape, &centre, m, x, true)?;
                    if best.is_none_or(|b| g.0 < b.0) {
                        best = Some(g);
                    }
                }
                best
            }
            (Geometry::Swept(fe), Geometry::Convex { shape, .. }) => {
                let mut best: Option<(f64, SVector<f64, D>)> = None;
                for f in fe {
                    let (d, n) = swept_contact(shape, x, f, &centre, false)?;
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, n));
                    }
                }
                best
            }
            (Geometry::Convex { shape: a, .. }, Geometry::Convex { shape: b, .. }) => {
                convex_convex(a, &centre, b, x)
            }
        },
    }
}

/// Newton's method on `g_i(x) = 0`, `i = 1..D`, from `start`. Returns the
/// contact position when every `|g_i| ≤ tol` within 40 iterations and the
/// Jacobian stays regular; `None` otherwise (no contact from this start).
#[must_use]
pub fn newton<const D: usize>(
    obstacles: &[Obstacle<'_, D>],
    mobile: &Grain<D>,
    start: SVector<f64, D>,
    tol: f64,
) -> Option<SVector<f64, D>> {
    if obstacles.len() != D {
        return None;
    }
    let mut x = start;
    let max_step = mobile.circumradius;
    for _ in 0..40 {
        let mut jac = SMatrix::<f64, D, D>::zeros();
        let mut g = SVector::<f64, D>::zeros();
        for (i, o) in obstacles.iter().enumerate() {
            let (gi, grad) = gap(o, mobile, &x)?;
            g[i] = gi;
            jac.set_row(i, &grad.transpose());
        }
        if g.amax() <= tol {
            return Some(x);
        }
        let step = solve_small(jac, -g)?;
        if !step.iter().all(|v| v.is_finite()) {
            return None;
        }
        let n = step.norm();
        x += if n > max_step {
            step * (max_step / n)
        } else {
            step
        };
    }
    None
}

/// Gaussian elimination with partial pivoting for the `D × D` Jacobian;
/// `None` when a pivot is below `1e-12` of the largest entry (parallel
/// gradients: no isolated contact).
fn solve_small<const D: usize>(
    mut a: SMatrix<f64, D, D>,
    mut b: SVector<f64, D>,
) -> Option<SVector<f64, D>> {
    let scale = a.amax();
    if !scale.gt(&0.0) || !scale.is_finite() {
        return None;
    }
    for k in 0..D {
        let mut piv = k;
        for i in k + 1..D {
            if a[(i, k)].abs() > a[(piv, k)].abs() {
                piv = i;
            }
        }
        if a[(piv, k)].abs() <= 1e-12 * scale {
            return None;
        }
        if piv != k {
            a.swap_rows(k, piv);
            b.swap_rows(k, piv);
        }
        for i in k + 1..D {
            let f = a[(i, k)] / a[(k, k)];
            for j in k..D {
                a[(i, j)] -= f * a[(k, j)];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = SVector::<f64, D>::zeros();
    for k in (0..D).rev() {
        let mut s = b[k];
        for j in k + 1..D {
            s -= a[(k, j)] * x[j];
        }
        x[k] = s / a[(k, k)];
    }
    Some(x)
}

/// Nelder–Mead (Nelder & Mead 1965) on `Σ g_i(x)²`, as the seed does
/// (§3.2), from a simplex of size `0.1·R` around `start`. `side` is the
/// seed's half-space restriction `(normal, point)`: positions with
/// `normal·(x − point) < 0` are penalised. Returns `x` when every
/// `|g_i| ≤ tol`, else `None`.
#[must_use]
pub fn nelder_mead<const D: usize>(
    obstacles: &[Obstacle<'_, D>],
    mobile: &Grain<D>,
    start: SVector<f64, D>,
    side: Option<(SVector<f64, D>, SVector<f64, D>)>,
    tol: f64,
) -> Option<SVector<f64, D>> {
    let f = |x: &SVector<f64, D>| -> f64 {
        let mut s = 0.0;
        for o in obstacles {
            match gap(o, mobile, x) {
                Some((g, _)) => s += g * g,
                None => return f64::INFINITY,
            }
        }
        if let Some((n, p)) = side {
            let h = n.dot(&(x - p));
            if h < 0.0 {
                s += h * h + mobile.circumradius.powi(2);
            }
        }
        s
    };
    let h = 0.1 * mobile.circumradius;
    let mut simplex: Vec<(SVector<f64, D>, f64)> = (0..=D)
        .map(|k| {
            let mut v = start;
            if k > 0 {
                v[k - 1] += h;
            }
            (v, f(&v))
        })
        .collect();
    let target = (tol * 0.25).powi(2);
    for _ in 0..4000 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if simplex[0].1 <= target {
            break;
        }
        let size = simplex[1..]
            .iter()
            .map(|v| (v.0 - simplex[0].0).amax())
            .fold(0.0, f64::max);
        if size <= 1e-15 * mobile.circumradius {
            break;
        }
        let centroid = simplex[..D]
            .iter()
            .fold(SVector::<f64, D>::zeros(), |acc, v| acc + v.0)
            / D as f64;
        let worst = simplex[D];
        let xr = centroid + (centroid - worst.0);
        let fr = f(&xr);
        if fr < simplex[0].1 {
            let xe = centroid + (centroid - worst.0) * 2.0;
            let fe = f(&xe);
            simplex[D] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[D - 1].1 {
            simplex[D] = (xr, fr);
        } else {
            let xc = if fr < worst.1 {
                centroid + (xr - centroid) * 0.5
            } else {
                centroid + (worst.0 - centroid) * 0.5
            };
            let fc = f(&xc);
            if fc < worst.1.min(fr) {
                simplex[D] = (xc, fc);
            } else {
                let best = simplex[0].0;
                for v in simplex.iter_mut().skip(1) {
                    v.0 = best + (v.0 - best) * 0.5;
                    v.1 = f(&v.0);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let x = simplex[0].0;
    let ok = obstacles
        .iter()
        .all(|o| gap(o, mobile, &x).is_some_and(|(g, _)| g.abs() <= tol));
    ok.then_some(x)
}

#[cfg(test)]
mod tests;
