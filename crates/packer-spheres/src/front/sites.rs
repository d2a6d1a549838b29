//! The open sites of the front: a site, its heap key, the capacity-level
//! heaps that hand out the lowest site for a radius, and the grid that lets
//! a new sphere kill the sites it covers.

// Coordinates are `[f64; 3]` triples indexed in step with box bounds,
// periods and cell counts: index loops read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// An open site: where a sphere touches the three obstacles `ids`
/// (`ids[0]` the sphere that generated it); `k` is its centre for the
/// smallest size (the ordering key).
#[derive(Clone, Copy, Debug)]
pub(super) struct Site {
    pub(super) k: [f64; 3],
    pub(super) ids: [u32; 3],
    /// Secondary key: `z` of the generating sphere (front order
    /// [`FrontOrder::LowestFirst`](packer_quadtree::FrontOrder::LowestFirst)), else 0.
    pub(super) g: f64,
    /// Largest radius known to fit (infinite until a size failed here).
    pub(super) cap: f64,
    /// Registry slot (liveness and the site grid).
    pub(super) slot: u32,
}
/// A waiting site in a heap: its order keys and registry slot (24 bytes;
/// the site itself stays in the registry). Ties in `z` (a floor layer of
/// equal spheres) go to the lower slot: slots are handed out in a
/// deterministic order, so the packing is.
#[derive(Clone, Copy, Debug)]
pub(super) struct Key {
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
    pub(super) fn of(s: &Site) -> Self {
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

/// A new sphere kills the sites whose smallest-size centre lies within
/// `KILL · (r + r_min)` of its centre.
const KILL: f64 = 1.0;

/// Number of capacity levels of the waiting sites.
const LEVELS: usize = 16;

/// The open sites, in `LEVELS + 1` heaps: level `j < LEVELS` holds sites
/// known to take radii up to `r_min + j·Δ` (capacity found by bisection,
/// rounded down to a level), level `LEVELS` the sites not yet known to be
/// too small for any size. For a radius `r` the eligible levels are those
/// whose capacity is at least `r`; the next site is the lowest key among
/// their tops (at most 17 comparisons, no re-queuing when sizes change).
pub(super) struct Sites {
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
    pub(super) region: [f64; 2],
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
    pub(super) fn add(&mut self, mut s: Site) {
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
    pub(super) fn is_alive(&self, slot: u32) -> bool {
        self.alive[slot as usize]
    }
    /// Removes a popped site for good.
    pub(super) fn retire(&mut self, slot: u32) {
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
    pub(super) fn kill_near(&mut self, c: &[f64; 3], r: f64, r_min: f64, tol: f64) -> u64 {
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
    pub(super) fn new(
        r_min: f64,
        r_max: f64,
        lo: [f64; 3],
        hi: [f64; 3],
        periodic: [bool; 2],
    ) -> Self {
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
    pub(super) fn push(&mut self, s: Site) {
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
    pub(super) fn pop_for(&mut self, r: f64) -> Option<Site> {
        let j = self.best_level(r)?;
        self.len -= 1;
        let key = self.heaps[j].pop()?;
        Some(self.data[key.slot as usize])
    }
    /// The site [`Sites::pop_for`] would return, without removing it.
    pub(super) fn peek_for(&self, r: f64) -> Option<Site> {
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
    pub(super) fn is_empty(&self) -> bool {
        self.len == 0
    }
    pub(super) fn len(&self) -> usize {
        self.len
    }
}
