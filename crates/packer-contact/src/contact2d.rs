//! Closed-form wrappers in 2D (Pérez Morales et al. 2016, §3.1): a circle
//! tangent to two circles, to a circle and a wall (line or segment), to two
//! circle clusters, and to a circle and a convex polygon.
//!
//! The wrapper of a fixed circle `(c, r_fix)` for a mobile circle of radius
//! `r` is the circle `(c, r_fix + r)`; of a wall line `n·x = o` it is the
//! line `n·x = o + r`; of a convex polygon it is the polygon offset by `r`
//! (edges shifted along their outward normals, vertices rounded by arcs).
//! The mobile centre is an intersection of two wrappers. Everything is
//! written by hand because parry has no "intersect two offset curves"
//! query; parry is used only to confirm the polygon distance of a candidate.
//!
//! Robustness: coincident centres, parallel walls and nested wrappers give
//! no solution (never NaN); a discriminant within a few ulps of zero is a
//! tangency and gives exactly one solution.

use nalgebra::{Point2, Unit, Vector2};

use crate::error::{Error, Result};

/// Up to two solutions of a particle-in-contact problem, without allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solutions<P: Copy> {
    points: [Option<P>; 2],
}

impl<P: Copy> Solutions<P> {
    /// No solution.
    #[must_use]
    pub fn none() -> Self {
        Self {
            points: [None, None],
        }
    }

    /// One solution (a tangency or a unique corner).
    #[must_use]
    pub fn one(p: P) -> Self {
        Self {
            points: [Some(p), None],
        }
    }

    /// Two solutions.
    #[must_use]
    pub fn two(p: P, q: P) -> Self {
        Self {
            points: [Some(p), Some(q)],
        }
    }

    /// Number of solutions (0, 1 or 2).
    #[must_use]
    pub fn len(&self) -> usize {
        self.points.iter().flatten().count()
    }

    /// Whether there is no solution.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.points[0].is_none()
    }

    /// The solutions.
    pub fn iter(&self) -> impl Iterator<Item = P> + '_ {
        self.points.iter().flatten().copied()
    }
}

/// A wrapper curve in 2D: where the mobile centre may lie to touch one
/// fixed object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wrapper2 {
    /// `|x − centre| = radius` (a fixed circle of radius `radius − r_mob`).
    Circle {
        /// Centre of the fixed circle.
        centre: Point2<f64>,
        /// Wrapper radius, fixed radius plus mobile radius.
        radius: f64,
    },
    /// `normal · x = offset` (a wall line shifted by the mobile radius).
    Line {
        /// Unit normal, pointing to the side where the mobile lies.
        normal: Unit<Vector2<f64>>,
        /// Offset along the normal.
        offset: f64,
    },
}

/// Relative width of the band around a zero discriminant that counts as a
/// tangency (a few ulps of the squared lengths involved).
const TANGENCY: f64 = 64.0 * f64::EPSILON;

/// Intersections of two wrappers: the centres of a mobile circle touching
/// both fixed objects. 0, 1 (tangency, or two crossing lines) or 2 points.
#[must_use]
pub fn intersect(a: &Wrapper2, b: &Wrapper2) -> Solutions<Point2<f64>> {
    use Wrapper2::{Circle, Line};
    match (*a, *b) {
        (
            Line {
                normal: n1,
                offset: o1,
            },
            Line {
                normal: n2,
                offset: o2,
            },
        ) => {
            let det = n1.x * n2.y - n1.y * n2.x;
            if det.abs() <= 1e-12 {
                return Solutions::none();
            }
            let x = (o1 * n2.y - o2 * n1.y) / det;
            let y = (n1.x * o2 - n2.x * o1) / det;
            Solutions::one(Point2::new(x, y))
        }
        (Circle { centre, radius }, Line { normal, offset })
        | (Line { normal, offset }, Circle { centre, radius }) => {
            if !radius.gt(&0.0) {
                return Solutions::none();
            }
            // Linear equation relative to the centre: n·y = offset − n·c.
            let b = offset - normal.dot(&centre.coords);
            solve_line_circle(centre, radius, normal.into_inner(), b)
        }
        (
            Circle {
                centre: c1,
                radius: r1,
            },
            Circle {
                centre: c2,
                radius: r2,
            },
        ) => {
            if !(r1.gt(&0.0) && r2.gt(&0.0)) {
                return Solutions::none();
            }
            let a = c2 - c1;
            let d2 = a.norm_squared();
            // Coincident (or numerically coincident) centres: a whole circle
            // of solutions or none; either way no isolated contact point.
            if d2 <= (1e-12 * (r1 + r2)).powi(2) {
                return Solutions::none();
            }
            // 2 a·y = r1² − r2² + |a|² with y = x − c1.
            let b = 0.5 * (r1 * r1 - r2 * r2 + d2);
            solve_line_circle(c1, r1, a, b)
        }
    }
}

/// Points `c + y` with `a·y = b` and `|y| = rho` (`a ≠ 0`).
fn solve_line_circle(c: Point2<f64>, rho: f64, a: Vector2<f64>, b: f64) -> Solutions<Point2<f64>> {
    let aa = a.norm_squared();
    if !aa.gt(&0.0) || !aa.is_finite() || !b.is_finite() {
        return Solutions::none();
    }
    let y0 = a * (b / aa);
    let u = Vector2::new(-a.y, a.x);
    let y0n = y0.norm_squared();
    let disc = rho * rho - y0n;
    if disc < -TANGENCY * (rho * rho + y0n) {
        return Solutions::none();
    }
    if disc <= TANGENCY * (rho * rho + y0n) {
        return Solutions::one(c + y0);
    }
    let t = (disc / aa).sqrt();
    Solutions::two(c + y0 + u * t, c + y0 - u * t)
}

/// Centres of a circle of radius `r` tangent to the circles `(c1, r1)` and
/// `(c2, r2)` from outside (Wang & Liang 1997, as cited by the seed §3.1).
///
/// Returns 0, 1 or 2 centres; coincident or nested circles and
/// non-positive radii give none.
#[must_use]
pub fn circle_two_circles(
    c1: Point2<f64>,
    r1: f64,
    c2: Point2<f64>,
    r2: f64,
    r: f64,
) -> Solutions<Point2<f64>> {
    if !(r1.gt(&0.0) && r2.gt(&0.0) && r.gt(&0.0)) {
        return Solutions::none();
    }
    intersect(
        &Wrapper2::Circle {
            centre: c1,
            radius: r1 + r,
        },
        &Wrapper2::Circle {
            centre: c2,
            radius: r2 + r,
        },
    )
}

/// Centres of a circle of radius `r` tangent to the circle `(c1, r1)` and to
/// the infinite wall line through `p` with unit normal `n` (the mobile stays
/// on the side `n` points to).
#[must_use]
pub fn circle_circle_line(
    c1: Point2<f64>,
    r1: f64,
    p: Point2<f64>,
    n: Unit<Vector2<f64>>,
    r: f64,
) -> Solutions<Point2<f64>> {
    if !(r1.gt(&0.0) && r.gt(&0.0)) {
        return Solutions::none();
    }
    intersect(
        &Wrapper2::Circle {
            centre: c1,
            radius: r1 + r,
        },
        &Wrapper2::Line {
            normal: n,
            offset: n.dot(&p.coords) + r,
        },
    )
}

/// Centres of a circle of radius `r` tangent to the circle `(c1, r1)` and to
/// the wall segment `[a, b]` (a fixed segment of zero thickness, touched
/// from either side). The wrapper of a segment is a stadium: two offset
/// lines limited to the segment and two end arcs. Up to four points.
#[must_use]
pub fn circle_circle_segment(
    c1: Point2<f64>,
    r1: f64,
    a: Point2<f64>,
    b: Point2<f64>,
    r: f64,
) -> Vec<Point2<f64>> {
    let mut out = Vec::new();
    if !(r1.gt(&0.0) && r.gt(&0.0)) {
        return out;
    }
    let ab = b - a;
    let len2 = ab.norm_squared();
    let scale = r1 + r;
    let push = |p: Point2<f64>, out: &mut Vec<Point2<f64>>| {
        if !out.iter().any(|q| (q - p).norm() <= 1e-12 * scale) {
            out.push(p);
        }
    };
    let wrapper = Wrapper2::Circle {
        centre: c1,
        radius: r1 + r,
    };
    if len2 > (1e-12 * scale).powi(2) {
        let n = Unit::new_normalize(Vector2::new(-ab.y, ab.x));
        for side in [n, -n] {
            let line = Wrapper2::Line {
                normal: side,
                offset: side.dot(&a.coords) + r,
            };
            for p in intersect(&wrapper, &line).iter() {
                let t = (p - a).dot(&ab) / len2;
                if (0.0..=1.0).contains(&t) {
                    push(p, &mut out);
                }
            }
        }
    }
    for (end, other) in [(a, b), (b, a)] {
        let cap = Wrapper2::Circle {
            centre: end,
            radius: r,
        };
        for p in intersect(&wrapper, &cap).iter() {
            // The end arc is the part of the end circle beyond the segment.
            if (p - end).dot(&(end - other)) >= 0.0 || len2 == 0.0 {
                push(p, &mut out);
            }
        }
    }
    out
}

/// Centres of a circle cluster touching two fixed circle clusters
/// (Pérez Morales 2016, §3.1, Eqs. 1–2): every combination of a disk of
/// each fixed cluster with a disk of the mobile one gives a pair of
/// wrapper circles centred at `c_fix − m_mob`; a solution is kept when the
/// translated mobile cluster overlaps neither fixed cluster.
///
/// `mobile` holds disk offsets from the mobile reference point and radii;
/// the returned points are positions of that reference point. `tol` is the
/// admissible overlap (absolute). Cost `O(n1·n2·n3²)` as in the seed.
#[must_use]
pub fn cluster_two_clusters(
    fixed1: &[(Point2<f64>, f64)],
    fixed2: &[(Point2<f64>, f64)],
    mobile: &[(Vector2<f64>, f64)],
    tol: f64,
) -> Vec<Point2<f64>> {
    let mut out: Vec<Point2<f64>> = Vec::new();
    let scale = mobile.iter().map(|m| m.1).fold(0.0, f64::max);
    for &(c1, r1) in fixed1 {
        for &(c2, r2) in fixed2 {
            for &(m1, s1) in mobile {
                for &(m2, s2) in mobile {
                    let w1 = Wrapper2::Circle {
                        centre: c1 - m1,
                        radius: r1 + s1,
                    };
                    let w2 = Wrapper2::Circle {
                        centre: c2 - m2,
                        radius: r2 + s2,
                    };
                    for x in intersect(&w1, &w2).iter() {
                        let ok = [fixed1, fixed2]
                            .iter()
                            .all(|f| cluster_gap(f, mobile, x) >= -tol);
                        if ok && !out.iter().any(|q| (q - x).norm() <= 1e-9 * scale) {
                            out.push(x);
                        }
                    }
                }
            }
        }
    }
    out
}

/// Smallest signed gap between a fixed cluster and a mobile cluster placed
/// at `x`.
#[must_use]
pub fn cluster_gap(
    fixed: &[(Point2<f64>, f64)],
    mobile: &[(Vector2<f64>, f64)],
    x: Point2<f64>,
) -> f64 {
    let mut g = f64::INFINITY;
    for &(c, r) in fixed {
        for &(m, s) in mobile {
            g = g.min((x + m - c).norm() - r - s);
        }
    }
    g
}

/// A validated convex polygon, counter-clockwise, without repeated vertices.
///
/// # Errors
/// [`Error::PolygonTooFewVertices`], [`Error::RepeatedVertex`],
/// [`Error::NotConvex`], [`Error::NonFinite`].
pub fn convex_polygon(vertices: &[Point2<f64>]) -> Result<Vec<Point2<f64>>> {
    let n = vertices.len();
    if n < 3 {
        return Err(Error::PolygonTooFewVertices { got: n });
    }
    let scale = vertices
        .iter()
        .map(|v| v.coords.norm())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    for v in vertices {
        crate::error::finite("polygon vertex x", v.x)?;
        crate::error::finite("polygon vertex y", v.y)?;
    }
    for i in 0..n {
        for j in i + 1..n {
            if (vertices[i] - vertices[j]).norm() <= 1e-12 * scale {
                return Err(Error::RepeatedVertex {
                    first: i,
                    second: j,
                });
            }
        }
    }
    let cross = |i: usize| {
        let a = vertices[i];
        let b = vertices[(i + 1) % n];
        let c = vertices[(i + 2) % n];
        let u = b - a;
        let v = c - b;
        u.x * v.y - u.y * v.x
    };
    let area2: f64 = (0..n)
        .map(|i| {
            let a = vertices[i];
            let b = vertices[(i + 1) % n];
            a.x * b.y - a.y * b.x
        })
        .sum();
    if area2.abs() <= 1e-12 * scale * scale {
        return Err(Error::DegeneratePolygon);
    }
    let sign = area2.signum();
    for i in 0..n {
        if cross(i) * sign <= 1e-14 * scale * scale {
            return Err(Error::NotConvex {
                vertex: (i + 1) % n,
            });
        }
    }
    // Winding number 1: total turning 2π (rules out star polygons).
    let mut turning = 0.0;
    for i in 0..n {
        let a = vertices[i];
        let b = vertices[(i + 1) % n];
        let c = vertices[(i + 2) % n];
        let u = b - a;
        let v = c - b;
        turning += (u.x * v.y - u.y * v.x).atan2(u.dot(&v));
    }
    if (turning.abs() - std::f64::consts::TAU).abs() > 1e-6 {
        return Err(Error::NotConvex { vertex: 0 });
    }
    let mut out = vertices.to_vec();
    if sign < 0.0 {
        out.reverse();
    }
    Ok(out)
}

/// Signed distance from `x` to a counter-clockwise convex polygon (negative
/// inside).
#[must_use]
pub fn polygon_signed_distance(poly: &[Point2<f64>], x: Point2<f64>) -> f64 {
    let n = poly.len();
    let mut inside = true;
    let mut best = f64::INFINITY;
    let mut max_plane = f64::NEG_INFINITY;
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        let e = b - a;
        let nrm = Vector2::new(e.y, -e.x).normalize();
        let s = nrm.dot(&(x - a));
        max_plane = max_plane.max(s);
        if s > 0.0 {
            inside = false;
        }
        let t = ((x - a).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
        best = best.min((x - (a + e * t)).norm());
    }
    if inside { max_plane } else { best }
}

/// Centres of a circle of radius `r` touching the circle `(c1, r1)` and the
/// convex polygon `poly` (counter-clockwise, see [`convex_polygon`]) from
/// outside. The polygon's wrapper is a circumpolygon (seed §3.1): each
/// edge shifted by `r` along its outward normal, and an arc of radius `r`
/// at each vertex between the normals of its two edges.
#[must_use]
pub fn circle_circle_polygon(
    c1: Point2<f64>,
    r1: f64,
    poly: &[Point2<f64>],
    r: f64,
) -> Vec<Point2<f64>> {
    let mut out: Vec<Point2<f64>> = Vec::new();
    if !(r1.gt(&0.0) && r.gt(&0.0)) || poly.len() < 3 {
        return out;
    }
    let n = poly.len();
    let wrapper = Wrapper2::Circle {
        centre: c1,
        radius: r1 + r,
    };
    let normal = |i: usize| {
        let e = poly[(i + 1) % n] - poly[i];
        Unit::new_normalize(Vector2::new(e.y, -e.x))
    };
    let mut push = |p: Point2<f64>| {
        if !out.iter().any(|q| (q - p).norm() <= 1e-12 * (r1 + r)) {
            out.push(p);
        }
    };
    for i in 0..n {
        let a = poly[i];
        let e = poly[(i + 1) % n] - a;
        let nrm = normal(i);
        let line = Wrapper2::Line {
            normal: nrm,
            offset: nrm.dot(&a.coords) + r,
        };
        for p in intersect(&wrapper, &line).iter() {
            let t = (p - a).dot(&e) / e.norm_squared();
            if (0.0..=1.0).contains(&t) {
                push(p);
            }
        }
        // Vertex arc: the part of the circle (v, r) between the normals of
        // the edges meeting at v.
        let (n_in, n_out) = (normal((i + n - 1) % n), nrm);
        let arc = Wrapper2::Circle {
            centre: a,
            radius: r,
        };
        for p in intersect(&wrapper, &arc).iter() {
            let d = p - a;
            let cross = |u: &Vector2<f64>, v: &Vector2<f64>| u.x * v.y - u.y * v.x;
            if cross(&n_in, &d) >= 0.0 && cross(&d, &n_out) >= 0.0 {
                push(p);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests;
