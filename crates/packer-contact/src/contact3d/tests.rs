//! Oracles (tetrahedron, corner, floor) and property tests of the 3D wrappers.

use super::*;
use approx::assert_relative_eq;
use proptest::prelude::*;

#[test]
fn tetrahedron_oracle() {
    // Three unit spheres at the vertices of an equilateral triangle of
    // side 2 in z = 0; a unit mobile sits at height 2·√(2/3) above/below
    // the centroid (regular tetrahedron of side 2).
    let s3 = 3f64.sqrt();
    let fixed = [
        (Point3::new(0.0, 0.0, 0.0), 1.0),
        (Point3::new(2.0, 0.0, 0.0), 1.0),
        (Point3::new(1.0, s3, 0.0), 1.0),
    ];
    let s = sphere_three_spheres(&fixed, 1.0);
    assert_eq!(s.len(), 2);
    for p in s.iter() {
        assert_relative_eq!(p.x, 1.0, epsilon = 1e-14);
        assert_relative_eq!(p.y, s3 / 3.0, epsilon = 1e-14);
        assert_relative_eq!(p.z.abs(), 2.0 * (2.0f64 / 3.0).sqrt(), epsilon = 1e-14);
    }
}

#[test]
fn degenerate_triples_give_no_solution() {
    let col = [
        (Point3::new(0.0, 0.0, 0.0), 1.0),
        (Point3::new(1.0, 0.0, 0.0), 1.0),
        (Point3::new(2.0, 0.0, 0.0), 1.0),
    ];
    assert!(sphere_three_spheres(&col, 1.0).is_empty(), "collinear");
    let coin = [
        (Point3::new(0.0, 0.0, 0.0), 1.0),
        (Point3::new(0.0, 0.0, 0.0), 1.0),
        (Point3::new(2.0, 0.0, 0.0), 1.0),
    ];
    assert!(sphere_three_spheres(&coin, 1.0).is_empty(), "coincident");
    let far = [
        (Point3::new(0.0, 0.0, 0.0), 1.0),
        (Point3::new(10.0, 0.0, 0.0), 1.0),
        (Point3::new(0.0, 10.0, 0.0), 1.0),
    ];
    assert!(sphere_three_spheres(&far, 1.0).is_empty(), "apart");
    assert!(sphere_three_spheres(&far, f64::NAN).is_empty(), "NaN");
    let z = Vector3::z_axis();
    let planes = [(Point3::origin(), z), (Point3::new(0.0, 0.0, 1.0), z)];
    assert!(
        sphere_spheres_planes(&[(Point3::new(0.0, 0.0, 3.0), 1.0)], &planes, 1.0).is_empty(),
        "parallel planes"
    );
}

#[test]
fn corner_and_floor_oracles() {
    // Three walls x = y = z = 0: one centre at (r, r, r).
    let planes = [
        (Point3::origin(), Vector3::x_axis()),
        (Point3::origin(), Vector3::y_axis()),
        (Point3::origin(), Vector3::z_axis()),
    ];
    let s = sphere_spheres_planes(&[], &planes, 0.7);
    assert_eq!(s.len(), 1);
    for p in s.iter() {
        assert_relative_eq!(p, &Point3::new(0.7, 0.7, 0.7), epsilon = 1e-15);
    }
    // Two unit spheres on the floor at (±1, 0, 1), unit mobile on the floor:
    // centres at (0, ±√3, 1).
    let s = sphere_spheres_planes(
        &[
            (Point3::new(-1.0, 0.0, 1.0), 1.0),
            (Point3::new(1.0, 0.0, 1.0), 1.0),
        ],
        &[(Point3::origin(), Vector3::z_axis())],
        1.0,
    );
    assert_eq!(s.len(), 2);
    for p in s.iter() {
        assert_relative_eq!(p.z, 1.0, epsilon = 1e-15);
        assert_relative_eq!(p.y.abs(), 3f64.sqrt(), epsilon = 1e-15);
    }
}

#[test]
fn sphere_clusters_touch_all_three() {
    let pair = |x: f64, y: f64| {
        [
            (Point3::new(x, y, 0.0), 1.0),
            (Point3::new(x + 1.0, y, 0.0), 1.0),
        ]
    };
    let (a, b, c) = (pair(0.0, 0.0), pair(3.0, 0.0), pair(1.5, 2.8));
    let m = [
        (Vector3::new(0.0, 0.0, -0.4), 0.9),
        (Vector3::new(0.0, 0.0, 0.4), 0.9),
    ];
    let pts = cluster_three_clusters([&a, &b, &c], &m, 1e-12);
    assert!(!pts.is_empty());
    for p in pts {
        for f in [&a[..], &b[..], &c[..]] {
            assert_relative_eq!(cluster_gap(f, &m, p), 0.0, epsilon = 1e-12);
        }
    }
}

proptest! {
    /// Every returned centre touches the three spheres to 1e-12 relative;
    /// near-degenerate inputs (nearly collinear, tangent) give no NaN.
    #[test]
    fn three_sphere_solutions_touch(
        c in prop::array::uniform9(-5.0..5.0f64),
        r in prop::array::uniform4(0.05..3.0f64),
        squash in prop::bool::ANY,
    ) {
        let mut p3 = Point3::new(c[6], c[7], c[8]);
        if squash {
            // Nearly collinear: third centre close to the line of the first two.
            p3 = Point3::new(c[0], c[1], c[2]) + (Point3::new(c[3], c[4], c[5]) - Point3::new(c[0], c[1], c[2])) * 0.5
                + Vector3::new(1e-9, 0.0, 0.0);
        }
        let fixed = [
            (Point3::new(c[0], c[1], c[2]), r[0]),
            (Point3::new(c[3], c[4], c[5]), r[1]),
            (p3, r[2]),
        ];
        for x in sphere_three_spheres(&fixed, r[3]).iter() {
            prop_assert!(x.iter().all(|v| v.is_finite()));
            for (cf, rf) in fixed {
                let g = (x - cf).norm() - rf - r[3];
                prop_assert!(g.abs() <= 1e-12 * (rf + r[3]) * 10.0_f64.max((x - cf).norm() / (rf + r[3])), "gap {g}");
            }
        }
    }

    /// Sphere + spheres + floor: touches all.
    #[test]
    fn sphere_floor_solutions_touch(
        c in prop::array::uniform6(0.0..5.0f64),
        r in prop::array::uniform3(0.05..3.0f64),
    ) {
        let s = [(Point3::new(c[0], c[1], c[2]), r[0]), (Point3::new(c[3], c[4], c[5]), r[1])];
        let floor = [(Point3::origin(), Vector3::z_axis())];
        for x in sphere_spheres_planes(&s, &floor, r[2]).iter() {
            prop_assert!((x.z - r[2]).abs() <= 1e-12 * (r[2] + x.coords.norm()));
            for (cf, rf) in s {
                prop_assert!(((x - cf).norm() - rf - r[2]).abs() <= 1e-12 * (rf + r[2] + (cf.coords.norm())));
            }
        }
    }
}
