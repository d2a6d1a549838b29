//! Zero-level-set extraction (marching cubes, tetrahedral variant) and the cell walker
//! shared with the property integrals.
//!
//! Design choice: every cube is split into the six Kuhn (Freudenthal) tetrahedra that share
//! the diagonal from corner (0,0,0) to (1,1,1); all cubes are split the same way, so the
//! face diagonals of neighbouring cubes match and the piecewise-linear zero set is a closed,
//! manifold surface with no ambiguous cases (Doi & Koide 1991, IEICE Trans. E74;
//! the Lorensen–Cline 1987 case table, doi:10.1145/37402.37422, has face ambiguities that
//! can leave holes). Vertices are shared per grid edge (no duplicates); orientation is fixed
//! combinatorially per tetrahedron (normal from inside, φ < 0, to outside).
//! A node with φ = 0 counts as outside and its value is replaced by `1e-9·h` when
//! interpolating, so vertices stay on distinct edges and no triangle degenerates
//! topologically. If the grain touches the grid boundary, the grid is padded by one node
//! of value `+h` so the surface is still closed.

use nalgebra::{Point3, Vector3};

use crate::grid::{Grid, GridSpec};
use crate::mesh::TriMesh;

/// Receives the vertices and triangles produced by [`walk`].
pub(crate) trait Sink {
    /// Vertex handle.
    type V: Copy;
    /// Called before the cells of layer `k` (cells between node layers k and k+1).
    fn begin_layer(&mut self, _k: usize) {}
    /// Vertex on the grid edge starting at node `(i, j, k)` in direction `dir` (bit mask
    /// x = 1, y = 2, z = 4) at position `p`.
    fn vertex(&mut self, i: usize, j: usize, k: usize, dir: u8, p: Point3<f64>) -> Self::V;
    /// An outward-oriented triangle.
    fn triangle(&mut self, t: [Self::V; 3]);
    /// Called once for every cell `(i, j, k)` with corners of both signs, before its
    /// vertices and triangles.
    fn cell(&mut self, _i: usize, _j: usize, _k: usize) {}
}

impl<T: Sink> Sink for &mut T {
    type V = T::V;
    fn begin_layer(&mut self, k: usize) {
        (**self).begin_layer(k);
    }
    #[inline]
    fn vertex(&mut self, i: usize, j: usize, k: usize, dir: u8, p: Point3<f64>) -> T::V {
        (**self).vertex(i, j, k, dir, p)
    }
    #[inline]
    fn triangle(&mut self, t: [T::V; 3]) {
        (**self).triangle(t);
    }
    fn cell(&mut self, i: usize, j: usize, k: usize) {
        (**self).cell(i, j, k);
    }
}

/// The six Kuhn tetrahedra as corner bit masks (x = 1, y = 2, z = 4).
const TETS: [[u8; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// Slot (0..19) of the cube edge from corner `lo` to corner `hi ⊇ lo` (index `lo·8 + hi`).
/// Every edge of a Kuhn tetrahedron joins a corner to a superset corner; there are 19 such
/// pairs (12 cube edges, 6 face diagonals, 1 body diagonal).
const EDGE_SLOT: [u8; 64] = {
    let mut t = [u8::MAX; 64];
    let mut n = 0u8;
    let mut lo = 0usize;
    while lo < 8 {
        let mut hi = lo + 1;
        while hi < 8 {
            if hi & lo == lo {
                t[lo * 8 + hi] = n;
                n += 1;
            }
            hi += 1;
        }
        lo += 1;
    }
    t
};

/// The unit-cube corner of every corner mask (x = 1, y = 2, z = 4): a lookup instead of
/// three integer conversions per vertex.
const CORNERS: [[f64; 3]; 8] = {
    let mut t = [[0.0; 3]; 8];
    let mut c = 0;
    while c < 8 {
        t[c] = [(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64];
        c += 1;
    }
    t
};

#[inline]
fn corner_vec(c: u8) -> Vector3<f64> {
    let [x, y, z] = CORNERS[usize::from(c & 7)];
    Vector3::new(x, y, z)
}

/// Triangles of the cube's sign patterns, assembled from those of the six tetrahedra
/// (oriented edge lists for all 16 sign patterns of each, built first).
struct TetTable {
    /// For every sign pattern of the cube (256): the span `cube_off[m]..cube_off[m + 1]`
    /// of its triangles in `local` (in the order of the tetrahedra and of `tris`: the order
    /// the walk emits them).
    cube_off: [u16; 257],
    /// For every sign pattern: the edge slots its triangles use, each once, in the order
    /// of their first use in `cube` (the order the walk creates the vertices),
    /// `used[used_off[m]..used_off[m + 1]]`.
    used: Vec<u8>,
    used_off: [u16; 257],
    /// The triangles, each vertex as the position of its edge slot ([`EDGE_SLOT`]) in the
    /// pattern's `used` list.
    local: Vec<[u8; 3]>,
    /// Corners `(lo, hi)` of every edge slot.
    ends: [(u8, u8); 19],
}

fn build_table() -> TetTable {
    let mut tris = [[([[0u8; 2]; 3], false); 2]; 96];
    for (t, tet) in TETS.iter().enumerate() {
        for mask in 0u8..16 {
            let inside: Vec<usize> = (0..4).filter(|&v| mask & (1 << v) != 0).collect();
            let outside: Vec<usize> = (0..4).filter(|&v| mask & (1 << v) == 0).collect();
            let mut out: Vec<[[u8; 2]; 3]> = Vec::new();
            let e = |a: usize, b: usize| [tet[a], tet[b]];
            match inside.len() {
                1 => {
                    let i = inside[0];
                    out.push([e(i, outside[0]), e(i, outside[1]), e(i, outside[2])]);
                }
                3 => {
                    let o = outside[0];
                    out.push([e(inside[0], o), e(inside[1], o), e(inside[2], o)]);
                }
                2 => {
                    let (i1, i2, o1, o2) = (inside[0], inside[1], outside[0], outside[1]);
                    let q = [e(i1, o1), e(i1, o2), e(i2, o2), e(i2, o1)];
                    out.push([q[0], q[1], q[2]]);
                    out.push([q[0], q[2], q[3]]);
                }
                _ => {}
            }
            // Orient with edge midpoints: normal must point from inside corners to outside.
            let mut dir = Vector3::zeros();
            for &o in &outside {
                dir += corner_vec(tet[o]);
            }
            for &i in &inside {
                dir -= corner_vec(tet[i]);
            }
            for (slot, tri) in out.iter_mut().enumerate() {
                let m: Vec<Vector3<f64>> = tri
                    .iter()
                    .map(|[a, b]| 0.5 * (corner_vec(*a) + corner_vec(*b)))
                    .collect();
                let n = (m[1] - m[0]).cross(&(m[2] - m[0]));
                if n.dot(&dir) < 0.0 {
                    tri.swap(1, 2);
                }
                tris[t * 16 + mask as usize][slot] = (*tri, true);
            }
        }
    }
    let mut ends = [(0u8, 0u8); 19];
    for lo in 0u8..8 {
        for hi in lo + 1..8 {
            let k = EDGE_SLOT[usize::from(lo) * 8 + usize::from(hi)];
            if k != u8::MAX {
                ends[usize::from(k)] = (lo, hi);
            }
        }
    }
    let mut cube = Vec::new();
    let mut cube_off = [0u16; 257];
    for cmask in 0usize..256 {
        for (t, tet) in TETS.iter().enumerate() {
            let mut m = 0usize;
            for (v, &c) in tet.iter().enumerate() {
                m |= ((cmask >> c) & 1) << v;
            }
            if m == 0 || m == 15 {
                continue;
            }
            for &(tri, used) in &tris[t * 16 + m] {
                if used {
                    cube.push(tri.map(|[a, b]| {
                        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                        EDGE_SLOT[usize::from(lo) * 8 + usize::from(hi)]
                    }));
                }
            }
        }
        // at most 12 triangles per cube: 256·12 fits u16
        cube_off[cmask + 1] = u16::try_from(cube.len()).unwrap_or(u16::MAX);
    }
    let mut used = Vec::new();
    let mut used_off = [0u16; 257];
    let mut local = Vec::with_capacity(cube.len());
    for cmask in 0usize..256 {
        let start = used.len();
        for tri in &cube[usize::from(cube_off[cmask])..usize::from(cube_off[cmask + 1])] {
            local.push(tri.map(|slot| {
                let at = used[start..]
                    .iter()
                    .position(|&u| u == slot)
                    .unwrap_or_else(|| {
                        used.push(slot);
                        used.len() - 1 - start
                    });
                // at most 19 slots per pattern
                u8::try_from(at).unwrap_or(u8::MAX)
            }));
        }
        // at most 19 slots per cube: 256·19 fits u16
        used_off[cmask + 1] = u16::try_from(used.len()).unwrap_or(u16::MAX);
    }
    TetTable {
        cube_off,
        used,
        used_off,
        local,
        ends,
    }
}

fn table() -> &'static TetTable {
    static TABLE: std::sync::OnceLock<TetTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(build_table)
}

/// Walks all cells of a grid whose boundary nodes are all outside and emits the oriented
/// triangles of the zero level set.
pub(crate) fn walk<S: Sink>(spec: &GridSpec, values: &[f64], sink: &mut S) {
    let tab = table();
    let [nx, ny, nz] = spec.dims;
    let h = spec.spacing;
    let delta = 1e-9 * h;
    let sy = nx;
    let sz = nx * ny;
    let mut off = [0usize; 8];
    for (c, o) in off.iter_mut().enumerate() {
        *o = (c & 1) + sy * ((c >> 1) & 1) + sz * ((c >> 2) & 1);
    }
    // Inside bits of every node row, 64 nodes per word: a cell row is scanned with a few
    // word operations and only cells with mixed corner signs are visited.
    let words = nx.div_ceil(64);
    let mut bits = vec![0u64; words * ny * nz];
    for (out, row) in bits.chunks_exact_mut(words).zip(values.chunks_exact(nx)) {
        for (w, chunk) in out.iter_mut().zip(row.chunks(64)) {
            *w = chunk
                .iter()
                .enumerate()
                .fold(0u64, |a, (i, &v)| a | (u64::from(v < 0.0) << i));
        }
    }
    let mut any = vec![0u64; words];
    let mut all = vec![0u64; words];
    for k in 0..nz - 1 {
        sink.begin_layer(k);
        for j in 0..ny - 1 {
            let rows = [
                j + ny * k,
                j + 1 + ny * k,
                j + ny * (k + 1),
                j + 1 + ny * (k + 1),
            ];
            for w in 0..words {
                let r = rows.map(|r| bits[r * words + w]);
                any[w] = r[0] | r[1] | r[2] | r[3];
                all[w] = r[0] & r[1] & r[2] & r[3];
            }
            for w in 0..words {
                // Cell i uses nodes i and i+1: combine each word with its right neighbour.
                let next_any = if w + 1 < words { any[w + 1] << 63 } else { 0 };
                let next_all = if w + 1 < words { all[w + 1] << 63 } else { 0 };
                let some_in = any[w] | (any[w] >> 1) | next_any;
                let all_in = all[w] & ((all[w] >> 1) | next_all);
                let mut mixed = some_in & !all_in;
                // Keep cells 0..nx-1 only.
                let first = w * 64;
                if first + 64 > nx - 1 {
                    let valid = (nx - 1).saturating_sub(first);
                    mixed &= if valid >= 64 {
                        u64::MAX
                    } else {
                        (1u64 << valid) - 1
                    };
                }
                while mixed != 0 {
                    let i = first + mixed.trailing_zeros() as usize;
                    mixed &= mixed - 1;
                    let b = i + sy * j + sz * k;
                    let mut phi = [0.0; 8];
                    let mut cmask = 0u8;
                    for c in 0..8 {
                        let v = values[b + off[c]];
                        phi[c] = v;
                        cmask |= u8::from(v < 0.0) << c;
                    }
                    if cmask == 0 || cmask == 255 {
                        continue;
                    }
                    sink.cell(i, j, k);
                    let m = usize::from(cmask);
                    let used =
                        &tab.used[usize::from(tab.used_off[m])..usize::from(tab.used_off[m + 1])];
                    // the vertices of the pattern's edges, in the order of their first use
                    // (the order the sink numbers them in)
                    let vertex = |sink: &mut S, slot: u8| {
                        let (lo, hi) = tab.ends[usize::from(slot)];
                        let fa = phi[lo as usize];
                        let fa = if fa < 0.0 { fa } else { fa.max(delta) };
                        let fb = phi[hi as usize];
                        let fb = if fb < 0.0 { fb } else { fb.max(delta) };
                        let tpar = fa / (fa - fb);
                        let d = hi ^ lo;
                        let (gi, gj, gk) = (
                            i + (lo & 1) as usize,
                            j + ((lo >> 1) & 1) as usize,
                            k + ((lo >> 2) & 1) as usize,
                        );
                        // from the edge's own start node, so that every cell sharing the
                        // edge computes the same point bit for bit (the integrals over the
                        // walk and over the extracted mesh agree exactly)
                        let p = spec.node(gi, gj, gk) + (h * tpar) * corner_vec(d);
                        sink.vertex(gi, gj, gk, d, p)
                    };
                    let Some((&first_slot, rest)) = used.split_first() else {
                        continue;
                    };
                    let first = vertex(sink, first_slot);
                    let mut handles = [first; 19];
                    for (hnd, &slot) in handles[1..].iter_mut().zip(rest) {
                        *hnd = vertex(sink, slot);
                    }
                    let span = usize::from(tab.cube_off[m])..usize::from(tab.cube_off[m + 1]);
                    for tri in &tab.local[span] {
                        sink.triangle(tri.map(|l| handles[usize::from(l)]));
                    }
                }
            }
        }
    }
}

/// Runs `f` on the grid values, padded by one node of value `+h` on every side if any
/// boundary node is inside (so the surface is closed).
pub(crate) fn with_closed_values<R>(grid: &Grid, f: impl FnOnce(&GridSpec, &[f64]) -> R) -> R {
    let spec = grid.spec();
    let [nx, ny, nz] = spec.dims;
    let v = grid.values();
    let mut open = false;
    for k in 0..nz {
        for j in 0..ny {
            let row = nx * (j + ny * k);
            if k == 0 || k == nz - 1 || j == 0 || j == ny - 1 {
                open |= v[row..row + nx].iter().any(|&x| x < 0.0);
            } else {
                open |= v[row] < 0.0 || v[row + nx - 1] < 0.0;
            }
        }
    }
    if !open {
        return f(spec, v);
    }
    let h = spec.spacing;
    let pd = [nx + 2, ny + 2, nz + 2];
    let mut pv = vec![h; pd[0] * pd[1] * pd[2]];
    for k in 0..nz {
        for j in 0..ny {
            let src = nx * (j + ny * k);
            let dst = 1 + pd[0] * ((j + 1) + pd[1] * (k + 1));
            pv[dst..dst + nx].copy_from_slice(&v[src..src + nx]);
        }
    }
    let pspec = GridSpec {
        dims: pd,
        origin: spec.origin - Vector3::repeat(h),
        spacing: h,
    };
    f(&pspec, &pv)
}

/// Builds the shared-vertex mesh, with a two-layer edge cache.
struct MeshSink {
    nx: usize,
    ny: usize,
    /// Per layer parity, per node of the layer, per direction: vertex index + 1 (0 = none).
    cache: Vec<u32>,
    /// Per slot of `cache`: the entries written since it was last cleared.
    written: [Vec<usize>; 2],
    vertices: Vec<Point3<f64>>,
    triangles: Vec<[usize; 3]>,
    /// The mixed cells, when recorded.
    cells: Option<Vec<[u32; 3]>>,
}

impl Sink for MeshSink {
    type V = usize;

    fn begin_layer(&mut self, k: usize) {
        // Layer k + 1 reuses the slot of layer k − 1: clear the entries it wrote (a few
        // hundred, against 8·nx·ny for the whole slot).
        let slot = (k + 1) & 1;
        for &idx in &self.written[slot] {
            self.cache[idx] = 0;
        }
        self.written[slot].clear();
    }

    fn vertex(&mut self, i: usize, j: usize, k: usize, dir: u8, p: Point3<f64>) -> usize {
        let layer = self.nx * self.ny * 8;
        let idx = (k & 1) * layer + (i + self.nx * j) * 8 + dir as usize;
        let c = self.cache[idx];
        if c != 0 {
            return c as usize - 1;
        }
        self.vertices.push(p);
        let n = self.vertices.len();
        self.cache[idx] = u32::try_from(n).unwrap_or(u32::MAX);
        self.written[k & 1].push(idx);
        n - 1
    }

    fn triangle(&mut self, t: [usize; 3]) {
        self.triangles.push(t);
    }

    fn cell(&mut self, i: usize, j: usize, k: usize) {
        if let Some(c) = &mut self.cells {
            // grids are far below 2³² nodes per axis (GridSpec limits the node count)
            c.push([i, j, k].map(|x| u32::try_from(x).unwrap_or(u32::MAX)));
        }
    }
}

impl Grid {
    /// Triangle mesh of the zero level set (marching cubes with the tetrahedral split, see
    /// the module docs): closed, consistently oriented (outward normals), one vertex per
    /// crossed grid edge. Empty if the grid has no negative node.
    pub fn marching_cubes(&self) -> TriMesh {
        with_closed_values(self, |spec, values| extract(spec, values, false).0)
    }

    /// [`Grid::marching_cubes`] together with the cells the surface crosses: what
    /// [`Grid::mass_properties_of`] needs to integrate over the extracted mesh instead of
    /// walking the grid again (the same values bit for bit as [`Grid::mass_properties`]).
    pub fn surface(&self) -> Surface {
        with_closed_values(self, |spec, values| {
            let (mesh, cells) = extract(spec, values, true);
            let fingerprint = fingerprint(spec, values, &cells);
            Surface {
                mesh,
                cells,
                spec: *self.spec(),
                fingerprint,
            }
        })
    }
}

/// The mesh of the (closed) values and, if `record`, the mixed cells in walk order.
fn extract(spec: &GridSpec, values: &[f64], record: bool) -> (TriMesh, Vec<[u32; 3]>) {
    // Reserve from the number of sign changes along x (a sphere gives ≈ 9 vertices and
    // ≈ 18 triangles per x crossing, cloned grains 10–14 and 21–29): avoids regrowing the
    // buffers (the pages of an over-reserved tail are never touched).
    let crossings: usize = values
        .chunks_exact(spec.dims[0])
        .map(|row| {
            row.windows(2)
                .filter(|w| (w[0] < 0.0) != (w[1] < 0.0))
                .count()
        })
        .sum();
    let mut sink = MeshSink {
        nx: spec.dims[0],
        ny: spec.dims[1],
        cache: vec![0; 2 * spec.dims[0] * spec.dims[1] * 8],
        written: [Vec::new(), Vec::new()],
        vertices: Vec::with_capacity(16 * crossings + 16),
        triangles: Vec::with_capacity(32 * crossings + 16),
        cells: record.then(|| Vec::with_capacity(8 * crossings + 16)),
    };
    walk(spec, values, &mut sink);
    (
        TriMesh::from_parts_unchecked(sink.vertices, sink.triangles),
        sink.cells.unwrap_or_default(),
    )
}

/// A hash of the values at the base nodes of `cells` (and of their number): what ties a
/// [`Surface`] to the grid it was extracted from.
fn fingerprint(spec: &GridSpec, values: &[f64], cells: &[[u32; 3]]) -> u64 {
    let [nx, ny, _] = spec.dims;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ cells.len() as u64;
    for &[i, j, k] in cells {
        let b = i as usize + nx * (j as usize + ny * k as usize);
        h = (h ^ values.get(b).map_or(u64::MAX, |v| v.to_bits())).wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// The zero surface of a grid extracted once ([`Grid::surface`]): its triangle mesh and the
/// grid cells it crosses. [`Grid::mass_properties_of`] integrates over the mesh (no second
/// pass over the grid), bit for bit as [`Grid::mass_properties`].
#[derive(Debug, Clone)]
pub struct Surface {
    mesh: TriMesh,
    /// The mixed cells in walk order (indices into the walked grid: padded by one node on
    /// every side if the grain touches the boundary).
    cells: Vec<[u32; 3]>,
    spec: GridSpec,
    fingerprint: u64,
}

impl Surface {
    /// The mesh ([`Grid::marching_cubes`]).
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The mesh, by value.
    pub fn into_mesh(self) -> TriMesh {
        self.mesh
    }

    /// The cells crossed by the surface, in walk order.
    pub(crate) fn cells(&self) -> &[[u32; 3]] {
        &self.cells
    }

    /// Whether `grid` is the grid this surface was extracted from (same layout, same values
    /// at the crossed cells).
    pub(crate) fn matches(&self, grid: &Grid, spec: &GridSpec, values: &[f64]) -> bool {
        *grid.spec() == self.spec && fingerprint(spec, values, &self.cells) == self.fingerprint
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{Cuboid, Shape};
    use nalgebra::Isometry3;

    fn check_closed(mesh: &TriMesh) {
        // Every directed edge appears once and its reverse once.
        let mut edges: Vec<(usize, usize)> = Vec::new();
        for t in mesh.triangles() {
            for e in 0..3 {
                edges.push((t[e], t[(e + 1) % 3]));
            }
        }
        edges.sort_unstable();
        for w in edges.windows(2) {
            assert!(w[0] != w[1], "directed edge {:?} used twice", w[0]);
        }
        for &(a, b) in &edges {
            assert!(
                edges.binary_search(&(b, a)).is_ok(),
                "edge ({a},{b}) has no twin"
            );
        }
    }

    #[test]
    fn sphere_mesh_is_closed_oriented_without_duplicates() {
        let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
        let g = Grid::from_fn(spec, |p| p.coords.norm() - 1.0).expect("grid");
        let m = g.marching_cubes();
        assert!(m.triangles().len() > 1000);
        check_closed(&m);
        // No duplicate vertex positions.
        let mut v: Vec<[f64; 3]> = m.vertices().iter().map(|p| [p.x, p.y, p.z]).collect();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        for w in v.windows(2) {
            let d = ((w[0][0] - w[1][0]).powi(2)
                + (w[0][1] - w[1][1]).powi(2)
                + (w[0][2] - w[1][2]).powi(2))
            .sqrt();
            assert!(d > 1e-12, "duplicate vertex {:?}", w[0]);
        }
        // Outward: signed volume positive; vertices on the sphere.
        assert!(m.signed_volume() > 0.0);
        for p in m.vertices() {
            assert!((p.coords.norm() - 1.0).abs() < 0.01);
        }
        // Euler characteristic of a sphere.
        let e = m.triangles().len() * 3 / 2;
        assert_eq!(
            m.vertices().len() as i64 - e as i64 + m.triangles().len() as i64,
            2
        );
    }

    #[test]
    fn rows_longer_than_one_bit_word_are_scanned() {
        // 130 nodes along x: three 64-bit words per row, cells across word boundaries.
        let spec = GridSpec {
            dims: [130, 23, 23],
            origin: Point3::new(-3.2, -0.55, -0.55),
            spacing: 0.05,
        };
        let e = crate::shapes::Ellipsoid::new(Vector3::new(3.0, 0.4, 0.4)).expect("e");
        let g = Grid::from_shape(spec, &e, &Isometry3::identity()).expect("grid");
        let m = g.marching_cubes();
        check_closed(&m);
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 3.0 * 0.16;
        assert!((m.signed_volume() / exact - 1.0).abs() < 0.01);
        approx::assert_relative_eq!(g.volume_linear(), m.signed_volume(), max_relative = 1e-9);
    }

    #[test]
    fn grain_touching_boundary_and_exact_zeros_still_close() {
        let spec = GridSpec::cube(11, -1.0, 1.0).expect("spec");
        // Box larger than the grid in x: touches the boundary; many nodes exactly zero.
        let b = Cuboid::new(Vector3::new(2.0, 0.6, 0.6)).expect("box");
        let g = Grid::from_shape(spec, &b, &Isometry3::identity()).expect("grid");
        assert!(g.values().contains(&0.0));
        let _ = b.signed_distance(&Point3::origin());
        let m = g.marching_cubes();
        check_closed(&m);
        assert!(m.signed_volume() > 0.0);
    }
}
