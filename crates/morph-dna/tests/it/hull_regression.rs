//! Regression: the marching-cubes vertices of one smoothed voxel grain (label 616 of the
//! 512³ synthetic scan, extracted with a looser minimal-bending tolerance than the
//! default) on which Quickhull's horizon at the base tolerance came out pinched; before
//! the horizon checks a conflict list became a cycle and `convex_hull_volume` never
//! returned. Now the base tolerance is refused as numerically degenerate and the hull is
//! rebuilt with 1e-8 of the extent.

use morph_dna::{convex_hull, convex_hull_volume};
use nalgebra::Point3;

fn points() -> Vec<Point3<f64>> {
    let bytes = include_bytes!("../data/hull_horizon_cycle.f64le");
    let v: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect();
    v.chunks_exact(3)
        .map(|c| Point3::new(c[0], c[1], c[2]))
        .collect()
}

#[test]
fn pinched_horizon_is_retried_not_looped() {
    let pts = points();
    assert_eq!(pts.len(), 7490);
    let faces = convex_hull(&pts).expect("hull");
    let vol = convex_hull_volume(&pts).expect("volume");
    // every point inside or on the hull (within the retry tolerance, 1e-6 of the extent)
    let (mut lo, mut hi) = (pts[0].coords, pts[0].coords);
    for p in &pts {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let tol = 1e-6 * (hi - lo).norm();
    for f in &faces {
        let (a, b, c) = (pts[f[0]], pts[f[1]], pts[f[2]]);
        let n = (b - a).cross(&(c - a));
        if n.norm() == 0.0 {
            continue;
        }
        let n = n.normalize();
        for p in &pts {
            assert!(n.dot(&(p - a)) <= tol, "point outside a face");
        }
    }
    // a closed triangulation: Euler's formula for a sphere (V − E + F = 2, E = 3F/2)
    let mut used = vec![false; pts.len()];
    for f in &faces {
        for &i in f {
            used[i] = true;
        }
    }
    let v = used.iter().filter(|&&u| u).count();
    assert_eq!(
        v as i64 - faces.len() as i64 / 2,
        2,
        "{} faces",
        faces.len()
    );
    // the grain is about 21 voxels across: its hull is a few thousand cubic voxels
    assert!(vol > 1000.0 && vol.is_finite(), "{vol}");
}
