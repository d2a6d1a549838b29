//! The 3D advancing front (Pinto 2009, Ch. 3, carried to 3D).
//!
//! Every placed sphere is a *front*. Evaluating a front `f` for the next
//! radius `r` gathers the obstacles whose halo (radius `r_j + r`) can meet
//! the front's halo (`r_f + r`): spheres with `|c_j − c_f| ≤ r_f + r_j + 2r`
//! and walls within `r_f + 2r`. The candidate centres are the common points
//! of the front's halo with two more halos or offset walls: the closed-form
//! three-sphere wrapper of Pérez Morales et al. 2016, §3.1
//! ([`packer_contact::contact3d`]), spheres and planes, and for the cylinder the
//! intersection of the front/obstacle circle with the offset cylinder. A
//! candidate is feasible when it lies inside the container (exact
//! clearance) and outside every obstacle halo; the feasible candidate with
//! the lowest `z` (ties: `x`, then `y`) receives the sphere. A front without
//! a feasible candidate is tried with the smallest size of the grading;
//! when even that fails it is removed, otherwise it waits for the next
//! placement (the size is kept for the other fronts, as in 2D). A size that
//! no front can take is skipped (counted in [`Pack3Stats::sizes_skipped`]).

// Coordinates are `[f64; 3]` triples indexed in step with box bounds,
// periods and cell counts: index loops read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::sync::mpsc;

use nalgebra::{Point3, Vector3};

use super::container::Container;
use super::grid::Grid3;
use packer_quadtree::FrontOrder;

/// Relative tolerance of the feasibility test: a candidate may enter an
/// obstacle halo by `FEAS_TOL · d_max` (round-off of the intersection), far
/// below the `1e-9 · d` overlap criterion of the checker.
const FEAS_TOL: f64 = 1e-11;

/// Counters of one packing run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Pack3Stats {
    /// Site generations (one per placed sphere).
    pub evaluations: u64,
    /// Sites dropped (no room even for the smallest size).
    pub fronts_removed: u64,
    /// Sizes drawn from the grading.
    pub sizes_drawn: u64,
    /// Sizes skipped because no front could take them (at the end of the
    /// packing, when only small pockets are left).
    pub sizes_skipped: u64,
    /// Peak heap bytes of the packer's own structures.
    pub peak_bytes: u64,
    /// Neighbours gathered over all evaluations.
    pub neighbours: u64,
    /// Candidates generated over all evaluations.
    pub candidates: u64,
    /// Site tests (closed-form position and feasibility).
    pub site_tests: u64,
    /// Sites popped.
    pub pops: u64,
    /// Sites generated.
    pub sites: u64,
    /// Slabs of a slab-parallel packing (0 or 1: one front).
    pub slabs: u64,
}

/// A wall plane `n · x = o` (unit `n` pointing into the container).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plane {
    pub(crate) n: Vector3<f64>,
    pub(crate) o: f64,
}

/// Walls of the container as the front sees them.
#[derive(Clone)]
pub(crate) enum Walls {
    /// Box walls (up to six planes; periodic sides have none).
    Planes(Vec<Plane>),
    /// Cylinder: bottom and top planes plus the side.
    Cylinder {
        planes: [Plane; 2],
        axis: [f64; 2],
        radius: f64,
    },
    /// Mesh: per-cell lists of nearby face planes and a lower bound of the
    /// clearance per cell.
    Mesh(MeshWalls),
}

#[derive(Clone)]
pub(crate) struct MeshWalls {
    lo: [f64; 3],
    inv: f64,
    n: [usize; 3],
    /// Lower bound of the clearance over each cell.
    pub(crate) deep: Vec<f64>,
    start: Vec<u32>,
    list: Vec<u32>,
    pub(crate) planes: Vec<Plane>,
}

impl MeshWalls {
    fn cell(&self, p: &[f64; 3]) -> Option<usize> {
        let mut idx = 0;
        let mut mul = 1;
        for k in 0..3 {
            let f = (p[k] - self.lo[k]) * self.inv;
            if !f.ge(&0.0) {
                return None;
            }
            let i = f as usize;
            if i >= self.n[k] {
                return None;
            }
            idx += i * mul;
            mul *= self.n[k];
        }
        Some(idx)
    }
    fn near(&self, c: usize) -> &[u32] {
        &self.list[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

impl Walls {
    pub(crate) fn new(container: &Container, r_max: f64) -> Self {
        match container {
            Container::Box { min, max, periodic } => {
                let mut v = Vec::new();
                for k in 0..3 {
                    if k < 2 && periodic[k] {
                        continue;
                    }
                    let mut n = Vector3::zeros();
                    n[k] = 1.0;
                    v.push(Plane { n, o: min[k] });
                    v.push(Plane { n: -n, o: -max[k] });
                }
                Self::Planes(v)
            }
            Container::Cylinder {
                base,
                radius,
                height,
            } => Self::Cylinder {
                planes: [
                    Plane {
                        n: Vector3::z(),
                        o: base.z,
                    },
                    Plane {
                        n: -Vector3::z(),
                        o: -(base.z + height),
                    },
                ],
                axis: [base.x, base.y],
                radius: *radius,
            },
            Container::Mesh(m) => {
                let mesh = m.mesh();
                let v = mesh.vertices();
                let (lo, hi) = container.bbox();
                let ext = hi - lo;
                let mut c = r_max;
                while (ext.x / c + 3.0) * (ext.y / c + 3.0) * (ext.z / c + 3.0) > 5.0e5 {
                    c *= 1.25;
                }
                let n = [0, 1, 2].map(|k| (ext[k] / c).ceil() as usize + 2);
                let lo = [lo.x - c, lo.y - c, lo.z - c];
                let half_diag = c * 0.5 * 3f64.sqrt();
                // Distinct face planes: sorted, then runs of equal planes
                // (within round-off) merged.
                let raw: Vec<Plane> = mesh
                    .triangles()
                    .iter()
                    .map(|t| {
                        let nrm = (v[t[1]] - v[t[0]]).cross(&(v[t[2]] - v[t[0]])).normalize();
                        // Inward normal: the mesh is outward oriented.
                        Plane {
                            n: -nrm,
                            o: -nrm.dot(&v[t[0]].coords),
                        }
                    })
                    .collect();
                let mut order: Vec<usize> = (0..raw.len()).collect();
                order.sort_by(|&i, &j| {
                    let (p, q) = (&raw[i], &raw[j]);
                    p.n[0]
                        .total_cmp(&q.n[0])
                        .then(p.n[1].total_cmp(&q.n[1]))
                        .then(p.n[2].total_cmp(&q.n[2]))
                        .then(p.o.total_cmp(&q.o))
                        .then(i.cmp(&j))
                });
                let mut planes: Vec<Plane> = Vec::new();
                let mut tri_plane = vec![0u32; raw.len()];
                for &t in &order {
                    let p = raw[t];
                    let same = planes.last().is_some_and(|q| {
                        (q.n - p.n).norm() <= 1e-9 && (q.o - p.o).abs() <= 1e-9 * (1.0 + q.o.abs())
                    });
                    if !same {
                        planes.push(p);
                    }
                    tri_plane[t] = (planes.len() - 1) as u32;
                }
                let reach = 3.0 * r_max + half_diag;
                let cells = n[0] * n[1] * n[2];
                // Lower bound of the clearance over each cell, from the exact
                // clearance at its centre.
                let mut deep = vec![f64::NEG_INFINITY; cells];
                for iz in 0..n[2] {
                    for iy in 0..n[1] {
                        for ix in 0..n[0] {
                            let idx = ix + n[0] * (iy + n[1] * iz);
                            let p = Point3::new(
                                lo[0] + (ix as f64 + 0.5) * c,
                                lo[1] + (iy as f64 + 0.5) * c,
                                lo[2] + (iz as f64 + 0.5) * c,
                            );
                            deep[idx] = m.clearance_bounded(&p, reach + half_diag) - half_diag;
                        }
                    }
                }
                // Face planes near each cell: every triangle visits the
                // cells of its box widened by the reach.
                let mut per_cell: Vec<Vec<u32>> = vec![Vec::new(); cells];
                for (t, tri) in mesh.triangles().iter().enumerate() {
                    let (a, b2, c2) = (v[tri[0]], v[tri[1]], v[tri[2]]);
                    let tlo = a.inf(&b2).inf(&c2);
                    let thi = a.sup(&b2).sup(&c2);
                    let range = |k: usize| {
                        let i0 = (((tlo[k] - reach - lo[k]) / c).floor().max(0.0)) as usize;
                        let i1 = ((((thi[k] + reach - lo[k]) / c).floor()) as usize).min(n[k] - 1);
                        (i0, i1)
                    };
                    let ((x0, x1), (y0, y1), (z0, z1)) = (range(0), range(1), range(2));
                    for iz in z0..=z1 {
                        for iy in y0..=y1 {
                            for ix in x0..=x1 {
                                let idx = ix + n[0] * (iy + n[1] * iz);
                                let p = Point3::new(
                                    lo[0] + (ix as f64 + 0.5) * c,
                                    lo[1] + (iy as f64 + 0.5) * c,
                                    lo[2] + (iz as f64 + 0.5) * c,
                                );
                                if levelset::mesh::point_triangle_distance(&p, &a, &b2, &c2)
                                    <= reach
                                {
                                    let pl = tri_plane[t];
                                    if !per_cell[idx].contains(&pl) {
                                        per_cell[idx].push(pl);
                                    }
                                }
                            }
                        }
                    }
                }
                let mut start = Vec::with_capacity(cells + 1);
                let mut list = Vec::new();
                for l in &per_cell {
                    start.push(list.len() as u32);
                    list.extend_from_slice(l);
                }
                start.push(list.len() as u32);
                Self::Mesh(MeshWalls {
                    lo,
                    inv: 1.0 / c,
                    n,
                    deep,
                    start,
                    list,
                    planes,
                })
            }
        }
    }
}

#[inline]
fn lower(a: &[f64; 3], b: &[f64; 3]) -> bool {
    (a[2], a[0], a[1]) < (b[2], b[0], b[1])
}

/// Obstacle ids at or above `WALL` are walls: `WALL + i` is plane `i`,
/// [`CYL`] the cylinder side.
const WALL: u32 = 0xFFFF_0000;
const CYL: u32 = u32::MAX;
/// Third obstacle of the bootstrap site of a box periodic in x and y: the
/// second sphere touches the first and the floor on the first's `+x` side.
const FREE: u32 = u32::MAX - 1;

/// Sizes tried for the first sphere before the container is declared too
/// small.
const MAX_SKIPS: usize = 256;

/// An open site: where a sphere touches the three obstacles `ids`
/// (`ids[0]` the sphere that generated it); `k` is its centre for the
/// smallest size (the ordering key).
#[derive(Clone, Copy, Debug)]
struct Site {
    k: [f64; 3],
    ids: [u32; 3],
    /// Secondary key: `z` of the generating sphere (front order
    /// [`FrontOrder::LowestFirst`]), else 0.
    g: f64,
    /// Largest radius known to fit (infinite until a size failed here).
    cap: f64,
    /// Registry slot (liveness and the site grid).
    slot: u32,
}
/// A waiting site in a heap: its order keys and registry slot (24 bytes;
/// the site itself stays in the registry). Ties in `z` (a floor layer of
/// equal spheres) go to the lower slot: slots are handed out in a
/// deterministic order, so the packing is.
#[derive(Clone, Copy, Debug)]
struct Key {
    g: f64,
    z: f64,
    slot: u32,
}
impl PartialEq for Key {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Key {}
impl PartialOrd for Key {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Key {
    fn of(s: &Site) -> Self {
        Self {
            g: s.g,
            z: s.k[2],
            slot: s.slot,
        }
    }
}
impl Ord for Key {
    // Reversed: the max-heap pops the lowest key.
    fn cmp(&self, o: &Self) -> Ordering {
        o.g.total_cmp(&self.g)
            .then(o.z.total_cmp(&self.z))
            .then(o.slot.cmp(&self.slot))
    }
}

/// Sites of one generation closer than `DEDUP · r_min` are one pocket.
const DEDUP: f64 = 1.0;

/// A new sphere kills the sites whose smallest-size centre lies within
/// `KILL · (r + r_min)` of its centre.
const KILL: f64 = 1.0;

/// Bisection steps of a site's capacity.
const BISECTIONS: usize = 4;

/// What happens to a popped site.
#[derive(Clone, Copy, Debug)]
enum Outcome {
    /// Killed by a later sphere: retired without a test.
    Dead,
    /// No room even for the smallest size: retired.
    Drop,
    /// Too small for the window: back in the queue with this capacity.
    Defer(f64),
    /// Window entry `i` (radius `r`) goes to `p`.
    Place { p: [f64; 3], r: f64, i: usize },
}

/// A message to the site-generation worker.
enum Job {
    /// Insert a placed sphere `[x, y, z, r]` into the replica.
    Place([f64; 4]),
    /// Generate the open sites of sphere `id` (secondary key `g`).
    Generate(u32, f64),
}

/// The channels to the worker.
struct Pipe {
    jobs: mpsc::Sender<Job>,
    results: mpsc::Receiver<Vec<Site>>,
}

impl Pipe {
    fn send(&self, job: Job) {
        // A failed send means the worker is gone; the receive below then
        // reports an empty batch and the packing ends early but valid.
        let _ = self.jobs.send(job);
    }
    fn receive(&self) -> Vec<Site> {
        spin_receive(&self.results).unwrap_or_default()
    }
}

/// Receives with a short spin before blocking (the two threads hand work
/// to each other every few microseconds; parking costs more than that).
fn spin_receive<T>(rx: &mpsc::Receiver<T>) -> Option<T> {
    for i in 0..20_000u32 {
        match rx.try_recv() {
            Ok(x) => return Some(x),
            Err(mpsc::TryRecvError::Disconnected) => return None,
            Err(mpsc::TryRecvError::Empty) => {
                if i % 64 == 63 {
                    std::thread::yield_now();
                } else {
                    std::hint::spin_loop();
                }
            }
        }
    }
    rx.recv().ok()
}

/// The open sites with the lag-one rule's pending sphere.
struct Lag {
    sites: Sites,
    /// The last placed sphere, whose sites are not merged yet.
    pending: Option<(u32, f64)>,
    pipe: Option<Pipe>,
}

/// Number of capacity levels of the waiting sites.
const LEVELS: usize = 16;

/// The open sites, in `LEVELS + 1` heaps: level `j < LEVELS` holds sites
/// known to take radii up to `r_min + j·Δ` (capacity found by bisection,
/// rounded down to a level), level `LEVELS` the sites not yet known to be
/// too small for any size. For a radius `r` the eligible levels are those
/// whose capacity is at least `r`; the next site is the lowest key among
/// their tops (at most 17 comparisons, no re-queuing when sizes change).
struct Sites {
    heaps: Vec<BinaryHeap<Key>>,
    /// The sites by slot.
    data: Vec<Site>,
    r_min: f64,
    step: f64,
    len: usize,
    /// Per slot: alive (not overlapped by a later sphere at its
    /// smallest-size centre) and its site-grid cell.
    alive: Vec<bool>,
    cell_of: Vec<u32>,
    free: Vec<u32>,
    grid: SiteGrid,
    /// Sites are kept only if their key's `x` lies in `[region[0],
    /// region[1])` (the slab of a slab-parallel packing; unbounded
    /// otherwise).
    region: [f64; 2],
}

/// Open sites by their smallest-size centre, so that a new sphere kills
/// the sites it overlaps at once (instead of two failed tests each when
/// they come up).
struct SiteGrid {
    lo: [f64; 3],
    inv: f64,
    n: [usize; 3],
    period: [f64; 2],
    cells: Vec<Vec<(u32, [f64; 3])>>,
}

impl SiteGrid {
    fn new(lo: [f64; 3], hi: [f64; 3], cell: f64, periodic: [bool; 2]) -> Self {
        let mut c = cell;
        while (0..3)
            .map(|k| ((hi[k] - lo[k]) / c).ceil().max(1.0))
            .product::<f64>()
            > 16.0e6
        {
            c *= 1.25;
        }
        let n = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / c).ceil() as usize).max(1));
        let period = [
            if periodic[0] { hi[0] - lo[0] } else { 0.0 },
            if periodic[1] { hi[1] - lo[1] } else { 0.0 },
        ];
        Self {
            lo,
            inv: 1.0 / c,
            n,
            period,
            cells: vec![Vec::new(); n[0] * n[1] * n[2]],
        }
    }
    /// Wraps periodic coordinates into the box.
    fn wrap(&self, mut p: [f64; 3]) -> [f64; 3] {
        for k in 0..2 {
            let l = self.period[k];
            if l > 0.0 {
                p[k] -= ((p[k] - self.lo[k]) / l).floor() * l;
            }
        }
        p
    }
    fn index(&self, k: usize, x: f64) -> i64 {
        ((x - self.lo[k]) * self.inv).floor() as i64
    }
    fn cell(&self, p: &[f64; 3]) -> usize {
        let i = [0, 1, 2].map(|k| self.index(k, p[k]).clamp(0, self.n[k] as i64 - 1) as usize);
        i[0] + self.n[0] * (i[1] + self.n[1] * i[2])
    }
}

impl Sites {
    /// Registers a new site and queues it.
    fn add(&mut self, mut s: Site) {
        if !(s.k[0] >= self.region[0] && s.k[0] < self.region[1]) {
            return;
        }
        let slot = match self.free.pop() {
            Some(x) => x,
            None => {
                self.alive.push(false);
                self.cell_of.push(0);
                self.data.push(s);
                (self.alive.len() - 1) as u32
            }
        };
        let p = self.grid.wrap(s.k);
        let c = self.grid.cell(&p);
        self.grid.cells[c].push((slot, p));
        self.alive[slot as usize] = true;
        self.cell_of[slot as usize] = c as u32;
        s.slot = slot;
        self.push(s);
    }
    fn is_alive(&self, slot: u32) -> bool {
        self.alive[slot as usize]
    }
    /// Removes a popped site for good.
    fn retire(&mut self, slot: u32) {
        let i = slot as usize;
        if self.alive[i] {
            let cell = &mut self.grid.cells[self.cell_of[i] as usize];
            if let Some(pos) = cell.iter().position(|e| e.0 == slot) {
                cell.swap_remove(pos);
            }
            self.alive[i] = false;
        }
        self.free.push(slot);
    }
    /// Kills every site whose smallest-size sphere overlaps the sphere
    /// `(c, r)`; returns how many.
    fn kill_near(&mut self, c: &[f64; 3], r: f64, r_min: f64, tol: f64) -> u64 {
        let reach = r + r_min;
        let lim = (KILL * reach - tol).max(0.0);
        let lim2 = lim * lim;
        let g = &mut self.grid;
        let mut lo = [0i64; 3];
        let mut hi = [0i64; 3];
        for k in 0..3 {
            lo[k] = g.index(k, c[k] - reach);
            hi[k] = g.index(k, c[k] + reach);
            let periodic = k < 2 && g.period[k] > 0.0;
            if periodic {
                hi[k] = hi[k].min(lo[k] + g.n[k] as i64 - 1);
            } else {
                lo[k] = lo[k].max(0);
                hi[k] = hi[k].min(g.n[k] as i64 - 1);
            }
        }
        let mut killed = 0;
        for iz in lo[2]..=hi[2] {
            for iy in lo[1]..=hi[1] {
                for ix in lo[0]..=hi[0] {
                    let w = |k: usize, i: i64| i.rem_euclid(g.n[k] as i64) as usize;
                    let idx = w(0, ix) + g.n[0] * (w(1, iy) + g.n[1] * iz as usize);
                    let cell = &mut g.cells[idx];
                    let mut j = 0;
                    while j < cell.len() {
                        let (slot, p) = cell[j];
                        let mut d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                        for k in 0..2 {
                            let l = g.period[k];
                            if l > 0.0 {
                                d[k] -= (d[k] / l).round() * l;
                            }
                        }
                        if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < lim2 {
                            cell.swap_remove(j);
                            self.alive[slot as usize] = false;
                            killed += 1;
                        } else {
                            j += 1;
                        }
                    }
                }
            }
        }
        killed
    }
}

impl Sites {
    fn new(r_min: f64, r_max: f64, lo: [f64; 3], hi: [f64; 3], periodic: [bool; 2]) -> Self {
        Self {
            heaps: (0..=LEVELS).map(|_| BinaryHeap::new()).collect(),
            data: Vec::new(),
            r_min,
            step: (r_max - r_min) / LEVELS as f64,
            len: 0,
            alive: Vec::new(),
            cell_of: Vec::new(),
            free: Vec::new(),
            grid: SiteGrid::new(lo, hi, 2.0 * r_max, periodic),
            region: [f64::NEG_INFINITY, f64::INFINITY],
        }
    }
    /// Capacity of level `j`.
    fn cap(&self, j: usize) -> f64 {
        if j >= LEVELS {
            f64::INFINITY
        } else {
            self.r_min + j as f64 * self.step
        }
    }
    /// Level of a capacity (rounded down).
    fn level(&self, cap: f64) -> usize {
        if !cap.is_finite() {
            return LEVELS;
        }
        if self.step <= 0.0 {
            return 0;
        }
        (((cap - self.r_min) / self.step).floor().max(0.0) as usize).min(LEVELS - 1)
    }
    fn push(&mut self, s: Site) {
        let mut j = self.level(s.cap);
        // A capacity that is exactly a level's (a site put back) stays in it.
        if j < LEVELS && self.cap(j + 1) <= s.cap {
            j += 1;
        }
        let cap = self.cap(j);
        self.data[s.slot as usize] = Site { cap, ..s };
        self.heaps[j].push(Key::of(&s));
        self.len += 1;
    }
    /// The lowest site among the levels that can take radius `r`.
    fn pop_for(&mut self, r: f64) -> Option<Site> {
        let j = self.best_level(r)?;
        self.len -= 1;
        let key = self.heaps[j].pop()?;
        Some(self.data[key.slot as usize])
    }
    /// The site [`Sites::pop_for`] would return, without removing it.
    fn peek_for(&self, r: f64) -> Option<Site> {
        let j = self.best_level(r)?;
        let key = self.heaps[j].peek()?;
        Some(self.data[key.slot as usize])
    }
    /// The level whose top is the lowest among those that take radius `r`.
    fn best_level(&self, r: f64) -> Option<usize> {
        let mut best: Option<(usize, &Key)> = None;
        for j in (0..=LEVELS).rev() {
            if self.cap(j) < r * (1.0 - 1e-12) {
                break;
            }
            if let Some(t) = self.heaps[j].peek()
                && best.is_none_or(|(_, b)| t > b)
            {
                best = Some((j, t));
            }
        }
        best.map(|(j, _)| j)
    }
    /// Whether any site waits.
    fn is_empty(&self) -> bool {
        self.len == 0
    }
    fn len(&self) -> usize {
        self.len
    }
}

/// One neighbour of the generating sphere, relative to its centre.
#[derive(Clone, Copy, Default)]
struct Nb {
    /// `c_j − c_f` (periodic image applied).
    d: [f64; 3],
    /// `|d|²`.
    dd: f64,
    /// Halo radius `r_j + r`.
    rho: f64,
    /// `(|d|² + ρ_f² − ρ_j²)/2`: right-hand side of `d · y = b`.
    b: f64,
    /// Sphere id.
    id: u32,
}

#[derive(Clone)]
pub(crate) struct Front3<'a> {
    container: &'a Container,
    walls: Walls,
    /// Every wall plane (box faces, cylinder ends, mesh faces).
    all_planes: Vec<Plane>,
    periodic: [bool; 2],
    period: [f64; 2],
    box_lo: [f64; 3],
    r_min: f64,
    r_max: f64,
    tol: f64,
    grid: Grid3,
    pub(crate) xs: Vec<[f64; 4]>,
    nb: Vec<Nb>,
    planes: Vec<(Plane, u32)>,
    cands: Vec<([f64; 3], u32, u32)>,
    /// Spheres near a site (periodic images applied), for repeated tests.
    local: Vec<[f64; 4]>,
    /// Feasible sites of one generation.
    kept: Vec<([f64; 3], u32, u32)>,
    /// Sites of one placement (sequential mode).
    batch: Vec<Site>,
    /// Neighbour halos of the generating sphere as `[dx, dy, dz, (ρ −
    /// tol)²]`, padded to a multiple of 4 with halos nothing enters.
    halos: Vec<[f64; 4]>,
    /// `x` of the first sphere: its wall side in a box (default: the box's
    /// `min.x`; a slab's left end), its centre in a cylinder (default: on
    /// the `+x` side).
    seed_x: Option<f64>,
    pub(crate) stats: Pack3Stats,
}

/// Settings of one front run (see [`crate::Pack3Params`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RunOpts {
    pub(crate) order: FrontOrder,
    /// Upper bound on the spheres held (imported ones included).
    pub(crate) max: usize,
    pub(crate) lookahead: usize,
    pub(crate) max_skips: usize,
    /// Site generation on a second thread.
    pub(crate) pipeline: bool,
}

/// How a run starts: the whole container from a seed sphere (default), or
/// one slab of a slab-parallel packing (sites restricted to `region`;
/// `imported`: spheres of the neighbouring slabs, placed first as
/// obstacles, whose sites near the slab start the front).
#[derive(Debug, Clone, Default)]
pub(crate) struct Start {
    pub(crate) region: Option<[f64; 2]>,
    pub(crate) seed_x: Option<f64>,
    pub(crate) imported: Vec<[f64; 4]>,
}

impl<'a> Front3<'a> {
    pub(crate) fn new(container: &'a Container, r_min: f64, r_max: f64, capacity: usize) -> Self {
        let (lo, hi) = container.bbox();
        let periodic = container.periodic();
        let grid = Grid3::new(lo, hi, 2.0 * r_max, periodic, 64_000_000);
        let walls = Walls::new(container, r_max);
        let all_planes = match &walls {
            Walls::Planes(p) => p.clone(),
            Walls::Cylinder { planes, .. } => planes.to_vec(),
            Walls::Mesh(m) => m.planes.clone(),
        };
        Self {
            container,
            walls,
            all_planes,
            periodic,
            period: [hi.x - lo.x, hi.y - lo.y],
            box_lo: [lo.x, lo.y, lo.z],
            r_min,
            r_max,
            tol: FEAS_TOL * 2.0 * r_max,
            grid,
            xs: Vec::with_capacity(capacity),
            nb: Vec::with_capacity(64),
            planes: Vec::with_capacity(16),
            cands: Vec::with_capacity(1024),
            local: Vec::with_capacity(128),
            kept: Vec::with_capacity(64),
            batch: Vec::with_capacity(64),
            halos: Vec::with_capacity(64),
            seed_x: None,
            stats: Pack3Stats::default(),
        }
    }

    fn place(&mut self, mut p: [f64; 3], r: f64) -> u32 {
        for k in 0..2 {
            if self.periodic[k] {
                let l = self.period[k];
                let mut x = p[k] - self.box_lo[k];
                x -= (x / l).floor() * l;
                if x >= l {
                    x = 0.0;
                }
                p[k] = self.box_lo[k] + x;
            }
        }
        let id = self.xs.len() as u32;
        let q = [p[0], p[1], p[2], r];
        self.xs.push(q);
        self.grid.insert(id, &q);
        id
    }

    /// Exact container test for a sphere of radius `r` at `p`.
    #[inline]
    fn inside(&self, p: &[f64; 3], r: f64) -> bool {
        let need = r - self.tol;
        match &self.walls {
            Walls::Planes(pl) => pl
                .iter()
                .all(|w| w.n[0] * p[0] + w.n[1] * p[1] + w.n[2] * p[2] - w.o >= need),
            Walls::Cylinder {
                planes,
                axis,
                radius,
            } => {
                planes.iter().all(|w| w.n[2] * p[2] - w.o >= need) && {
                    let (dx, dy) = (p[0] - axis[0], p[1] - axis[1]);
                    let lim = radius - need;
                    lim >= 0.0 && dx * dx + dy * dy <= lim * lim
                }
            }
            Walls::Mesh(mw) => {
                if let Some(c) = mw.cell(p)
                    && mw.deep[c] >= need
                {
                    return true;
                }
                match self.container {
                    Container::Mesh(m) => {
                        let pp = Point3::new(p[0], p[1], p[2]);
                        m.clearance_bounded(&pp, need.abs() + self.r_max) >= need
                    }
                    _ => false,
                }
            }
        }
    }

    /// A sphere of radius `r` at `p` is inside and overlaps no sphere.
    fn feasible(&mut self, p: &[f64; 3], r: f64) -> bool {
        if !self.inside(p, r) {
            return false;
        }
        let tol = self.tol;
        let xs = &self.xs;
        !self.grid.any_near(p, r + self.r_max, |id, s| {
            let o = xs[id as usize];
            let (dx, dy, dz) = (p[0] - o[0] - s[0], p[1] - o[1] - s[1], p[2] - o[2] - s[2]);
            let m = r + o[3] - tol;
            dx * dx + dy * dy + dz * dz < m * m
        })
    }

    /// The first sphere: as low as possible, touching walls.
    fn seed(&mut self, r: f64) -> Option<u32> {
        let p = match (&self.walls, self.container) {
            (Walls::Planes(_), Container::Box { min, .. }) => {
                Some([self.seed_x.unwrap_or(min.x) + r, min.y + r, min.z + r])
            }
            (
                Walls::Cylinder {
                    axis,
                    radius,
                    planes,
                },
                _,
            ) => match self.seed_x {
                // A slab's first sphere: against the side at `x` (the
                // slab's middle), on the −y side.
                Some(x) => {
                    let rr = radius - r;
                    let dx = x - axis[0];
                    (dx.abs() < rr)
                        .then(|| [x, axis[1] - (rr * rr - dx * dx).sqrt(), planes[0].o + r])
                }
                None => Some([axis[0] + radius - r, axis[1], planes[0].o + r]),
            },
            (Walls::Mesh(mw), _) => {
                // Lowest feasible corner of three face planes, among the
                // planes facing most upwards.
                let mut order: Vec<usize> = (0..mw.planes.len()).collect();
                order.sort_by(|&a, &b| {
                    let (pa, pb) = (&mw.planes[a], &mw.planes[b]);
                    pb.n[2].total_cmp(&pa.n[2]).then(a.cmp(&b))
                });
                let take: Vec<usize> = order.into_iter().take(48).collect();
                let mut best: Option<[f64; 3]> = None;
                for (i, &a) in take.iter().enumerate() {
                    for (j, &b) in take.iter().enumerate().skip(i + 1) {
                        for &c in take.iter().skip(j + 1) {
                            let pl = [mw.planes[a], mw.planes[b], mw.planes[c]];
                            let m = nalgebra::Matrix3::from_rows(&[
                                pl[0].n.transpose(),
                                pl[1].n.transpose(),
                                pl[2].n.transpose(),
                            ]);
                            if m.determinant().abs() <= 1e-9 {
                                continue;
                            }
                            if let Some(inv) = m.try_inverse() {
                                let x = inv * Vector3::new(pl[0].o + r, pl[1].o + r, pl[2].o + r);
                                let q = [x.x, x.y, x.z];
                                if best.is_none_or(|b| lower(&q, &b)) && self.inside(&q, r) {
                                    best = Some(q);
                                }
                            }
                        }
                    }
                }
                best
            }
            _ => None,
        }?;
        if !self.inside(&p, r) {
            return None;
        }
        Some(self.place(p, r))
    }

    /// Open sites of the new sphere `f` for the smallest size: the common
    /// points of its halo with two more halos or offset walls that are
    /// inside the container and outside every halo.
    fn generate(&mut self, f: u32, g: f64, out: &mut Vec<Site>) {
        self.stats.evaluations += 1;
        let r = self.r_min;
        let q = self.xs[f as usize];
        let cf = [q[0], q[1], q[2]];
        let rho_f = q[3] + r;
        let rho_f2 = rho_f * rho_f;
        let reach = q[3] + 2.0 * r + self.r_max;
        self.nb.clear();
        {
            let xs = &self.xs;
            let nb = &mut self.nb;
            self.grid.for_each_near(&cf, reach, |id, s| {
                if id == f && s == [0.0; 3] {
                    return;
                }
                let o = xs[id as usize];
                let d = [
                    o[0] + s[0] - cf[0],
                    o[1] + s[1] - cf[1],
                    o[2] + s[2] - cf[2],
                ];
                let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let lim = q[3] + o[3] + 2.0 * r;
                if dd <= lim * lim {
                    let rho = o[3] + r;
                    nb.push(Nb {
                        d,
                        dd,
                        rho,
                        b: 0.5 * (dd + rho_f2 - rho * rho),
                        id,
                    });
                }
            });
        }
        self.planes.clear();
        let mut cyl: Option<([f64; 2], f64)> = None;
        let wall_reach = q[3] + 2.0 * r;
        let cfv = Vector3::from(cf);
        match &self.walls {
            Walls::Planes(pl) => {
                for (i, w) in pl.iter().enumerate() {
                    if w.n.dot(&cfv) - w.o <= wall_reach {
                        self.planes.push((*w, WALL + i as u32));
                    }
                }
            }
            Walls::Cylinder {
                planes,
                axis,
                radius,
            } => {
                for (i, w) in planes.iter().enumerate() {
                    if w.n.dot(&cfv) - w.o <= wall_reach {
                        self.planes.push((*w, WALL + i as u32));
                    }
                }
                let rho = (cf[0] - axis[0]).hypot(cf[1] - axis[1]);
                if radius - rho <= wall_reach {
                    cyl = Some((*axis, *radius));
                }
            }
            Walls::Mesh(mw) => {
                if let Some(c) = mw.cell(&cf) {
                    for &i in mw.near(c) {
                        let w = mw.planes[i as usize];
                        let s = w.n.dot(&cfv) - w.o;
                        if s <= wall_reach && s >= -q[3] {
                            self.planes.push((w, WALL + i));
                        }
                    }
                }
            }
        }
        self.halos.clear();
        let tol = self.tol;
        self.halos.extend(self.nb.iter().map(|o| {
            let m = o.rho - tol;
            [o.d[0], o.d[1], o.d[2], m * m]
        }));
        while !self.halos.len().is_multiple_of(4) {
            self.halos.push([f64::INFINITY, 0.0, 0.0, -1.0]);
        }
        self.cands.clear();
        let nb = &self.nb;
        let n = nb.len();
        let mut tmp = Pts::default();
        for i in 0..n {
            let a = nb[i];
            for bj in &nb[i + 1..] {
                let (ex, ey, ez) = (bj.d[0] - a.d[0], bj.d[1] - a.d[1], bj.d[2] - a.d[2]);
                let s = a.rho + bj.rho;
                if ex * ex + ey * ey + ez * ez > s * s {
                    continue;
                }
                tmp.clear();
                three_spheres(&a, bj, rho_f2, &mut tmp);
                for y in tmp.as_slice() {
                    self.cands.push((*y, a.id, bj.id));
                }
            }
        }
        for (w, wid) in &self.planes {
            let pw = Plane {
                n: w.n,
                o: w.o + r - w.n.dot(&cfv),
            };
            for a in nb {
                tmp.clear();
                sphere_sphere_plane(a, &pw, rho_f2, &mut tmp);
                for y in tmp.as_slice() {
                    self.cands.push((*y, a.id, *wid));
                }
            }
        }
        for (i, (w1, id1)) in self.planes.iter().enumerate() {
            for (w2, id2) in &self.planes[i + 1..] {
                let p1 = w1.o + r - w1.n.dot(&cfv);
                let p2 = w2.o + r - w2.n.dot(&cfv);
                tmp.clear();
                sphere_two_planes(&w1.n, p1, &w2.n, p2, rho_f2, &mut tmp);
                for y in tmp.as_slice() {
                    self.cands.push((*y, *id1, *id2));
                }
            }
        }
        if let Some((axis, radius)) = cyl {
            let rr = radius - r;
            if rr > 0.0 {
                let ax = [axis[0] - cf[0], axis[1] - cf[1]];
                for (w, wid) in &self.planes {
                    let zc = (w.o + r) / w.n[2] - cf[2];
                    tmp.clear();
                    circle_cylinder_horizontal(zc, rho_f2, ax, rr, &mut tmp);
                    for y in tmp.as_slice() {
                        self.cands.push((*y, *wid, CYL));
                    }
                }
                for a in nb {
                    tmp.clear();
                    circle_cylinder(a, rho_f2, ax, rr, &mut tmp);
                    for y in tmp.as_slice() {
                        self.cands.push((*y, a.id, CYL));
                    }
                }
            }
        }
        self.stats.neighbours += n as u64;
        self.stats.candidates += self.cands.len() as u64;
        let mut cands = std::mem::take(&mut self.cands);
        let mut kept = std::mem::take(&mut self.kept);
        kept.clear();
        for (y, a, b) in &cands {
            let p = [y[0] + cf[0], y[1] + cf[1], y[2] + cf[2]];
            if self.free(y) && self.inside(&p, r) {
                kept.push((p, *a, *b));
            }
        }
        // One site per pocket: sites of this batch closer than `DEDUP ·
        // r_min` describe the same hole; the lowest is kept.
        kept.sort_by(|x, y| {
            x.0[2]
                .total_cmp(&y.0[2])
                .then(x.0[0].total_cmp(&y.0[0]))
                .then(x.0[1].total_cmp(&y.0[1]))
                .then((x.1, x.2).cmp(&(y.1, y.2)))
        });
        let eps2 = (DEDUP * r).powi(2);
        for i in 0..kept.len() {
            let (p, a, b) = kept[i];
            let dup = kept[..i].iter().any(|(q, _, _)| {
                (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2) < eps2
            });
            if dup {
                continue;
            }
            self.stats.sites += 1;
            out.push(Site {
                k: p,
                ids: [f, a, b],
                g,
                cap: f64::INFINITY,
                slot: 0,
            });
        }
        cands.clear();
        self.cands = cands;
        self.kept = kept;
    }

    /// `y` (relative to the generating sphere) outside every neighbour halo.
    #[inline]
    fn free(&self, y: &[f64; 3]) -> bool {
        // Chunks of four halos without early exit inside a chunk (the
        // compiler vectorises them); padding halos never hit.
        let h = &self.halos;
        for c in h.chunks_exact(4) {
            let mut hit = false;
            for o in c {
                let (dx, dy, dz) = (y[0] - o[0], y[1] - o[1], y[2] - o[2]);
                hit |= dx * dx + dy * dy + dz * dz < o[3];
            }
            if hit {
                return false;
            }
        }
        true
    }

    /// Centre of a sphere of radius `r` at `site` (the solution nearest to
    /// the site's key), or `None` when the obstacles no longer have a
    /// common point at this radius.
    fn site_position(&self, site: &Site, r: f64) -> Option<[f64; 3]> {
        let q0 = self.xs[site.ids[0] as usize];
        let c0 = [q0[0], q0[1], q0[2]];
        let rho0 = q0[3] + r;
        let rho02 = rho0 * rho0;
        // Obstacle sphere `id` relative to c0 (nearest periodic image).
        let rel = |id: u32| -> Nb {
            let o = self.xs[id as usize];
            let mut d = [o[0] - c0[0], o[1] - c0[1], o[2] - c0[2]];
            for k in 0..2 {
                if self.periodic[k] {
                    let l = self.period[k];
                    d[k] -= (d[k] / l).round() * l;
                }
            }
            let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let rho = o[3] + r;
            Nb {
                d,
                dd,
                rho,
                b: 0.5 * (dd + rho02 - rho * rho),
                id,
            }
        };
        let cv = Vector3::from(c0);
        let plane = |id: u32| -> Plane {
            let w = self.all_planes[(id - WALL) as usize];
            Plane {
                n: w.n,
                o: w.o + r - w.n.dot(&cv),
            }
        };
        let mut tmp = Pts::default();
        let [_, a, b] = site.ids;
        if b == FREE {
            let w = self.all_planes[(a - WALL) as usize];
            let zc = (w.o + r) / w.n[2] - c0[2];
            let s2 = rho02 - zc * zc;
            return (s2 >= 0.0).then(|| [c0[0] + s2.sqrt(), c0[1], c0[2] + zc]);
        }
        match (a < WALL, b < WALL, b == CYL) {
            (true, true, _) => three_spheres(&rel(a), &rel(b), rho02, &mut tmp),
            (true, false, false) => sphere_sphere_plane(&rel(a), &plane(b), rho02, &mut tmp),
            (false, false, false) => {
                let (p1, p2) = (plane(a), plane(b));
                sphere_two_planes(&p1.n, p1.o, &p2.n, p2.o, rho02, &mut tmp);
            }
            (_, _, true) => {
                let Walls::Cylinder { axis, radius, .. } = &self.walls else {
                    return None;
                };
                let rr = radius - r;
                if rr <= 0.0 {
                    return None;
                }
                let ax = [axis[0] - c0[0], axis[1] - c0[1]];
                if a < WALL {
                    circle_cylinder(&rel(a), rho02, ax, rr, &mut tmp);
                } else {
                    let w = self.all_planes[(a - WALL) as usize];
                    let zc = (w.o + r) / w.n[2] - c0[2];
                    circle_cylinder_horizontal(zc, rho02, ax, rr, &mut tmp);
                }
            }
            _ => return None,
        }
        let key = [site.k[0] - c0[0], site.k[1] - c0[1], site.k[2] - c0[2]];
        tmp.as_slice()
            .iter()
            .map(|y| {
                let e = (y[0] - key[0]).powi(2) + (y[1] - key[1]).powi(2) + (y[2] - key[2]).powi(2);
                (e, y)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, y)| [y[0] + c0[0], y[1] + c0[1], y[2] + c0[2]])
    }

    /// The site's centre for radius `r` if a sphere fits there.
    fn try_site(&mut self, site: &Site, r: f64) -> Option<[f64; 3]> {
        self.stats.site_tests += 1;
        let p = self.site_position(site, r)?;
        self.feasible(&p, r).then_some(p)
    }

    /// Gathers the spheres near `site` for the capacity bisection on
    /// `[r_min, r]`: those within `r + r_max + δ` of the site's centre `c`
    /// for `r_min`, with `δ` the distance between its centres for `r_min` and
    /// `r` (the site moves little between the two). The capacity is only an
    /// estimate (a placement is always checked against the full index), so
    /// a sphere missed by a curving path costs at most a retry.
    fn gather_local(&mut self, site: &Site, c: &[f64; 3], r: f64) {
        let c = *c;
        let delta = self.site_position(site, r).map_or(r - self.r_min, |q| {
            ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2) + (q[2] - c[2]).powi(2)).sqrt()
        });
        let reach = r + self.r_max + delta;
        self.local.clear();
        let xs = &self.xs;
        let local = &mut self.local;
        self.grid.for_each_near(&c, reach, |id, s| {
            let o = xs[id as usize];
            let p = [o[0] + s[0], o[1] + s[1], o[2] + s[2], o[3]];
            let (dx, dy, dz) = (p[0] - c[0], p[1] - c[1], p[2] - c[2]);
            let lim = r + delta + o[3];
            if dx * dx + dy * dy + dz * dz <= lim * lim {
                local.push(p);
            }
        });
    }

    /// [`Front3::try_site`] against the gathered spheres (radius at most
    /// the one gathered for).
    fn try_local(&mut self, site: &Site, r: f64) -> bool {
        self.stats.site_tests += 1;
        let Some(p) = self.site_position(site, r) else {
            return false;
        };
        if !self.inside(&p, r) {
            return false;
        }
        let tol = self.tol;
        self.local.iter().all(|o| {
            let (dx, dy, dz) = (p[0] - o[0], p[1] - o[1], p[2] - o[2]);
            let m = r + o[3] - tol;
            dx * dx + dy * dy + dz * dz >= m * m
        })
    }

    /// Runs the front loop; `sizes(k)` gives the `k`-th diameter. A site
    /// takes the oldest of the next `lookahead` sizes that fits it (1: the
    /// strict size order of the seed).
    pub(crate) fn run(
        &mut self,
        sizes: &mut dyn FnMut(usize) -> Option<f64>,
        opts: RunOpts,
        start: Start,
    ) {
        let RunOpts {
            order,
            max,
            lookahead,
            max_skips,
            pipeline,
        } = opts;
        self.seed_x = start.seed_x;
        // Secondary key per order: lowest candidate (none), lowest
        // generating sphere, newest generating sphere (stack).
        let gkey = |s: &Self, id: u32| match order {
            FrontOrder::LowestFirst => s.xs[id as usize][2],
            FrontOrder::Stack => -f64::from(id),
            _ => 0.0,
        };
        let (blo, bhi) = self.container.bbox();
        let mut sites = Sites::new(
            self.r_min,
            self.r_max,
            [blo.x, blo.y, blo.z],
            [bhi.x, bhi.y, bhi.z],
            self.periodic,
        );
        let mut k = 0usize;
        let mut batch = Vec::new();
        if let Some(region) = start.region {
            sites.region = region;
        }
        if !start.imported.is_empty() {
            // A slab between packed neighbours: their spheres are obstacles,
            // and those within reach of the slab start the front.
            let reach = 2.0 * self.r_max;
            let (x0, x1) = (sites.region[0] - reach, sites.region[1] + reach);
            let first = self.xs.len() as u32;
            for q in &start.imported {
                self.place([q[0], q[1], q[2]], q[3]);
            }
            for id in first..self.xs.len() as u32 {
                let x = self.xs[id as usize][0];
                if x >= x0 && x < x1 {
                    let g = gkey(self, id);
                    self.generate(id, g, &mut batch);
                    for st in batch.drain(..) {
                        sites.add(st);
                    }
                }
            }
            if sites.is_empty() {
                return;
            }
        } else {
            let first = loop {
                let Some(d) = sizes(k) else { return };
                k += 1;
                self.stats.sizes_drawn += 1;
                if let Some(id) = self.seed(0.5 * d) {
                    break id;
                }
                self.stats.sizes_skipped += 1;
                if k > MAX_SKIPS {
                    return;
                }
            };
            let g = gkey(self, first);
            self.generate(first, g, &mut batch);
            for st in batch.drain(..) {
                sites.add(st);
            }
            if sites.is_empty()
                && let Some(floor) = self.all_planes.iter().position(|w| w.n[2] > 0.999_999)
            {
                // Periodic in x and y (or a slab periodic in y): nothing
                // but the floor around the first sphere; the second one
                // sits beside it.
                let q = self.xs[first as usize];
                sites.add(Site {
                    k: [q[0] + q[3] + self.r_min, q[1], q[2]],
                    ids: [first, WALL + floor as u32, FREE],
                    g,
                    cap: f64::INFINITY,
                    slot: 0,
                });
            }
        }
        let mut main = |this: &mut Self, lag: &mut Lag| {
            // The window of upcoming radii, oldest first.
            let w = lookahead.max(1);
            let mut window: Vec<f64> = Vec::with_capacity(w);
            let mut refill = |window: &mut Vec<f64>, k: &mut usize, st: &mut Pack3Stats| {
                while window.len() < w {
                    let Some(d) = sizes(*k) else { break };
                    *k += 1;
                    st.sizes_drawn += 1;
                    window.push(0.5 * d);
                }
            };
            refill(&mut window, &mut k, &mut this.stats);
            let mut skips = 0usize;
            let mut peak = 0usize;
            let mut spec: Vec<(Site, Outcome)> = Vec::new();
            let mut cache: Vec<(u32, Outcome)> = Vec::new();
            while this.xs.len() < max && !window.is_empty() {
                let r_small = window.iter().copied().fold(f64::INFINITY, f64::min);
                if lag.pending.is_some() {
                    // The worker generates the last sphere's sites: decide
                    // the next pops meanwhile (read-only), then replay them
                    // in the exact sequential order once the sites are in.
                    spec.clear();
                    let mut ready: Option<Vec<Site>> = None;
                    loop {
                        // Speculate only while the worker is busy: the
                        // replay gives the same packing however far we got.
                        if let Some(pipe) = &lag.pipe
                            && let Ok(b) = pipe.results.try_recv()
                        {
                            ready = Some(b);
                            break;
                        }
                        let Some(site) = lag.sites.pop_for(r_small) else {
                            break;
                        };
                        let o = if lag.sites.is_alive(site.slot) {
                            this.decide(&site, &window)
                        } else {
                            Outcome::Dead
                        };
                        let stop = matches!(o, Outcome::Place { .. });
                        spec.push((site, o));
                        if stop {
                            break;
                        }
                    }
                    this.merge_pending(lag, ready);
                    let mut iter = std::mem::take(&mut spec).into_iter();
                    while let Some((site, o)) = iter.next() {
                        if lag
                            .sites
                            .peek_for(r_small)
                            .is_some_and(|t| Key::of(&t) > Key::of(&site))
                        {
                            // A new site is lower: the sequential loop would
                            // have taken it first.
                            lag.sites.push(site);
                            cache.push((site.slot, o));
                            for (rest, ro) in iter.by_ref() {
                                lag.sites.push(rest);
                                cache.push((rest.slot, ro));
                            }
                            break;
                        }
                        if this.apply(site, o, lag, &mut window, &gkey) {
                            skips = 0;
                            cache.clear();
                            refill(&mut window, &mut k, &mut this.stats);
                        }
                    }
                    peak = peak.max(lag.sites.len());
                    continue;
                }
                let Some(site) = lag.sites.pop_for(r_small) else {
                    if lag.sites.is_empty() || skips >= max_skips {
                        break;
                    }
                    // No site takes any size of the window: skip the oldest.
                    this.stats.sizes_skipped += 1;
                    skips += 1;
                    window.remove(0);
                    refill(&mut window, &mut k, &mut this.stats);
                    continue;
                };
                // A decision made while speculating still holds: nothing
                // was placed since.
                let cached = cache
                    .iter()
                    .position(|c| c.0 == site.slot)
                    .map(|i| cache.swap_remove(i).1);
                let o = match cached {
                    Some(o) => o,
                    None if lag.sites.is_alive(site.slot) => this.decide(&site, &window),
                    None => Outcome::Dead,
                };
                if this.apply(site, o, lag, &mut window, &gkey) {
                    skips = 0;
                    cache.clear();
                    refill(&mut window, &mut k, &mut this.stats);
                }
                peak = peak.max(lag.sites.len());
            }
            this.merge_pending(lag, None);
            this.note_memory(peak * std::mem::size_of::<Site>());
        };
        let threaded = pipeline && rayon::current_num_threads() >= 2;
        if threaded {
            let mut replica = self.clone();
            replica.stats = Pack3Stats::default();
            let (job_tx, job_rx) = mpsc::channel::<Job>();
            let (res_tx, res_rx) = mpsc::channel::<Vec<Site>>();
            let worker_stats = std::thread::scope(|scope| {
                let worker = scope.spawn(move || {
                    loop {
                        match spin_receive(&job_rx) {
                            Some(Job::Place(q)) => {
                                replica.place([q[0], q[1], q[2]], q[3]);
                            }
                            Some(Job::Generate(id, g)) => {
                                let mut b = Vec::new();
                                replica.generate(id, g, &mut b);
                                if res_tx.send(b).is_err() {
                                    break;
                                }
                            }
                            None => break,
                        }
                    }
                    replica.stats
                });
                let mut lag = Lag {
                    sites,
                    pending: None,
                    pipe: Some(Pipe {
                        jobs: job_tx,
                        results: res_rx,
                    }),
                };
                main(self, &mut lag);
                // Closing the job channel stops the worker.
                drop(lag.pipe.take());
                worker.join().unwrap_or_default()
            });
            self.stats.evaluations += worker_stats.evaluations;
            self.stats.neighbours += worker_stats.neighbours;
            self.stats.candidates += worker_stats.candidates;
            self.stats.sites += worker_stats.sites;
        } else {
            let mut lag = Lag {
                sites,
                pending: None,
                pipe: None,
            };
            main(self, &mut lag);
        }
    }

    /// What the front does with a popped site for the current window
    /// (reads the spheres, changes nothing but scratch and counters).
    fn decide(&mut self, site: &Site, window: &[f64]) -> Outcome {
        self.stats.pops += 1;
        let r0 = window[0];
        let mut r0_failed = false;
        if site.cap >= r0 {
            if let Some(p) = self.try_site(site, r0) {
                return Outcome::Place { p, r: r0, i: 0 };
            }
            r0_failed = true;
        }
        self.stats.site_tests += 1;
        let Some(c) = self.site_position(site, self.r_min) else {
            return Outcome::Drop;
        };
        if !self.feasible(&c, self.r_min) {
            return Outcome::Drop;
        }
        // Capacity by bisection on [r_min, min(r0, cap)] to 1/16, against
        // the spheres gathered once (the top is known to fail when it is
        // r0 and r0 failed against the full index).
        let top = r0.min(site.cap);
        self.gather_local(site, &c, top);
        let (mut lo, mut hi) = (self.r_min, top);
        if !(r0_failed && top == r0) && self.try_local(site, hi) {
            lo = hi;
        } else {
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if self.try_local(site, mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
        }
        // The oldest size of the window that fits. A size the local test
        // admits but the full index refuses (a sphere beyond the gathered
        // reach) lowers the capacity below it, so the site cannot come back
        // for the same sizes.
        for (i, &r) in window.iter().enumerate() {
            if r > lo {
                continue;
            }
            if let Some(p) = self.try_site(site, r) {
                return Outcome::Place { p, r, i };
            }
            lo = r * (1.0 - 1e-9);
        }
        if lo < self.r_min {
            Outcome::Drop
        } else {
            Outcome::Defer(lo)
        }
    }

    /// Carries out a decision; returns whether a sphere was placed (the
    /// window entry is then removed and must be refilled).
    fn apply(
        &mut self,
        site: Site,
        o: Outcome,
        lag: &mut Lag,
        window: &mut Vec<f64>,
        g_of: &dyn Fn(&Self, u32) -> f64,
    ) -> bool {
        match o {
            Outcome::Dead => {
                lag.sites.retire(site.slot);
                false
            }
            Outcome::Drop => {
                self.stats.fronts_removed += 1;
                lag.sites.retire(site.slot);
                false
            }
            Outcome::Defer(lo) => {
                lag.sites.push(Site { cap: lo, ..site });
                false
            }
            Outcome::Place { p, r, i } => {
                lag.sites.retire(site.slot);
                let id = self.place(p, r);
                let q = self.xs[id as usize];
                self.stats.fronts_removed +=
                    lag.sites
                        .kill_near(&[q[0], q[1], q[2]], r, self.r_min, self.tol);
                let g = g_of(self, id);
                match &lag.pipe {
                    Some(pipe) => {
                        pipe.send(Job::Place(q));
                        pipe.send(Job::Generate(id, g));
                        lag.pending = Some((id, g));
                    }
                    None => {
                        let mut b = std::mem::take(&mut self.batch);
                        self.generate(id, g, &mut b);
                        for st in b.drain(..) {
                            lag.sites.add(st);
                        }
                        self.batch = b;
                    }
                }
                window.remove(i);
                true
            }
        }
    }

    /// Adds the pending sphere's sites (from the worker) to the open sites.
    fn merge_pending(&mut self, lag: &mut Lag, ready: Option<Vec<Site>>) {
        if lag.pending.take().is_none() {
            return;
        }
        if let Some(pipe) = &lag.pipe {
            let batch = ready.unwrap_or_else(|| pipe.receive());
            for st in batch {
                lag.sites.add(st);
            }
        }
    }

    fn note_memory(&mut self, extra: usize) {
        let b = self.xs.capacity() * 32 + self.grid.heap_bytes() + extra;
        self.stats.peak_bytes = self.stats.peak_bytes.max(b as u64);
    }
}

/// Up to eight solution points, without allocation.
#[derive(Default)]
struct Pts {
    p: [[f64; 3]; 8],
    n: usize,
}

impl Pts {
    #[inline]
    fn push(&mut self, q: [f64; 3]) {
        if self.n < 8 {
            self.p[self.n] = q;
            self.n += 1;
        }
    }
    #[inline]
    fn clear(&mut self) {
        self.n = 0;
    }
    #[inline]
    fn as_slice(&self) -> &[[f64; 3]] {
        &self.p[..self.n]
    }
}

/// Centres (relative to the front) of a sphere tangent to the front and to
/// obstacles `a`, `b`: `|y|² = ρ_f²`, `d_a·y = b_a`, `d_b·y = b_b`. The
/// solution line `y_0 + t (d_a × d_b)` with `y_0` in the plane of `d_a`,
/// `d_b` (the closed form of [`packer_contact::contact3d::intersect`], inlined).
#[inline]
fn three_spheres(a: &Nb, b: &Nb, rho_f2: f64, out: &mut Pts) {
    let (da, db) = (a.d, b.d);
    let u = [
        da[1] * db[2] - da[2] * db[1],
        da[2] * db[0] - da[0] * db[2],
        da[0] * db[1] - da[1] * db[0],
    ];
    let uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    if !uu.gt(&(1e-20 * a.dd * b.dd)) {
        return;
    }
    // y0 = ((d_b × u) b_a + (u × d_a) b_b) / |u|²
    let dbu = [
        db[1] * u[2] - db[2] * u[1],
        db[2] * u[0] - db[0] * u[2],
        db[0] * u[1] - db[1] * u[0],
    ];
    let uda = [
        u[1] * da[2] - u[2] * da[1],
        u[2] * da[0] - u[0] * da[2],
        u[0] * da[1] - u[1] * da[0],
    ];
    let inv = 1.0 / uu;
    let y0 = [
        (dbu[0] * a.b + uda[0] * b.b) * inv,
        (dbu[1] * a.b + uda[1] * b.b) * inv,
        (dbu[2] * a.b + uda[2] * b.b) * inv,
    ];
    let y0n = y0[0] * y0[0] + y0[1] * y0[1] + y0[2] * y0[2];
    let disc = rho_f2 - y0n;
    if disc < 0.0 {
        return;
    }
    let t = (disc * inv).sqrt();
    out.push([y0[0] + u[0] * t, y0[1] + u[1] * t, y0[2] + u[2] * t]);
    if t > 0.0 {
        out.push([y0[0] - u[0] * t, y0[1] - u[1] * t, y0[2] - u[2] * t]);
    }
}

/// Front, obstacle `a` and a plane `n·y = o` (relative to the front).
#[inline]
fn sphere_sphere_plane(a: &Nb, w: &Plane, rho_f2: f64, out: &mut Pts) {
    let da = Vector3::from(a.d);
    let u = da.cross(&w.n);
    let uu = u.norm_squared();
    if !uu.gt(&(1e-20 * a.dd)) {
        return;
    }
    let y0 = (w.n.cross(&u) * a.b + u.cross(&da) * w.o) / uu;
    let disc = rho_f2 - y0.norm_squared();
    if disc < 0.0 {
        return;
    }
    let t = (disc / uu).sqrt();
    let p = y0 + u * t;
    out.push([p.x, p.y, p.z]);
    if t > 0.0 {
        let p = y0 - u * t;
        out.push([p.x, p.y, p.z]);
    }
}

/// Front and two planes `n_i·y = o_i`.
#[inline]
fn sphere_two_planes(
    n1: &Vector3<f64>,
    o1: f64,
    n2: &Vector3<f64>,
    o2: f64,
    rho_f2: f64,
    out: &mut Pts,
) {
    let u = n1.cross(n2);
    let uu = u.norm_squared();
    if !uu.gt(&1e-20) {
        return;
    }
    let y0 = (n2.cross(&u) * o1 + u.cross(n1) * o2) / uu;
    let disc = rho_f2 - y0.norm_squared();
    if disc < 0.0 {
        return;
    }
    let t = (disc / uu).sqrt();
    let p = y0 + u * t;
    out.push([p.x, p.y, p.z]);
    if t > 0.0 {
        let p = y0 - u * t;
        out.push([p.x, p.y, p.z]);
    }
}

/// Front circle at height `zc` (relative) meets the offset cylinder of
/// radius `rr` around `ax` (relative, horizontal).
fn circle_cylinder_horizontal(zc: f64, rho_f2: f64, ax: [f64; 2], rr: f64, out: &mut Pts) {
    let s2 = rho_f2 - zc * zc;
    if s2 < 0.0 {
        return;
    }
    let s = s2.sqrt();
    // Circles (0, s) and (ax, rr) in the plane.
    let d2 = ax[0] * ax[0] + ax[1] * ax[1];
    if d2 == 0.0 {
        return;
    }
    let d = d2.sqrt();
    if d > s + rr || d < (s - rr).abs() {
        return;
    }
    let a = (d2 + s2 - rr * rr) / (2.0 * d);
    let h = (s2 - a * a).max(0.0).sqrt();
    let (ux, uy) = (ax[0] / d, ax[1] / d);
    let (mx, my) = (a * ux, a * uy);
    out.push([mx - h * uy, my + h * ux, zc]);
    if h > 0.0 {
        out.push([mx + h * uy, my - h * ux, zc]);
    }
}

/// The circle common to the front's halo and obstacle `a`'s halo meets the
/// offset cylinder (radius `rr` around `ax`, relative): the roots of
/// `g(θ) = |x_xy(θ) − ax|² − rr²` on the circle, bracketed on 32 samples
/// and refined by the Illinois method to round-off.
fn circle_cylinder(a: &Nb, rho_f2: f64, ax: [f64; 2], rr: f64, out: &mut Pts) {
    let dd = a.dd;
    if dd == 0.0 {
        return;
    }
    let dl = dd.sqrt();
    let u = Vector3::from(a.d) / dl;
    let t = a.b / dl;
    let s2 = rho_f2 - t * t;
    if s2 <= 0.0 {
        return;
    }
    let s = s2.sqrt();
    let m = u * t;
    let helper = if u.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = u.cross(&helper).normalize();
    let e2 = u.cross(&e1);
    let at = |th: f64| -> Vector3<f64> { m + (e1 * th.cos() + e2 * th.sin()) * s };
    let g = |th: f64| -> f64 {
        let x = at(th);
        let (dx, dy) = (x.x - ax[0], x.y - ax[1]);
        dx * dx + dy * dy - rr * rr
    };
    const N: usize = 32;
    let step = std::f64::consts::TAU / N as f64;
    let mut t0 = 0.0;
    let mut g0 = g(t0);
    for i in 1..=N {
        let t1 = i as f64 * step;
        let g1 = g(t1);
        if g0 == 0.0 {
            let p = at(t0);
            out.push([p.x, p.y, p.z]);
        } else if g0 * g1 < 0.0 {
            // Illinois (modified regula falsi).
            let (mut a0, mut fa, mut b0, mut fb) = (t0, g0, t1, g1);
            for _ in 0..80 {
                let c = b0 - fb * (b0 - a0) / (fb - fa);
                let fc = g(c);
                if fc == 0.0 {
                    b0 = c;
                    break;
                }
                if fc * fb < 0.0 {
                    a0 = b0;
                    fa = fb;
                } else {
                    fa *= 0.5;
                }
                b0 = c;
                fb = fc;
                if (b0 - a0).abs() <= 1e-15 {
                    break;
                }
            }
            let p = at(b0);
            out.push([p.x, p.y, p.z]);
        }
        t0 = t1;
        g0 = g1;
    }
}

/// Test access to the closed forms.
#[cfg(test)]
pub(crate) mod tests_api {
    use super::*;

    /// Centres of a sphere of radius `r` tangent to three spheres, through
    /// the packer's inlined closed form.
    pub(crate) fn three(c: &[(Point3<f64>, f64)], r: f64) -> Vec<Point3<f64>> {
        let f = c[0];
        let rho_f = f.1 + r;
        let nb = |o: (Point3<f64>, f64)| {
            let d = o.0 - f.0;
            let dd = d.norm_squared();
            let rho = o.1 + r;
            Nb {
                d: [d.x, d.y, d.z],
                dd,
                rho,
                b: 0.5 * (dd + rho_f * rho_f - rho * rho),
                id: 0,
            }
        };
        let mut out = Pts::default();
        three_spheres(&nb(c[1]), &nb(c[2]), rho_f * rho_f, &mut out);
        out.as_slice()
            .iter()
            .map(|y| f.0 + Vector3::new(y[0], y[1], y[2]))
            .collect()
    }

    /// Centres touching a front sphere, an obstacle sphere and the inside
    /// of a cylinder of `radius` around the z axis.
    pub(crate) fn circle_cylinder(
        cf: [f64; 3],
        rf: f64,
        ca: [f64; 3],
        ra: f64,
        r: f64,
        radius: f64,
    ) -> Vec<[f64; 3]> {
        let rho_f = rf + r;
        let d = [ca[0] - cf[0], ca[1] - cf[1], ca[2] - cf[2]];
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let rho = ra + r;
        let a = Nb {
            d,
            dd,
            rho,
            b: 0.5 * (dd + rho_f * rho_f - rho * rho),
            id: 0,
        };
        let mut out = Pts::default();
        super::circle_cylinder(&a, rho_f * rho_f, [-cf[0], -cf[1]], radius - r, &mut out);
        out.as_slice()
            .iter()
            .map(|y| [y[0] + cf[0], y[1] + cf[1], y[2] + cf[2]])
            .collect()
    }
}
