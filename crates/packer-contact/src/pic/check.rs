//! The independent overlap checker [`check_pic`] on parry's exact
//! queries.

use super::front::{PicPacking, Placed};
use crate::error::{Error, Result};
use crate::shapes::{Geometry, ParryConvex};

/// Result of [`check_pic`].
#[derive(Debug, Clone, PartialEq)]
pub struct PicReport {
    /// Smallest signed gap over all grain pairs divided by the smaller
    /// circumscribed diameter of the pair (`+∞` with fewer than two grains).
    pub min_relative_gap: f64,
    /// Smallest signed wall clearance divided by the grain's diameter.
    pub min_relative_wall_gap: f64,
    /// Grain pairs with `gap ≤ contact_tol · d` (contacts).
    pub contacts: usize,
    /// Mean coordination number `2·contacts / n`.
    pub coordination: f64,
}

/// Independent overlap checker on parry's exact queries: every pair of
/// grains whose bounding spheres meet is measured with parry's `contact`
/// (signed distance: balls and capsules exactly, convex shapes by GJK/EPA)
/// element by element; walls with parry's AABBs. It shares no arithmetic
/// with the placement code. Pairs are found by sorting on the first
/// coordinate (sweep and prune).
///
/// # Errors
/// [`Error::Empty`] for an empty packing.
pub fn check_pic<const D: usize>(p: &PicPacking<D>, contact_tol: f64) -> Result<PicReport> {
    if p.grains.is_empty() {
        return Err(Error::Empty { what: "packing" });
    }
    let shapes: Vec<Vec<ParryPart>> = p.grains.iter().map(parts).collect();
    let mut order: Vec<usize> = (0..p.grains.len()).collect();
    order.sort_by(|&a, &b| {
        let ka = p.grains[a].centre[0] - p.grains[a].grain.circumradius;
        let kb = p.grains[b].centre[0] - p.grains[b].grain.circumradius;
        ka.total_cmp(&kb).then(a.cmp(&b))
    });
    let mut min_gap = f64::INFINITY;
    let mut contacts = 0usize;
    let mut min_wall = f64::INFINITY;
    for (k, &i) in order.iter().enumerate() {
        let gi = &p.grains[i];
        let ri = gi.grain.circumradius;
        for (lo, hi) in parts_aabb(&shapes[i]) {
            for a in 0..D {
                min_wall = min_wall
                    .min(lo[a] / (2.0 * ri))
                    .min((p.side - hi[a]) / (2.0 * ri));
            }
        }
        for &j in &order[k + 1..] {
            let gj = &p.grains[j];
            let rj = gj.grain.circumradius;
            if gj.centre[0] - rj > gi.centre[0] + ri {
                break;
            }
            if (gj.centre - gi.centre).norm() > ri + rj {
                continue;
            }
            let d = 2.0 * ri.min(rj);
            let g = pair_gap(&shapes[i], &shapes[j], d);
            min_gap = min_gap.min(g / d);
            if g <= contact_tol * d {
                contacts += 1;
            }
        }
    }
    Ok(PicReport {
        min_relative_gap: min_gap,
        min_relative_wall_gap: min_wall,
        contacts,
        coordination: 2.0 * contacts as f64 / p.grains.len() as f64,
    })
}

/// One parry shape of a grain, placed in the world.
enum ParryPart {
    D2(parry2d_f64::math::Pose, parry2d_f64::shape::SharedShape),
    D3(parry3d_f64::math::Pose, parry3d_f64::shape::SharedShape),
}

fn parts<const D: usize>(g: &Placed<D>) -> Vec<ParryPart> {
    let c = g.centre;
    match &g.grain.geometry {
        Geometry::Swept(e) => e
            .iter()
            .map(|s| {
                if D == 2 {
                    let pose = parry2d_f64::math::Pose::translation(c[0], c[1]);
                    let a = parry2d_f64::math::Vector::new(s.a[0], s.a[1]);
                    let b = parry2d_f64::math::Vector::new(s.b[0], s.b[1]);
                    let sh = if s.a == s.b {
                        parry2d_f64::shape::SharedShape::ball(s.radius)
                    } else {
                        parry2d_f64::shape::SharedShape::capsule(a, b, s.radius)
                    };
                    let pose = if s.a == s.b {
                        parry2d_f64::math::Pose::translation(c[0] + s.a[0], c[1] + s.a[1])
                    } else {
                        pose
                    };
                    ParryPart::D2(pose, sh)
                } else {
                    let a = parry3d_f64::math::Vector::new(s.a[0], s.a[1], s.a[2]);
                    let b = parry3d_f64::math::Vector::new(s.b[0], s.b[1], s.b[2]);
                    if s.a == s.b {
                        ParryPart::D3(
                            parry3d_f64::math::Pose::translation(
                                c[0] + s.a[0],
                                c[1] + s.a[1],
                                c[2] + s.a[2],
                            ),
                            parry3d_f64::shape::SharedShape::ball(s.radius),
                        )
                    } else {
                        ParryPart::D3(
                            parry3d_f64::math::Pose::translation(c[0], c[1], c[2]),
                            parry3d_f64::shape::SharedShape::capsule(a, b, s.radius),
                        )
                    }
                }
            })
            .collect(),
        Geometry::Convex { shape, .. } => match shape {
            ParryConvex::Polygon(poly) => vec![ParryPart::D2(
                parry2d_f64::math::Pose::translation(c[0], c[1]),
                parry2d_f64::shape::SharedShape::new(poly.as_ref().clone()),
            )],
            ParryConvex::Polyhedron(poly) => vec![ParryPart::D3(
                parry3d_f64::math::Pose::translation(c[0], c[1], c[2]),
                parry3d_f64::shape::SharedShape::new(poly.as_ref().clone()),
            )],
        },
    }
}

fn parts_aabb(parts: &[ParryPart]) -> Vec<([f64; 3], [f64; 3])> {
    parts
        .iter()
        .map(|p| match p {
            ParryPart::D2(pose, s) => {
                let b = s.compute_aabb(pose);
                ([b.mins.x, b.mins.y, 0.0], [b.maxs.x, b.maxs.y, 0.0])
            }
            ParryPart::D3(pose, s) => {
                let b = s.compute_aabb(pose);
                (
                    [b.mins.x, b.mins.y, b.mins.z],
                    [b.maxs.x, b.maxs.y, b.maxs.z],
                )
            }
        })
        .collect()
}

/// Smallest signed gap between two grains by parry (`d` sets the contact
/// prediction distance).
fn pair_gap(a: &[ParryPart], b: &[ParryPart], d: f64) -> f64 {
    let mut g = f64::INFINITY;
    for pa in a {
        for pb in b {
            let v = match (pa, pb) {
                (ParryPart::D2(p1, s1), ParryPart::D2(p2, s2)) => {
                    parry2d_f64::query::contact(p1, s1.as_ref(), p2, s2.as_ref(), d)
                        .ok()
                        .flatten()
                        .map(|c| c.dist)
                }
                (ParryPart::D3(p1, s1), ParryPart::D3(p2, s2)) => {
                    parry3d_f64::query::contact(p1, s1.as_ref(), p2, s2.as_ref(), d)
                        .ok()
                        .flatten()
                        .map(|c| c.dist)
                }
                _ => None,
            };
            g = g.min(v.unwrap_or(d));
        }
    }
    g
}
