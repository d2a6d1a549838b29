//! Grain shapes of the particle-in-contact solvers, in 2D and 3D: disks and
//! spheres, spherocylinders (capsules), circle/sphere clusters, convex
//! polygons and polyhedra.
//!
//! Every grain is stored in its world orientation relative to its
//! reference point (the centre of its circumscribed circle/sphere): a union
//! of sphere-swept segments ([`Swept`]; a disk or sphere when `a == b`) or a
//! convex vertex set. Convex grains also carry their parry shape
//! (`ConvexPolygon` / `ConvexPolyhedron`), built once, for exact distances.
//!
//! Conventions (Pérez Morales et al. 2016, Fig. 6, read as follows, see
//! `fixtures/reference/NOTES.md` perezmorales2016 P1):
//! * *circumscribed radius* `R`: radius of the smallest sphere about the
//!   grain's centre containing it; for a spherocylinder `R = h + r`
//!   (half segment length plus radius);
//! * *aspect ratio* `α = width / length = 2r / 2R = r / R ∈ (0, 1]`; 0.5
//!   gives `r = h = R/2` (length twice the width). `α = 1` is a sphere.
//!   This reading reproduces the seed's counts: 77 capsules at 82.2 % in
//!   the 20 × 20 square and 5901 capsules at 45.8 % in the 40³ cube both
//!   need a mean grain area/volume that `α = r/R = 0.5` with `R ~ U[1, 2]`
//!   gives (4.17 and 4.91 against 4.27 and 4.96).
//! * a spherocylinder "approximated by a cluster" of `n` disks/spheres has
//!   `n` equal disks of radius `r` with centres evenly spaced on the
//!   segment, so the cluster has the same circumscribed radius.

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::{SVector, UnitQuaternion, Vector3};
use rand::Rng;

use crate::error::{Error, Result};

/// A sphere-swept segment: all points within `radius` of `[a, b]`; a disk
/// (2D) or sphere (3D) when `a == b`. Offsets are relative to the grain's
/// reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Swept<const D: usize> {
    /// First end of the core segment.
    pub a: SVector<f64, D>,
    /// Second end of the core segment.
    pub b: SVector<f64, D>,
    /// Sweep radius.
    pub radius: f64,
}

/// A parry convex shape of either dimension.
#[derive(Debug, Clone)]
pub enum ParryConvex {
    /// A convex polygon (parry2d).
    Polygon(Arc<parry2d_f64::shape::ConvexPolygon>),
    /// A convex polyhedron (parry3d).
    Polyhedron(Arc<parry3d_f64::shape::ConvexPolyhedron>),
}

/// Geometry of a grain in its world orientation.
#[derive(Debug, Clone)]
pub enum Geometry<const D: usize> {
    /// A union of sphere-swept segments (disk, sphere, capsule, cluster).
    Swept(Vec<Swept<D>>),
    /// A convex polygon or polyhedron: its vertices and its parry shape.
    Convex {
        /// Vertices relative to the reference point.
        vertices: Vec<SVector<f64, D>>,
        /// The same shape for parry queries.
        shape: ParryConvex,
    },
}

/// One grain: geometry, bounds and measure.
#[derive(Debug, Clone)]
pub struct Grain<const D: usize> {
    /// The geometry.
    pub geometry: Geometry<D>,
    /// Circumscribed radius about the reference point.
    pub circumradius: f64,
    /// An inner size used as the effective radius of the first guesses.
    pub inradius: f64,
    /// Area (2D) or volume (3D), exact.
    pub measure: f64,
    /// Lower corner of the bounding box, relative to the reference point.
    pub lo: SVector<f64, D>,
    /// Upper corner of the bounding box.
    pub hi: SVector<f64, D>,
}

impl<const D: usize> Grain<D> {
    /// A disk (2D) or sphere (3D) of radius `r`.
    ///
    /// # Errors
    /// [`Error::NonPositive`] for `r ≤ 0`.
    pub fn ball(r: f64) -> Result<Self> {
        crate::error::positive("radius", r)?;
        let z = SVector::<f64, D>::zeros();
        Ok(Self::from_swept(vec![Swept {
            a: z,
            b: z,
            radius: r,
        }]))
    }

    /// A spherocylinder of circumscribed radius `big_r` and aspect ratio
    /// `aspect = r / R ∈ (0, 1]` along the unit `axis`.
    ///
    /// # Errors
    /// [`Error::NonPositive`], [`Error::Parameter`] for an aspect ratio
    /// outside `(0, 1]`.
    pub fn capsule(big_r: f64, aspect: f64, axis: SVector<f64, D>) -> Result<Self> {
        crate::error::positive("circumscribed radius", big_r)?;
        check_aspect(aspect)?;
        let r = aspect * big_r;
        let h = big_r - r;
        Ok(Self::from_swept(vec![Swept {
            a: -axis * h,
            b: axis * h,
            radius: r,
        }]))
    }

    /// A spherocylinder approximated by `n ≥ 2` equal disks/spheres evenly
    /// spaced on its segment (seed Fig. 6: 4 disks).
    ///
    /// # Errors
    /// As [`Grain::capsule`], and [`Error::Parameter`] for `n < 2`.
    pub fn capsule_cluster(
        big_r: f64,
        aspect: f64,
        n: usize,
        axis: SVector<f64, D>,
    ) -> Result<Self> {
        crate::error::positive("circumscribed radius", big_r)?;
        check_aspect(aspect)?;
        if !(2..=64).contains(&n) {
            return Err(Error::Parameter {
                what: "spheres per cluster",
                value: n as f64,
                range: "2..=64",
            });
        }
        let r = aspect * big_r;
        let h = big_r - r;
        let elems = (0..n)
            .map(|i| {
                let t = -h + 2.0 * h * i as f64 / (n - 1) as f64;
                Swept {
                    a: axis * t,
                    b: axis * t,
                    radius: r,
                }
            })
            .collect();
        Ok(Self::from_swept(elems))
    }

    /// A grain from sphere-swept segments (a general cluster).
    ///
    /// The measure is exact for one element and for equal collinear evenly
    /// spaced disks/spheres (the capsule clusters), where each disk adds
    /// itself minus its lens with the previous one; for other clusters it
    /// is the sum of the element measures minus consecutive lenses (an
    /// approximation, documented).
    #[must_use]
    pub fn from_swept(elems: Vec<Swept<D>>) -> Self {
        let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        let mut circ: f64 = 0.0;
        let mut inr: f64 = f64::INFINITY;
        let mut measure = 0.0;
        for (k, e) in elems.iter().enumerate() {
            for p in [e.a, e.b] {
                for i in 0..D {
                    lo[i] = lo[i].min(p[i] - e.radius);
                    hi[i] = hi[i].max(p[i] + e.radius);
                }
                circ = circ.max(p.norm() + e.radius);
            }
            inr = inr.min(e.radius);
            let len = (e.b - e.a).norm();
            measure += swept_measure::<D>(e.radius, len);
            if k > 0 {
                let prev = elems[k - 1];
                if prev.a == prev.b && e.a == e.b && prev.radius == e.radius {
                    measure -= lens::<D>(e.radius, (e.a - prev.a).norm());
                }
            }
        }
        Self {
            geometry: Geometry::Swept(elems),
            circumradius: circ,
            inradius: inr,
            measure,
            lo,
            hi,
        }
    }

    /// Whether the grain is one disk or sphere.
    #[must_use]
    pub fn is_ball(&self) -> bool {
        matches!(&self.geometry, Geometry::Swept(e) if e.len() == 1 && e[0].a == e[0].b)
    }

    /// Whether the grain is a union of disks/spheres (no segment, no convex).
    #[must_use]
    pub fn is_sphere_cluster(&self) -> bool {
        matches!(&self.geometry, Geometry::Swept(e) if e.iter().all(|s| s.a == s.b))
    }
}

fn check_aspect(aspect: f64) -> Result<()> {
    if aspect.is_finite() && aspect > 0.0 && aspect <= 1.0 {
        Ok(())
    } else {
        Err(Error::Parameter {
            what: "aspect ratio (width / length)",
            value: aspect,
            range: "(0, 1]",
        })
    }
}

/// Area (2D) or volume (3D) of a sphere-swept segment of length `len`.
fn swept_measure<const D: usize>(r: f64, len: f64) -> f64 {
    if D == 2 {
        PI * r * r + 2.0 * r * len
    } else {
        4.0 / 3.0 * PI * r.powi(3) + PI * r * r * len
    }
}

/// Area (2D) or volume (3D) of the lens of two equal disks/spheres of radius
/// `r` at distance `s`.
fn lens<const D: usize>(r: f64, s: f64) -> f64 {
    if s >= 2.0 * r {
        return 0.0;
    }
    if D == 2 {
        2.0 * r * r * (s / (2.0 * r)).acos() - 0.5 * s * (4.0 * r * r - s * s).max(0.0).sqrt()
    } else {
        PI * (4.0 * r + s) * (2.0 * r - s).powi(2) / 12.0
    }
}

impl Grain<2> {
    /// A convex polygon from vertices relative to the reference point
    /// (validated: convex, no repeated vertex, non-zero area).
    ///
    /// # Errors
    /// See [`crate::contact2d::convex_polygon`].
    pub fn polygon(vertices: &[nalgebra::Point2<f64>]) -> Result<Self> {
        let v = crate::contact2d::convex_polygon(vertices)?;
        let pts: Vec<parry2d_f64::math::Vector> = v
            .iter()
            .map(|p| parry2d_f64::math::Vector::new(p.x, p.y))
            .collect();
        let shape = parry2d_f64::shape::ConvexPolygon::from_convex_polyline_unmodified(pts)
            .ok_or(Error::DegeneratePolygon)?;
        let verts: Vec<SVector<f64, 2>> = v.iter().map(|p| p.coords).collect();
        let n = verts.len();
        let area: f64 = 0.5
            * (0..n)
                .map(|i| {
                    let a = verts[i];
                    let b = verts[(i + 1) % n];
                    a.x * b.y - a.y * b.x
                })
                .sum::<f64>();
        let circ = verts.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let inr = (0..n)
            .map(|i| {
                let a = verts[i];
                let e = verts[(i + 1) % n] - a;
                (a.x * e.y - a.y * e.x).abs() / e.norm()
            })
            .fold(f64::INFINITY, f64::min);
        let mut lo = SVector::<f64, 2>::repeat(f64::INFINITY);
        let mut hi = -lo;
        for p in &verts {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        Ok(Self {
            geometry: Geometry::Convex {
                vertices: verts,
                shape: ParryConvex::Polygon(Arc::new(shape)),
            },
            circumradius: circ,
            inradius: inr.max(0.0),
            measure: area.abs(),
            lo,
            hi,
        })
    }

    /// A regular polygon with `sides` vertices on the circle of radius
    /// `big_r`, rotated by `angle`.
    ///
    /// # Errors
    /// [`Error::NonPositive`], [`Error::PolygonTooFewVertices`].
    pub fn regular_polygon(big_r: f64, sides: usize, angle: f64) -> Result<Self> {
        crate::error::positive("circumscribed radius", big_r)?;
        if sides < 3 {
            return Err(Error::PolygonTooFewVertices { got: sides });
        }
        let v: Vec<nalgebra::Point2<f64>> = (0..sides)
            .map(|i| {
                let t = angle + 2.0 * PI * i as f64 / sides as f64;
                nalgebra::Point2::new(big_r * t.cos(), big_r * t.sin())
            })
            .collect();
        Self::polygon(&v)
    }
}

impl Grain<3> {
    /// A convex polyhedron: the convex hull of `points` (parry's Quickhull),
    /// refused when a point is repeated or not a hull vertex.
    ///
    /// # Errors
    /// [`Error::PolygonTooFewVertices`] (fewer than 4 points),
    /// [`Error::RepeatedVertex`], [`Error::NotConvex`] (a point inside the
    /// hull), [`Error::DegeneratePolygon`] (flat), [`Error::NonFinite`].
    pub fn polyhedron(points: &[nalgebra::Point3<f64>]) -> Result<Self> {
        if points.len() < 4 {
            return Err(Error::PolygonTooFewVertices { got: points.len() });
        }
        for p in points {
            for c in p.iter() {
                crate::error::finite("polyhedron vertex", *c)?;
            }
        }
        let scale = points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
        for i in 0..points.len() {
            for j in i + 1..points.len() {
                if (points[i] - points[j]).norm() <= 1e-12 * scale {
                    return Err(Error::RepeatedVertex {
                        first: i,
                        second: j,
                    });
                }
            }
        }
        let pts: Vec<parry3d_f64::math::Vector> = points
            .iter()
            .map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z))
            .collect();
        let shape = parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&pts)
            .ok_or(Error::DegeneratePolygon)?;
        if shape.points().len() != points.len() {
            let vertex = pts
                .iter()
                .position(|p| {
                    !shape
                        .points()
                        .iter()
                        .any(|q| (*q - *p).length() <= 1e-12 * scale)
                })
                .unwrap_or(0);
            return Err(Error::NotConvex { vertex });
        }
        let (tv, ti) = shape.to_trimesh();
        let mut vol = 0.0;
        let mut inr = f64::INFINITY;
        for t in &ti {
            let a = Vector3::new(
                tv[t[0] as usize].x,
                tv[t[0] as usize].y,
                tv[t[0] as usize].z,
            );
            let b = Vector3::new(
                tv[t[1] as usize].x,
                tv[t[1] as usize].y,
                tv[t[1] as usize].z,
            );
            let c = Vector3::new(
                tv[t[2] as usize].x,
                tv[t[2] as usize].y,
                tv[t[2] as usize].z,
            );
            vol += a.dot(&b.cross(&c)) / 6.0;
            let n = (b - a).cross(&(c - a));
            if n.norm() > 0.0 {
                inr = inr.min((a.dot(&n) / n.norm()).abs());
            }
        }
        if !vol.abs().gt(&(1e-12 * scale.powi(3))) {
            return Err(Error::DegeneratePolygon);
        }
        let verts: Vec<SVector<f64, 3>> = points.iter().map(|p| p.coords).collect();
        let mut lo = SVector::<f64, 3>::repeat(f64::INFINITY);
        let mut hi = -lo;
        for p in &verts {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        Ok(Self {
            circumradius: verts.iter().map(|p| p.norm()).fold(0.0, f64::max),
            inradius: inr,
            measure: vol.abs(),
            lo,
            hi,
            geometry: Geometry::Convex {
                vertices: verts,
                shape: ParryConvex::Polyhedron(Arc::new(shape)),
            },
        })
    }
}

/// The grain family of a packing; sizes are circumscribed radii.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GrainShape {
    /// Disks (2D) or spheres (3D).
    Ball,
    /// Spherocylinders with aspect ratio `r / R`.
    Capsule {
        /// Width over length, `r / R ∈ (0, 1]`.
        aspect: f64,
    },
    /// Spherocylinders approximated by `spheres` equal disks/spheres.
    Cluster {
        /// Width over length of the approximated spherocylinder.
        aspect: f64,
        /// Disks/spheres per cluster (≥ 2).
        spheres: usize,
    },
    /// Regular polygons (2D) with a random side count in `sides_min..=sides_max`,
    /// or random convex polyhedra (3D) with that many hull vertices.
    Polygon {
        /// Fewest sides (vertices in 3D).
        sides_min: usize,
        /// Most sides (vertices in 3D).
        sides_max: usize,
    },
    /// A mix of disks/spheres and [`GrainShape::Polygon`] grains, each grain
    /// a polygon with probability `polygon_share`.
    Mix {
        /// Probability that a grain is a polygon.
        polygon_share: f64,
        /// Fewest sides.
        sides_min: usize,
        /// Most sides.
        sides_max: usize,
    },
}

impl GrainShape {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::Parameter`] for an aspect ratio outside `(0, 1]`, a side
    /// range that is empty or below 3 (4 in 3D), a share outside `[0, 1]`.
    pub fn validate(&self, dim: usize) -> Result<()> {
        let min_sides = if dim == 2 { 3 } else { 4 };
        let sides = |lo: usize, hi: usize| {
            if lo < min_sides || hi < lo || hi > 64 {
                Err(Error::Parameter {
                    what: "polygon side range",
                    value: lo as f64,
                    range: "3 (4 in 3D) ≤ min ≤ max ≤ 64",
                })
            } else {
                Ok(())
            }
        };
        match *self {
            Self::Ball => Ok(()),
            Self::Capsule { aspect } => check_aspect(aspect),
            Self::Cluster { aspect, spheres } => {
                check_aspect(aspect)?;
                if (2..=64).contains(&spheres) {
                    Ok(())
                } else {
                    Err(Error::Parameter {
                        what: "spheres per cluster",
                        value: spheres as f64,
                        range: "2..=64",
                    })
                }
            }
            Self::Polygon {
                sides_min,
                sides_max,
            } => sides(sides_min, sides_max),
            Self::Mix {
                polygon_share,
                sides_min,
                sides_max,
            } => {
                if !(0.0..=1.0).contains(&polygon_share) {
                    return Err(Error::Parameter {
                        what: "polygon share",
                        value: polygon_share,
                        range: "[0, 1]",
                    });
                }
                sides(sides_min, sides_max)
            }
        }
    }

    /// Draws one grain of circumscribed radius `big_r` with a random
    /// orientation (uniform angle in 2D, uniform on the sphere in 3D).
    ///
    /// # Errors
    /// The constructors' errors.
    pub fn sample<const D: usize>(&self, big_r: f64, rng: &mut impl Rng) -> Result<Grain<D>> {
        let axis = random_axis::<D>(rng);
        match *self {
            Self::Ball => Grain::ball(big_r),
            Self::Capsule { aspect } => Grain::capsule(big_r, aspect, axis),
            Self::Cluster { aspect, spheres } => {
                Grain::capsule_cluster(big_r, aspect, spheres, axis)
            }
            Self::Polygon {
                sides_min,
                sides_max,
            } => convex_grain::<D>(big_r, rng.random_range(sides_min..=sides_max), rng),
            Self::Mix {
                polygon_share,
                sides_min,
                sides_max,
            } => {
                if rng.random::<f64>() < polygon_share {
                    convex_grain::<D>(big_r, rng.random_range(sides_min..=sides_max), rng)
                } else {
                    Grain::ball(big_r)
                }
            }
        }
    }
}

fn random_axis<const D: usize>(rng: &mut impl Rng) -> SVector<f64, D> {
    if D == 2 {
        let t = rng.random::<f64>() * PI;
        SVector::from_fn(|i, _| if i == 0 { t.cos() } else { t.sin() })
    } else {
        let z = 2.0 * rng.random::<f64>() - 1.0;
        let t = rng.random::<f64>() * 2.0 * PI;
        let s = (1.0 - z * z).max(0.0).sqrt();
        let v = [s * t.cos(), s * t.sin(), z];
        SVector::from_fn(|i, _| v[i])
    }
}

/// A regular polygon (2D) or a random convex polyhedron (3D: `n` points on
/// the circumscribed sphere, a random rotation of a Fibonacci lattice).
fn convex_grain<const D: usize>(big_r: f64, n: usize, rng: &mut impl Rng) -> Result<Grain<D>> {
    if D == 2 {
        let g = Grain::<2>::regular_polygon(big_r, n, rng.random::<f64>() * 2.0 * PI)?;
        Ok(recast::<2, D>(g))
    } else {
        let q = UnitQuaternion::from_euler_angles(
            rng.random::<f64>() * 2.0 * PI,
            rng.random::<f64>() * PI,
            rng.random::<f64>() * 2.0 * PI,
        );
        let golden = PI * (3.0 - 5f64.sqrt());
        let pts: Vec<nalgebra::Point3<f64>> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let s = (1.0 - z * z).sqrt();
                let t = golden * i as f64;
                nalgebra::Point3::from(q * Vector3::new(s * t.cos(), s * t.sin(), z) * big_r)
            })
            .collect();
        let g = Grain::<3>::polyhedron(&pts)?;
        Ok(recast::<3, D>(g))
    }
}

/// Re-types a grain whose dimension is known to be `D` at run time.
pub(crate) fn recast<const E: usize, const D: usize>(g: Grain<E>) -> Grain<D> {
    let v = |x: SVector<f64, E>| SVector::<f64, D>::from_fn(|i, _| x[i]);
    let geometry = match g.geometry {
        Geometry::Swept(e) => Geometry::Swept(
            e.into_iter()
                .map(|s| Swept {
                    a: v(s.a),
                    b: v(s.b),
                    radius: s.radius,
                })
                .collect(),
        ),
        Geometry::Convex { vertices, shape } => Geometry::Convex {
            vertices: vertices.into_iter().map(v).collect(),
            shape,
        },
    };
    Grain {
        geometry,
        circumradius: g.circumradius,
        inradius: g.inradius,
        measure: g.measure,
        lo: v(g.lo),
        hi: v(g.hi),
    }
}
