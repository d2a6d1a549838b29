//! Spatial indexes over particle centres: the seed's MX quadtree (Pinto
//! 2009, §3.1.1–3.1.2, after Samet) and a uniform cell grid, behind one
//! trait so the packer and the benchmark can swap them.

use nalgebra::Point2;

const NIL: u32 = u32::MAX;

/// A point index answering rectangle range queries, as used by the
/// advancing front to find the particles near a front (Pinto 2009, §3.1).
pub trait SpatialIndex {
    /// An empty index over the box `[min, max]`; `cell` is the intended
    /// finest resolution (a particle diameter); `capacity` the expected
    /// number of points.
    fn with_bounds(min: Point2<f64>, max: Point2<f64>, cell: f64, capacity: usize) -> Self
    where
        Self: Sized;
    /// Inserts point `id` at `p`. Ids are dense (0, 1, 2, …); points outside
    /// the bounds are clamped into the border cells.
    fn insert(&mut self, id: u32, p: Point2<f64>);
    /// Appends to `out` the ids of a superset of the points inside the
    /// closed box `[min, max]` (every point inside is reported; the caller
    /// filters by exact distance).
    fn query(&self, min: Point2<f64>, max: Point2<f64>, out: &mut Vec<u32>);
    /// Calls `visit` with the id of a superset of the points inside the
    /// closed box `[min, max]`, in the order [`SpatialIndex::query`] reports
    /// them (the packer's allocation-free query path).
    fn for_each_in(&self, min: Point2<f64>, max: Point2<f64>, visit: impl FnMut(u32));
    /// Heap memory held by the index, in bytes.
    fn heap_bytes(&self) -> usize;
}

/// Uniform cell grid with intrusive per-cell linked lists (`head` per cell,
/// `next` per point): O(1) insert, query cost proportional to the cells
/// touched. The fast default.
#[derive(Debug, Clone)]
pub struct CellGrid {
    origin: [f64; 2],
    inv: f64,
    nx: usize,
    ny: usize,
    head: Vec<u32>,
    next: Vec<u32>,
}

impl CellGrid {
    #[inline]
    fn cell_of(&self, x: f64, y: f64) -> (usize, usize) {
        let fx = ((x - self.origin[0]) * self.inv).max(0.0);
        let fy = ((y - self.origin[1]) * self.inv).max(0.0);
        (
            (fx as usize).min(self.nx - 1),
            (fy as usize).min(self.ny - 1),
        )
    }
}

impl SpatialIndex for CellGrid {
    fn with_bounds(min: Point2<f64>, max: Point2<f64>, cell: f64, capacity: usize) -> Self {
        let w = (max.x - min.x).max(cell);
        let h = (max.y - min.y).max(cell);
        // Cap the cell count at 2^26 (256 MiB of heads) for huge sparse boxes.
        let mut c = cell.max(f64::MIN_POSITIVE);
        while (w / c).ceil() * (h / c).ceil() > 67_108_864.0 {
            c *= 2.0;
        }
        let nx = ((w / c).ceil() as usize).max(1);
        let ny = ((h / c).ceil() as usize).max(1);
        Self {
            origin: [min.x, min.y],
            inv: 1.0 / c,
            nx,
            ny,
            head: vec![NIL; nx * ny],
            next: Vec::with_capacity(capacity),
        }
    }

    #[inline]
    fn insert(&mut self, id: u32, p: Point2<f64>) {
        let (ix, iy) = self.cell_of(p.x, p.y);
        let c = iy * self.nx + ix;
        let i = id as usize;
        if self.next.len() <= i {
            self.next.resize(i + 1, NIL);
        }
        self.next[i] = self.head[c];
        self.head[c] = id;
    }

    #[inline]
    fn query(&self, min: Point2<f64>, max: Point2<f64>, out: &mut Vec<u32>) {
        self.for_each_in(min, max, |id| out.push(id));
    }

    #[inline]
    fn for_each_in(&self, min: Point2<f64>, max: Point2<f64>, mut visit: impl FnMut(u32)) {
        let (x0, y0) = self.cell_of(min.x, min.y);
        let (x1, y1) = self.cell_of(max.x, max.y);
        for iy in y0..=y1 {
            let row = iy * self.nx;
            for &head in &self.head[row + x0..=row + x1] {
                let mut id = head;
                while id != NIL {
                    visit(id);
                    id = self.next[id as usize];
                }
            }
        }
    }

    fn heap_bytes(&self) -> usize {
        4 * (self.head.capacity() + self.next.capacity())
    }
}

/// MX quadtree (Samet; Pinto 2009, §3.1.1): the bounding square of side
/// `2^N · cell` is split regularly at its centre down to unit cells; only
/// leaves (unit cells) hold data, here as linked lists of point ids. Nodes
/// live in an arena; children are created on insertion.
#[derive(Debug, Clone)]
pub struct MxQuadtree {
    origin: [f64; 2],
    cell: f64,
    depth: u32,
    /// Per node: four child indices (NW, NE, SW, SE order is irrelevant:
    /// quadrant = 2·bit_y + bit_x); at leaf depth `child[0]` is the list head.
    nodes: Vec<[u32; 4]>,
    next: Vec<u32>,
}

impl MxQuadtree {
    #[inline]
    fn coords(&self, x: f64, y: f64) -> (u32, u32) {
        let side = 1u64 << self.depth;
        let max = (side - 1) as f64;
        let fx = ((x - self.origin[0]) / self.cell).clamp(0.0, max);
        let fy = ((y - self.origin[1]) / self.cell).clamp(0.0, max);
        (fx as u32, fy as u32)
    }

    #[allow(clippy::too_many_arguments)]
    fn query_node(
        &self,
        node: u32,
        level: u32,
        nx: u32,
        ny: u32,
        lo: (u32, u32),
        hi: (u32, u32),
        visit: &mut impl FnMut(u32),
    ) {
        // Node covers [nx, nx + size) × [ny, ny + size) in unit cells.
        let size = 1u32 << (self.depth - level);
        if nx > hi.0 || ny > hi.1 || nx + (size - 1) < lo.0 || ny + (size - 1) < lo.1 {
            return;
        }
        let n = &self.nodes[node as usize];
        if level == self.depth {
            let mut id = n[0];
            while id != NIL {
                visit(id);
                id = self.next[id as usize];
            }
            return;
        }
        let half = size / 2;
        for (q, &child) in n.iter().enumerate() {
            if child != NIL {
                let q = q as u32;
                self.query_node(
                    child,
                    level + 1,
                    nx + (q & 1) * half,
                    ny + (q >> 1) * half,
                    lo,
                    hi,
                    visit,
                );
            }
        }
    }
}

impl SpatialIndex for MxQuadtree {
    fn with_bounds(min: Point2<f64>, max: Point2<f64>, cell: f64, capacity: usize) -> Self {
        let extent = (max.x - min.x).max(max.y - min.y).max(cell);
        let mut depth = 0u32;
        while ((1u64 << depth) as f64) * cell < extent && depth < 31 {
            depth += 1;
        }
        let cell = cell.max(extent / ((1u64 << depth) as f64));
        let mut nodes = Vec::with_capacity(capacity / 2 + 1);
        nodes.push([NIL; 4]);
        Self {
            origin: [min.x, min.y],
            cell,
            depth,
            nodes,
            next: Vec::with_capacity(capacity),
        }
    }

    fn insert(&mut self, id: u32, p: Point2<f64>) {
        let (ix, iy) = self.coords(p.x, p.y);
        let mut node = 0usize;
        for level in 0..self.depth {
            let bit = self.depth - 1 - level;
            let q = (((iy >> bit) & 1) << 1 | ((ix >> bit) & 1)) as usize;
            let child = self.nodes[node][q];
            node = if child == NIL {
                let new = self.nodes.len();
                self.nodes.push([NIL; 4]);
                self.nodes[node][q] = new as u32;
                new
            } else {
                child as usize
            };
        }
        let i = id as usize;
        if self.next.len() <= i {
            self.next.resize(i + 1, NIL);
        }
        self.next[i] = self.nodes[node][0];
        self.nodes[node][0] = id;
    }

    fn query(&self, min: Point2<f64>, max: Point2<f64>, out: &mut Vec<u32>) {
        self.for_each_in(min, max, |id| out.push(id));
    }

    fn for_each_in(&self, min: Point2<f64>, max: Point2<f64>, mut visit: impl FnMut(u32)) {
        let lo = self.coords(min.x, min.y);
        let hi = self.coords(max.x, max.y);
        self.query_node(0, 0, 0, 0, lo, hi, &mut visit);
    }

    fn heap_bytes(&self) -> usize {
        16 * self.nodes.capacity() + 4 * self.next.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn check<I: SpatialIndex>() {
        let seed = 5;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let pts: Vec<Point2<f64>> = (0..2000)
            .map(|_| Point2::new(rng.random_range(0.0..50.0), rng.random_range(0.0..20.0)))
            .collect();
        let mut idx = I::with_bounds(
            Point2::new(0.0, 0.0),
            Point2::new(50.0, 20.0),
            1.3,
            pts.len(),
        );
        for (i, p) in pts.iter().enumerate() {
            idx.insert(i as u32, *p);
        }
        let mut out = Vec::new();
        for _ in 0..200 {
            let c = Point2::new(rng.random_range(-5.0..55.0), rng.random_range(-5.0..25.0));
            let h = rng.random_range(0.1..6.0);
            let (lo, hi) = (Point2::new(c.x - h, c.y - h), Point2::new(c.x + h, c.y + h));
            out.clear();
            idx.query(lo, hi, &mut out);
            out.sort_unstable();
            for (i, p) in pts.iter().enumerate() {
                let inside = p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y;
                if inside {
                    assert!(out.binary_search(&(i as u32)).is_ok(), "point {i} missed");
                }
            }
        }
    }

    #[test]
    fn grid_reports_every_point_in_box() {
        check::<CellGrid>();
    }

    #[test]
    fn quadtree_reports_every_point_in_box() {
        check::<MxQuadtree>();
    }
}
