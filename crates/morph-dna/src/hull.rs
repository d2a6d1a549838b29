//! 3D convex hull (Quickhull with conflict lists, Barber, Dobkin & Huhdanpaa
//! 1996, doi:10.1145/235815.235821), used for the convexity descriptor.

use nalgebra::{Point3, Vector3};

use crate::error::{Error, Result};

struct Face {
    v: [usize; 3],
    /// `nb[k]`: the face across edge `(v[k], v[k+1])`.
    nb: [usize; 3],
    normal: Vector3<f64>,
    offset: f64,
    outside: Vec<usize>,
    alive: bool,
}

impl Face {
    fn new(points: &[Point3<f64>], v: [usize; 3]) -> Self {
        let (a, b, c) = (points[v[0]], points[v[1]], points[v[2]]);
        let n = (b - a).cross(&(c - a));
        let len = n.norm();
        let normal = if len > 0.0 { n / len } else { Vector3::zeros() };
        Self {
            v,
            nb: [usize::MAX; 3],
            normal,
            offset: normal.dot(&a.coords),
            outside: Vec::new(),
            alive: true,
        }
    }

    fn distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&p.coords) - self.offset
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

/// Triangles of the convex hull of `points`, outward oriented.
///
/// # Errors
/// As [`convex_hull_volume`].
pub fn convex_hull(points: &[Point3<f64>]) -> Result<Vec<[usize; 3]>> {
    let degenerate = |reason: &'static str| Error::InvalidParameter {
        name: "hull points",
        value: points.len() as f64,
        reason,
    };
    if points.len() < 4 {
        return Err(degenerate("at least 4 points are needed"));
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
    let eps = 1e-10 * scale;
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
    if n.norm() <= eps * scale {
        return Err(degenerate("points are collinear"));
    }
    let n = n.normalize();
    let i3 = ext(&|p| (p - points[i0]).dot(&n).abs());
    let h = (points[i3] - points[i0]).dot(&n);
    if h.abs() <= eps * 1e3 {
        return Err(degenerate("points are coplanar"));
    }
    let mut faces: Vec<Face> = Vec::new();
    let tet = if h > 0.0 {
        [[i0, i2, i1], [i0, i1, i3], [i1, i2, i3], [i2, i0, i3]]
    } else {
        [[i0, i1, i2], [i0, i3, i1], [i1, i3, i2], [i2, i3, i0]]
    };
    for v in tet {
        faces.push(Face::new(points, v));
    }
    // adjacency of the tetrahedron
    for f in 0..4 {
        for k in 0..3 {
            let (a, b) = (faces[f].v[k], faces[f].v[(k + 1) % 3]);
            let twin = (0..4)
                .find(|&g| (0..3).any(|j| faces[g].v[j] == b && faces[g].v[(j + 1) % 3] == a));
            faces[f].nb[k] = twin.ok_or_else(|| degenerate("inconsistent initial tetrahedron"))?;
        }
    }
    let used = [i0, i1, i2, i3];
    for (p, pt) in points.iter().enumerate() {
        if used.contains(&p) {
            continue;
        }
        if let Some(f) = faces.iter_mut().find(|f| f.distance(pt) > eps) {
            f.outside.push(p);
        }
    }
    // visibility memo per iteration: stamp[f] == iteration ⇒ visible[f] valid
    let mut stamp: Vec<usize> = Vec::new();
    let mut seen_visible: Vec<bool> = Vec::new();
    let mut in_region: Vec<bool> = Vec::new();
    // work list of faces that may have outside points (LIFO, deterministic)
    let mut pending: Vec<usize> = (0..faces.len()).collect();
    let mut iteration = 0usize;
    while let Some(fi) = pending.pop() {
        if !faces[fi].alive || faces[fi].outside.is_empty() {
            continue;
        }
        iteration += 1;
        let eye = *faces[fi]
            .outside
            .iter()
            .max_by(|&&a, &&b| {
                faces[fi]
                    .distance(&points[a])
                    .total_cmp(&faces[fi].distance(&points[b]))
            })
            .unwrap_or(&faces[fi].outside[0]);
        let ep = points[eye];
        // visible region: connected faces seen from the eye, walked over the
        // adjacency from the face the eye was chosen from; the horizon is
        // where the walk meets a face that is not visible
        stamp.resize(faces.len(), 0);
        seen_visible.resize(faces.len(), false);
        in_region.resize(faces.len(), false);
        in_region[fi] = true;
        let mut visible = vec![fi];
        // (a, b, face across) for each horizon edge
        let mut horizon: Vec<(usize, usize, usize)> = Vec::new();
        let mut cur = 0;
        while cur < visible.len() {
            let f = visible[cur];
            cur += 1;
            for k in 0..3 {
                let nb = faces[f].nb[k];
                if stamp[nb] != iteration {
                    stamp[nb] = iteration;
                    seen_visible[nb] = in_region[nb] || faces[nb].distance(&ep) > eps;
                }
                if seen_visible[nb] {
                    if !in_region[nb] {
                        in_region[nb] = true;
                        visible.push(nb);
                    }
                } else {
                    horizon.push((faces[f].v[k], faces[f].v[(k + 1) % 3], nb));
                }
            }
        }
        let mut orphans = Vec::new();
        for &i in &visible {
            in_region[i] = false;
            faces[i].alive = false;
            orphans.append(&mut faces[i].outside);
        }
        let first_new = faces.len();
        for &(a, b, across) in &horizon {
            let id = faces.len();
            let mut face = Face::new(points, [a, b, eye]);
            face.nb[0] = across;
            let k = (0..3)
                .find(|&j| faces[across].v[j] == b && faces[across].v[(j + 1) % 3] == a)
                .ok_or_else(|| degenerate("numerically degenerate point set"))?;
            faces[across].nb[k] = id;
            faces.push(face);
        }
        // link the fan of new faces around the eye
        for (i, &(a, b, _)) in horizon.iter().enumerate() {
            let next = horizon.iter().position(|&(s, _, _)| s == b);
            let prev = horizon.iter().position(|&(_, e, _)| e == a);
            let (Some(next), Some(prev)) = (next, prev) else {
                return Err(degenerate("numerically degenerate point set"));
            };
            faces[first_new + i].nb[1] = first_new + next;
            faces[first_new + i].nb[2] = first_new + prev;
        }
        for p in orphans {
            if p == eye {
                continue;
            }
            let pt = &points[p];
            if let Some(f) = faces[first_new..].iter_mut().find(|f| f.distance(pt) > eps) {
                f.outside.push(p);
            }
        }
        pending.extend((first_new..faces.len()).filter(|&i| !faces[i].outside.is_empty()));
    }
    Ok(faces.into_iter().filter(|f| f.alive).map(|f| f.v).collect())
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
