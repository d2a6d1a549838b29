//! Surface nodes and LS-DEM node-to-grid contact (Kawamoto et al. 2016, J. Mech. Phys.
//! Solids 91, doi:10.1016/j.jmps.2016.02.021, Sec. 2.2–2.3).
//!
//! Each grain carries its level set and a set of nodes on its surface, both in the body
//! frame. Grain A touches grain B where a node of A has φ_B < 0; the penetration is `−φ_B`
//! and the contact normal is `∇φ_B/|∇φ_B|` at the node (both from the second-order
//! corrected interpolant [`Grid::sample`]) (pointing out of B), rotated to the
//! world frame. A bounding-sphere test on the pair, then per node, skips most work.
//!
//! Surface nodes (choice left open by the seeds): candidates are the vertices (and, when
//! many nodes are requested, the triangle centroids) of the marching-cubes mesh; a greedy
//! farthest-point selection picks `count` of them, which spreads them roughly uniformly
//! in surface distance; each is finally projected onto the zero level set of the
//! trilinear interpolant.

use nalgebra::{Isometry3, Point3, Unit, Vector3};

use crate::error::{Error, Result};
use crate::grid::Grid;

impl Grid {
    /// `count` roughly uniform points on the zero level set (farthest-point sampling of the
    /// marching-cubes vertices, then Newton projection), deterministic.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for `count == 0`, [`Error::NoSurface`] if the grid has
    /// no surface, [`Error::TooManyNodes`] if the mesh offers fewer candidates than `count`.
    pub fn surface_nodes(&self, count: usize) -> Result<Vec<Point3<f64>>> {
        if count == 0 {
            return Err(Error::InvalidParameter {
                name: "count",
                value: 0.0,
                requirement: "at least 1",
            });
        }
        let mesh = self.marching_cubes();
        if mesh.triangles().is_empty() {
            return Err(Error::NoSurface);
        }
        let mut cand: Vec<Point3<f64>> = mesh.vertices().to_vec();
        if count * 4 > cand.len() {
            let v = mesh.vertices();
            cand.extend(
                mesh.triangles().iter().map(|&[a, b, c]| {
                    Point3::from((v[a].coords + v[b].coords + v[c].coords) / 3.0)
                }),
            );
        }
        if count > cand.len() {
            return Err(Error::TooManyNodes {
                requested: count,
                available: cand.len(),
            });
        }
        let centre = cand.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / cand.len() as f64;
        // Start from the candidate farthest from the centroid (ties: lowest index).
        let mut first = 0;
        let mut far = -1.0;
        for (i, p) in cand.iter().enumerate() {
            let d = (p.coords - centre).norm_squared();
            if d > far {
                far = d;
                first = i;
            }
        }
        let mut out: Vec<Point3<f64>> = farthest_points(&cand, first, count)
            .into_iter()
            .map(|i| cand[i])
            .collect();
        for p in &mut out {
            if let Ok(q) = self.closest_point(p)
                && (q - *p).norm() < self.spacing()
            {
                *p = q;
            }
        }
        Ok(out)
    }
}

/// Greedy farthest-point selection of `count` of `cand`, starting at `first`: each pick
/// is the candidate farthest from those picked (ties: lowest index). Returns indices.
///
/// The candidates are binned in cells (about 16 per cell); a cell whose box is no
/// closer to the new pick than its largest distance-to-the-picked cannot change and is
/// skipped, and the argmax is taken over the cells' maxima. The distances and the tie
/// rule are those of the plain O(count · n) scan ([`farthest_points_plain`]), so the
/// selection is identical; late picks touch only the few cells near them.
fn farthest_points(cand: &[Point3<f64>], first: usize, count: usize) -> Vec<usize> {
    let n = cand.len();
    let (mut lo, mut hi) = (cand[0].coords, cand[0].coords);
    for p in cand {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let cells_per_axis = ((n as f64 / 16.0).cbrt().ceil() as usize).clamp(1, 64);
    let ext = (hi - lo).map(|e| e.max(f64::MIN_POSITIVE));
    let cell_of = |p: &Point3<f64>| -> usize {
        let mut c = 0;
        for k in (0..3).rev() {
            let t = ((p[k] - lo[k]) / ext[k] * cells_per_axis as f64) as usize;
            c = c * cells_per_axis + t.min(cells_per_axis - 1);
        }
        c
    };
    let n_cells = cells_per_axis.pow(3);
    // members of each cell in index order, and each cell's exact bounding box
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n_cells];
    for (i, p) in cand.iter().enumerate() {
        members[cell_of(p)].push(i);
    }
    members.retain(|m| !m.is_empty());
    let boxes: Vec<(Vector3<f64>, Vector3<f64>)> = members
        .iter()
        .map(|m| {
            m.iter()
                .fold((cand[m[0]].coords, cand[m[0]].coords), |(a, b), &i| {
                    (a.inf(&cand[i].coords), b.sup(&cand[i].coords))
                })
        })
        .collect();
    let mut mind = vec![f64::INFINITY; n];
    // per cell: (largest mind, its lowest index)
    let mut best: Vec<(f64, usize)> = members.iter().map(|m| (f64::INFINITY, m[0])).collect();
    let mut out = Vec::with_capacity(count);
    let mut next = first;
    for _ in 0..count {
        let s = cand[next];
        out.push(next);
        for (c, m) in members.iter().enumerate() {
            let (a, b) = &boxes[c];
            let gap = (a - s.coords).sup(&(s.coords - b)).sup(&Vector3::zeros());
            // conservative: skip only when every member is certainly no closer
            if gap.norm_squared() * (1.0 - 1e-9) > best[c].0 {
                continue;
            }
            let mut cb = (-1.0, m[0]);
            for &i in m {
                let d = (cand[i] - s).norm_squared();
                if d < mind[i] {
                    mind[i] = d;
                }
                if mind[i] > cb.0 {
                    cb = (mind[i], i);
                }
            }
            best[c] = cb;
        }
        let mut g = (-1.0, 0usize);
        for &(v, i) in &best {
            if v > g.0 || (v == g.0 && i < g.1) {
                g = (v, i);
            }
        }
        next = g.1;
    }
    out
}

/// The plain O(count · n) farthest-point scan: the oracle of [`farthest_points`].
#[cfg(test)]
fn farthest_points_plain(cand: &[Point3<f64>], first: usize, count: usize) -> Vec<usize> {
    let mut mind = vec![f64::INFINITY; cand.len()];
    let mut out = Vec::with_capacity(count);
    let mut next = first;
    for _ in 0..count {
        let s = cand[next];
        out.push(next);
        let mut best = (-1.0, 0usize);
        for (i, p) in cand.iter().enumerate() {
            let d = (p - s).norm_squared();
            if d < mind[i] {
                mind[i] = d;
            }
            if mind[i] > best.0 {
                best = (mind[i], i);
            }
        }
        next = best.1;
    }
    out
}

/// A grain for contact: level set and surface nodes in the body frame, plus a bounding
/// radius about the body-frame origin.
#[derive(Debug, Clone)]
pub struct Body {
    grid: Grid,
    nodes: Vec<Point3<f64>>,
    radius: f64,
}

impl Body {
    /// Bundles a grid and its surface nodes (body frame). The bounding radius is the larger of
    /// the farthest node and the farthest inside node + h√3 (every point of the trilinear
    /// zero set lies within h√3 of an inside node), so it bounds the grain rigorously.
    ///
    /// # Errors
    /// [`Error::NoSurface`] if no node is inside; [`Error::NonFiniteVertex`] for a
    /// non-finite surface node.
    pub fn new(grid: Grid, nodes: Vec<Point3<f64>>) -> Result<Self> {
        if let Some(index) = nodes
            .iter()
            .position(|p| !p.coords.iter().all(|c| c.is_finite()))
        {
            return Err(Error::NonFiniteVertex { index });
        }
        let spec = *grid.spec();
        let [nx, ny, nz] = spec.dims;
        let mut r2: f64 = -1.0;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    if grid.at(i, j, k) < 0.0 {
                        r2 = r2.max(spec.node(i, j, k).coords.norm_squared());
                    }
                }
            }
        }
        if r2 < 0.0 {
            return Err(Error::NoSurface);
        }
        let mut radius = r2.sqrt() + spec.spacing * 3f64.sqrt();
        for p in &nodes {
            radius = radius.max(p.coords.norm());
        }
        Ok(Self {
            grid,
            nodes,
            radius,
        })
    }

    /// Level set (body frame).
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Surface nodes (body frame).
    pub fn nodes(&self) -> &[Point3<f64>] {
        &self.nodes
    }

    /// Bounding radius about the body-frame origin.
    pub fn bounding_radius(&self) -> f64 {
        self.radius
    }
}

/// One penetrating node of A in B.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeContact {
    /// Index of the node in A's node list.
    pub node: usize,
    /// Node position in the world frame.
    pub point: Point3<f64>,
    /// Penetration depth `−φ_B` (> 0).
    pub penetration: f64,
    /// Unit outward normal of B at the node, world frame (direction to push A's node out).
    pub normal: Unit<Vector3<f64>>,
}

/// Nodes of `a` penetrating `b`, both placed by their poses (body → world). Appends to
/// `out` (cleared first) so the buffer can be reused; returns the number of contacts.
pub fn contact_into(
    a: &Body,
    pose_a: &Isometry3<f64>,
    b: &Body,
    pose_b: &Isometry3<f64>,
    out: &mut Vec<NodeContact>,
) -> usize {
    out.clear();
    let centres = pose_a.translation.vector - pose_b.translation.vector;
    let reach = a.radius + b.radius;
    if centres.norm_squared() > reach * reach {
        return 0;
    }
    let a_to_b = pose_b.inv_mul(pose_a);
    let rb2 = b.radius * b.radius;
    let half_h = 0.5 * b.grid.spacing();
    for (n, p) in a.nodes.iter().enumerate() {
        let q = a_to_b * p;
        if q.coords.norm_squared() > rb2 {
            continue;
        }
        // Cheap trilinear reject first (the correction of `sample` is far below h/2).
        let Some(phi) = b.grid.try_value(&q) else {
            continue;
        };
        if phi >= half_h {
            continue;
        }
        let Some((phi, g)) = b.grid.sample(&q) else {
            continue;
        };
        if phi >= 0.0 {
            continue;
        }
        let Some(nb) = Unit::try_new(g, 1e-12) else {
            continue;
        };
        out.push(NodeContact {
            node: n,
            point: pose_a * p,
            penetration: -phi,
            normal: pose_b.rotation * nb,
        });
    }
    out.len()
}

/// Nodes of `a` penetrating `b` (allocating convenience wrapper of [`contact_into`]).
pub fn contact(
    a: &Body,
    pose_a: &Isometry3<f64>,
    b: &Body,
    pose_b: &Isometry3<f64>,
) -> Vec<NodeContact> {
    let mut out = Vec::new();
    contact_into(a, pose_a, b, pose_b, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::shapes::Sphere;

    /// The binned farthest-point selection picks exactly what the plain scan picks: on
    /// marching-cubes vertices and on a lattice (many exact ties).
    #[test]
    fn binned_farthest_points_equal_the_plain_scan() {
        let spec = GridSpec::cube(31, -1.2, 1.2).expect("spec");
        let g = Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity())
            .expect("grid");
        let verts = g.marching_cubes().vertices().to_vec();
        let mut lattice = Vec::new();
        for i in 0..12 {
            for j in 0..9 {
                for k in 0..7 {
                    lattice.push(Point3::new(i as f64, 0.5 * j as f64, 2.0 * k as f64));
                }
            }
        }
        for (cand, count) in [(&verts, 400), (&verts, 7), (&lattice, 300), (&lattice, 756)] {
            for first in [0, cand.len() / 3] {
                assert_eq!(
                    farthest_points(cand, first, count),
                    farthest_points_plain(cand, first, count)
                );
            }
        }
    }

    fn sphere_body(nodes: usize) -> Body {
        let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
        let g = Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity())
            .expect("grid");
        let n = g.surface_nodes(nodes).expect("nodes");
        Body::new(g, n).expect("body")
    }

    #[test]
    fn nodes_lie_on_surface_and_spread() {
        let b = sphere_body(500);
        let mut min_gap = f64::INFINITY;
        for (i, p) in b.nodes().iter().enumerate() {
            assert!((p.coords.norm() - 1.0).abs() < 1e-3, "node off surface");
            for q in &b.nodes()[..i] {
                min_gap = min_gap.min((p - q).norm());
            }
        }
        // Uniform spacing on the unit sphere for 500 points ≈ sqrt(4π/500) ≈ 0.16.
        assert!(min_gap > 0.08, "min gap {min_gap}");
        assert!(b.bounding_radius() > 1.0 && b.bounding_radius() < 1.2);
    }

    #[test]
    fn overlapping_spheres_penetration_and_normals() {
        let body = sphere_body(1000);
        let h = body.grid().spacing();
        // Line of centres through node 17 of A.
        let axis = body.nodes()[17].coords.normalize();
        for delta in [0.01, 0.1, 0.3] {
            let pa = Isometry3::identity();
            let cb = axis * (2.0 - delta);
            let pb = Isometry3::new(cb, Vector3::new(0.4, -0.3, 0.2));
            let cs = contact(&body, &pa, &body, &pb);
            assert!(!cs.is_empty());
            let maxpen = cs.iter().map(|c| c.penetration).fold(0.0, f64::max);
            assert!(
                (maxpen - delta).abs() < 0.02 * h,
                "delta {delta}: max pen {maxpen}"
            );
            for c in &cs {
                let exact = (c.point.coords - cb).normalize();
                let ang = c.normal.dot(&exact).clamp(-1.0, 1.0).acos().to_degrees();
                assert!(ang < 1.0, "normal off by {ang}°");
            }
        }
        // Far apart: early exit.
        let far = Isometry3::translation(3.0, 0.0, 0.0);
        assert!(contact(&body, &Isometry3::identity(), &body, &far).is_empty());
    }
}
