//! Overlap removal by gap minimisation: Jacobi sweeps of pair pushes with
//! node-versus-star gaps, walls as constraints (see the parent module).

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rayon::prelude::*;

use super::region::Region;
use super::{GrainPackParams, GrainPackStats, StarGrain, fibonacci, to_world};
use crate::error::{Error, Result};

/// Patches per node set (each with a bounding sphere per grain).
const PATCHES: usize = 32;

/// Nodes whose radial gap is under this many margins get the first-order
/// distance `g/|∇g|` (3 more lookups); farther ones count as clear (a
/// surface steeper than |∇g| = 4, 75° off radial, is not resolved).
const SLOPE_LIMIT: f64 = 4.0;

/// Extra push beyond the deepest penetration, in margins.
const OVERSHOOT: f64 = 0.25;

/// Node directions grouped by patch.
struct NodeSet {
    dirs: Vec<Vector3<f64>>,
    /// `starts[p]..starts[p + 1]`: the nodes of patch `p`.
    starts: Vec<usize>,
}

impl NodeSet {
    fn new(dirs: Vec<Vector3<f64>>) -> Self {
        let centres = fibonacci(PATCHES);
        let mut tagged: Vec<(usize, usize, Vector3<f64>)> = dirs
            .into_iter()
            .enumerate()
            .map(|(idx, u)| {
                let mut best = (f64::NEG_INFINITY, 0);
                for (p, c) in centres.iter().enumerate() {
                    let d = c.dot(&u);
                    if d > best.0 {
                        best = (d, p);
                    }
                }
                (best.1, idx, u)
            })
            .collect();
        tagged.sort_by_key(|t| (t.0, t.1));
        let mut starts = vec![0; PATCHES + 1];
        for t in &tagged {
            starts[t.0 + 1] += 1;
        }
        for p in 0..PATCHES {
            starts[p + 1] += starts[p];
        }
        Self {
            dirs: tagged.into_iter().map(|t| t.2).collect(),
            starts,
        }
    }
}

/// Body-frame nodes of every grain for one node set, with patch spheres.
pub(super) struct Shapes<'a> {
    grains: &'a [StarGrain],
    set: NodeSet,
    /// `nodes[i·k + m]`: node m of grain i (f32: 6e-8 relative).
    nodes: Vec<[f32; 3]>,
    /// `patches[i·PATCHES + p]`: centre and radius of patch p of grain i.
    patches: Vec<[f32; 4]>,
    /// Gaps as first-order distances `g/|∇g|` (else radial gaps).
    slope: bool,
}

impl<'a> Shapes<'a> {
    /// `k` Fibonacci nodes per grain, or with `k = 0` the directions of the
    /// grains' cube map (the vertices of the tabulated surface: nothing of
    /// a rough surface lies between them but the sagitta of a table cell).
    pub(super) fn new(grains: &'a [StarGrain], k: usize, slope: bool) -> Self {
        let dirs = if k == 0 {
            // At least 16 cells per face (a multiple of the tables', so
            // their vertices are among the nodes).
            let f = grains.iter().map(StarGrain::face_cells).max().unwrap_or(2);
            let f = f * 16usize.div_ceil(f);
            levelset::cube_map_directions(f)
                .map(|d| d.into_iter().map(|u| u.into_inner()).collect())
                .unwrap_or_else(|_| fibonacci(6 * (f + 1) * (f + 1)))
        } else {
            fibonacci(k)
        };
        let set = NodeSet::new(dirs);
        type PerGrain = (Vec<[f32; 3]>, Vec<[f32; 4]>);
        let per: Vec<PerGrain> = grains
            .par_iter()
            .with_min_len(64)
            .map(|g| {
                let nodes: Vec<Vector3<f64>> = set.dirs.iter().map(|u| u * g.radius(u)).collect();
                let mut patches = Vec::with_capacity(PATCHES);
                for p in 0..PATCHES {
                    let s = &nodes[set.starts[p]..set.starts[p + 1]];
                    if s.is_empty() {
                        patches.push([0.0, 0.0, 0.0, -1.0]);
                        continue;
                    }
                    let c = s.iter().sum::<Vector3<f64>>() / s.len() as f64;
                    let r = s.iter().map(|q| (q - c).norm()).fold(0.0, f64::max);
                    // f32 rounding of centre and nodes: grow by a relative 1e-6.
                    let r = r + 1e-6 * g.r_max();
                    patches.push([c.x as f32, c.y as f32, c.z as f32, r as f32]);
                }
                let nodes = nodes
                    .iter()
                    .map(|q| [q.x as f32, q.y as f32, q.z as f32])
                    .collect();
                (nodes, patches)
            })
            .collect();
        let k = set.dirs.len();
        let mut nodes = Vec::with_capacity(grains.len() * k);
        let mut patches = Vec::with_capacity(grains.len() * PATCHES);
        for (n, p) in per {
            nodes.extend(n);
            patches.extend(p);
        }
        Self {
            grains,
            set,
            nodes,
            patches,
            slope,
        }
    }

    fn node(&self, i: usize, m: usize) -> Vector3<f64> {
        let q = self.nodes[i * self.set.dirs.len() + m];
        Vector3::new(f64::from(q[0]), f64::from(q[1]), f64::from(q[2]))
    }

    /// Nodes of `a` against the surface of `b` grown by `mu_b`: adds the
    /// depth-weighted radial directions of penetrating nodes (world, signed
    /// so that `acc.dir` is the direction to move `a`) and tracks the
    /// deepest penetration and the smallest gap over `d_b`.
    #[allow(clippy::too_many_arguments)]
    fn one_way(
        &self,
        a: usize,
        b: usize,
        pose_a: (&Matrix3<f64>, &Vector3<f64>),
        pose_b: (&Matrix3<f64>, &Vector3<f64>),
        mu_b: f64,
        d_b: f64,
        sign: f64,
        lam: f64,
        acc: &mut Acc,
    ) {
        let gb = &self.grains[b];
        let m = pose_b.0.transpose() * pose_a.0 * lam;
        let t = pose_b.0.transpose() * (pose_a.1 - pose_b.1);
        let reach = lam * gb.r_max() + mu_b;
        for p in 0..PATCHES {
            let ps = self.patches[a * PATCHES + p];
            if ps[3] < 0.0 {
                continue;
            }
            let pc = Vector3::new(f64::from(ps[0]), f64::from(ps[1]), f64::from(ps[2]));
            if (m * pc + t).norm() - lam * f64::from(ps[3]) >= reach {
                continue;
            }
            for k in self.set.starts[p]..self.set.starts[p + 1] {
                let q = m * self.node(a, k) + t;
                let rr = q.norm_squared();
                if rr >= reach * reach {
                    continue;
                }
                acc.tested += 1;
                let rho = rr.sqrt();
                let radial = rho - lam * gb.radius(&q);
                let limit = if self.slope { SLOPE_LIMIT } else { 1.0 };
                if radial >= limit * mu_b || rho == 0.0 {
                    // Beyond reach of the margin even on the steepest
                    // slope allowed for (|∇g| ≤ SLOPE_LIMIT).
                    acc.min_gap = acc.min_gap.min(radial / limit / d_b);
                    continue;
                }
                // First-order distance to B's surface: g/|∇g| with g(x) =
                // |x| − λ r(x̂) (|∇g| ≥ 1: the radial gap over-states the
                // distance where the surface is steep; the level sets of
                // the check measure distance), ∇g by forward differences.
                let h = 1e-3 * lam * gb.r_max();
                let mut grad = Vector3::zeros();
                for k in 0..3 {
                    let mut x = q;
                    x[k] += h;
                    grad[k] = (x.norm() - lam * gb.radius(&x) - radial) / h;
                }
                let len = grad.norm();
                let (gap, nrm) = if len > 0.0 {
                    let g = if self.slope {
                        radial / len.max(1.0)
                    } else {
                        radial
                    };
                    (g, grad / len)
                } else {
                    (radial, q / rho)
                };
                acc.min_gap = acc.min_gap.min(gap / d_b);
                if gap < mu_b {
                    let depth = mu_b - gap;
                    acc.depth = acc.depth.max(depth);
                    // Outward normal of B's surface at the node.
                    acc.dir += (sign * depth) * (pose_b.0 * nrm);
                    acc.point += depth * (pose_b.0 * q + pose_b.1);
                    acc.weight += depth;
                }
            }
        }
    }

    /// Smallest wall clearance of grain `i`'s nodes at `(r, c)` and the
    /// node where it occurs.
    fn wall(
        &self,
        i: usize,
        r: &Matrix3<f64>,
        c: &Vector3<f64>,
        lam: f64,
        region: &Region<'_>,
    ) -> (f64, Vector3<f64>) {
        let mut worst = (f64::INFINITY, *c);
        for k in 0..self.set.dirs.len() {
            let x = to_world(r, c, &(lam * self.node(i, k)));
            let cl = region.clearance(&x);
            if cl < worst.0 {
                worst = (cl, x.coords);
            }
        }
        worst
    }
}

/// Accumulator of one pair test.
#[derive(Debug, Clone, Copy)]
struct Acc {
    dir: Vector3<f64>,
    /// Depth-weighted sum of the world positions of penetrating nodes.
    point: Vector3<f64>,
    /// Sum of the depths (the weight of `point`).
    weight: f64,
    depth: f64,
    min_gap: f64,
    tested: u64,
}

impl Acc {
    fn new() -> Self {
        Self {
            dir: Vector3::zeros(),
            point: Vector3::zeros(),
            weight: 0.0,
            depth: 0.0,
            min_gap: f64::INFINITY,
            tested: 0,
        }
    }
}

/// Uniform cell grid of bounding boxes `c ± reach`: a grain is listed in
/// every cell its box meets (a wide grading keeps small cells: the cell is
/// twice the median reach), and a pair is reported once, in the cell that
/// holds the lower corner of the intersection of the two boxes.
pub(super) struct Cells {
    lo: Vector3<f64>,
    inv: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Cells {
    pub(super) fn new(centres: &[Vector3<f64>], reach: &[f64], cell: f64) -> Self {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for (c, r) in centres.iter().zip(reach) {
            lo = lo.inf(&c.add_scalar(-r));
            hi = hi.sup(&c.add_scalar(*r));
        }
        // At most 2^21 cells: coarser cells for a huge extent.
        let mut cell = cell;
        while ((hi - lo) / cell)
            .iter()
            .map(|e| e.floor() + 1.0)
            .product::<f64>()
            > 2_097_152.0
        {
            cell *= 1.25;
        }
        let inv = 1.0 / cell;
        let mut dims = [1usize; 3];
        for k in 0..3 {
            dims[k] = ((hi[k] - lo[k]) * inv).floor() as usize + 1;
        }
        let mut grid = Self {
            lo,
            inv,
            dims,
            start: vec![0; dims[0] * dims[1] * dims[2] + 1],
            items: Vec::new(),
        };
        let boxes: Vec<([usize; 3], [usize; 3])> = centres
            .iter()
            .zip(reach)
            .map(|(c, r)| (grid.coord(&c.add_scalar(-r)), grid.coord(&c.add_scalar(*r))))
            .collect();
        let mut counts = vec![0u32; grid.start.len()];
        for (a, b) in &boxes {
            grid.for_cells(a, b, |id| counts[id + 1] += 1);
        }
        for k in 0..counts.len() - 1 {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[counts.len() - 1] as usize];
        for (i, (a, b)) in boxes.iter().enumerate() {
            grid.for_cells(a, b, |id| {
                items[fill[id] as usize] = i as u32;
                fill[id] += 1;
            });
        }
        grid.start = counts;
        grid.items = items;
        grid
    }

    /// The items whose boxes meet the cell holding `p` (a point outside
    /// the grid looks in the nearest edge cell: a superset of the boxes
    /// that hold it).
    pub(super) fn at(&self, p: &Vector3<f64>) -> &[u32] {
        let id = self.id(&self.coord(p));
        &self.items[self.start[id] as usize..self.start[id + 1] as usize]
    }

    fn for_cells(&self, a: &[usize; 3], b: &[usize; 3], mut f: impl FnMut(usize)) {
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    f(self.id(&[x, y, z]));
                }
            }
        }
    }

    fn coord(&self, c: &Vector3<f64>) -> [usize; 3] {
        let mut out = [0; 3];
        for k in 0..3 {
            let v = ((c[k] - self.lo[k]) * self.inv).floor();
            out[k] = if v > 0.0 {
                (v as usize).min(self.dims[k] - 1)
            } else {
                0
            };
        }
        out
    }

    fn id(&self, q: &[usize; 3]) -> usize {
        q[0] + self.dims[0] * (q[1] + self.dims[1] * q[2])
    }

    /// Calls `f(j)` once for every item `j ≠ i` whose box meets item
    /// `i`'s.
    fn meeting(&self, i: usize, c: &[Vector3<f64>], reach: &[f64], mut f: impl FnMut(usize)) {
        let (lo_i, hi_i) = (c[i].add_scalar(-reach[i]), c[i].add_scalar(reach[i]));
        let (a, b) = (self.coord(&lo_i), self.coord(&hi_i));
        self.for_cells(&a, &b, |id| {
            for &j in &self.items[self.start[id] as usize..self.start[id + 1] as usize] {
                let j = j as usize;
                if j == i {
                    continue;
                }
                let lo_j = c[j].add_scalar(-reach[j]);
                let hi_j = c[j].add_scalar(reach[j]);
                if (0..3).any(|k| lo_j[k] > hi_i[k] || lo_i[k] > hi_j[k]) {
                    continue;
                }
                if self.id(&self.coord(&lo_i.sup(&lo_j))) == id {
                    f(j);
                }
            }
        });
    }
}

/// One pair verdict: push `a` along `dir` (and `b` against it) by `step`.
struct Push {
    b: usize,
    /// Translation and rotation (scaled axis) of `a`.
    move_a: (Vector3<f64>, Vector3<f64>),
    /// Translation and rotation (scaled axis) of `b`.
    move_b: (Vector3<f64>, Vector3<f64>),
    depth_over_d: f64,
}

/// The smallest rigid move (in the metric of an isotropic inertia `k2`)
/// that moves the contact point at arm `r` from the centre by `step` along
/// the unit `n`: translation `t·n` and rotation `t·(r × n)/k2`, with
/// `t = step / (1 + |r × n|²/k2)` (the response of a rigid body to an
/// impulse along `n` at `r`). Without rotations (`k2 = ∞`): `step·n`.
fn rigid_move(
    r: &Vector3<f64>,
    n: &Vector3<f64>,
    step: f64,
    k2: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    if !k2.is_finite() {
        return (step * n, Vector3::zeros());
    }
    let arm = r.cross(n);
    let t = step / (1.0 + arm.norm_squared() / k2);
    (t * n, (t / k2) * arm)
}

/// Geometry shared by the sweeps.
struct Frame {
    quats: Vec<UnitQuaternion<f64>>,
    rots: Vec<Matrix3<f64>>,
    /// Squared radius of gyration of each grain (`0.1·d_eq²`, a sphere's),
    /// or `+inf` when the moves are translations only.
    k2: Vec<f64>,
    d_eq: Vec<f64>,
    mu: Vec<f64>,
    reach: Vec<f64>,
    cell: f64,
}

/// The grains' centres (wrapped into a periodic cell) and their periodic
/// images, in a cell grid of their bounding boxes.
struct Near {
    /// Centres, then images.
    c: Vec<Vector3<f64>>,
    /// Grain of each entry.
    real: Vec<u32>,
    reach: Vec<f64>,
    cells: Cells,
}

impl Near {
    fn new(frame: &Frame, region: &Region<'_>, centres: &[Vector3<f64>]) -> Self {
        let width = 2.0 * frame.reach.iter().copied().fold(0.0, f64::max);
        let (c, real, _) = region.extended(centres, width);
        let reach: Vec<f64> = real.iter().map(|&r| frame.reach[r as usize]).collect();
        let cells = Cells::new(&c, &reach, frame.cell);
        Self {
            c,
            real,
            reach,
            cells,
        }
    }
}

impl Frame {
    /// Both-way node test of `a` at `ca` and `b` at `cb`.
    fn pair(
        &self,
        s: &Shapes<'_>,
        a: usize,
        b: usize,
        ca: &Vector3<f64>,
        cb: &Vector3<f64>,
        lam: f64,
    ) -> Acc {
        let mut acc = Acc::new();
        let (pa, pb) = ((&self.rots[a], ca), (&self.rots[b], cb));
        s.one_way(a, b, pa, pb, self.mu[b], self.d_eq[b], 1.0, lam, &mut acc);
        s.one_way(b, a, pb, pa, self.mu[a], self.d_eq[a], -1.0, lam, &mut acc);
        acc
    }

    /// Grains `j ≠ i` in reach of grain `i`, each with the centre of the
    /// image (or the grain itself) that meets it.
    fn for_neighbours(&self, near: &Near, i: usize, mut f: impl FnMut(usize, &Vector3<f64>)) {
        let c = &near.c;
        near.cells.meeting(i, c, &near.reach, |e| {
            let j = near.real[e] as usize;
            if j != i && (c[i] - c[e]).norm_squared() < (self.reach[i] + self.reach[j]).powi(2) {
                f(j, &c[e]);
            }
        });
    }

    /// Pairs `(i, j > i)` in reach (each once, directly or through one
    /// image).
    fn for_pairs(&self, near: &Near, i: usize, mut f: impl FnMut(usize, &Vector3<f64>)) {
        self.for_neighbours(near, i, |j, cj| {
            if j > i {
                f(j, cj);
            }
        });
    }
}

/// Centres and orientations of the grains.
type Poses = (Vec<Vector3<f64>>, Vec<UnitQuaternion<f64>>);

/// Relaxes the skeleton centres until no pair and no wall is closer than
/// the margin (fine node set), or [`Error::NotConverged`].
pub(super) fn relax(
    grains: &[StarGrain],
    region: &Region<'_>,
    rotations: &[UnitQuaternion<f64>],
    mut centres: Vec<Vector3<f64>>,
    lam0: f64,
    params: &GrainPackParams,
    stats: &mut GrainPackStats,
) -> Result<Poses> {
    let n = grains.len();
    let d_eq: Vec<f64> = grains.iter().map(StarGrain::equivalent_diameter).collect();
    let mu: Vec<f64> = d_eq
        .iter()
        .map(|d| COARSE_MARGIN * params.margin * d)
        .collect();
    let reach: Vec<f64> = grains.iter().zip(&mu).map(|(g, m)| g.r_max() + m).collect();
    let mut sorted = reach.clone();
    sorted.sort_by(f64::total_cmp);
    let cell = 2.0 * sorted[sorted.len() / 2];
    let k2 = d_eq
        .iter()
        .map(|d| {
            if params.rotations {
                0.1 * d * d
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let mut frame = Frame {
        quats: rotations.to_vec(),
        rots: rotations
            .iter()
            .map(|q| q.to_rotation_matrix().into_inner())
            .collect(),
        k2,
        d_eq,
        mu,
        reach,
        cell,
    };
    let mut sweeps = 0;
    let mut first = true;
    let omega = params.relaxation;
    let coarse = Shapes::new(grains, params.coarse_nodes, false);
    let mut lam = lam0.clamp(0.5, 1.0);
    let mut moved = vec![true; n];
    // Growth: relax at scale λ until clean, then grow λ towards 1.
    loop {
        let budget = if lam < 1.0 { GROWTH_SWEEPS } else { usize::MAX };
        let clean = relax_at(
            &mut frame,
            &coarse,
            region,
            &mut centres,
            &mut moved,
            lam,
            omega,
            budget,
            params.max_sweeps,
            &mut sweeps,
            &mut first,
            stats,
        )?;
        stats.coarse_sweeps = sweeps;
        if clean && lam >= 1.0 {
            break;
        }
        if clean {
            // Straight to full size once clean at the skeleton's scale: on
            // 2000 Ottawa clones at 0.50 (3 seeds) steps of half the
            // remaining scale took 944–2156 sweeps, one step 320–713 (every
            // step ends in the same slow tail of a few stubborn pairs), and
            // one step also converges at 0.56 where small steps did not.
            lam = 1.0;
            moved.fill(true);
        }
    }
    drop(coarse);
    // The fine stage keeps the margin asked for: the coarse stage's wider
    // one leaves room for what its sparse nodes miss.
    for (m, d) in frame.mu.iter_mut().zip(&frame.d_eq) {
        *m = params.margin * d;
    }
    let shapes = Shapes::new(grains, params.fine_nodes, true);
    moved.fill(true);
    relax_at(
        &mut frame,
        &shapes,
        region,
        &mut centres,
        &mut moved,
        1.0,
        omega,
        usize::MAX,
        params.max_sweeps,
        &mut sweeps,
        &mut first,
        stats,
    )?;
    stats.fine_sweeps = sweeps - stats.coarse_sweeps;
    stats.growth_start = lam0;
    // the poses handed out are wrapped into a periodic cell
    if region.is_periodic() {
        for c in &mut centres {
            *c = region.wrap(c);
        }
    }
    let near = Near::new(&frame, region, &centres);
    let fin: Vec<(f64, usize, f64)> = (0..n)
        .into_par_iter()
        .with_min_len(16)
        .map(|i| {
            let mut gap = f64::INFINITY;
            let mut count = 0;
            frame.for_pairs(&near, i, |j, cj| {
                count += 1;
                gap = gap.min(frame.pair(&shapes, i, j, &centres[i], cj, 1.0).min_gap);
            });
            let wall = shapes.wall(i, &frame.rots[i], &centres[i], 1.0, region).0 / frame.d_eq[i];
            (gap, count, wall)
        })
        .collect();
    stats.worst_gap_over_d = fin.iter().map(|f| f.0).fold(f64::INFINITY, f64::min);
    stats.near_pairs = fin.iter().map(|f| f.1).sum();
    stats.worst_wall_over_d = fin.iter().map(|f| f.2).fold(f64::INFINITY, f64::min);
    Ok((centres, frame.quats))
}

/// The coarse stage's margin, in margins: what the coarse nodes miss of a
/// neighbour's surface (the sagitta between nodes) is absorbed by the
/// extra half margin, so the fine stage starts with few pairs under the
/// margin instead of nearly every contact just under it.
const COARSE_MARGIN: f64 = 2.5;

/// Sweeps per growth step before the step is judged (the scale is not
/// grown until the step is clean).
const GROWTH_SWEEPS: usize = 40;

/// Jacobi sweeps at scale `lam` until no pair and no wall is closer than
/// the margin (`Ok(true)`) or `budget` sweeps (`Ok(false)`);
/// [`Error::NotConverged`] past `max_sweeps` in total.
#[allow(clippy::too_many_arguments)]
fn relax_at(
    frame_mut: &mut Frame,
    shapes: &Shapes<'_>,
    region: &Region<'_>,
    centres: &mut [Vector3<f64>],
    moved: &mut [bool],
    lam: f64,
    omega: f64,
    budget: usize,
    max_sweeps: usize,
    sweeps: &mut usize,
    first: &mut bool,
    stats: &mut GrainPackStats,
) -> Result<bool> {
    let n = centres.len();
    for _ in 0..budget {
        if region.is_periodic() {
            for c in centres.iter_mut() {
                *c = region.wrap(c);
            }
        }
        let frame: &Frame = frame_mut;
        let near = Near::new(frame, region, centres);
        if *sweeps >= max_sweeps {
            return Err(Error::NotConverged {
                sweeps: *sweeps,
                overlapping_pairs: overlapping_pairs(frame, shapes, &near, centres, lam),
                scale: lam,
            });
        }
        *sweeps += 1;
        let found = find_pushes(frame, shapes, &near, centres, moved, lam);
        let mut disp = vec![Vector3::zeros(); n];
        let mut turn = vec![Vector3::zeros(); n];
        let mut count = vec![0u32; n];
        let mut overlaps = 0;
        let mut deepest = 0.0_f64;
        for &(i, ref list, tests) in &found {
            stats.pair_tests += tests;
            for p in list {
                disp[i] += p.move_a.0;
                turn[i] += p.move_a.1;
                disp[p.b] += p.move_b.0;
                turn[p.b] += p.move_b.1;
                count[i] += 1;
                count[p.b] += 1;
                overlaps += 1;
                deepest = deepest.max(p.depth_over_d);
            }
        }
        if *first {
            stats.initial_overlaps = overlaps;
            stats.initial_depth_over_d = deepest;
            *first = false;
        }
        let frame = &mut *frame_mut;
        for i in 0..n {
            moved[i] = count[i] > 0;
            if moved[i] {
                let k = omega / f64::from(count[i]);
                centres[i] += k * disp[i];
                if turn[i] != Vector3::zeros() {
                    let q = UnitQuaternion::from_scaled_axis(k * turn[i]) * frame.quats[i];
                    frame.quats[i] = q;
                    frame.rots[i] = q.to_rotation_matrix().into_inner();
                }
            }
        }
        let frame: &Frame = frame;
        // Walls as constraints: project each grain back inside.
        let c: &[Vector3<f64>] = centres;
        let walls: Vec<Option<Vector3<f64>>> = (0..n)
            .into_par_iter()
            .with_min_len(64)
            .map(|i| wall_projection(frame, shapes, region, i, &c[i], lam))
            .collect();
        let mut any = overlaps > 0;
        for (i, w) in walls.into_iter().enumerate() {
            if let Some(p) = w {
                centres[i] = p;
                moved[i] = true;
                any = true;
            }
        }
        if !any {
            return Ok(true);
        }
    }
    Ok(false)
}

/// Pairs still overlapping at scale `lam` (the count of
/// [`Error::NotConverged`]).
fn overlapping_pairs(
    frame: &Frame,
    shapes: &Shapes<'_>,
    near: &Near,
    c: &[Vector3<f64>],
    lam: f64,
) -> usize {
    (0..c.len())
        .into_par_iter()
        .map(|i| {
            let mut cnt = 0;
            frame.for_pairs(near, i, |j, cj| {
                if frame.pair(shapes, i, j, &c[i], cj, lam).depth > 0.0 {
                    cnt += 1;
                }
            });
            cnt
        })
        .sum()
}

/// The pushes of one sweep: for each moved grain `i`, its overlapping
/// pairs and the pair tests made. Only pairs with a moved grain are
/// tested, each from its moved grain (the lower one when both moved).
fn find_pushes(
    frame: &Frame,
    shapes: &Shapes<'_>,
    near: &Near,
    c: &[Vector3<f64>],
    mv: &[bool],
    lam: f64,
) -> Vec<(usize, Vec<Push>, u64)> {
    let active: Vec<usize> = (0..c.len()).filter(|&i| mv[i]).collect();
    active
        .par_iter()
        .with_min_len(16)
        .map(|&i| {
            let mut out = Vec::new();
            let mut tests = 0;
            frame.for_neighbours(near, i, |j, cj| {
                if mv[j] && j < i {
                    return;
                }
                tests += 1;
                let acc = frame.pair(shapes, i, j, &c[i], cj, lam);
                if acc.depth > 0.0 {
                    out.push(frame.push(&acc, i, j, &c[i], cj));
                }
            });
            (i, out, tests)
        })
        .collect()
}

impl Frame {
    /// The push of an overlapping pair `(a, b)` at `ca`, `cb` from its node
    /// test `acc`: both grains apart along the depth-weighted normal by half
    /// the depth plus the overshoot, at the contact point.
    #[inline]
    fn push(&self, acc: &Acc, a: usize, b: usize, ca: &Vector3<f64>, cb: &Vector3<f64>) -> Push {
        let mut dir = acc.dir;
        if dir.norm().partial_cmp(&(1e-12 * acc.depth)) != Some(std::cmp::Ordering::Greater) {
            dir = ca - cb;
        }
        let len = dir.norm();
        let dir = if len > 0.0 { dir / len } else { Vector3::z() };
        let extra = OVERSHOOT * self.mu[a].max(self.mu[b]);
        let step = 0.5 * (acc.depth + extra);
        let x = if acc.weight > 0.0 {
            acc.point / acc.weight
        } else {
            0.5 * (ca + cb)
        };
        Push {
            b,
            move_a: rigid_move(&(x - ca), &dir, step, self.k2[a]),
            move_b: rigid_move(&(x - cb), &(-dir), step, self.k2[b]),
            depth_over_d: acc.depth / self.d_eq[a].min(self.d_eq[b]),
        }
    }
}

/// Grain `i` at `ci` projected back inside the walls until its nodes clear
/// them by the margin (up to 6 steps along the clearance gradient), or
/// `None` when it already does.
fn wall_projection(
    frame: &Frame,
    shapes: &Shapes<'_>,
    region: &Region<'_>,
    i: usize,
    ci: &Vector3<f64>,
    lam: f64,
) -> Option<Vector3<f64>> {
    if region.clearance(&(*ci).into()) >= lam * frame.reach[i] {
        return None;
    }
    let mut p = *ci;
    let mu = frame.mu[i];
    let mut changed = false;
    for _ in 0..6 {
        let (cl, x) = shapes.wall(i, &frame.rots[i], &p, lam, region);
        if cl >= mu {
            break;
        }
        let g = region
            .inward(&x.into(), 1e-4 * frame.d_eq[i])
            .unwrap_or_else(Vector3::z);
        p += (mu - cl + OVERSHOOT * mu) * g;
        changed = true;
    }
    changed.then_some(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The contact point moves by `step` along `n` (translation plus the
    /// rotation's velocity at the arm), for any arm; a central push is a
    /// pure translation; no rotation without inertia.
    #[test]
    fn rigid_moves_give_the_contact_point_its_step() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        for r in [
            Vector3::new(0.0, 0.0, 0.5),
            Vector3::new(0.3, 0.0, 0.4),
            Vector3::new(0.5, -0.2, 0.0),
        ] {
            let (t, w) = rigid_move(&r, &n, 0.01, 0.1);
            let at_contact = t + w.cross(&r);
            assert_relative_eq!(at_contact.dot(&n), 0.01, max_relative = 1e-12);
        }
        let (t, w) = rigid_move(&Vector3::new(0.0, 0.0, 0.5), &n, 0.01, 0.1);
        assert_relative_eq!(t.z, 0.01, max_relative = 1e-12);
        assert_eq!(w, Vector3::zeros());
        let (t, w) = rigid_move(&Vector3::new(0.5, 0.0, 0.0), &n, 0.01, f64::INFINITY);
        assert_relative_eq!(t.z, 0.01, max_relative = 1e-12);
        assert_eq!(w, Vector3::zeros());
    }
}
