//! Golden digests, overlap-free packings of every shape (parry checker), bad input, VTU.

use super::wrap::tangent3;
use super::*;
use crate::contact3d::{self, Wrapper3};
use crate::error::Error;
use crate::shapes::{Grain, GrainShape};
use nalgebra::{Point2, Point3, SVector};
use proptest::prelude::*;

/// FNV-1a over the bits of every centre.
fn digest<const D: usize>(p: &PicPacking<D>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for g in &p.grains {
        for v in g.centre.iter() {
            for b in v.to_bits().to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h
}

fn small(shape: GrainShape, side: f64) -> PicParams {
    PicParams {
        side,
        shape,
        ..PicParams::default()
    }
}

/// Golden determinism (2D capsules and 3D spheres, seed 1): guards the
/// packer's arithmetic and candidate order. A deliberate change of the
/// algorithm re-mints it: run this test, copy the printed `(len, digest)`.
#[test]
fn golden_digest_2d_and_3d() {
    let p2 = pack_pic::<2>(&small(GrainShape::Capsule { aspect: 0.5 }, 12.0), 1).expect("pack 2D");
    let p3 = pack_pic::<3>(&small(GrainShape::Ball, 8.0), 1).expect("pack 3D");
    let got = (p2.grains.len(), digest(&p2), p3.grains.len(), digest(&p3));
    println!("golden {got:?}");
    assert_eq!(got, GOLDEN);
}

const GOLDEN: (usize, u64, usize, u64) = (25, 0x47a4bcaaf480a32c, 21, 0x627ba952aafddc06);

#[test]
fn every_shape_packs_without_overlap() {
    let shapes = [
        GrainShape::Ball,
        GrainShape::Capsule { aspect: 0.5 },
        GrainShape::Cluster {
            aspect: 0.5,
            spheres: 4,
        },
        GrainShape::Polygon {
            sides_min: 4,
            sides_max: 7,
        },
        GrainShape::Mix {
            polygon_share: 0.5,
            sides_min: 4,
            sides_max: 6,
        },
    ];
    for shape in shapes {
        for method in [
            ContactMethod::Wrappers,
            ContactMethod::Newton,
            ContactMethod::NelderMead,
            ContactMethod::ApproxWrappers,
        ] {
            let params = PicParams {
                method,
                ..small(shape, 9.0)
            };
            let p = pack_pic::<2>(&params, 3).expect("pack 2D");
            let rep = check_pic(&p, 1e-9).expect("check");
            assert!(
                p.grains.len() > 3,
                "{shape:?} {method:?}: {}",
                p.grains.len()
            );
            assert!(
                rep.min_relative_gap >= -1e-9,
                "{shape:?} {method:?}: {rep:?}"
            );
            assert!(
                rep.min_relative_wall_gap >= -1e-9,
                "{shape:?} {method:?}: {rep:?}"
            );
        }
        let p = pack_pic::<3>(&small(shape, 7.0), 3).expect("pack 3D");
        let rep = check_pic(&p, 1e-9).expect("check");
        assert!(p.grains.len() > 3, "3D {shape:?}: {}", p.grains.len());
        assert!(rep.min_relative_gap >= -1e-9, "3D {shape:?}: {rep:?}");
        assert!(rep.min_relative_wall_gap >= -1e-9, "3D {shape:?}: {rep:?}");
    }
}

/// Approximate wrappers (P5's method) in 3D, spheres and 4-sphere
/// clusters over three seeds: no overlap by the parry checker, a loose but
/// real packing, and the tangent contacts it builds.
#[test]
fn approx_wrappers_pack_clusters_without_overlap_3d() {
    for shape in [
        GrainShape::Ball,
        GrainShape::Cluster {
            aspect: 0.5,
            spheres: 4,
        },
    ] {
        for seed in 1..=3 {
            let params = PicParams {
                method: ContactMethod::ApproxWrappers,
                neighbours: 6,
                ..small(shape, 12.0)
            };
            let p = pack_pic::<3>(&params, seed).expect("pack 3D");
            let rep = check_pic(&p, 1e-9).expect("check");
            assert!(p.grains.len() > 20, "{shape:?} {seed}: {}", p.grains.len());
            assert!(p.fraction() > 0.2, "{shape:?} {seed}: {}", p.fraction());
            assert!(rep.min_relative_gap >= -1e-9, "{shape:?} {seed}: {rep:?}");
            assert!(
                rep.min_relative_wall_gap >= -1e-9,
                "{shape:?} {seed}: {rep:?}"
            );
            assert!(rep.coordination > 2.0, "{shape:?} {seed}: {rep:?}");
        }
    }
}

/// The closed-form three-sphere tangency agrees with `contact3d`.
#[test]
fn tangent3_matches_contact3d() {
    let c = [
        SVector::<f64, 3>::new(0.0, 0.0, 0.0),
        SVector::<f64, 3>::new(2.0, 0.1, 0.0),
        SVector::<f64, 3>::new(0.9, 1.8, 0.2),
    ];
    let rho = [1.7, 1.5, 1.6];
    let mut out = Vec::new();
    tangent3(&c[0], rho[0], &c[1], rho[1], &c[2], rho[2], &mut out);
    assert_eq!(out.len(), 2);
    for x in &out {
        for k in 0..3 {
            assert!(((x - c[k]).norm() - rho[k]).abs() < 1e-12);
        }
    }
    let w = [0, 1, 2].map(|k| Wrapper3::Sphere {
        centre: Point3::from(c[k]),
        radius: rho[k],
    });
    let s = contact3d::intersect(&w);
    assert_eq!(s.iter().count(), 2);
    // Collinear centres: none.
    let col = SVector::<f64, 3>::new(4.0, 0.2, 0.0);
    tangent3(&c[0], 1.0, &c[1], 1.0, &col, 1.0, &mut out);
    assert!(out.is_empty());
}

#[test]
fn bad_input_is_an_error() {
    let bad = |p: PicParams| pack_pic::<2>(&p, 1).is_err() && pack_pic::<3>(&p, 1).is_err();
    assert!(bad(PicParams {
        radius_min: -1.0,
        ..PicParams::default()
    }));
    assert!(bad(PicParams {
        radius_min: 0.0,
        ..PicParams::default()
    }));
    assert!(bad(PicParams {
        radius_max: f64::NAN,
        ..PicParams::default()
    }));
    assert!(bad(PicParams {
        shape: GrainShape::Capsule { aspect: 1.5 },
        ..PicParams::default()
    }));
    assert!(bad(PicParams {
        shape: GrainShape::Capsule { aspect: 0.0 },
        ..PicParams::default()
    }));
    assert!(matches!(
        pack_pic::<2>(
            &PicParams {
                side: 3.0,
                ..PicParams::default()
            },
            1
        ),
        Err(Error::DomainTooSmall { .. })
    ));
    assert!(bad(PicParams {
        shape: GrainShape::Polygon {
            sides_min: 2,
            sides_max: 5
        },
        ..PicParams::default()
    }));
    assert!(Grain::<2>::capsule(-1.0, 0.5, SVector::<f64, 2>::x()).is_err());
    assert!(Grain::<3>::ball(0.0).is_err());
    let sq = [
        Point2::new(0.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(0.0, 1.0),
    ];
    assert!(matches!(
        Grain::<2>::polygon(&sq),
        Err(Error::RepeatedVertex { .. })
    ));
    let cube_with_inner: Vec<Point3<f64>> = (0..8)
        .map(|i| {
            Point3::new(
                f64::from(i & 1),
                f64::from((i >> 1) & 1),
                f64::from((i >> 2) & 1),
            )
        })
        .chain([Point3::new(0.5, 0.5, 0.5)])
        .collect();
    assert!(matches!(
        Grain::<3>::polyhedron(&cube_with_inner),
        Err(Error::NotConvex { .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]
    /// Random domains, size ranges and shapes: never an overlap.
    #[test]
    fn random_packings_never_overlap(
        side in 5.0..9.0f64, rmin in 0.3..0.8f64, spread in 1.0..2.5f64,
        kind in 0usize..5, aspect in 0.2..1.0f64, seed in 0u64..1000, three in prop::bool::ANY,
    ) {
        let shape = match kind {
            0 => GrainShape::Ball,
            1 => GrainShape::Capsule { aspect },
            2 => GrainShape::Cluster { aspect, spheres: 3 },
            3 => GrainShape::Polygon { sides_min: 4, sides_max: 6 },
            _ => GrainShape::Mix { polygon_share: 0.3, sides_min: 4, sides_max: 5 },
        };
        let params = PicParams {
            side,
            radius_min: rmin,
            radius_max: rmin * spread,
            shape,
            max_grains: 150,
            ..PicParams::default()
        };
        let (g, w) = if three {
            let p = pack_pic::<3>(&params, seed).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let r = check_pic(&p, 1e-9).map_err(|e| TestCaseError::fail(e.to_string()))?;
            (r.min_relative_gap, r.min_relative_wall_gap)
        } else {
            let p = pack_pic::<2>(&params, seed).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let r = check_pic(&p, 1e-9).map_err(|e| TestCaseError::fail(e.to_string()))?;
            (r.min_relative_gap, r.min_relative_wall_gap)
        };
        prop_assert!(g >= -1e-9, "gap {g}");
        prop_assert!(w >= -1e-9, "wall {w}");
    }
}

#[test]
fn vtu_for_every_shape() {
    for shape in [
        GrainShape::Ball,
        GrainShape::Capsule { aspect: 0.5 },
        GrainShape::Polygon {
            sides_min: 4,
            sides_max: 5,
        },
    ] {
        let p = pack_pic::<2>(&small(shape, 6.0), 1).expect("pack");
        let mut out = Vec::new();
        write_pic_vtu(&p, &mut out).expect("vtu 2D");
        assert!(String::from_utf8_lossy(&out).contains("</VTKFile>"));
        let p = pack_pic::<3>(&small(shape, 5.0), 1).expect("pack");
        let mut out = Vec::new();
        write_pic_vtu(&p, &mut out).expect("vtu 3D");
        assert!(String::from_utf8_lossy(&out).contains("<Piece NumberOfPoints"));
    }
}
