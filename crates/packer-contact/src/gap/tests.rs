//! Gap oracles and the convergence of Newton and Nelder–Mead from 100 random starts.

use super::*;
use crate::shapes::Grain;
use approx::assert_relative_eq;
use rand::{Rng, SeedableRng};

fn v2(x: f64, y: f64) -> SVector<f64, 2> {
    SVector::<f64, 2>::new(x, y)
}

#[test]
fn segment_distance_oracles() {
    // Crossing segments: distance 0; parallel offset: 1; point-segment.
    let (p, q) =
        closest_segment_points(&v2(-1.0, 0.0), &v2(1.0, 0.0), &v2(0.0, -1.0), &v2(0.0, 1.0));
    assert_relative_eq!((p - q).norm(), 0.0, epsilon = 1e-15);
    let (p, q) = closest_segment_points(&v2(0.0, 0.0), &v2(2.0, 0.0), &v2(1.0, 1.0), &v2(3.0, 1.0));
    assert_relative_eq!((p - q).norm(), 1.0, epsilon = 1e-15);
    let (p, q) = closest_segment_points(&v2(3.0, 4.0), &v2(3.0, 4.0), &v2(0.0, 0.0), &v2(0.0, 0.0));
    assert_relative_eq!((p - q).norm(), 5.0, epsilon = 1e-15);
}

#[test]
fn sphere_gap_is_seed_eq5() {
    let a = Grain::<3>::ball(1.0).expect("valid grain");
    let b = Grain::<3>::ball(0.5).expect("valid grain");
    let o = Obstacle::Grain {
        centre: SVector::<f64, 3>::zeros(),
        grain: &a,
    };
    let (g, grad) = gap(&o, &b, &SVector::<f64, 3>::new(0.0, 3.0, 4.0)).expect("ball gap");
    assert_relative_eq!(g, 3.5, epsilon = 1e-15);
    assert_relative_eq!(grad, SVector::<f64, 3>::new(0.0, 0.6, 0.8), epsilon = 1e-15);
}

/// Two fixed capsules, one mobile capsule (2D): the same contact is found
/// from 100 random starts on one side, by Newton and by Nelder–Mead.
#[test]
fn contact_found_from_100_random_starts() {
    let ax = |t: f64| v2(t.cos(), t.sin());
    let f1 = Grain::<2>::capsule(1.5, 0.5, ax(0.3)).expect("valid grain");
    let f2 = Grain::<2>::capsule(1.2, 0.5, ax(1.9)).expect("valid grain");
    let m = Grain::<2>::capsule(1.0, 0.5, ax(-0.7)).expect("valid grain");
    let obs = [
        Obstacle::Grain {
            centre: v2(0.0, 0.0),
            grain: &f1,
        },
        Obstacle::Grain {
            centre: v2(3.0, 0.0),
            grain: &f2,
        },
    ];
    let reference = newton(&obs, &m, v2(1.5, 2.0), 1e-13).expect("converges");
    for o in &obs {
        assert!(gap(o, &m, &reference).is_some_and(|(g, _)| g.abs() <= 1e-13));
    }
    let seed = 7;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let side = Some((v2(0.0, 1.0), v2(1.5, 0.0)));
    for _ in 0..100 {
        let start = reference + v2(rng.random_range(-0.4..0.4), rng.random_range(-0.4..0.4));
        let x = newton(&obs, &m, start, 1e-13)
            .unwrap_or_else(|| panic!("Newton failed from {start:?}"));
        assert_relative_eq!(x, reference, epsilon = 1e-10);
        let y = nelder_mead(&obs, &m, start, side, 1e-10)
            .unwrap_or_else(|| panic!("NM failed from {start:?}"));
        assert_relative_eq!(y, reference, epsilon = 1e-6);
    }
}

/// A convex polygon against a disk via parry: Newton lands on contact.
#[test]
fn polygon_contacts_converge() {
    let sq = Grain::<2>::regular_polygon(1.0, 4, 0.0).expect("valid grain");
    let d = Grain::<2>::ball(0.5).expect("valid grain");
    let obs = [
        Obstacle::Grain {
            centre: v2(0.0, 0.0),
            grain: &sq,
        },
        Obstacle::Wall {
            axis: 1,
            at: -1.0,
            upper: false,
        },
    ];
    let x = newton(&obs, &d, v2(1.2, -0.3), 1e-13).expect("converges");
    for o in &obs {
        assert!(
            gap(o, &d, &x).is_some_and(|(g, _)| g.abs() <= 1e-12),
            "{x:?}"
        );
    }
}
