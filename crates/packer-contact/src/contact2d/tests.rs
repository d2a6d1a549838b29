//! Oracles (analytic tangent configurations) and property tests of the 2D wrappers.

use super::*;
use approx::assert_relative_eq;
use proptest::prelude::*;

#[test]
fn equal_circles_oracle() {
    // Unit circles at (±1, 0), mobile radius 1: centres at (0, ±√3).
    let s = circle_two_circles(Point2::new(-1.0, 0.0), 1.0, Point2::new(1.0, 0.0), 1.0, 1.0);
    assert_eq!(s.len(), 2);
    let mut ys: Vec<f64> = s.iter().map(|p| p.y).collect();
    ys.sort_by(f64::total_cmp);
    assert_relative_eq!(ys[0], -3f64.sqrt(), epsilon = 1e-15);
    assert_relative_eq!(ys[1], 3f64.sqrt(), epsilon = 1e-15);
    for p in s.iter() {
        assert_relative_eq!(p.x, 0.0, epsilon = 1e-15);
    }
}

#[test]
fn tangency_gives_one_solution_and_apart_gives_none() {
    // Wrappers of radius 2 at distance 4: touching, one solution.
    let s = circle_two_circles(Point2::new(0.0, 0.0), 1.0, Point2::new(4.0, 0.0), 1.0, 1.0);
    assert_eq!(s.len(), 1);
    assert_relative_eq!(
        s.iter().next().unwrap_or(Point2::origin()).x,
        2.0,
        epsilon = 1e-15
    );
    let s = circle_two_circles(Point2::new(0.0, 0.0), 1.0, Point2::new(4.5, 0.0), 1.0, 1.0);
    assert!(s.is_empty());
}

#[test]
fn degenerate_inputs_give_no_solution() {
    let c = Point2::new(1.0, 2.0);
    assert!(
        circle_two_circles(c, 1.0, c, 1.0, 1.0).is_empty(),
        "coincident"
    );
    assert!(
        circle_two_circles(c, 3.0, c + Vector2::new(0.1, 0.0), 0.5, 0.1).is_empty(),
        "nested"
    );
    assert!(
        circle_two_circles(c, -1.0, Point2::origin(), 1.0, 1.0).is_empty(),
        "negative radius"
    );
    assert!(
        circle_two_circles(c, 1.0, Point2::origin(), 1.0, f64::NAN).is_empty(),
        "NaN radius"
    );
    let n = Unit::new_normalize(Vector2::new(0.0, 1.0));
    let par = intersect(
        &Wrapper2::Line {
            normal: n,
            offset: 1.0,
        },
        &Wrapper2::Line {
            normal: n,
            offset: 2.0,
        },
    );
    assert!(par.is_empty(), "parallel walls");
}

#[test]
fn circle_and_floor_oracle() {
    // Circle r1 = 1 at (0, 1) on the floor y = 0; mobile r = 1 on the floor:
    // centres at (±2, 1).
    let s = circle_circle_line(
        Point2::new(0.0, 1.0),
        1.0,
        Point2::origin(),
        Unit::new_normalize(Vector2::new(0.0, 1.0)),
        1.0,
    );
    let mut xs: Vec<f64> = s.iter().map(|p| p.x).collect();
    xs.sort_by(f64::total_cmp);
    assert_eq!(xs.len(), 2);
    assert_relative_eq!(xs[0], -2.0, epsilon = 1e-15);
    assert_relative_eq!(xs[1], 2.0, epsilon = 1e-15);
}

#[test]
fn circle_and_segment_wall_touch_both() {
    let a = Point2::new(-1.0, 0.0);
    let b = Point2::new(1.0, 0.0);
    let c1 = Point2::new(1.5, 1.0);
    let pts = circle_circle_segment(c1, 0.8, a, b, 0.5);
    assert!(!pts.is_empty());
    for p in pts {
        assert_relative_eq!((p - c1).norm(), 1.3, max_relative = 1e-12);
        let t = ((p - a).dot(&(b - a)) / 4.0).clamp(0.0, 1.0);
        assert_relative_eq!((p - (a + (b - a) * t)).norm(), 0.5, max_relative = 1e-12);
    }
}

#[test]
fn clusters_of_two_disks_touch_without_overlap() {
    let f1 = [(Point2::new(0.0, 0.0), 1.0), (Point2::new(1.0, 0.0), 1.0)];
    let f2 = [(Point2::new(4.0, 0.0), 1.0), (Point2::new(5.0, 0.0), 1.0)];
    let m = [
        (Vector2::new(-0.5, 0.0), 0.8),
        (Vector2::new(0.5, 0.0), 0.8),
    ];
    let pts = cluster_two_clusters(&f1, &f2, &m, 1e-12);
    assert!(!pts.is_empty());
    for p in pts {
        assert_relative_eq!(cluster_gap(&f1, &m, p), 0.0, epsilon = 1e-12);
        assert_relative_eq!(cluster_gap(&f2, &m, p), 0.0, epsilon = 1e-12);
    }
}

#[test]
fn circle_and_square_oracle() {
    // Unit square [0,1]², circle r1 = 0.5 at (2.4, 0.5), mobile r = 0.5
    // touching the right edge: x = 1.5, |(1.5, y) − (2.4, 0.5)| = 1.
    let sq = convex_polygon(&[
        Point2::new(0.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 1.0),
        Point2::new(0.0, 1.0),
    ])
    .unwrap_or_default();
    let c1 = Point2::new(2.4, 0.5);
    let pts = circle_circle_polygon(c1, 0.5, &sq, 0.5);
    assert!(!pts.is_empty());
    for p in &pts {
        assert_relative_eq!((p - c1).norm(), 1.0, max_relative = 1e-12);
        assert_relative_eq!(polygon_signed_distance(&sq, *p), 0.5, max_relative = 1e-12);
    }
    let y = (1.0f64 - 0.81).sqrt();
    assert!(
        pts.iter()
            .any(|p| (p.x - 1.5).abs() < 1e-12 && (p.y - 0.5 - y).abs() < 1e-12)
    );
}

#[test]
fn bad_polygons_are_errors() {
    let p = |v: &[(f64, f64)]| {
        v.iter()
            .map(|&(x, y)| Point2::new(x, y))
            .collect::<Vec<_>>()
    };
    assert!(matches!(
        convex_polygon(&p(&[(0.0, 0.0), (1.0, 0.0)])),
        Err(Error::PolygonTooFewVertices { got: 2 })
    ));
    assert!(matches!(
        convex_polygon(&p(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (0.0, 1.0)])),
        Err(Error::RepeatedVertex { .. })
    ));
    assert!(matches!(
        convex_polygon(&p(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (1.0, 0.3),
            (2.0, 2.0),
            (0.0, 2.0)
        ])),
        Err(Error::NotConvex { .. })
    ));
    assert!(matches!(
        convex_polygon(&p(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)])),
        Err(Error::DegeneratePolygon)
    ));
    // Clockwise input is accepted and returned counter-clockwise.
    let cw = convex_polygon(&p(&[(0.0, 0.0), (0.0, 1.0), (1.0, 0.0)])).unwrap_or_default();
    assert_eq!(cw.len(), 3);
    assert!(polygon_signed_distance(&cw, Point2::new(0.2, 0.2)) < 0.0);
}

proptest! {
    /// Every returned centre touches both circles to 1e-12 relative and
    /// overlaps neither; nothing is NaN, including near-degenerate inputs.
    #[test]
    fn two_circle_solutions_touch(
        x1 in -10.0..10.0f64, y1 in -10.0..10.0f64, r1 in 0.01..5.0f64,
        dx in -10.0..10.0f64, dy in -10.0..10.0f64, r2 in 0.01..5.0f64,
        r in 0.01..5.0f64, snap in 0usize..4,
    ) {
        let c1 = Point2::new(x1, y1);
        // Degenerate cases: coincident centres, exact tangency, collinear.
        let c2 = match snap {
            0 => c1,
            1 => c1 + Vector2::new(r1 + r2 + 2.0 * r, 0.0),
            _ => c1 + Vector2::new(dx, dy),
        };
        let s = circle_two_circles(c1, r1, c2, r2, r);
        for p in s.iter() {
            prop_assert!(p.x.is_finite() && p.y.is_finite());
            let g1 = (p - c1).norm() - r1 - r;
            let g2 = (p - c2).norm() - r2 - r;
            prop_assert!(g1.abs() <= 1e-12 * (r1 + r), "g1 {g1}");
            prop_assert!(g2.abs() <= 1e-12 * (r2 + r), "g2 {g2}");
        }
        if snap == 1 { prop_assert_eq!(s.len(), 1); }
        if snap == 0 { prop_assert!(s.is_empty()); }
    }

    /// Circle + wall line: touches both.
    #[test]
    fn circle_line_solutions_touch(
        x1 in -10.0..10.0f64, y1 in 0.0..10.0f64, r1 in 0.01..5.0f64,
        ang in 0.0..6.3f64, r in 0.01..5.0f64,
    ) {
        let c1 = Point2::new(x1, y1);
        let n = Unit::new_normalize(Vector2::new(ang.cos(), ang.sin()));
        for p in circle_circle_line(c1, r1, Point2::origin(), n, r).iter() {
            prop_assert!(((p - c1).norm() - r1 - r).abs() <= 1e-12 * (r1 + r));
            prop_assert!((n.dot(&p.coords) - r).abs() <= 1e-12 * (r1 + r + p.coords.norm()));
        }
    }

    /// Circle + regular polygon: every centre touches both, overlaps none.
    #[test]
    fn circle_polygon_solutions_touch(
        sides in 3usize..9, rot in 0.0..6.3f64, cx in -4.0..4.0f64, cy in -4.0..4.0f64,
        r1 in 0.1..2.0f64, r in 0.1..2.0f64,
    ) {
        let poly: Vec<Point2<f64>> = (0..sides)
            .map(|i| {
                let t = rot + std::f64::consts::TAU * i as f64 / sides as f64;
                Point2::new(t.cos(), t.sin())
            })
            .collect();
        let c1 = Point2::new(cx, cy);
        prop_assume!(polygon_signed_distance(&poly, c1) > r1);
        for p in circle_circle_polygon(c1, r1, &poly, r) {
            prop_assert!(((p - c1).norm() - r1 - r).abs() <= 1e-12 * (r1 + r));
            prop_assert!((polygon_signed_distance(&poly, p) - r).abs() <= 1e-12 * (1.0 + r));
        }
    }
}
