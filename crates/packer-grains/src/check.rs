//! Independent overlap check of a grain packing on level-set grids
//! (LS-DEM style), with a 4×-finer raster cross-check of the closest pairs.
//!
//! Independent of the packer: its own neighbour search (centres sorted by
//! z, scanned within reach), its own nodes (a Fibonacci direction set of
//! [`CheckParams::nodes`] per grain, started on the star surface and pushed
//! onto the zero of the grain's own rasterised level set by Newton steps on
//! [`levelset::Grid::sample`]), and the neighbours' level sets built by
//! [`levelset::Grid::from_star_table`] at [`CheckParams::resolution`]³ over
//! `±1.1 r_max` in the body frame. Streamed: pass 1 builds each grid, takes
//! its nodes (kept in the body frame as f32) and drops it; pass 2 builds each
//! grid again and samples every neighbour's nodes in it, so only one grid per
//! worker thread is alive. A node overlaps when `φ < −tolerance·d_eq` of the
//! grid's grain; nodes are also checked against the walls.
//!
//! Cross-check: the [`CheckParams::raster_pairs`] pairs with the smallest
//! `φ` are rasterised together on a common grid of spacing `h / refine` (`h`
//! the finer of their check grids' spacings) over the intersection of their
//! node bounding boxes; a voxel centre inside both star surfaces (`|p| <
//! r(p̂)` in each body frame) is an overlap voxel (must be none).
//!
//! Periodic cells ([`check_grain_overlaps_in`]): the centres are wrapped
//! into the cell and every grain within two bounding radii of a periodic
//! face is copied as an image beyond the opposite face (its own copies,
//! not the packer's neighbour lists; wrapping and wall clearance are the
//! shared `Region`'s); a pair meeting through an image is checked with the
//! image's position, and counted in [`GrainOverlapReport::periodic_pairs`].

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::region::Region;
use super::{StarGrain, fibonacci};
use crate::error::{Error, Result, finite, positive};
use levelset::{DirectionTable, Grid, GridSpec, StarParams};
use packer_spheres::{Boundary, Container};

/// Parameters of [`check_grain_overlaps`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckParams {
    /// Nodes per grain side of the level sets (≥ 8; e.g. 32–45).
    pub resolution: usize,
    /// Surface nodes per grain (≥ 1).
    pub nodes: usize,
    /// Relative tolerance: a node overlaps when `φ < −tolerance · d_eq`.
    pub tolerance: f64,
    /// Closest pairs rasterised for the cross-check.
    pub raster_pairs: usize,
    /// Refinement of the cross-check raster over the check grids (≥ 1).
    pub refine: usize,
}

impl Default for CheckParams {
    fn default() -> Self {
        Self {
            resolution: 32,
            nodes: 1000,
            tolerance: 1e-6,
            raster_pairs: 16,
            refine: 4,
        }
    }
}

/// Result of [`check_grain_overlaps`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrainOverlapReport {
    /// Grains checked.
    pub grains: usize,
    /// Pairs whose bounding spheres meet.
    pub pairs: usize,
    /// Of those, pairs that meet across a periodic face.
    pub periodic_pairs: usize,
    /// Node samples taken in a neighbour's level set.
    pub nodes_checked: u64,
    /// Smallest `φ_neighbour(node) / d_eq(neighbour)` (`+inf` without samples).
    pub worst_phi_over_d: f64,
    /// The pair `(grain of the node, grain of the level set)` where it occurs.
    pub worst_pair: Option<(usize, usize)>,
    /// Nodes with `φ < −tolerance · d_eq`.
    pub overlapping_nodes: u64,
    /// Smallest wall clearance of a node over its grain's `d_eq`.
    pub worst_wall_over_d: f64,
    /// Nodes with a wall clearance below `−tolerance · d_eq`.
    pub nodes_outside: u64,
    /// Largest `|φ_own(node)| / d_eq` after the push onto the zero.
    pub node_residual_over_d: f64,
    /// Pairs rasterised for the cross-check.
    pub raster_pairs: usize,
    /// Voxels evaluated in the cross-check.
    pub raster_voxels: u64,
    /// Voxels inside both grains of a pair (must be 0).
    pub raster_overlap_voxels: u64,
}

impl GrainOverlapReport {
    /// No overlapping node, no node outside, no overlap voxel.
    pub fn is_clean(&self) -> bool {
        self.overlapping_nodes == 0 && self.nodes_outside == 0 && self.raster_overlap_voxels == 0
    }
}

fn check_grid(g: &StarGrain, resolution: usize) -> Result<Grid> {
    let half = 1.1 * g.r_max();
    let spec = GridSpec::cube(resolution, -half, half).map_err(Error::StarTable)?;
    let params = StarParams {
        table: DirectionTable::CubeMap {
            face_cells: g.face_cells(),
        },
        ..StarParams::default()
    };
    let (grid, _) = Grid::from_star_table(spec, &Point3::origin(), &g.table_radii(), &params)
        .map_err(Error::StarTable)?;
    Ok(grid)
}

/// Checks a grain packing in a container (see the module docs):
/// [`check_grain_overlaps_in`] with the container's walls.
///
/// # Errors
/// As [`check_grain_overlaps_in`].
pub fn check_grain_overlaps(
    grains: &[StarGrain],
    poses: &[Isometry3<f64>],
    container: &Container,
    params: &CheckParams,
) -> Result<GrainOverlapReport> {
    check_grain_overlaps_in(grains, poses, &Boundary::Walls(container.clone()), params)
}

/// Checks a grain packing in a container or a periodic cell (see the
/// module docs); periodic faces are not walls, pairs across them are
/// checked through images.
///
/// # Errors
/// [`Error::Empty`] without grains; [`Error::Parameter`] for bad
/// parameters or a pose count that differs from the grain count;
/// [`Error::NonFinite`] for a non-finite pose; boundary validation errors;
/// [`Error::DomainTooSmall`] for a periodic side shorter than three
/// bounding diameters of the largest grain; levelset errors
/// ([`Error::StarTable`]) from the rasterisation.
pub fn check_grain_overlaps_in(
    grains: &[StarGrain],
    poses: &[Isometry3<f64>],
    boundary: &Boundary,
    params: &CheckParams,
) -> Result<GrainOverlapReport> {
    let region = validate_input(grains, poses, boundary, params)?;
    let n = grains.len();
    let rots: Vec<Matrix3<f64>> = poses
        .iter()
        .map(|p| p.rotation.to_rotation_matrix().into_inner())
        .collect();
    let cs: Vec<Vector3<f64>> = poses
        .iter()
        .map(|p| region.wrap(&p.translation.vector))
        .collect();
    let d_eq: Vec<f64> = grains.iter().map(StarGrain::equivalent_diameter).collect();
    let nbrs = neighbours(grains, &cs, &region);
    let pairs = nbrs.iter().map(Vec::len).sum::<usize>() / 2;
    let periodic_pairs = nbrs
        .iter()
        .flatten()
        .filter(|(_, s)| *s != Vector3::zeros())
        .count()
        / 2;
    let dirs = fibonacci(params.nodes);
    let mut ck = Checker {
        grains,
        params,
        region: &region,
        rots,
        cs,
        d_eq,
        nbrs,
        dirs,
        nodes: Vec::new(),
    };

    // Pass 1: own grid, nodes pushed onto its zero, wall clearances.
    let pass1: Vec<(Vec<[f32; 3]>, f64, f64, u64)> = (0..n)
        .into_par_iter()
        .with_min_len(8)
        .map(|i| ck.surface_nodes(i))
        .collect::<Result<_>>()?;
    let mut report = GrainOverlapReport {
        grains: n,
        pairs,
        periodic_pairs,
        nodes_checked: 0,
        worst_phi_over_d: f64::INFINITY,
        worst_pair: None,
        overlapping_nodes: 0,
        worst_wall_over_d: f64::INFINITY,
        nodes_outside: 0,
        node_residual_over_d: 0.0,
        raster_pairs: 0,
        raster_voxels: 0,
        raster_overlap_voxels: 0,
    };
    for p in &pass1 {
        report.node_residual_over_d = report.node_residual_over_d.max(p.1);
        report.worst_wall_over_d = report.worst_wall_over_d.min(p.2);
        report.nodes_outside += p.3;
    }
    ck.nodes = pass1.into_iter().map(|p| p.0).collect();
    let ck = &ck;

    // Pass 2: each grid again; every neighbour's nodes sampled in it.
    let pass2: Vec<Pass2> = (0..n)
        .into_par_iter()
        .with_min_len(8)
        .map(|j| ck.sample_neighbours(j))
        .collect::<Result<_>>()?;
    let mut minima: Vec<Minimum> = Vec::new();
    for (j, p) in pass2.iter().enumerate() {
        report.nodes_checked += p.0;
        report.overlapping_nodes += p.1;
        if p.2 < report.worst_phi_over_d {
            report.worst_phi_over_d = p.2;
            report.worst_pair = Some((p.3, j));
        }
        minima.extend(p.4.iter().copied());
    }
    let chosen = closest_pairs(minima, params.raster_pairs);
    let raster: Vec<(u64, u64)> = chosen
        .par_iter()
        .map(|&(a, b, shift)| ck.raster_pair(a, b, shift))
        .collect();
    report.raster_pairs = chosen.len();
    for (v, b) in raster {
        report.raster_voxels += v;
        report.raster_overlap_voxels += b;
    }
    Ok(report)
}

/// Validates the input of [`check_grain_overlaps_in`] (in the order of its
/// documented errors) and returns the boundary's region.
fn validate_input<'a>(
    grains: &[StarGrain],
    poses: &[Isometry3<f64>],
    boundary: &'a Boundary,
    params: &CheckParams,
) -> Result<Region<'a>> {
    if grains.is_empty() {
        return Err(Error::Empty { what: "grain list" });
    }
    // (a grain the container cannot hold is not refused: its nodes outside
    // the walls are what the report counts)
    let largest = grains.iter().map(|g| 2.0 * g.r_max()).fold(0.0, f64::max);
    super::validate_boundary(boundary)?;
    super::check_periodic_sides(boundary, largest)?;
    let region = Region::new(boundary);
    if poses.len() != grains.len() {
        return Err(Error::Parameter {
            what: "pose count",
            value: poses.len() as f64,
            range: "equal to the grain count",
        });
    }
    if params.resolution < 8 || params.resolution > 256 {
        return Err(Error::Parameter {
            what: "resolution",
            value: params.resolution as f64,
            range: "[8, 256]",
        });
    }
    if params.nodes == 0 || params.refine == 0 {
        return Err(Error::Parameter {
            what: "nodes / refine",
            value: 0.0,
            range: "[1, inf)",
        });
    }
    positive("tolerance", params.tolerance)?;
    for p in poses {
        for v in p.translation.vector.iter().chain(p.rotation.coords.iter()) {
            finite("pose", *v)?;
        }
    }
    Ok(region)
}

/// A pair's smallest `φ/d`, its lower grain, upper grain, and the shift of
/// the upper grain's image relative to the lower one.
type Minimum = (f64, usize, usize, [f64; 3]);

/// Per grid `j` of pass 2: samples, overlapping samples, worst `φ/d`, the
/// grain of that node, and the per-pair minima.
type Pass2 = (u64, u64, f64, usize, Vec<Minimum>);

/// The wrapped poses, neighbour lists and nodes shared by the passes of
/// [`check_grain_overlaps_in`].
struct Checker<'a> {
    grains: &'a [StarGrain],
    params: &'a CheckParams,
    region: &'a Region<'a>,
    rots: Vec<Matrix3<f64>>,
    cs: Vec<Vector3<f64>>,
    d_eq: Vec<f64>,
    nbrs: Vec<Vec<(usize, Vector3<f64>)>>,
    dirs: Vec<Vector3<f64>>,
    /// Body-frame nodes of every grain (after pass 1).
    nodes: Vec<Vec<[f32; 3]>>,
}

impl Checker<'_> {
    /// Node `k` of grain `i` in its body frame.
    fn node(&self, i: usize, k: usize) -> Vector3<f64> {
        let q = self.nodes[i][k];
        Vector3::new(f64::from(q[0]), f64::from(q[1]), f64::from(q[2]))
    }

    /// Pass 1 for grain `i`: its nodes pushed onto the zero of its own
    /// grid, the largest residual `|φ|/d`, the smallest wall clearance over
    /// `d` and the count of nodes outside.
    fn surface_nodes(&self, i: usize) -> Result<(Vec<[f32; 3]>, f64, f64, u64)> {
        let g = &self.grains[i];
        let d_eq = &self.d_eq;
        let grid = check_grid(g, self.params.resolution)?;
        let mut nodes = Vec::with_capacity(self.dirs.len());
        let (mut resid, mut wall, mut outside) = (0.0_f64, f64::INFINITY, 0);
        for u in &self.dirs {
            let (t, phi) = onto_zero(g, &grid, u, d_eq[i]);
            let p = u * t;
            resid = resid.max(phi.abs() / d_eq[i]);
            let cl = self
                .region
                .clearance(&Point3::from(self.rots[i] * p + self.cs[i]))
                / d_eq[i];
            wall = wall.min(cl);
            if cl < -self.params.tolerance {
                outside += 1;
            }
            nodes.push([p.x as f32, p.y as f32, p.z as f32]);
        }
        Ok((nodes, resid, wall, outside))
    }

    /// Pass 2 for grid `j`: every neighbour's nodes sampled in it.
    fn sample_neighbours(&self, j: usize) -> Result<Pass2> {
        let (rots, cs, d_eq) = (&self.rots, &self.cs, &self.d_eq);
        let gj = &self.grains[j];
        let grid = check_grid(gj, self.params.resolution)?;
        let (mut samples, mut bad, mut worst, mut worst_i) = (0, 0, f64::INFINITY, j);
        let mut minima = Vec::with_capacity(self.nbrs[j].len());
        let rt = rots[j].transpose();
        let r2 = (gj.r_max() * (1.0 + 1e-9)).powi(2);
        for &(i, shift) in &self.nbrs[j] {
            let m = rt * rots[i];
            let t = rt * (cs[i] + shift - cs[j]);
            let mut pair_min = f64::INFINITY;
            for k in 0..self.dirs.len() {
                let q = m * self.node(i, k) + t;
                if q.norm_squared() > r2 {
                    continue;
                }
                let Some((phi, _)) = grid.sample(&q.into()) else {
                    continue;
                };
                samples += 1;
                let v = phi / d_eq[j];
                pair_min = pair_min.min(v);
                if v < -self.params.tolerance {
                    bad += 1;
                }
                if v < worst {
                    worst = v;
                    worst_i = i;
                }
            }
            // the upper grain's image relative to the lower one
            let up = if i > j { shift } else { -shift };
            minima.push((pair_min, i.min(j), i.max(j), [up.x, up.y, up.z]));
        }
        Ok((samples, bad, worst, worst_i, minima))
    }

    /// The cross-check of pair `(a, b)` (`b` at its image `shift` next to
    /// `a`): voxels evaluated and voxels inside both grains.
    fn raster_pair(&self, a: usize, b: usize, shift: Vector3<f64>) -> (u64, u64) {
        let (grains, params, rots, cs) = (self.grains, self.params, &self.rots, &self.cs);
        // b at its image next to a
        let at = |i: usize| if i == b { cs[b] + shift } else { cs[i] };
        let h = [a, b]
            .iter()
            .map(|&i| 2.2 * grains[i].r_max() / (params.resolution - 1) as f64)
            .fold(f64::INFINITY, f64::min)
            / params.refine as f64;
        let bbox = |i: usize| {
            let mut lo = Vector3::repeat(f64::INFINITY);
            let mut hi = Vector3::repeat(f64::NEG_INFINITY);
            for k in 0..self.dirs.len() {
                let x = rots[i] * self.node(i, k) + at(i);
                lo = lo.inf(&x);
                hi = hi.sup(&x);
            }
            (lo.add_scalar(-h), hi.add_scalar(h))
        };
        let ((la, ha), (lb, hb)) = (bbox(a), bbox(b));
        let (lo, hi) = (la.sup(&lb), ha.inf(&hb));
        let mut dims = [0usize; 3];
        for k in 0..3 {
            if hi[k] <= lo[k] {
                return (0, 0);
            }
            dims[k] = (((hi[k] - lo[k]) / h).ceil() as usize).clamp(1, 512);
        }
        let step = Vector3::new(
            (hi.x - lo.x) / dims[0] as f64,
            (hi.y - lo.y) / dims[1] as f64,
            (hi.z - lo.z) / dims[2] as f64,
        );
        let (ra, rb) = (rots[a].transpose(), rots[b].transpose());
        let (mut voxels, mut both) = (0, 0);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let p = lo
                        + Vector3::new(
                            (x as f64 + 0.5) * step.x,
                            (y as f64 + 0.5) * step.y,
                            (z as f64 + 0.5) * step.z,
                        );
                    voxels += 1;
                    if grains[a].contains(&(ra * (p - at(a))))
                        && grains[b].contains(&(rb * (p - at(b))))
                    {
                        both += 1;
                    }
                }
            }
        }
        (voxels, both)
    }
}

/// The node of direction `u` on the zero of `grid` (grain `g`, `d_eq` = `d`):
/// radial Newton on `φ(t·u)` from the star radius, then bisection on the
/// bracket `[0, 1.1 r_max]` if it stalls. Returns `t` and `φ` there.
fn onto_zero(g: &StarGrain, grid: &Grid, u: &Vector3<f64>, d: f64) -> (f64, f64) {
    let phi_at = |t: f64| grid.sample(&(u * t).into());
    let mut t = g.radius(u);
    let mut phi = f64::INFINITY;
    for _ in 0..6 {
        let Some((v, grad)) = phi_at(t) else {
            break;
        };
        phi = v;
        let slope = grad.dot(u);
        if v.abs() < 1e-9 * d || slope <= 0.1 {
            break;
        }
        t = (t - v / slope).clamp(0.0, 1.1 * g.r_max());
    }
    if let Some((v, _)) = phi_at(t) {
        phi = v;
    }
    if phi.is_nan() || phi.abs() >= 1e-7 * d {
        let (mut lo, mut hi) = (0.0, 1.1 * g.r_max() * (1.0 - 1e-9));
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            match phi_at(mid) {
                Some((v, _)) if v < 0.0 => lo = mid,
                _ => hi = mid,
            }
        }
        // The outer end of the bracket: never inside the grain.
        t = hi;
        phi = phi_at(t).map_or(0.0, |x| x.0);
    }
    (t, phi)
}

/// The `count` closest pairs (each unordered pair once, by its smaller
/// minimum), with the shift of the upper grain's image.
fn closest_pairs(mut minima: Vec<Minimum>, count: usize) -> Vec<(usize, usize, Vector3<f64>)> {
    minima.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut chosen: Vec<(usize, usize, Vector3<f64>)> = Vec::new();
    for &(_, a, b, s) in &minima {
        if chosen.len() >= count {
            break;
        }
        if !chosen.iter().any(|c| (c.0, c.1) == (a, b)) {
            chosen.push((a, b, Vector3::from(s)));
        }
    }
    chosen
}

/// For every grain, the grains whose bounding spheres meet its own (both
/// directions), each with the shift of the image it meets through (zero
/// within the cell), by a sweep over the centres and their images sorted
/// by z.
fn neighbours(
    grains: &[StarGrain],
    cs: &[Vector3<f64>],
    region: &Region<'_>,
) -> Vec<Vec<(usize, Vector3<f64>)>> {
    let ((lo, hi), period) = (region.bbox(), region.period());
    let n = grains.len();
    let r_all = grains.iter().map(StarGrain::r_max).fold(0.0_f64, f64::max);
    // images: every combination of shifts by ± a side towards the faces a
    // centre is within 2 r_all of
    let mut ext: Vec<(usize, Vector3<f64>)> = (0..n).map(|i| (i, Vector3::zeros())).collect();
    for (i, c) in cs.iter().enumerate() {
        let mut options: Vec<Vector3<f64>> = vec![Vector3::zeros()];
        for k in 0..3 {
            if !period[k] {
                continue;
            }
            let l = hi[k] - lo[k];
            let s = if c[k] - lo[k] < 2.0 * r_all {
                l
            } else if hi[k] - c[k] < 2.0 * r_all {
                -l
            } else {
                continue;
            };
            let more: Vec<Vector3<f64>> = options
                .iter()
                .map(|o| {
                    let mut v = *o;
                    v[k] = s;
                    v
                })
                .collect();
            options.extend(more);
        }
        ext.extend(options.into_iter().skip(1).map(|s| (i, s)));
    }
    let pos = |e: &(usize, Vector3<f64>)| cs[e.0] + e.1;
    let mut order: Vec<usize> = (0..ext.len()).collect();
    order.sort_by(|&a, &b| pos(&ext[a]).z.total_cmp(&pos(&ext[b]).z).then(a.cmp(&b)));
    let zs: Vec<f64> = order.iter().map(|&e| pos(&ext[e]).z).collect();
    let mut out: Vec<Vec<(usize, Vector3<f64>)>> = (0..n)
        .into_par_iter()
        .with_min_len(64)
        .map(|i| {
            let ri = grains[i].r_max();
            let lo = zs.partition_point(|&z| z < cs[i].z - ri - r_all);
            let mut v = Vec::new();
            for &e in &order[lo..] {
                let (j, shift) = ext[e];
                let p = cs[j] + shift;
                if p.z > cs[i].z + ri + r_all {
                    break;
                }
                if j != i && (cs[i] - p).norm() < ri + grains[j].r_max() {
                    v.push((j, shift));
                }
            }
            v
        })
        .collect();
    // a grain meets another through one image at most: the grain orders
    for v in &mut out {
        v.sort_unstable_by_key(|e| e.0);
    }
    out
}
