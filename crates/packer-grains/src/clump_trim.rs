//! Clumps of a packing made a valid DEM start: [`separate_clumps`] trims the spheres of
//! multi-sphere clumps (e.g. `levelset::clump` of packed grains) that reach into a
//! neighbouring grain's spheres or through a wall.

use nalgebra::{Isometry3, Point3};

use crate::error::{Error, Result};
use packer_spheres::Container;

/// Radius trimming of [`separate_clumps`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ClumpTrim {
    /// Sphere pairs of different clumps that overlapped.
    pub pairs: usize,
    /// Worst of those overlaps over the smaller sphere's diameter.
    pub worst: f64,
    /// Spheres that crossed a wall.
    pub walls: usize,
    /// Spheres whose radius was trimmed.
    pub trimmed: usize,
    /// Largest relative radius reduction.
    pub max_cut: f64,
    /// Relative change of the summed sphere volumes.
    pub volume_change: f64,
}

/// Makes the clumps of a grain packing a valid DEM start: the clumps
/// approximate the level sets (their radii are offset to match each
/// grain's volume), so their spheres may reach past a grain's surface,
/// across the margin the packer leaves and into a neighbour's spheres or a
/// wall. Every sphere of a pair of different grains that overlaps by `δ`
/// loses `δ/2` (plus 1e-9 of its radius) of radius — the largest cut any of
/// its pairs asks, so one pass leaves no overlap — and a sphere crossing a
/// wall is cut to its clearance. Grains that copy one shape (`template_of`)
/// share its clump: a shape's sphere takes the largest cut over all its
/// copies, so every copy stays one rigid template. Spheres of one clump keep
/// overlapping each other (they are one rigid body). A uniform cell grid of
/// sphere centres (cell = the largest diameter): O(spheres).
///
/// # Errors
/// [`Error::ClumpTrimTooDeep`] for a sphere that would lose more than 90 % of its radius
/// (the packing is not one a clump of this size can follow); [`Error::NonFinite`] for a
/// non-finite pose, [`Error::NonPositive`] for a non-positive or non-finite sphere,
/// [`Error::Parameter`] for a pose whose shape index is out of range.
pub fn separate_clumps(
    shapes: &mut [Vec<(Point3<f64>, f64)>],
    poses: &[Isometry3<f64>],
    shape_of: impl Fn(usize) -> usize,
    container: &Container,
) -> Result<ClumpTrim> {
    // every sphere of every grain in the world: (centre, radius, grain, template, sphere)
    let spheres: Vec<(Point3<f64>, f64, usize, usize, usize)> = poses
        .iter()
        .enumerate()
        .flat_map(|(g, pose)| {
            let t = shape_of(g);
            shapes[t]
                .iter()
                .enumerate()
                .map(move |(m, (c, r))| (pose * c, *r, g, t, m))
        })
        .collect();
    for (k, p) in poses.iter().enumerate() {
        if !p.translation.vector.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFinite {
                what: "pose translation",
                value: p
                    .translation
                    .vector
                    .iter()
                    .copied()
                    .find(|v| !v.is_finite())
                    .unwrap_or(f64::NAN),
            });
        }
        if shape_of(k) >= shapes.len() {
            return Err(Error::Parameter {
                what: "shape index of a pose",
                value: shape_of(k) as f64,
                range: "below the number of shapes",
            });
        }
    }
    for s in shapes.iter() {
        for (c, r) in s {
            if !(r.is_finite() && *r > 0.0 && c.coords.iter().all(|v| v.is_finite())) {
                return Err(Error::NonPositive {
                    what: "clump sphere radius",
                    value: *r,
                });
            }
        }
    }
    let mut trim = ClumpTrim::default();
    let Some(r_max) = spheres.iter().map(|s| s.1).reduce(f64::max) else {
        return Ok(trim);
    };
    let cell = 2.0 * r_max;
    let key = |p: &Point3<f64>| {
        [
            (p.x / cell).floor() as i64,
            (p.y / cell).floor() as i64,
            (p.z / cell).floor() as i64,
        ]
    };
    let mut grid: std::collections::BTreeMap<[i64; 3], Vec<usize>> =
        std::collections::BTreeMap::new();
    for (i, s) in spheres.iter().enumerate() {
        grid.entry(key(&s.0)).or_default().push(i);
    }
    let mut cut = vec![0.0_f64; spheres.len()];
    for (i, a) in spheres.iter().enumerate() {
        let clear = container.clearance(&a.0);
        if clear < a.1 {
            trim.walls += 1;
            cut[i] = cut[i].max(a.1 - clear + 1e-9 * a.1);
        }
        let k = key(&a.0);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                        continue;
                    };
                    for &j in list {
                        let b = &spheres[j];
                        if j <= i || b.2 == a.2 {
                            continue;
                        }
                        let overlap = a.1 + b.1 - (a.0 - b.0).norm();
                        if overlap > 0.0 {
                            trim.pairs += 1;
                            trim.worst = trim.worst.max(overlap / (2.0 * a.1.min(b.1)));
                            cut[i] = cut[i].max(0.5 * overlap + 1e-9 * a.1);
                            cut[j] = cut[j].max(0.5 * overlap + 1e-9 * b.1);
                        }
                    }
                }
            }
        }
    }
    // a shape's sphere takes the largest cut over its copies
    let mut shape_cut: Vec<Vec<f64>> = shapes.iter().map(|t| vec![0.0; t.len()]).collect();
    for (i, s) in spheres.iter().enumerate() {
        let c = &mut shape_cut[s.3][s.4];
        *c = c.max(cut[i]);
    }
    let (mut before, mut after) = (0.0, 0.0);
    for (t, tpl) in shapes.iter_mut().enumerate() {
        for (m, (_, r)) in tpl.iter_mut().enumerate() {
            before += r.powi(3);
            let c = shape_cut[t][m];
            if c > 0.0 {
                let rel = c / *r;
                if rel > 0.9 {
                    return Err(Error::ClumpTrimTooDeep {
                        shape: t,
                        radius: *r,
                        percent: 100.0 * rel,
                    });
                }
                trim.trimmed += 1;
                trim.max_cut = trim.max_cut.max(rel);
                *r -= c;
            }
            after += r.powi(3);
        }
    }
    trim.volume_change = after / before - 1.0;
    Ok(trim)
}
