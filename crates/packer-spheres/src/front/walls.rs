//! Container geometry as the front sees it: wall planes of a box, the
//! ends and side of a cylinder, and the face planes of a mesh indexed by
//! cell; the exact inside test and the first sphere's seat.

// Coordinates are `[f64; 3]` triples indexed in step with box bounds and
// cell counts: index loops read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

use nalgebra::{Point3, Vector3};

use super::Front3;
use crate::container::{Container, MeshContainer};
use levelset::TriMesh;

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
    pub(super) fn cell(&self, p: &[f64; 3]) -> Option<usize> {
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
    pub(super) fn near(&self, c: usize) -> &[u32] {
        &self.list[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

impl Walls {
    /// The walls of `container` (a mesh's indexed on cells of at least
    /// `r_max`).
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
            Container::Mesh(m) => Self::Mesh(MeshWalls::new(m, container, r_max)),
        }
    }
}

impl MeshWalls {
    /// The face planes of a mesh container and their per-cell lists, on
    /// cells of at least `r_max` over the bounding box widened by a cell.
    fn new(m: &MeshContainer, container: &Container, r_max: f64) -> Self {
        let mesh = m.mesh();
        let (lo, hi) = container.bbox();
        let ext = hi - lo;
        let mut c = r_max;
        while (ext.x / c + 3.0) * (ext.y / c + 3.0) * (ext.z / c + 3.0) > 5.0e5 {
            c *= 1.25;
        }
        let n = [0, 1, 2].map(|k| (ext[k] / c).ceil() as usize + 2);
        let lo = [lo.x - c, lo.y - c, lo.z - c];
        let half_diag = c * 0.5 * 3f64.sqrt();
        let (planes, tri_plane) = face_planes(mesh);
        let reach = 3.0 * r_max + half_diag;
        let cells = CellLayout { lo, n, c };
        let deep = cells.depths(m, reach, half_diag);
        let (start, list) = cells.plane_lists(mesh, &tri_plane, reach);
        Self {
            lo,
            inv: 1.0 / c,
            n,
            deep,
            start,
            list,
            planes,
        }
    }
}

/// Distinct face planes of a mesh (inward normals): sorted, then runs of
/// equal planes (within round-off) merged; with the plane of each triangle.
fn face_planes(mesh: &TriMesh) -> (Vec<Plane>, Vec<u32>) {
    let v = mesh.vertices();
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
    (planes, tri_plane)
}

/// The cells of a mesh's wall index: lower corner, counts and side.
struct CellLayout {
    lo: [f64; 3],
    n: [usize; 3],
    c: f64,
}

impl CellLayout {
    /// Centre of cell `(ix, iy, iz)`.
    #[inline]
    fn centre(&self, ix: usize, iy: usize, iz: usize) -> Point3<f64> {
        let (lo, c) = (self.lo, self.c);
        Point3::new(
            lo[0] + (ix as f64 + 0.5) * c,
            lo[1] + (iy as f64 + 0.5) * c,
            lo[2] + (iz as f64 + 0.5) * c,
        )
    }

    /// Lower bound of the clearance over each cell, from the exact
    /// clearance at its centre.
    fn depths(&self, m: &MeshContainer, reach: f64, half_diag: f64) -> Vec<f64> {
        let n = self.n;
        let mut deep = vec![f64::NEG_INFINITY; n[0] * n[1] * n[2]];
        for iz in 0..n[2] {
            for iy in 0..n[1] {
                for ix in 0..n[0] {
                    let idx = ix + n[0] * (iy + n[1] * iz);
                    let p = self.centre(ix, iy, iz);
                    deep[idx] = m.clearance_bounded(&p, reach + half_diag) - half_diag;
                }
            }
        }
        deep
    }

    /// Face planes near each cell (every triangle visits the cells of its
    /// box widened by the reach), as offsets `start` into one `list`.
    fn plane_lists(&self, mesh: &TriMesh, tri_plane: &[u32], reach: f64) -> (Vec<u32>, Vec<u32>) {
        let (lo, n, c) = (self.lo, self.n, self.c);
        let v = mesh.vertices();
        let cells = n[0] * n[1] * n[2];
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
                        let p = self.centre(ix, iy, iz);
                        if levelset::mesh::point_triangle_distance(&p, &a, &b2, &c2) <= reach {
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
        (start, list)
    }
}

#[inline]
fn lower(a: &[f64; 3], b: &[f64; 3]) -> bool {
    (a[2], a[0], a[1]) < (b[2], b[0], b[1])
}

impl Front3<'_> {
    /// Exact container test for a sphere of radius `r` at `p`.
    #[inline]
    pub(super) fn inside(&self, p: &[f64; 3], r: f64) -> bool {
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

    /// The first sphere: as low as possible, touching walls.
    pub(super) fn seed(&mut self, r: f64) -> Option<u32> {
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
}
