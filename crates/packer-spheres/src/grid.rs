//! The packer's uniform cell grid over sphere centres (intrusive per-cell
//! linked lists: O(1) insertion, a query visits the cells of a cube),
//! periodic in x and/or y when the container is.

use nalgebra::Point3;

const NIL: u32 = u32::MAX;

/// Cell grid over `[lo, hi]`; periodic axes wrap, others clamp.
#[derive(Debug, Clone)]
pub(crate) struct Grid3 {
    lo: [f64; 3],
    inv: [f64; 3],
    n: [usize; 3],
    /// Period per axis (0 when not periodic).
    period: [f64; 3],
    head: Vec<u32>,
    next: Vec<u32>,
    any_periodic: bool,
}

impl Grid3 {
    /// A grid with cells of about `cell` over `[lo, hi]`, at most
    /// `max_cells` cells (the cell grows if needed).
    pub(crate) fn new(
        lo: Point3<f64>,
        hi: Point3<f64>,
        cell: f64,
        periodic: [bool; 2],
        max_cells: usize,
    ) -> Self {
        let ext = hi - lo;
        let mut c = cell;
        loop {
            let cells: f64 = (0..3).map(|k| (ext[k] / c).ceil().max(1.0)).product();
            if cells <= max_cells as f64 {
                break;
            }
            c *= 1.25;
        }
        let mut n = [1usize; 3];
        let mut csz = [c; 3];
        let mut period = [0.0; 3];
        for k in 0..3 {
            if k < 2 && periodic[k] {
                n[k] = ((ext[k] / c).floor() as usize).max(1);
                csz[k] = ext[k] / n[k] as f64;
                period[k] = ext[k];
            } else {
                n[k] = ((ext[k] / c).ceil() as usize).max(1);
            }
        }
        Self {
            lo: [lo.x, lo.y, lo.z],
            inv: [1.0 / csz[0], 1.0 / csz[1], 1.0 / csz[2]],
            n,
            period,
            head: vec![NIL; n[0] * n[1] * n[2]],
            next: Vec::new(),
            any_periodic: periodic[0] || periodic[1],
        }
    }

    #[inline]
    fn coord(&self, k: usize, x: f64) -> usize {
        let f = ((x - self.lo[k]) * self.inv[k]).max(0.0);
        (f as usize).min(self.n[k] - 1)
    }

    /// Inserts `id` (ids dense and increasing) at `p`.
    pub(crate) fn insert(&mut self, id: u32, p: &[f64; 4]) {
        let c = self.coord(0, p[0])
            + self.n[0] * (self.coord(1, p[1]) + self.n[1] * self.coord(2, p[2]));
        let id_us = id as usize;
        if self.next.len() <= id_us {
            self.next.resize(id_us + 1, NIL);
        }
        self.next[id_us] = self.head[c];
        self.head[c] = id;
    }

    /// Calls `visit(id, shift)` for every point in the cells overlapping the
    /// cube of half-side `reach` around `p`; `shift` is the periodic image
    /// offset to add to the point's stored position.
    #[inline]
    pub(crate) fn for_each_near(
        &self,
        p: &[f64; 3],
        reach: f64,
        mut visit: impl FnMut(u32, [f64; 3]),
    ) {
        self.any_near(p, reach, |id, s| {
            visit(id, s);
            false
        });
    }

    /// As [`Grid3::for_each_near`], stopping at the first point for which
    /// `hit` returns `true`; returns whether one did.
    #[inline]
    pub(crate) fn any_near(
        &self,
        p: &[f64; 3],
        reach: f64,
        mut hit: impl FnMut(u32, [f64; 3]) -> bool,
    ) -> bool {
        if !self.any_periodic {
            let lo = [
                self.coord(0, p[0] - reach),
                self.coord(1, p[1] - reach),
                self.coord(2, p[2] - reach),
            ];
            let hi = [
                self.coord(0, p[0] + reach),
                self.coord(1, p[1] + reach),
                self.coord(2, p[2] + reach),
            ];
            for iz in lo[2]..=hi[2] {
                for iy in lo[1]..=hi[1] {
                    let row = self.n[0] * (iy + self.n[1] * iz);
                    for c in &self.head[row + lo[0]..=row + hi[0]] {
                        let mut id = *c;
                        while id != NIL {
                            if hit(id, [0.0; 3]) {
                                return true;
                            }
                            id = self.next[id as usize];
                        }
                    }
                }
            }
            return false;
        }
        let mut lo = [0i64; 3];
        let mut hi = [0i64; 3];
        for k in 0..3 {
            let a = ((p[k] - reach - self.lo[k]) * self.inv[k]).floor() as i64;
            let b = ((p[k] + reach - self.lo[k]) * self.inv[k]).floor() as i64;
            if self.period[k] > 0.0 {
                // At most one full period of cells.
                let n = self.n[k] as i64;
                lo[k] = a;
                hi[k] = b.min(a + n - 1);
            } else {
                lo[k] = a.max(0);
                hi[k] = b.min(self.n[k] as i64 - 1);
            }
        }
        for iz in lo[2]..=hi[2] {
            let (cz, sz) = self.wrap(2, iz);
            for iy in lo[1]..=hi[1] {
                let (cy, sy) = self.wrap(1, iy);
                let row = self.n[0] * (cy + self.n[1] * cz);
                for ix in lo[0]..=hi[0] {
                    let (cx, sx) = self.wrap(0, ix);
                    let mut id = self.head[row + cx];
                    while id != NIL {
                        if hit(id, [sx, sy, sz]) {
                            return true;
                        }
                        id = self.next[id as usize];
                    }
                }
            }
        }
        false
    }

    #[inline]
    fn wrap(&self, k: usize, i: i64) -> (usize, f64) {
        if self.period[k] > 0.0 {
            let n = self.n[k] as i64;
            let w = i.rem_euclid(n);
            let s = (i - w) / n;
            (w as usize, s as f64 * self.period[k])
        } else {
            (i as usize, 0.0)
        }
    }

    /// Heap bytes held.
    pub(crate) fn heap_bytes(&self) -> usize {
        4 * (self.head.capacity() + self.next.capacity())
    }
}
