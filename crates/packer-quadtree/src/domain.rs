//! Packing domains: rectangle, trapezoid, inverted trapezoid, circle,
//! arbitrary simple polygon and fracture slot; their exact walls and the
//! seed's boundary discretisation by circles (Pinto 2009, Fig. 3.1).
//!
//! Conventions: gravity points to −y (the front advances upwards); the
//! rectangle-like domains have their lower-left corner at the origin; the
//! circle is centred at `(radius, radius)`; trapezoids are symmetric about
//! `x = max(bottom, top) / 2` with their bottom base on `y = 0`.

use crate::error::{Error, Result, finite, positive};
use nalgebra::Point2;

/// A two-dimensional packing domain.
#[derive(Debug, Clone, PartialEq)]
pub enum Domain {
    /// Axis-aligned rectangle `[0, width] × [0, height]`.
    Rectangle {
        /// Extent along x.
        width: f64,
        /// Extent along y.
        height: f64,
    },
    /// Symmetric trapezoid with horizontal bases; `bottom > top` is the
    /// seed's "trapezoid" reading, `bottom < top` the "inverted trapezoid"
    /// (Pinto 2009, §3.3 does not say which base is at the bottom, NOTES T2).
    Trapezoid {
        /// Height along y.
        height: f64,
        /// Length of the base on `y = 0`.
        bottom: f64,
        /// Length of the base on `y = height`.
        top: f64,
    },
    /// Disk of the given radius centred at `(radius, radius)`.
    Circle {
        /// Radius.
        radius: f64,
    },
    /// Simple polygon (any orientation; self-intersections are rejected).
    Polygon {
        /// Vertices in order, without repeating the first one.
        vertices: Vec<Point2<f64>>,
    },
    /// Vertical fracture slot (Pinto 2009, Fig. 3.26, Tables 3.15/3.16):
    /// aperture `width` along x, fracture `height` along y.
    FractureSlot {
        /// Fracture aperture (x extent).
        width: f64,
        /// Fracture height (y extent).
        height: f64,
    },
}

/// Exact wall primitive of a resolved domain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Wall {
    /// Segment `a → b` with unit inward normal `n` (domain on the left of a
    /// counter-clockwise boundary).
    Segment {
        a: [f64; 2],
        b: [f64; 2],
        n: [f64; 2],
        len: f64,
    },
    /// A reflex (concave) polygon vertex, an obstacle point.
    Vertex { p: [f64; 2] },
    /// Circular boundary with the domain inside.
    Arc { c: [f64; 2], r: f64 },
}

impl Wall {
    /// Distance from point `p` to the wall (for an arc: distance to the
    /// circle measured inwards, negative outside).
    pub(crate) fn distance(&self, p: [f64; 2]) -> f64 {
        match *self {
            Self::Segment { a, b, len, .. } => {
                let (tx, ty) = ((b[0] - a[0]) / len, (b[1] - a[1]) / len);
                let (dx, dy) = (p[0] - a[0], p[1] - a[1]);
                let t = (dx * tx + dy * ty).clamp(0.0, len);
                let (ex, ey) = (dx - t * tx, dy - t * ty);
                (ex * ex + ey * ey).sqrt()
            }
            Self::Vertex { p: v } => ((p[0] - v[0]).powi(2) + (p[1] - v[1]).powi(2)).sqrt(),
            Self::Arc { c, r } => r - ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt(),
        }
    }
}

/// A validated domain in the form the packer uses.
#[derive(Debug, Clone)]
pub(crate) enum Shape {
    /// Counter-clockwise simple polygon.
    Poly(Vec<[f64; 2]>),
    /// Disk.
    Disk { c: [f64; 2], r: f64 },
}

impl Shape {
    /// Whether `p` lies inside (boundary counts as inside).
    pub(crate) fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Self::Poly(v) => point_in_polygon(v, p),
            Self::Disk { c, r } => (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) <= r * r,
        }
    }

    /// Exact walls: polygon edges plus reflex vertices, or the circle.
    pub(crate) fn walls(&self) -> Vec<Wall> {
        match self {
            Self::Disk { c, r } => vec![Wall::Arc { c: *c, r: *r }],
            Self::Poly(v) => {
                let n = v.len();
                let mut w = Vec::with_capacity(2 * n);
                for i in 0..n {
                    let a = v[i];
                    let b = v[(i + 1) % n];
                    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                    // Inward normal of a CCW polygon: left of the edge.
                    let nrm = [-(b[1] - a[1]) / len, (b[0] - a[0]) / len];
                    w.push(Wall::Segment { a, b, n: nrm, len });
                }
                for i in 0..n {
                    let p = v[(i + n - 1) % n];
                    let q = v[i];
                    let s = v[(i + 1) % n];
                    let cross = (q[0] - p[0]) * (s[1] - q[1]) - (q[1] - p[1]) * (s[0] - q[0]);
                    if cross < 0.0 {
                        w.push(Wall::Vertex { p: q });
                    }
                }
                w
            }
        }
    }

    /// Axis-aligned bounding box `(min, max)`.
    pub(crate) fn bbox(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Self::Disk { c, r } => ([c[0] - r, c[1] - r], [c[0] + r, c[1] + r]),
            Self::Poly(v) => {
                let mut lo = [f64::MAX; 2];
                let mut hi = [f64::MIN; 2];
                for p in v {
                    for k in 0..2 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
                (lo, hi)
            }
        }
    }

    /// Boundary discretised by circles of diameter `d` centred on the
    /// boundary, consecutive centres at most `0.95 d` apart so the union of
    /// the circles covers the boundary curve (Pinto 2009, Fig. 3.1).
    pub(crate) fn boundary_circles(&self, d: f64) -> Vec<[f64; 3]> {
        let r = d / 2.0;
        let step = 0.95 * d;
        let mut out = Vec::new();
        match self {
            Self::Disk { c, r: big } => {
                let n = ((std::f64::consts::TAU * big) / step).ceil().max(3.0) as usize;
                for k in 0..n {
                    let t = std::f64::consts::TAU * (k as f64) / (n as f64);
                    out.push([c[0] + big * t.cos(), c[1] + big * t.sin(), r]);
                }
            }
            Self::Poly(v) => {
                let n = v.len();
                for i in 0..n {
                    let a = v[i];
                    let b = v[(i + 1) % n];
                    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                    let m = (len / step).ceil().max(1.0) as usize;
                    for k in 0..m {
                        let t = (k as f64) / (m as f64);
                        out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), r]);
                    }
                }
            }
        }
        out
    }
}

/// Even-odd point-in-polygon test, boundary points count as inside.
pub(crate) fn point_in_polygon(v: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = v.len();
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (v[j], v[i]);
        if (b[1] > p[1]) != (a[1] > p[1]) {
            let x = b[0] + (p[1] - b[1]) * (a[0] - b[0]) / (a[1] - b[1]);
            if p[0] < x {
                inside = !inside;
            } else if p[0] == x {
                return true;
            }
        }
        j = i;
    }
    inside
}

fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn on_segment(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    p[0] >= a[0].min(b[0])
        && p[0] <= a[0].max(b[0])
        && p[1] >= a[1].min(b[1])
        && p[1] <= a[1].max(b[1])
}

/// Closed-segment intersection test (touching counts).
fn segments_intersect(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (o1, o2, o3, o4) = (
        orient(a, b, c),
        orient(a, b, d),
        orient(c, d, a),
        orient(c, d, b),
    );
    if ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0))
        && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0))
    {
        return true;
    }
    (o1 == 0.0 && on_segment(a, b, c))
        || (o2 == 0.0 && on_segment(a, b, d))
        || (o3 == 0.0 && on_segment(c, d, a))
        || (o4 == 0.0 && on_segment(c, d, b))
}

/// Signed area of a polygon (positive when counter-clockwise).
fn signed_area(v: &[[f64; 2]]) -> f64 {
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

impl Domain {
    /// Trapezoid of Pinto 2009, §3.3 (Figs. 3.27/3.28): height 20, bases
    /// 20 (bottom) and 10 (top), in mm.
    pub fn pinto_trapezoid() -> Self {
        Self::Trapezoid {
            height: 20.0,
            bottom: 20.0,
            top: 10.0,
        }
    }

    /// Inverted trapezoid of Pinto 2009, §3.3 (Figs. 3.29/3.30).
    pub fn pinto_inverted_trapezoid() -> Self {
        Self::Trapezoid {
            height: 20.0,
            bottom: 10.0,
            top: 20.0,
        }
    }

    /// Validates the domain and resolves it into the packer's form.
    pub(crate) fn shape(&self) -> Result<Shape> {
        match self {
            Self::Rectangle { width, height } | Self::FractureSlot { width, height } => {
                let w = positive("domain width", *width)?;
                let h = positive("domain height", *height)?;
                Ok(Shape::Poly(vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]))
            }
            Self::Trapezoid {
                height,
                bottom,
                top,
            } => {
                let h = positive("trapezoid height", *height)?;
                let b = positive("trapezoid bottom", *bottom)?;
                let t = positive("trapezoid top", *top)?;
                let m = b.max(t) / 2.0;
                Ok(Shape::Poly(vec![
                    [m - b / 2.0, 0.0],
                    [m + b / 2.0, 0.0],
                    [m + t / 2.0, h],
                    [m - t / 2.0, h],
                ]))
            }
            Self::Circle { radius } => {
                let r = positive("circle radius", *radius)?;
                Ok(Shape::Disk { c: [r, r], r })
            }
            Self::Polygon { vertices } => {
                let n = vertices.len();
                if n < 3 {
                    return Err(Error::PolygonTooFewVertices { got: n });
                }
                let mut v = Vec::with_capacity(n);
                for p in vertices {
                    finite("polygon vertex x", p.x)?;
                    finite("polygon vertex y", p.y)?;
                    v.push([p.x, p.y]);
                }
                for i in 0..n {
                    let (a, b) = (v[i], v[(i + 1) % n]);
                    if a == b {
                        return Err(Error::DegeneratePolygon);
                    }
                }
                for i in 0..n {
                    for j in i + 1..n {
                        let adjacent = j == i + 1 || (i == 0 && j == n - 1);
                        let (a, b) = (v[i], v[(i + 1) % n]);
                        let (c, d) = (v[j], v[(j + 1) % n]);
                        if adjacent {
                            // Adjacent edges share one vertex; they must not
                            // fold back onto each other.
                            let (shared, other_a, other_b) =
                                if j == i + 1 { (b, a, d) } else { (a, b, c) };
                            if orient(shared, other_a, other_b) == 0.0 {
                                let dot = (other_a[0] - shared[0]) * (other_b[0] - shared[0])
                                    + (other_a[1] - shared[1]) * (other_b[1] - shared[1]);
                                if dot > 0.0 {
                                    return Err(Error::SelfIntersecting {
                                        first: i,
                                        second: j,
                                    });
                                }
                            }
                        } else if segments_intersect(a, b, c, d) {
                            return Err(Error::SelfIntersecting {
                                first: i,
                                second: j,
                            });
                        }
                    }
                }
                let area = signed_area(&v);
                if area.abs() <= f64::EPSILON * 16.0 * bbox_scale(&v).powi(2) {
                    return Err(Error::DegeneratePolygon);
                }
                if area < 0.0 {
                    v.reverse();
                }
                Ok(Shape::Poly(v))
            }
        }
    }

    /// Area of the domain (`A_T` of Pinto 2009, Eq. 4-2).
    ///
    /// # Errors
    /// The validation errors of the domain.
    pub fn area(&self) -> Result<f64> {
        Ok(match self.shape()? {
            Shape::Poly(v) => signed_area(&v).abs(),
            Shape::Disk { r, .. } => std::f64::consts::PI * r * r,
        })
    }

    /// Validates the domain.
    ///
    /// # Errors
    /// [`Error::NonFinite`], [`Error::NonPositive`],
    /// [`Error::PolygonTooFewVertices`], [`Error::SelfIntersecting`] or
    /// [`Error::DegeneratePolygon`].
    pub fn validate(&self) -> Result<()> {
        self.shape().map(|_| ())
    }

    /// Whether a disk of centre `c` and radius `r` lies entirely inside the
    /// domain, up to `tol` (exact geometry, used by the checkers).
    ///
    /// # Errors
    /// The validation errors of the domain.
    pub fn contains_disk(&self, c: Point2<f64>, r: f64, tol: f64) -> Result<bool> {
        let s = self.shape()?;
        Ok(shape_contains_disk(&s, &s.walls(), [c.x, c.y], r, tol))
    }
}

fn bbox_scale(v: &[[f64; 2]]) -> f64 {
    v.iter()
        .map(|p| p[0].abs().max(p[1].abs()))
        .fold(1.0, f64::max)
}

/// Exact containment of a disk in a resolved shape (brute force over walls).
pub(crate) fn shape_contains_disk(
    s: &Shape,
    walls: &[Wall],
    c: [f64; 2],
    r: f64,
    tol: f64,
) -> bool {
    if !s.contains(c) {
        return false;
    }
    walls.iter().all(|w| match w {
        Wall::Vertex { .. } => true,
        _ => w.distance(c) >= r - tol,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn areas() {
        let a = |d: Domain| d.area().expect("valid");
        assert_relative_eq!(
            a(Domain::Rectangle {
                width: 8.6,
                height: 62.5
            }),
            537.5,
            epsilon = 1e-9
        );
        assert_relative_eq!(a(Domain::pinto_trapezoid()), 300.0, epsilon = 1e-9);
        assert_relative_eq!(a(Domain::pinto_inverted_trapezoid()), 300.0, epsilon = 1e-9);
        assert_relative_eq!(
            a(Domain::Circle { radius: 2.0 }),
            4.0 * std::f64::consts::PI,
            epsilon = 1e-12
        );
        let l = Domain::Polygon {
            vertices: [
                [0.0, 0.0],
                [2.0, 0.0],
                [2.0, 1.0],
                [1.0, 1.0],
                [1.0, 2.0],
                [0.0, 2.0],
            ]
            .iter()
            .map(|p| Point2::new(p[0], p[1]))
            .collect(),
        };
        assert_relative_eq!(a(l.clone()), 3.0, epsilon = 1e-12);
        // One reflex vertex in the L shape.
        let walls = l.shape().expect("valid").walls();
        assert_eq!(
            walls
                .iter()
                .filter(|w| matches!(w, Wall::Vertex { .. }))
                .count(),
            1
        );
    }

    #[test]
    fn bad_polygons_are_errors() {
        let bowtie = Domain::Polygon {
            vertices: [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]
                .iter()
                .map(|p| Point2::new(p[0], p[1]))
                .collect(),
        };
        assert!(matches!(
            bowtie.validate(),
            Err(Error::SelfIntersecting { .. })
        ));
        let two = Domain::Polygon {
            vertices: vec![Point2::new(0.0, 0.0), Point2::new(1.0, 0.0)],
        };
        assert!(matches!(
            two.validate(),
            Err(Error::PolygonTooFewVertices { got: 2 })
        ));
        let flat = Domain::Polygon {
            vertices: vec![
                Point2::new(0.0, 0.0),
                Point2::new(1.0, 0.0),
                Point2::new(2.0, 0.0),
            ],
        };
        assert!(flat.validate().is_err());
        let nan = Domain::Rectangle {
            width: f64::NAN,
            height: 1.0,
        };
        assert!(matches!(nan.validate(), Err(Error::NonFinite { .. })));
        let neg = Domain::Circle { radius: -1.0 };
        assert!(matches!(neg.validate(), Err(Error::NonPositive { .. })));
    }

    #[test]
    fn boundary_circles_cover_the_boundary() {
        let s = Domain::Circle { radius: 5.0 }.shape().expect("valid");
        let d = 0.3;
        let circles = s.boundary_circles(d);
        for k in 0..1000 {
            let t = std::f64::consts::TAU * f64::from(k) / 1000.0;
            let p = [5.0 + 5.0 * t.cos(), 5.0 + 5.0 * t.sin()];
            let near = circles
                .iter()
                .map(|c| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt())
                .fold(f64::MAX, f64::min);
            assert!(near <= d / 2.0, "uncovered boundary point at t = {t}");
        }
    }
}
