//! 3D convex hull (Quickhull with conflict lists, Barber, Dobkin & Huhdanpaa
//! 1996, doi:10.1145/235815.235821), used for the convexity descriptor.

use nalgebra::{Point3, Vector3};

use crate::error::{Error, Result};

/// No point / no face.
const NONE: u32 = u32::MAX;

/// A face of the hull under construction. Slots of deleted faces are
/// reused; `generation` tells a stale work-list entry from the slot's
/// current face.
#[derive(Clone, Copy)]
struct Face {
    v: [u32; 3],
    /// `nb[k]`: the face across edge `(v[k], v[k+1])`.
    nb: [u32; 3],
    /// Conflict list (points outside this face, in assignment order) as a
    /// singly linked list through `Faces::next`.
    head: u32,
    tail: u32,
    /// The farthest point of the conflict list (the last of equals).
    far: u32,
    generation: u32,
    far_d: f64,
    alive: bool,
}

/// Plane of a face: unit normal and offset (`n·x = offset`).
#[derive(Clone, Copy)]
struct Plane {
    normal: Vector3<f64>,
    offset: f64,
}

impl Plane {
    #[inline]
    fn new(points: &[Point3<f64>], v: [u32; 3]) -> Self {
        let (a, b, c) = (
            points[v[0] as usize],
            points[v[1] as usize],
            points[v[2] as usize],
        );
        let n = (b - a).cross(&(c - a));
        let len = n.norm();
        let normal = if len > 0.0 { n / len } else { Vector3::zeros() };
        Self {
            normal,
            offset: normal.dot(&a.coords),
        }
    }

    #[inline]
    fn distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&p.coords) - self.offset
    }
}

/// Faces and their planes (apart, so that distance tests read a dense
/// array), the conflict-list links of the points and the free slots.
struct Faces {
    faces: Vec<Face>,
    planes: Vec<Plane>,
    /// Per point: the next point of the same conflict list.
    next: Vec<u32>,
    free: Vec<u32>,
}

impl Faces {
    fn push(&mut self, points: &[Point3<f64>], v: [u32; 3]) -> u32 {
        let plane = Plane::new(points, v);
        let mut face = Face {
            v,
            nb: [NONE; 3],
            head: NONE,
            tail: NONE,
            far: NONE,
            generation: 0,
            far_d: f64::NEG_INFINITY,
            alive: true,
        };
        if let Some(id) = self.free.pop() {
            let slot = id as usize;
            face.generation = self.faces[slot].generation.wrapping_add(1);
            self.faces[slot] = face;
            self.planes[slot] = plane;
            id
        } else {
            self.faces.push(face);
            self.planes.push(plane);
            (self.faces.len() - 1) as u32
        }
    }

    /// Appends point `p` at distance `d` to the conflict list of face `f`.
    #[inline]
    fn assign(&mut self, f: u32, p: u32, d: f64) {
        self.next[p as usize] = NONE;
        let face = &mut self.faces[f as usize];
        if face.tail == NONE {
            face.head = p;
        } else {
            self.next[face.tail as usize] = p;
        }
        face.tail = p;
        // `max_by` semantics: the last of equal maxima wins
        if d >= face.far_d {
            face.far_d = d;
            face.far = p;
        }
    }
}

/// Volume of the convex hull of `points`.
///
/// # Errors
/// [`Error::InvalidParameter`] if the points are fewer than four, not finite,
/// or (nearly) coplanar, so that the hull has no volume.
pub fn convex_hull_volume(points: &[Point3<f64>]) -> Result<f64> {
    let faces = convex_hull(points)?;
    // divergence theorem from the first point (any reference works)
    let o = points[faces[0][0]].coords;
    let vol6: f64 = faces
        .iter()
        .map(|f| {
            let (a, b, c) = (
                points[f[0]].coords - o,
                points[f[1]].coords - o,
                points[f[2]].coords - o,
            );
            a.dot(&b.cross(&c))
        })
        .sum();
    Ok(vol6 / 6.0)
}

/// Why Quickhull stops when rounding makes its horizon inconsistent.
const NUMERICALLY_DEGENERATE: &str = "numerically degenerate point set";

/// Triangles of the convex hull of `points`, outward oriented.
///
/// The visibility tolerance is 1e-10 of the points' extent; if rounding still makes a
/// horizon inconsistent (nearly coplanar clusters of many points, as the surfaces of
/// finely smoothed voxel grains have), the hull is rebuilt with 1e-8 and then 1e-6 of the
/// extent (points that close to a face count as on it; the volume changes by at most
/// that thickness times the area). Hulls that succeed at 1e-10 are unchanged.
///
/// # Errors
/// As [`convex_hull_volume`].
pub fn convex_hull(points: &[Point3<f64>]) -> Result<Vec<[usize; 3]>> {
    let mut last = None;
    for rel_eps in [1e-10, 1e-8, 1e-6] {
        match quickhull(points, rel_eps) {
            Err(Error::InvalidParameter { reason, .. }) if reason == NUMERICALLY_DEGENERATE => {
                last = Some(reason);
            }
            other => return other,
        }
    }
    Err(Error::InvalidParameter {
        name: "hull points",
        value: points.len() as f64,
        reason: last.unwrap_or(NUMERICALLY_DEGENERATE),
    })
}

/// Quickhull with the visibility tolerance `rel_eps` of the points' extent.
fn quickhull(points: &[Point3<f64>], rel_eps: f64) -> Result<Vec<[usize; 3]>> {
    let degenerate = |reason: &'static str| Error::InvalidParameter {
        name: "hull points",
        value: points.len() as f64,
        reason,
    };
    if points.len() < 4 {
        return Err(degenerate("at least 4 points are needed"));
    }
    if u32::try_from(points.len()).is_err() {
        return Err(degenerate("at most 2^32 - 1 points"));
    }
    if points
        .iter()
        .any(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(degenerate("every point must be finite"));
    }
    // scale for tolerances
    let (mut lo, mut hi) = (points[0].coords, points[0].coords);
    for p in points {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let scale = (hi - lo).norm();
    if scale <= 0.0 {
        return Err(degenerate("points coincide"));
    }
    // degeneracy tests at the base tolerance, visibility at `rel_eps`
    let eps0 = 1e-10 * scale;
    let eps = rel_eps * scale;
    // initial tetrahedron: extreme pair, farthest from their line, farthest from that plane
    let ext = |f: &dyn Fn(&Point3<f64>) -> f64| {
        let mut best = 0;
        for (i, p) in points.iter().enumerate() {
            if f(p) > f(&points[best]) {
                best = i;
            }
        }
        best
    };
    let mut i0 = 0;
    let mut i1 = 0;
    let mut best = -1.0;
    for axis in 0..3 {
        let a = ext(&|p| -p[axis]);
        let b = ext(&|p| p[axis]);
        let d = (points[a] - points[b]).norm();
        if d > best {
            best = d;
            i0 = a;
            i1 = b;
        }
    }
    let dir = (points[i1] - points[i0]).normalize();
    let i2 = ext(&|p| {
        let w = p - points[i0];
        (w - dir * w.dot(&dir)).norm()
    });
    let n = (points[i1] - points[i0]).cross(&(points[i2] - points[i0]));
    if n.norm() <= eps0 * scale {
        return Err(degenerate("points are collinear"));
    }
    let n = n.normalize();
    let i3 = ext(&|p| (p - points[i0]).dot(&n).abs());
    let h = (points[i3] - points[i0]).dot(&n);
    if h.abs() <= eps0 * 1e3 {
        return Err(degenerate("points are coplanar"));
    }
    // a closed triangulation of n points has 2n − 4 faces
    let cap = 2 * points.len().min(1 << 20) + 64;
    let mut fs = Faces {
        faces: Vec::with_capacity(cap),
        planes: Vec::with_capacity(cap),
        next: vec![NONE; points.len()],
        free: Vec::new(),
    };
    let tet = if h > 0.0 {
        [[i0, i2, i1], [i0, i1, i3], [i1, i2, i3], [i2, i0, i3]]
    } else {
        [[i0, i1, i2], [i0, i3, i1], [i1, i3, i2], [i2, i3, i0]]
    };
    for v in tet {
        fs.push(points, v.map(|i| i as u32));
    }
    // adjacency of the tetrahedron
    for f in 0..4 {
        for k in 0..3 {
            let (a, b) = (fs.faces[f].v[k], fs.faces[f].v[(k + 1) % 3]);
            let twin = (0..4).find(|&g| {
                (0..3).any(|j| fs.faces[g].v[j] == b && fs.faces[g].v[(j + 1) % 3] == a)
            });
            fs.faces[f].nb[k] =
                twin.ok_or_else(|| degenerate("inconsistent initial tetrahedron"))? as u32;
        }
    }
    let used = [i0, i1, i2, i3];
    for (p, pt) in points.iter().enumerate() {
        if used.contains(&p) {
            continue;
        }
        for f in 0..4 {
            let d = fs.planes[f].distance(pt);
            if d > eps {
                fs.assign(f as u32, p as u32, d);
                break;
            }
        }
    }
    // visibility memo per iteration: stamp[f] == iteration ⇒ visible[f] valid
    let mut stamp: Vec<usize> = Vec::new();
    let mut seen_visible: Vec<bool> = Vec::new();
    let mut in_region: Vec<bool> = Vec::new();
    // horizon fan links: per point, the iteration that set it and the index
    // of the first horizon edge starting / ending there
    let mut start_stamp: Vec<usize> = vec![0; points.len()];
    let mut starts_at: Vec<u32> = vec![0; points.len()];
    let mut end_stamp: Vec<usize> = vec![0; points.len()];
    let mut ends_at: Vec<u32> = vec![0; points.len()];
    let mut visible: Vec<u32> = Vec::new();
    // (a, b, face across) for each horizon edge
    let mut horizon: Vec<(u32, u32, u32)> = Vec::new();
    let mut new_faces: Vec<u32> = Vec::new();
    // work list of faces that may have outside points (LIFO, deterministic):
    // (slot, generation)
    let mut pending: Vec<(u32, u32)> = (0..4).map(|f| (f, 0)).collect();
    let mut iteration = 0usize;
    while let Some((fi, generation)) = pending.pop() {
        let face = fs.faces[fi as usize];
        if face.generation != generation || !face.alive || face.head == NONE {
            continue;
        }
        iteration += 1;
        let eye = face.far;
        let ep = points[eye as usize];
        // visible region: connected faces seen from the eye, walked over the
        // adjacency from the face the eye was chosen from; the horizon is
        // where the walk meets a face that is not visible
        let nf = fs.faces.len();
        stamp.resize(nf, 0);
        seen_visible.resize(nf, false);
        in_region.resize(nf, false);
        in_region[fi as usize] = true;
        visible.clear();
        visible.push(fi);
        horizon.clear();
        let mut cur = 0;
        while cur < visible.len() {
            let f = visible[cur] as usize;
            cur += 1;
            for k in 0..3 {
                let nb = fs.faces[f].nb[k];
                let n = nb as usize;
                if !fs.faces[n].alive {
                    // adjacency left pointing at a deleted face: an earlier horizon was
                    // inconsistent in a way its checks missed
                    return Err(degenerate(NUMERICALLY_DEGENERATE));
                }
                if stamp[n] != iteration {
                    stamp[n] = iteration;
                    seen_visible[n] = in_region[n] || fs.planes[n].distance(&ep) > eps;
                }
                if seen_visible[n] {
                    if !in_region[n] {
                        in_region[n] = true;
                        visible.push(nb);
                    }
                } else {
                    let v = fs.faces[f].v;
                    horizon.push((v[k], v[(k + 1) % 3], nb));
                }
            }
        }
        for &i in &visible {
            in_region[i as usize] = false;
            fs.faces[i as usize].alive = false;
        }
        // new faces take slots freed by earlier iterations, so the conflict
        // lists of this iteration's visible faces stay readable
        new_faces.clear();
        for (e, &(a, b, across)) in horizon.iter().enumerate() {
            let id = fs.push(points, [a, b, eye]);
            fs.faces[id as usize].nb[0] = across;
            let acr = &mut fs.faces[across as usize];
            let k = (0..3)
                .find(|&j| acr.v[j] == b && acr.v[(j + 1) % 3] == a)
                .ok_or_else(|| degenerate(NUMERICALLY_DEGENERATE))?;
            acr.nb[k] = id;
            new_faces.push(id);
            // a visible region that is a topological disk has a horizon that is one simple
            // loop: every point starts and ends at most one horizon edge. Rounding can make
            // the region pinched or holed (a point on two loops, or two loops); linking such
            // a horizon corrupts the adjacency and the conflict lists (found on a smoothed
            // voxel grain: a conflict list became a cycle), so it is refused here and the
            // hull is rebuilt with a larger tolerance.
            if start_stamp[a as usize] == iteration || end_stamp[b as usize] == iteration {
                return Err(degenerate(NUMERICALLY_DEGENERATE));
            }
            start_stamp[a as usize] = iteration;
            starts_at[a as usize] = e as u32;
            end_stamp[b as usize] = iteration;
            ends_at[b as usize] = e as u32;
        }
        // one loop through every horizon edge
        {
            let mut e = 0usize;
            for step in 1..=horizon.len() {
                let b = horizon[e].1 as usize;
                if start_stamp[b] != iteration {
                    return Err(degenerate(NUMERICALLY_DEGENERATE));
                }
                e = starts_at[b] as usize;
                if e == 0 && step < horizon.len() {
                    return Err(degenerate(NUMERICALLY_DEGENERATE));
                }
            }
            if e != 0 {
                return Err(degenerate(NUMERICALLY_DEGENERATE));
            }
        }
        // link the fan of new faces around the eye
        // (every edge's ends start and end an edge: the loop check above)
        for (i, &(a, b, _)) in horizon.iter().enumerate() {
            let f = new_faces[i] as usize;
            fs.faces[f].nb[1] = new_faces[starts_at[b as usize] as usize];
            fs.faces[f].nb[2] = new_faces[ends_at[a as usize] as usize];
        }
        // the conflict points of the visible faces, in order, go to the first
        // new face they are outside of (or are inside the hull)
        // every point is in at most one conflict list, so a longer walk means corrupted
        // links: refuse rather than loop
        let mut walked = 0usize;
        for &vf in &visible {
            let mut p = fs.faces[vf as usize].head;
            while p != NONE {
                walked += 1;
                if walked > points.len() {
                    return Err(degenerate(NUMERICALLY_DEGENERATE));
                }
                let following = fs.next[p as usize];
                if p != eye {
                    let pt = &points[p as usize];
                    for &f in &new_faces {
                        let d = fs.planes[f as usize].distance(pt);
                        if d > eps {
                            fs.assign(f, p, d);
                            break;
                        }
                    }
                }
                p = following;
            }
        }
        fs.free.extend_from_slice(&visible);
        for &f in &new_faces {
            let face = &fs.faces[f as usize];
            if face.head != NONE {
                pending.push((f, face.generation));
            }
        }
    }
    Ok(fs
        .faces
        .iter()
        .filter(|f| f.alive)
        .map(|f| f.v.map(|i| i as usize))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn cube_with_interior_points() {
        let mut pts = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                for k in 0..5 {
                    pts.push(Point3::new(i as f64 * 0.5, j as f64 * 0.5, k as f64 * 0.5));
                }
            }
        }
        assert_relative_eq!(
            convex_hull_volume(&pts).expect("hull"),
            8.0,
            epsilon = 1e-12
        );
    }

    #[test]
    fn sphere_points_approach_sphere_volume() {
        let mut pts = Vec::new();
        let n = 60;
        for i in 0..n {
            let z = -1.0 + (2 * i + 1) as f64 / n as f64;
            for j in 0..2 * n {
                let phi = std::f64::consts::PI * j as f64 / n as f64 + 0.37 * i as f64;
                let r = (1.0 - z * z).sqrt();
                pts.push(Point3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        let v = convex_hull_volume(&pts).expect("hull");
        assert!(
            v < 4.0 / 3.0 * std::f64::consts::PI && v > 0.97 * 4.0 / 3.0 * std::f64::consts::PI,
            "{v}"
        );
    }

    #[test]
    fn degenerate_inputs_are_errors() {
        assert!(convex_hull_volume(&[Point3::origin(); 3]).is_err());
        let flat: Vec<_> = (0..20)
            .map(|i| Point3::new(i as f64, (i * i) as f64, 0.0))
            .collect();
        assert!(convex_hull_volume(&flat).is_err());
        let mut nan = vec![Point3::new(0.0, 0.0, 0.0); 4];
        nan[1].x = f64::NAN;
        assert!(convex_hull_volume(&nan).is_err());
        let same = vec![Point3::new(1.0, 1.0, 1.0); 10];
        assert!(convex_hull_volume(&same).is_err());
    }
}
#[cfg(test)]
mod manifold_tests {
    use super::*;

    /// A symmetric, non-convex point set with many coplanar ties (the
    /// marching-cubes vertices of a dumbbell): the hull is a closed 2-manifold
    /// (every directed edge has exactly one twin) with the expected volume.
    #[test]
    fn dumbbell_hull_is_closed_and_close_to_exact() {
        let spec = levelset::GridSpec::cube(45, -2.2, 2.2).expect("spec");
        let g = levelset::Grid::from_fn(spec, |p| {
            let a = (p - Point3::new(-0.9, 0.0, 0.0)).norm() - 1.0;
            let b = (p - Point3::new(0.9, 0.0, 0.0)).norm() - 1.0;
            a.min(b)
        })
        .expect("grid");
        let m = g.marching_cubes();
        let f = convex_hull(m.vertices()).expect("hull");
        let mut edges = std::collections::BTreeMap::new();
        for t in &f {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(
            edges
                .iter()
                .all(|(e, c)| *c == 1 && edges.contains_key(&(e.1, e.0)))
        );
        // exact hull: cylinder of length 1.8 plus a unit sphere
        let exact = std::f64::consts::PI * 1.8 + 4.0 / 3.0 * std::f64::consts::PI;
        let v = convex_hull_volume(m.vertices()).expect("volume");
        assert!((v - exact).abs() < 0.01 * exact, "{v} vs {exact}");
    }
}
