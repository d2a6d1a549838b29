//! The checker's own uniform cell grid: axes with periodic wrapping, and
//! buckets of items by cell (a counting sort into a flat cell-major list).

/// Axes of a uniform cell grid: `n[k]` cells of size `cell[k]` from
/// `origin[k]`; periodic axes wrap with period `len[k] = n[k] · cell[k]`.
pub(super) struct Axes {
    origin: [f64; 3],
    cell: [f64; 3],
    pub(super) len: [f64; 3],
    pub(super) n: [usize; 3],
    periodic: [bool; 3],
}

impl Axes {
    /// Cells of size at least `h` over `[lo, hi]`; the size grows until
    /// there are at most `max_cells` cells. Periodic axes get a whole
    /// number of cells per period `hi − lo`.
    pub(super) fn new(
        lo: [f64; 3],
        hi: [f64; 3],
        periodic: [bool; 3],
        h: f64,
        max_cells: usize,
    ) -> Self {
        let mut h = h;
        loop {
            let mut n = [1usize; 3];
            let mut cell = [h; 3];
            let mut len = [0.0; 3];
            for k in 0..3 {
                let ext = (hi[k] - lo[k]).max(0.0);
                if periodic[k] {
                    n[k] = ((ext / h).floor() as usize).max(1);
                    cell[k] = ext / n[k] as f64;
                    len[k] = ext;
                } else {
                    n[k] = (ext / h).floor() as usize + 1;
                }
            }
            let total = n[0].saturating_mul(n[1]).saturating_mul(n[2]);
            if total <= max_cells {
                return Self {
                    origin: lo,
                    cell,
                    len,
                    n,
                    periodic,
                };
            }
            h *= 1.5;
        }
    }

    pub(super) fn total(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    pub(super) fn coord_axis(&self, k: usize, x: f64) -> usize {
        let mut t = x - self.origin[k];
        if self.periodic[k] {
            t = t.rem_euclid(self.len[k]);
        }
        let c = (t / self.cell[k]).floor();
        if c <= 0.0 {
            0
        } else {
            (c as usize).min(self.n[k] - 1)
        }
    }

    pub(super) fn coord(&self, p: [f64; 3]) -> [usize; 3] {
        [
            self.coord_axis(0, p[0]),
            self.coord_axis(1, p[1]),
            self.coord_axis(2, p[2]),
        ]
    }

    pub(super) fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    /// Distinct neighbour cells of `c` along axis `k` (itself included).
    pub(super) fn neighbours(&self, k: usize, c: usize) -> ([usize; 3], usize) {
        let n = self.n[k];
        if self.periodic[k] {
            match n {
                1 => ([0, 0, 0], 1),
                2 => ([0, 1, 0], 2),
                _ => ([(c + n - 1) % n, c, (c + 1) % n], 3),
            }
        } else {
            let lo = c.saturating_sub(1);
            let hi = (c + 1).min(n - 1);
            let mut out = [0; 3];
            let mut m = 0;
            for v in lo..=hi {
                out[m] = v;
                m += 1;
            }
            (out, m)
        }
    }
}

/// Items bucketed by cell: the items of cell `c` are
/// `items[start[c]..start[c + 1]]`, in ascending order.
pub(super) struct Buckets {
    start: Vec<usize>,
    pub(super) items: Vec<usize>,
}

impl Buckets {
    /// Counting sort of item `i` into cell `keys[i]` (stable).
    pub(super) fn from_keys(ncells: usize, keys: &[usize]) -> Self {
        let mut start = vec![0usize; ncells + 1];
        for &k in keys {
            start[k + 1] += 1;
        }
        for c in 0..ncells {
            start[c + 1] += start[c];
        }
        let mut next = start.clone();
        let mut items = vec![0usize; keys.len()];
        for (i, &k) in keys.iter().enumerate() {
            items[next[k]] = i;
            next[k] += 1;
        }
        Self { start, items }
    }

    /// Item `i` in every cell of the box `ranges[i] = (lo, hi)` (inclusive
    /// cell coordinates).
    pub(super) fn from_ranges(axes: &Axes, ranges: &[([usize; 3], [usize; 3])]) -> Self {
        let ncells = axes.total();
        let mut start = vec![0usize; ncells + 1];
        let each = |r: &([usize; 3], [usize; 3]), f: &mut dyn FnMut(usize)| {
            for z in r.0[2]..=r.1[2] {
                for y in r.0[1]..=r.1[1] {
                    for x in r.0[0]..=r.1[0] {
                        f(axes.flat([x, y, z]));
                    }
                }
            }
        };
        for r in ranges {
            each(r, &mut |c| start[c + 1] += 1);
        }
        for c in 0..ncells {
            start[c + 1] += start[c];
        }
        let mut next = start.clone();
        let mut items = vec![0usize; start[ncells]];
        for (i, r) in ranges.iter().enumerate() {
            each(r, &mut |c| {
                items[next[c]] = i;
                next[c] += 1;
            });
        }
        Self { start, items }
    }

    pub(super) fn cell(&self, c: usize) -> std::ops::Range<usize> {
        self.start[c]..self.start[c + 1]
    }
}
