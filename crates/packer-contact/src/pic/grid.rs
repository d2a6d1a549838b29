//! Uniform cell grid of placed grains or elements, for the neighbour
//! queries of the placement.

use nalgebra::SVector;

/// Uniform grid of the placed grains (cell side `2·r_max`).
pub(super) struct Grid<const D: usize> {
    cell: f64,
    n: usize,
    cells: Vec<Vec<u32>>,
}

impl<const D: usize> Grid<D> {
    pub(super) fn new(side: f64, cell: f64) -> Self {
        let n = ((side / cell).ceil() as usize).max(1);
        Self {
            cell,
            n,
            cells: vec![Vec::new(); n.pow(D as u32)],
        }
    }

    fn coord(&self, v: f64) -> usize {
        ((v / self.cell).floor().max(0.0) as usize).min(self.n - 1)
    }

    pub(super) fn insert(&mut self, c: &SVector<f64, D>, id: u32) {
        let mut k = 0;
        for i in (0..D).rev() {
            k = k * self.n + self.coord(c[i]);
        }
        self.cells[k].push(id);
    }

    /// Calls `f` for every id in cells meeting the box around `c` of half
    /// side `r`.
    pub(super) fn query(&self, c: &SVector<f64, D>, r: f64, mut f: impl FnMut(u32)) {
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        for i in 0..D {
            lo[i] = self.coord(c[i] - r);
            hi[i] = self.coord(c[i] + r);
        }
        let mut idx = lo;
        loop {
            let mut k = 0;
            for i in (0..D).rev() {
                k = k * self.n + idx[i];
            }
            for &id in &self.cells[k] {
                f(id);
            }
            let mut i = 0;
            loop {
                if i == D {
                    return;
                }
                if idx[i] < hi[i] {
                    idx[i] += 1;
                    break;
                }
                idx[i] = lo[i];
                i += 1;
            }
        }
    }
}
