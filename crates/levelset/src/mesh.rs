//! Closed triangle meshes, their preparation as one grain, and their exact signed distance.
//!
//! # Distance
//! The distance is the exact Euclidean distance to the closest triangle (closest point on
//! a triangle: Ericson 2005, *Real-Time Collision Detection*, Sec. 5.1.5), found with a
//! bounding-volume hierarchy of axis-aligned boxes (median split on the longest axis,
//! leaves of ≤ 4 triangles). The sign comes from the angle-weighted pseudonormal of the
//! closest feature — face, edge or vertex — which is provably correct for closed, consistently
//! oriented meshes (Bærentzen & Aanæs 2005, IEEE TVCG 11, doi:10.1109/TVCG.2005.49, Thm. 1).
//! Meshes that are not closed 2-manifolds with consistent orientation are rejected.
//! [`Grid::from_mesh`] seeds every node's search with the closest triangle of its
//! neighbour, whose exact distance is a tight bound; the search then only proves it. Far
//! from a finely meshed surface that proof still visits many boxes (all those closer than
//! the answer), which dominates the cost of a 45³ grid; the values are exact everywhere.
//!
//! # Banded construction
//! [`Grid::from_mesh_banded`] is exact only within `band_cells·h` of the surface and fast
//! beyond: each triangle is scattered over the nodes of its bounding box grown by the band
//! (no proof searches; a node's closest candidate is provably its closest triangle exactly
//! when it lies within the band), the far field is fast-swept from the band
//! ([`crate::reinit`]) and raised to at least the band width (a true lower bound there), and
//! far signs come from one exact query per connected region of non-band nodes (the surface
//! cannot pass between two neighbouring non-band nodes). With [`MESH_BAND_CELLS`] = 3 cells
//! the volume, area, mass properties and marching-cubes surface equal [`Grid::from_mesh`]'s;
//! far values are within [`FAR_ERROR_CELLS`]·h of the exact distance on the tested grains.
//! Use it for grains (≈ 3–6× faster on 45³); keep [`Grid::from_mesh`] for exact values far
//! from the surface.
//!
//! # User meshes
//! A grain scanned or exported by someone else (STL, OBJ: [`crate::io`]) is a triangle
//! soup until [`TriMesh::prepare_closed`] has welded duplicated vertices, dropped degenerate
//! triangles and checked that the surface is one closed, edge- and vertex-manifold,
//! orientable component of non-zero volume. Choices and reasons:
//! * Welding is exact (bit-identical positions, `-0.0 = 0.0`): a tolerance would merge
//!   genuinely distinct vertices of fine scans, and exporters duplicate vertices exactly.
//! * Problems are errors that name the first offending edge or vertex (indices of the input
//!   mesh and positions) and count all of them, so the user can find them in a viewer;
//!   nothing is closed or cut silently.
//! * Orientation is made consistent by a breadth-first search over the edge adjacency, and
//!   the triangles of the minority orientation are the ones counted as flipped; the result
//!   is then turned outward by the sign of its volume. [`Orientation::Repair`] reports both
//!   ([`MeshRepair::flipped`], [`MeshRepair::inverted`]), [`Orientation::Refuse`] returns an
//!   error instead: a mesh is never inverted silently.
//! * One connected component per mesh, since a file holds one grain.
//! * [`TriMesh::centroid`] and [`crate::GridSpec::around_points`] then place a grid about
//!   the grain as the spherical-harmonic grains are placed (45³ nodes, margin 1.1).
//!
//! ```
//! use levelset::io::read_obj;
//! use levelset::{Grid, GridSpec, Orientation};
//!
//! // A tetrahedron exported with one face the wrong way round.
//! let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 4 3\n";
//! let soup = read_obj(obj.as_bytes())?;
//! let (grain, repair) = soup.prepare_closed(Orientation::Repair)?;
//! assert_eq!((repair.flipped, repair.inverted), (1, false));
//! assert!(soup.prepare_closed(Orientation::Refuse).is_err());
//! let centre = grain.centroid()?;
//! let spec = GridSpec::around_points(grain.vertices(), centre, 21, 1.1)?;
//! let grid = Grid::from_mesh(spec, &grain)?;
//! assert!(grid.at(10, 10, 10) < 0.0);
//! # Ok::<(), levelset::Error>(())
//! ```

use nalgebra::{Point3, Vector3};

use crate::error::{Error, Result};
use crate::grid::{Grid, GridSpec};

mod banded;
pub use banded::{FAR_ERROR_CELLS, MESH_BAND_CELLS};

/// An indexed triangle mesh; triangles are counter-clockwise seen from outside.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriMesh {
    vertices: Vec<Point3<f64>>,
    triangles: Vec<[usize; 3]>,
}

impl TriMesh {
    /// Checks indices, finiteness and non-degenerate triangles (closedness is checked by
    /// [`TriMesh::check_closed`] and by the distance constructors).
    ///
    /// # Errors
    /// [`Error::EmptyMesh`], [`Error::NonFiniteVertex`], [`Error::VertexIndexOutOfRange`],
    /// [`Error::DegenerateTriangle`].
    pub fn new(vertices: Vec<Point3<f64>>, triangles: Vec<[usize; 3]>) -> Result<Self> {
        let mesh = Self::new_allowing_degenerate(vertices, triangles)?;
        if let Some(triangle) = (0..mesh.triangles.len()).find(|&t| mesh.is_degenerate(t)) {
            return Err(Error::DegenerateTriangle { triangle });
        }
        Ok(mesh)
    }

    /// As [`TriMesh::new`] but keeps degenerate triangles (a repeated vertex or zero area),
    /// which mesh files often contain: the readers of [`crate::io`] build meshes this way,
    /// and [`TriMesh::prepare_closed`] removes (and counts) them.
    ///
    /// # Errors
    /// [`Error::EmptyMesh`], [`Error::NonFiniteVertex`], [`Error::VertexIndexOutOfRange`].
    pub fn new_allowing_degenerate(
        vertices: Vec<Point3<f64>>,
        triangles: Vec<[usize; 3]>,
    ) -> Result<Self> {
        if triangles.is_empty() {
            return Err(Error::EmptyMesh);
        }
        if let Some(index) = vertices
            .iter()
            .position(|p| !p.coords.iter().all(|c| c.is_finite()))
        {
            return Err(Error::NonFiniteVertex { index });
        }
        for (t, tri) in triangles.iter().enumerate() {
            for &index in tri {
                if index >= vertices.len() {
                    return Err(Error::VertexIndexOutOfRange {
                        triangle: t,
                        index,
                        vertices: vertices.len(),
                    });
                }
            }
        }
        Ok(Self {
            vertices,
            triangles,
        })
    }

    /// A repeated vertex index or an exactly zero (or non-finite) cross product.
    fn is_degenerate(&self, t: usize) -> bool {
        let [a, b, c] = self.triangles[t];
        degenerate(&self.vertices, a, b, c)
    }

    pub(crate) fn from_parts_unchecked(
        vertices: Vec<Point3<f64>>,
        triangles: Vec<[usize; 3]>,
    ) -> Self {
        Self {
            vertices,
            triangles,
        }
    }

    /// Vertex positions.
    pub fn vertices(&self) -> &[Point3<f64>] {
        &self.vertices
    }

    /// Triangles as vertex-index triples.
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Enclosed volume by the divergence theorem (positive for outward orientation).
    pub fn signed_volume(&self) -> f64 {
        let o = self
            .vertices
            .first()
            .copied()
            .unwrap_or_else(Point3::origin);
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                let (pa, pb, pc) = (
                    self.vertices[a] - o,
                    self.vertices[b] - o,
                    self.vertices[c] - o,
                );
                pa.dot(&pb.cross(&pc)) / 6.0
            })
            .sum()
    }

    /// Total triangle area.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                0.5 * (self.vertices[b] - self.vertices[a])
                    .cross(&(self.vertices[c] - self.vertices[a]))
                    .norm()
            })
            .sum()
    }

    /// Checks that every directed edge occurs exactly once and its reverse exactly once
    /// (closed, edge-manifold, consistently oriented). Returns, for every triangle and local
    /// edge `e` (from corner e to e+1), the index of the triangle across that edge.
    ///
    /// # Errors
    /// [`Error::NonClosedMesh`] with the first offending edge.
    pub fn check_closed(&self) -> Result<Vec<[usize; 3]>> {
        let mut edges: Vec<(usize, usize, usize, usize)> =
            Vec::with_capacity(3 * self.triangles.len());
        for (t, tri) in self.triangles.iter().enumerate() {
            for e in 0..3 {
                edges.push((tri[e], tri[(e + 1) % 3], t, e));
            }
        }
        edges.sort_unstable();
        let count = |a: usize, b: usize| -> (usize, Option<usize>) {
            let lo = edges.partition_point(|x| (x.0, x.1) < (a, b));
            let hi = edges.partition_point(|x| (x.0, x.1) <= (a, b));
            (hi - lo, (hi > lo).then(|| edges[lo].2))
        };
        let mut across = vec![[0usize; 3]; self.triangles.len()];
        for (i, &(a, b, t, e)) in edges.iter().enumerate() {
            let dup = i + 1 < edges.len() && (edges[i + 1].0, edges[i + 1].1) == (a, b);
            let (rev, twin) = count(b, a);
            if dup || rev != 1 {
                let (c, _) = count(a, b);
                return Err(Error::NonClosedMesh {
                    a,
                    b,
                    count: c,
                    reverse: rev,
                });
            }
            if let Some(tw) = twin {
                across[t][e] = tw;
            }
        }
        Ok(across)
    }

    /// Volume centroid: the volume-weighted mean of the centroids of the signed tetrahedra
    /// spanned by each triangle and the centre of the bounding box (exact for a closed mesh
    /// of either orientation).
    ///
    /// # Errors
    /// [`Error::EmptyMesh`]; [`Error::ZeroVolume`] if |volume| ≤ 1e-10 · area^{3/2}.
    pub fn centroid(&self) -> Result<Point3<f64>> {
        if self.triangles.is_empty() {
            return Err(Error::EmptyMesh);
        }
        let o = self.box_centre();
        let mut six_v = 0.0;
        let mut acc = Vector3::zeros();
        for &[a, b, c] in &self.triangles {
            let (pa, pb, pc) = (
                self.vertices[a] - o,
                self.vertices[b] - o,
                self.vertices[c] - o,
            );
            let w = pa.dot(&pb.cross(&pc));
            six_v += w;
            acc += w * (pa + pb + pc);
        }
        let (volume, area) = (six_v / 6.0, self.area());
        if !has_volume(volume, area) {
            return Err(Error::ZeroVolume { volume, area });
        }
        Ok(o + acc / (4.0 * six_v))
    }

    /// Centre of the bounding box of the vertices (the origin if there are none).
    fn box_centre(&self) -> Point3<f64> {
        let mut b = Aabb::empty();
        for p in &self.vertices {
            b.grow(&p.coords);
        }
        if self.vertices.is_empty() {
            Point3::origin()
        } else {
            Point3::from(0.5 * (b.lo + b.hi))
        }
    }

    /// Turns a user's mesh into a closed, manifold, outward-oriented surface of one grain,
    /// or says precisely why it is not one.
    ///
    /// Steps, in order:
    /// 1. weld vertices with bit-identical positions (`-0.0 = 0.0`; the lowest index of a
    ///    group stands for it, so errors name vertices of `self`);
    /// 2. drop degenerate triangles (a repeated vertex after welding, or an exactly zero
    ///    cross product);
    /// 3. every undirected edge must belong to exactly two triangles: more →
    ///    [`Error::NonManifoldEdge`], one → [`Error::OpenMesh`] (the lowest such edge and
    ///    the counts);
    /// 4. the triangles around every vertex must form one fan (a disk), else
    ///    [`Error::NonManifoldVertex`];
    /// 5. one edge-connected component, else [`Error::SeveralComponents`] (one grain per mesh);
    /// 6. orientation by breadth-first search over the edge adjacency from triangle 0; the
    ///    minority orientation (ties: the class of triangle 0 wins) is the one counted as
    ///    flipped; a one-sided surface is [`Error::NonOrientable`];
    /// 7. the volume of the consistent mesh must not vanish ([`Error::ZeroVolume`] if
    ///    |V| ≤ 1e-10 · area^{3/2}); a negative volume means the mesh faces inward.
    ///
    /// With [`Orientation::Repair`] the minority triangles are flipped and an inward mesh is
    /// inverted, both reported in [`MeshRepair`]; with [`Orientation::Refuse`] either is an
    /// error ([`Error::InconsistentOrientation`], [`Error::InwardOrientation`]). A mesh is
    /// never inverted without saying so. The result keeps the referenced vertices in their
    /// original order, renumbered densely, and the surviving triangles in their order; it
    /// passes [`TriMesh::check_closed`] and has a positive [`TriMesh::signed_volume`].
    ///
    /// Self-intersections are not detected (a closed, oriented but self-intersecting mesh
    /// passes, and its signed distance is then meaningless near the intersection).
    ///
    /// # Errors
    /// As listed above; [`Error::EmptyMesh`] if no triangle survives step 2.
    pub fn prepare_closed(&self, policy: Orientation) -> Result<(TriMesh, MeshRepair)> {
        let v = &self.vertices;
        let mut repair = MeshRepair::default();

        // 1. Weld: sort by position (then index), map every vertex to the first of its group.
        let (rep, welded) = weld(v);
        repair.welded = welded;

        // 2. Degenerate triangles.
        let (tris, source, removed) = without_degenerate(v, &self.triangles, &rep);
        repair.degenerate_removed = removed;
        if tris.is_empty() {
            return Err(Error::EmptyMesh);
        }
        let n = tris.len();

        // 3. Edges: every undirected edge in exactly two triangles.
        let pairs = pair_edges(v, &tris)?;

        // 4. Vertex fans and 5. one component.
        let across = fans_and_component(v, &tris, &pairs)?;

        // 6. Orientation classes by breadth-first search from triangle 0.
        let (flip, flipped) = orientation_classes(&across, &source)?;

        // 7. Volume of the consistent mesh.
        let volume = consistent_volume(v, self.box_centre(), &tris, &flip)?;
        let inverted = volume < 0.0;
        if policy == Orientation::Refuse {
            if flipped > 0 {
                return Err(Error::InconsistentOrientation {
                    flipped,
                    triangles: n,
                });
            }
            if inverted {
                return Err(Error::InwardOrientation { volume });
            }
        }
        repair.flipped = flipped;
        repair.inverted = inverted;

        // Output: referenced vertices in their original order.
        let (vertices, triangles) = renumbered(v, &tris, &flip, inverted);
        repair.unreferenced = v.len() - repair.welded - vertices.len();
        Ok((Self::from_parts_unchecked(vertices, triangles), repair))
    }
}

/// The coordinates of vertex `i`, as the errors report them.
fn position(v: &[Point3<f64>], i: usize) -> [f64; 3] {
    [v[i].x, v[i].y, v[i].z]
}

/// Step 1 of [`TriMesh::prepare_closed`]: sorts the vertices by position (then index) and
/// maps every vertex to the first of its group of bit-identical positions (−0 = +0).
/// Returns the representative of every vertex and the number of vertices welded.
fn weld(v: &[Point3<f64>]) -> (Vec<usize>, usize) {
    let key = |p: &Point3<f64>| {
        [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ]
    };
    let mut welded = 0;
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_unstable_by_key(|&i| (key(&v[i]), i));
    let mut rep: Vec<usize> = (0..v.len()).collect();
    for w in order.windows(2) {
        if key(&v[w[0]]) == key(&v[w[1]]) {
            rep[w[1]] = rep[w[0]];
            welded += 1;
        }
    }
    (rep, welded)
}

/// Step 2 of [`TriMesh::prepare_closed`]: the triangles over the welded vertices `rep`
/// without the degenerate ones, the input index of each, and the number removed.
fn without_degenerate(
    v: &[Point3<f64>],
    triangles: &[[usize; 3]],
    rep: &[usize],
) -> (Vec<[usize; 3]>, Vec<usize>, usize) {
    let mut removed = 0;
    let mut tris: Vec<[usize; 3]> = Vec::with_capacity(triangles.len());
    let mut source: Vec<usize> = Vec::with_capacity(triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| rep[i]);
        if degenerate(v, a, b, c) {
            removed += 1;
        } else {
            tris.push([a, b, c]);
            source.push(t);
        }
    }
    (tris, source, removed)
}

/// Step 3 of [`TriMesh::prepare_closed`]: the pairs of half-edges (h = 3t + e runs from
/// `tris[t][e]` to `tris[t][(e + 1) % 3]`) that share an undirected edge, in edge order.
///
/// # Errors
/// [`Error::NonManifoldEdge`] for an edge of more than two triangles, else
/// [`Error::OpenMesh`] for an edge of one (the lowest such edge and the counts).
fn pair_edges(v: &[Point3<f64>], tris: &[[usize; 3]]) -> Result<Vec<(usize, usize)>> {
    let n = tris.len();
    let mut edges: Vec<(usize, usize, usize)> = Vec::with_capacity(3 * n);
    for (t, tri) in tris.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            edges.push((a.min(b), a.max(b), 3 * t + e));
        }
    }
    edges.sort_unstable();
    let mut pairs: Vec<(usize, usize)> = Vec::with_capacity(3 * n / 2);
    let mut non_manifold: Option<(usize, usize, usize)> = None;
    let mut non_manifold_edges = 0;
    let mut boundary: Option<(usize, usize)> = None;
    let mut boundary_edges = 0;
    for group in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (a, b, h) = group[0];
        match group {
            [_] => {
                boundary_edges += 1;
                boundary.get_or_insert((a, b));
            }
            [_, (_, _, g)] => pairs.push((h, *g)),
            _ => {
                non_manifold_edges += 1;
                non_manifold.get_or_insert((a, b, group.len()));
            }
        }
    }
    if let Some((a, b, count)) = non_manifold {
        return Err(Error::NonManifoldEdge {
            a,
            b,
            pa: position(v, a),
            pb: position(v, b),
            count,
            edges: non_manifold_edges,
        });
    }
    if let Some((a, b)) = boundary {
        return Err(Error::OpenMesh {
            a,
            b,
            pa: position(v, a),
            pb: position(v, b),
            boundary_edges,
        });
    }
    Ok(pairs)
}

/// Steps 4 and 5 of [`TriMesh::prepare_closed`]: vertex fans, corners (3t + i, at
/// `tris[t][i]`) joined across shared edges (a manifold vertex has all its corners in one
/// class), and edge-connected components. Returns per half-edge the triangle across it and
/// whether both run the same way.
///
/// # Errors
/// [`Error::NonManifoldVertex`], [`Error::SeveralComponents`].
fn fans_and_component(
    v: &[Point3<f64>],
    tris: &[[usize; 3]],
    pairs: &[(usize, usize)],
) -> Result<Vec<(usize, bool)>> {
    let n = tris.len();
    let start = |h: usize| tris[h / 3][h % 3];
    let mut corners = UnionFind::new(3 * n);
    let mut triangles_uf = UnionFind::new(n);
    // Per half-edge: the triangle across it and whether both run the same way.
    let mut across = vec![(0usize, false); 3 * n];
    for &(h, g) in pairs {
        let next = |x: usize| 3 * (x / 3) + (x % 3 + 1) % 3;
        let same = start(h) == start(g);
        if same {
            corners.union(h, g);
            corners.union(next(h), next(g));
        } else {
            corners.union(h, next(g));
            corners.union(next(h), g);
        }
        triangles_uf.union(h / 3, g / 3);
        across[h] = (g / 3, same);
        across[g] = (h / 3, same);
    }
    let mut fans: Vec<(usize, usize)> = (0..3 * n).map(|c| (start(c), corners.find(c))).collect();
    fans.sort_unstable();
    fans.dedup();
    for group in fans.chunk_by(|x, y| x.0 == y.0) {
        if group.len() > 1 {
            let vertex = group[0].0;
            return Err(Error::NonManifoldVertex {
                vertex,
                position: position(v, vertex),
                fans: group.len(),
            });
        }
    }

    // 5. One component.
    let count = (0..n).filter(|&t| triangles_uf.find(t) == t).count();
    if count > 1 {
        return Err(Error::SeveralComponents { count });
    }
    Ok(across)
}

/// Step 6 of [`TriMesh::prepare_closed`]: the orientation class of every triangle by
/// breadth-first search from triangle 0 over `across` (see [`fans_and_component`]), the
/// minority class (ties: that of triangle 0 wins) marked as flipped. Returns the marks and
/// the number flipped.
///
/// # Errors
/// [`Error::NonOrientable`] (with the input index from `source`) for a one-sided surface.
fn orientation_classes(across: &[(usize, bool)], source: &[usize]) -> Result<(Vec<bool>, usize)> {
    let n = source.len();
    let mut flip: Vec<Option<bool>> = vec![None; n];
    flip[0] = Some(false);
    let mut queue = std::collections::VecDeque::from([0usize]);
    while let Some(t) = queue.pop_front() {
        let ft = flip[t].unwrap_or(false);
        for &(u, same) in &across[3 * t..3 * t + 3] {
            let want = ft ^ same;
            match flip[u] {
                None => {
                    flip[u] = Some(want);
                    queue.push_back(u);
                }
                Some(f) if f != want => {
                    return Err(Error::NonOrientable {
                        triangle: source[u],
                    });
                }
                Some(_) => {}
            }
        }
    }
    let mut flip: Vec<bool> = flip.into_iter().map(|f| f.unwrap_or(false)).collect();
    let mut flipped = flip.iter().filter(|&&f| f).count();
    if 2 * flipped > n {
        flip.iter_mut().for_each(|f| *f = !*f);
        flipped = n - flipped;
    }
    Ok((flip, flipped))
}

/// Step 7 of [`TriMesh::prepare_closed`]: the signed volume of the mesh with the `flip`ped
/// triangles reversed (about `o`, the centre of the bounding box).
///
/// # Errors
/// [`Error::ZeroVolume`] if the volume vanishes (see [`has_volume`]).
fn consistent_volume(
    v: &[Point3<f64>],
    o: Point3<f64>,
    tris: &[[usize; 3]],
    flip: &[bool],
) -> Result<f64> {
    let mut six_v = 0.0;
    let mut area = 0.0;
    for (tri, &f) in tris.iter().zip(flip) {
        let (pa, pb, pc) = (v[tri[0]] - o, v[tri[1]] - o, v[tri[2]] - o);
        let w = pa.dot(&pb.cross(&pc));
        six_v += if f { -w } else { w };
        area += 0.5 * (pb - pa).cross(&(pc - pa)).norm();
    }
    let volume = six_v / 6.0;
    if !has_volume(volume, area) {
        return Err(Error::ZeroVolume { volume, area });
    }
    Ok(volume)
}

/// The output of [`TriMesh::prepare_closed`]: the referenced vertices in their original
/// order, renumbered densely, and the triangles over them, reversed where `flip` differs
/// from `inverted`.
fn renumbered(
    v: &[Point3<f64>],
    tris: &[[usize; 3]],
    flip: &[bool],
    inverted: bool,
) -> (Vec<Point3<f64>>, Vec<[usize; 3]>) {
    let mut index = vec![usize::MAX; v.len()];
    for tri in tris {
        for &i in tri {
            index[i] = 0;
        }
    }
    let mut vertices = Vec::new();
    for (i, slot) in index.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = vertices.len();
            vertices.push(v[i]);
        }
    }
    let triangles = tris
        .iter()
        .zip(flip)
        .map(|(tri, &f)| {
            let [a, b, c] = tri.map(|i| index[i]);
            if f ^ inverted { [a, c, b] } else { [a, b, c] }
        })
        .collect();
    (vertices, triangles)
}

/// A repeated vertex or an exactly zero (or non-finite) cross product.
fn degenerate(v: &[Point3<f64>], a: usize, b: usize, c: usize) -> bool {
    let n2 = (v[b] - v[a]).cross(&(v[c] - v[a])).norm_squared();
    a == b || b == c || a == c || n2.is_nan() || n2 <= 0.0
}

/// A closed surface encloses volume if |V| > 1e-10 · A^{3/2} (a sphere has 0.094 A^{3/2}).
fn has_volume(volume: f64, area: f64) -> bool {
    volume.abs() > 1e-10 * area.powf(1.5) && volume.is_finite()
}

/// Disjoint sets with path halving and union by index (deterministic roots: the smaller
/// index of two roots becomes the root).
struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
        }
    }
    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi] = lo;
        }
    }
}

/// How [`TriMesh::prepare_closed`] treats orientation problems.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Orientation {
    /// Flip the triangles of the minority orientation and invert an inward mesh, and say so
    /// in [`MeshRepair`].
    #[default]
    Repair,
    /// Return [`Error::InconsistentOrientation`] or [`Error::InwardOrientation`] instead of
    /// flipping anything.
    Refuse,
}

/// What [`TriMesh::prepare_closed`] changed. Vertex counts add up:
/// input vertices = output vertices + `welded` + `unreferenced`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshRepair {
    /// Vertices merged into an earlier vertex at the bit-identical position.
    pub welded: usize,
    /// Vertices dropped because no (non-degenerate) triangle uses them.
    pub unreferenced: usize,
    /// Degenerate triangles removed (a repeated vertex after welding, or zero area).
    pub degenerate_removed: usize,
    /// Triangles flipped to agree with the majority orientation of their neighbours.
    pub flipped: usize,
    /// Whether the whole (consistent) mesh was inverted because it faced inward.
    pub inverted: bool,
}

#[derive(Debug, Clone, Copy)]
struct Aabb {
    lo: Vector3<f64>,
    hi: Vector3<f64>,
}

impl Aabb {
    fn empty() -> Self {
        Self {
            lo: Vector3::repeat(f64::INFINITY),
            hi: Vector3::repeat(f64::NEG_INFINITY),
        }
    }
    fn grow(&mut self, p: &Vector3<f64>) {
        self.lo = self.lo.inf(p);
        self.hi = self.hi.sup(p);
    }
    fn dist2(&self, p: &Vector3<f64>) -> f64 {
        let d = (self.lo - p).sup(&(p - self.hi)).sup(&Vector3::zeros());
        d.norm_squared()
    }
}

#[derive(Debug, Clone)]
struct BvhNode {
    bounds: Aabb,
    /// Leaf: `start..start+count` in the triangle order; inner: `count == 0`, children at
    /// `start` and `start + 1`.
    start: usize,
    count: usize,
}

/// Closed mesh prepared for exact signed-distance queries (BVH + pseudonormals).
#[derive(Debug, Clone)]
pub struct MeshDistance {
    a: Vec<Vector3<f64>>,
    b: Vec<Vector3<f64>>,
    c: Vec<Vector3<f64>>,
    /// Pseudonormals per triangle: face, edges ab, bc, ca, vertices a, b, c.
    normals: Vec<[Vector3<f64>; 7]>,
    nodes: Vec<BvhNode>,
}

/// Closest feature of a triangle.
#[derive(Debug, Clone, Copy)]
enum Feature {
    Face,
    Edge(usize),
    Vertex(usize),
}

/// Unsigned distance from `p` to the triangle `abc` (Ericson 2005, Sec. 5.1.5).
#[must_use]
pub fn point_triangle_distance(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> f64 {
    let (q, _) = closest_on_triangle(&p.coords, &a.coords, &b.coords, &c.coords);
    (p.coords - q).norm()
}

/// Ericson 2005, `ClosestPtPointTriangle` (Sec. 5.1.5), with the Voronoi region.
#[inline]
fn closest_on_triangle(
    p: &Vector3<f64>,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    c: &Vector3<f64>,
) -> (Vector3<f64>, Feature) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, Feature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, Feature::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (a + ab * v + ac * w, Feature::Face)
}

impl MeshDistance {
    /// Prepares a closed mesh.
    ///
    /// # Errors
    /// [`Error::EmptyMesh`] (possible for [`TriMesh::default`]);
    /// [`Error::DegenerateTriangle`] (its normal is undefined); [`Error::NonClosedMesh`] if
    /// the mesh is not closed and consistently oriented ([`TriMesh::prepare_closed`] makes
    /// it so, or says why not).
    pub fn new(mesh: &TriMesh) -> Result<Self> {
        if mesh.triangles.is_empty() {
            return Err(Error::EmptyMesh);
        }
        if let Some(triangle) = (0..mesh.triangles.len()).find(|&t| mesh.is_degenerate(t)) {
            return Err(Error::DegenerateTriangle { triangle });
        }
        let across = mesh.check_closed()?;
        let v = &mesh.vertices;
        let nt = mesh.triangles.len();
        let face: Vec<Vector3<f64>> = mesh
            .triangles
            .iter()
            .map(|&[a, b, c]| (v[b] - v[a]).cross(&(v[c] - v[a])).normalize())
            .collect();
        // Angle-weighted vertex pseudonormals.
        let mut vn = vec![Vector3::zeros(); v.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for e in 0..3 {
                let p = v[tri[e]];
                let u1 = (v[tri[(e + 1) % 3]] - p).normalize();
                let u2 = (v[tri[(e + 2) % 3]] - p).normalize();
                let ang = u1.dot(&u2).clamp(-1.0, 1.0).acos();
                vn[tri[e]] += ang * face[t];
            }
        }
        let mut normals = Vec::with_capacity(nt);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let mut n = [Vector3::zeros(); 7];
            n[0] = face[t];
            for e in 0..3 {
                n[1 + e] = face[t] + face[across[t][e]];
                n[4 + e] = vn[tri[e]];
            }
            normals.push(n);
        }
        // BVH over centroids.
        let mut order: Vec<usize> = (0..nt).collect();
        let cent: Vec<Vector3<f64>> = mesh
            .triangles
            .iter()
            .map(|&[a, b, c]| (v[a].coords + v[b].coords + v[c].coords) / 3.0)
            .collect();
        let mut nodes = vec![BvhNode {
            bounds: Aabb::empty(),
            start: 0,
            count: 0,
        }];
        let mut stack = vec![(0usize, 0usize, nt)];
        while let Some((ni, lo, hi)) = stack.pop() {
            let mut bounds = Aabb::empty();
            let mut cb = Aabb::empty();
            for &t in &order[lo..hi] {
                for &vi in &mesh.triangles[t] {
                    bounds.grow(&v[vi].coords);
                }
                cb.grow(&cent[t]);
            }
            nodes[ni].bounds = bounds;
            if hi - lo <= 4 {
                nodes[ni].start = lo;
                nodes[ni].count = hi - lo;
                continue;
            }
            let ext = cb.hi - cb.lo;
            let axis = ext.imax();
            let mid = (lo + hi) / 2;
            order[lo..hi]
                .select_nth_unstable_by(mid - lo, |&x, &y| cent[x][axis].total_cmp(&cent[y][axis]));
            let child = nodes.len();
            nodes.push(BvhNode {
                bounds: Aabb::empty(),
                start: 0,
                count: 0,
            });
            nodes.push(BvhNode {
                bounds: Aabb::empty(),
                start: 0,
                count: 0,
            });
            nodes[ni].start = child;
            nodes[ni].count = 0;
            stack.push((child, lo, mid));
            stack.push((child + 1, mid, hi));
        }
        let a = order
            .iter()
            .map(|&t| v[mesh.triangles[t][0]].coords)
            .collect();
        let b = order
            .iter()
            .map(|&t| v[mesh.triangles[t][1]].coords)
            .collect();
        let c = order
            .iter()
            .map(|&t| v[mesh.triangles[t][2]].coords)
            .collect();
        let normals = order.iter().map(|&t| normals[t]).collect();
        Ok(Self {
            a,
            b,
            c,
            normals,
            nodes,
        })
    }

    /// Exact signed distance (negative inside).
    pub fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        self.signed_distance_bounded(p, f64::INFINITY)
    }

    /// As [`MeshDistance::signed_distance`], given an upper bound of |distance| that speeds
    /// up the search (any bound ≥ the true distance gives the exact answer).
    pub fn signed_distance_bounded(&self, p: &Point3<f64>, bound: f64) -> f64 {
        let q = p.coords;
        let best2 = if bound.is_finite() {
            bound * bound * (1.0 + 1e-9) + 1e-300
        } else {
            f64::INFINITY
        };
        match self.search(&q, best2, None) {
            Some(hit) => self.signed(&q, hit),
            // Bound was too small (only possible with a wrong bound): exact search.
            None if bound.is_finite() => self.signed_distance_bounded(p, f64::INFINITY),
            None => f64::INFINITY,
        }
    }

    /// Exact signed distance and the closest triangle (in the internal order), starting
    /// from the exact distance to triangle `hint` as the bound: the closest triangle of a
    /// neighbouring query point is usually the answer, so the search only has to prove it.
    fn signed_distance_from(&self, q: &Vector3<f64>, hint: usize) -> (f64, usize) {
        let hint = hint.min(self.a.len().saturating_sub(1));
        let (cp, f) = closest_on_triangle(q, &self.a[hint], &self.b[hint], &self.c[hint]);
        let d2 = (q - cp).norm_squared();
        let hit = self
            .search(q, d2, Some((hint, cp, f)))
            .unwrap_or((hint, cp, f));
        (self.signed(q, hit), hit.0)
    }

    /// Depth-first nearest-triangle search, nearer child first, boxes farther than the best
    /// squared distance so far pruned when pushed and when popped.
    fn search(
        &self,
        q: &Vector3<f64>,
        mut best2: f64,
        mut best: Option<(usize, Vector3<f64>, Feature)>,
    ) -> Option<(usize, Vector3<f64>, Feature)> {
        let mut stack: [(usize, f64); 128] = [(0, 0.0); 128];
        let mut sp = 0usize;
        let root = self.nodes.first()?.bounds.dist2(q);
        if root <= best2 {
            stack[0] = (0, root);
            sp = 1;
        }
        while sp > 0 {
            sp -= 1;
            let (ni, d) = stack[sp];
            if d > best2 {
                continue;
            }
            let node = &self.nodes[ni];
            if node.count > 0 {
                for t in node.start..node.start + node.count {
                    let (cp, f) = closest_on_triangle(q, &self.a[t], &self.b[t], &self.c[t]);
                    let d2 = (q - cp).norm_squared();
                    if d2 <= best2 {
                        best2 = d2;
                        best = Some((t, cp, f));
                    }
                }
            } else if sp + 2 <= stack.len() {
                let (l, r) = (node.start, node.start + 1);
                let (dl, dr) = (self.nodes[l].bounds.dist2(q), self.nodes[r].bounds.dist2(q));
                // Visit the nearer child first (pushed last).
                let (near, far) = if dl < dr {
                    ((l, dl), (r, dr))
                } else {
                    ((r, dr), (l, dl))
                };
                for c in [far, near] {
                    if c.1 <= best2 {
                        stack[sp] = c;
                        sp += 1;
                    }
                }
            }
        }
        best
    }

    /// The signed distance of a search result (sign from the pseudonormal of the closest
    /// feature).
    fn signed(&self, q: &Vector3<f64>, (t, cp, f): (usize, Vector3<f64>, Feature)) -> f64 {
        let n = match f {
            Feature::Face => self.normals[t][0],
            Feature::Edge(e) => self.normals[t][1 + e],
            Feature::Vertex(v) => self.normals[t][4 + v],
        };
        let d = (q - cp).norm();
        if (q - cp).dot(&n) < 0.0 { -d } else { d }
    }
}

impl Grid {
    /// Exact signed distance of a closed triangle mesh at every node. Each node's search
    /// starts from the closest triangle of the previous node (of the previous row or slice
    /// at the start of a row): its exact distance is a tight bound, so the search mostly
    /// confirms it.
    ///
    /// # Errors
    /// Invalid spec; as [`MeshDistance::new`].
    pub fn from_mesh(spec: GridSpec, mesh: &TriMesh) -> Result<Self> {
        spec.validate()?;
        let md = MeshDistance::new(mesh)?;
        let [nx, ny, nz] = spec.dims;
        let mut values = Vec::with_capacity(spec.len());
        let (mut slice_start, mut row_start) = (0usize, 0usize);
        for k in 0..nz {
            for j in 0..ny {
                let mut hint = if j == 0 { slice_start } else { row_start };
                for i in 0..nx {
                    let (d, t) = md.signed_distance_from(&spec.node(i, j, k).coords, hint);
                    values.push(d);
                    hint = t;
                    if i == 0 {
                        row_start = t;
                        if j == 0 {
                            slice_start = t;
                        }
                    }
                }
            }
        }
        Self::new(spec, values)
    }
}

#[cfg(test)]
pub(crate) mod tests;
