//! Clumps of a packing made a valid DEM start: [`separate_clumps`] trims the spheres of
//! multi-sphere clumps (e.g. `levelset::clump` of packed grains) that reach into a
//! neighbouring grain's spheres or through a wall.

use std::collections::BTreeMap;

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
    check_poses(shapes.len(), poses, &shape_of)?;
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
    let spheres = world_spheres(shapes, poses, &shape_of);
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

/// Gap closing of [`close_clump_gaps`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ClumpReach {
    /// Pairs of different grains whose clumps were closer than the reach
    /// (and not touching) before.
    pub near_pairs: usize,
    /// Of those, pairs left closer than 1e-3 of the reach after.
    pub closed_pairs: usize,
    /// Spheres whose radius grew.
    pub grown: usize,
    /// Largest radius growth over the reach.
    pub max_growth: f64,
    /// Relative change of the summed sphere volumes.
    pub volume_change: f64,
}

/// Passes of [`close_clump_gaps`]: each closes at least half of a gap both of
/// whose spheres have it as their nearest.
const REACH_PASSES: usize = 10;

/// Closes the small gaps between the clumps of a packing whose grains rest on
/// each other (a settled packing): a clump approximates its grain's surface
/// and the packer keeps a margin, so clumps of grains in contact stand a few
/// hundredths of a diameter apart, and a DEM code's gravity closes those gaps
/// layer by layer (a settled bed compacts by the sum of them). For every pair
/// of grains whose clumps come closer than `reach`, the two spheres of its
/// closest approach grow by half of their nearest gap to any other grain's
/// sphere (never into a wall), in 10 passes, so that no pair
/// can come to overlap (each side takes at most half of every gap) and the
/// closest spheres of the pair end touching; so does every sphere closer
/// than `reach` to a wall (the walls carry a narrow container's grains as
/// much as the floor does); only those spheres grow; grains that copy one shape
/// grow its sphere by the smallest growth any copy allows. Gaps wider than
/// `reach` are left alone. Run after [`separate_clumps`].
///
/// # Errors
/// As [`separate_clumps`]; [`Error::Parameter`] for a `reach` that is not
/// positive and finite.
pub fn close_clump_gaps(
    shapes: &mut [Vec<(Point3<f64>, f64)>],
    poses: &[Isometry3<f64>],
    shape_of: impl Fn(usize) -> usize,
    container: &Container,
    reach: f64,
) -> Result<ClumpReach> {
    if !(reach.is_finite() && reach > 0.0) {
        return Err(Error::Parameter {
            what: "clump gap reach",
            value: reach,
            range: "(0, inf)",
        });
    }
    check_poses(shapes.len(), poses, &shape_of)?;
    let before: f64 = shapes.iter().flatten().map(|(_, r)| r.powi(3)).sum();
    let mut out = ClumpReach::default();
    let mut grown: Vec<Vec<f64>> = shapes.iter().map(|s| vec![0.0; s.len()]).collect();
    let mut first = None;
    for pass in 0..=REACH_PASSES {
        let spheres = world_spheres(shapes, poses, &shape_of);
        let scan = GapScan::new(&spheres, reach);
        let first = first.get_or_insert_with(|| scan.pair_gap.clone());
        let any =
            pass < REACH_PASSES && grow(shapes, &mut grown, &spheres, &scan, container, reach);
        if !any {
            let near = |g: &f64| *g > 1e-9 * reach;
            out.near_pairs = first.values().filter(|g| near(g)).count();
            out.closed_pairs = first
                .iter()
                .filter(|(k, g)| near(g) && scan.pair_gap.get(k).is_some_and(|a| *a < 1e-3 * reach))
                .count();
            break;
        }
    }
    for g in grown.iter().flatten() {
        if *g > 0.0 {
            out.grown += 1;
            out.max_growth = out.max_growth.max(g / reach);
        }
    }
    let after: f64 = shapes.iter().flatten().map(|(_, r)| r.powi(3)).sum();
    out.volume_change = after / before - 1.0;
    Ok(out)
}

/// Finite pose translations, and a shape index below `shapes` for every pose.
fn check_poses(
    shapes: usize,
    poses: &[Isometry3<f64>],
    shape_of: &impl Fn(usize) -> usize,
) -> Result<()> {
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
        if shape_of(k) >= shapes {
            return Err(Error::Parameter {
                what: "shape index of a pose",
                value: shape_of(k) as f64,
                range: "below the number of shapes",
            });
        }
    }
    Ok(())
}

/// A world sphere: centre, radius, grain, shape, sphere of the shape.
type WorldSphere = (Point3<f64>, f64, usize, usize, usize);

/// Every sphere of every grain in the world frame.
fn world_spheres(
    shapes: &[Vec<(Point3<f64>, f64)>],
    poses: &[Isometry3<f64>],
    shape_of: &impl Fn(usize) -> usize,
) -> Vec<WorldSphere> {
    poses
        .iter()
        .enumerate()
        .flat_map(|(g, pose)| {
            let t = shape_of(g);
            shapes[t]
                .iter()
                .enumerate()
                .map(move |(m, (c, r))| (pose * c, *r, g, t, m))
        })
        .collect()
}

/// Gaps between spheres of different grains (a cell grid of the centres).
struct GapScan {
    /// Nearest gap of every sphere to another grain's spheres.
    nearest: Vec<f64>,
    /// Smallest gap of every grain pair (lower index first) closer than the reach.
    pair_gap: BTreeMap<(usize, usize), f64>,
    /// Its sphere pair: (gap, sphere, sphere).
    pair_at: BTreeMap<(usize, usize), (f64, usize, usize)>,
}

impl GapScan {
    fn new(spheres: &[WorldSphere], reach: f64) -> Self {
        let mut scan = Self {
            nearest: vec![f64::INFINITY; spheres.len()],
            pair_gap: BTreeMap::new(),
            pair_at: BTreeMap::new(),
        };
        let Some(r_max) = spheres.iter().map(|s| s.1).reduce(f64::max) else {
            return scan;
        };
        let cell = 2.0 * r_max + reach;
        let key = |p: &Point3<f64>| {
            [
                (p.x / cell).floor() as i64,
                (p.y / cell).floor() as i64,
                (p.z / cell).floor() as i64,
            ]
        };
        let mut grid: BTreeMap<[i64; 3], Vec<usize>> = BTreeMap::new();
        for (i, s) in spheres.iter().enumerate() {
            grid.entry(key(&s.0)).or_default().push(i);
        }
        for (i, a) in spheres.iter().enumerate() {
            let k = key(&a.0);
            for d in 0..27_i64 {
                let cell = [k[0] + d % 3 - 1, k[1] + (d / 3) % 3 - 1, k[2] + d / 9 - 1];
                for &j in grid.get(&cell).map_or(&[][..], Vec::as_slice) {
                    let b = &spheres[j];
                    if b.2 == a.2 {
                        continue;
                    }
                    let gap = (a.0 - b.0).norm() - a.1 - b.1;
                    scan.nearest[i] = scan.nearest[i].min(gap);
                    if gap < reach {
                        let pair = (a.2.min(b.2), a.2.max(b.2));
                        let v = scan.pair_gap.entry(pair).or_insert(f64::INFINITY);
                        *v = v.min(gap);
                        let e = scan.pair_at.entry(pair).or_insert((f64::INFINITY, i, j));
                        if i < j && gap < e.0 {
                            *e = (gap, i, j);
                        }
                    }
                }
            }
        }
        scan
    }
}

/// One pass of [`close_clump_gaps`]: the spheres of each near pair's closest
/// approach and every sphere within reach of a wall grow by what every copy
/// of their shape allows; whether any grew.
fn grow(
    shapes: &mut [Vec<(Point3<f64>, f64)>],
    grown: &mut [Vec<f64>],
    spheres: &[WorldSphere],
    scan: &GapScan,
    container: &Container,
    reach: f64,
) -> bool {
    // growth each shape's sphere may take: the smallest over its copies
    let mut allow: Vec<Vec<f64>> = shapes
        .iter()
        .map(|s| vec![f64::INFINITY; s.len()])
        .collect();
    let mut want: Vec<Vec<bool>> = shapes.iter().map(|s| vec![false; s.len()]).collect();
    let open = |gap: f64| gap > 1e-9 * reach && gap.is_finite();
    for (i, a) in spheres.iter().enumerate() {
        let wall = container.clearance(&a.0) - a.1;
        let cap = &mut allow[a.3][a.4];
        *cap = cap.min((0.5 * scan.nearest[i]).min(wall).max(0.0));
        // every sphere within reach of a wall (floor, side walls, lid)
        if wall < reach && open(wall) {
            want[a.3][a.4] = true;
        }
    }
    for &(gap, i, j) in scan.pair_at.values() {
        if open(gap) {
            for k in [i, j] {
                want[spheres[k].3][spheres[k].4] = true;
            }
        }
    }
    let mut any = false;
    for (t, tpl) in shapes.iter_mut().enumerate() {
        for (m, (_, r)) in tpl.iter_mut().enumerate() {
            let g = allow[t][m];
            if want[t][m] && g.is_finite() && g > 0.0 {
                *r += g;
                grown[t][m] += g;
                any = true;
            }
        }
    }
    any
}
