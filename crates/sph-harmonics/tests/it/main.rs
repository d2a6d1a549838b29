//! Integration tests against real NIST/VCCTL grains (fixtures/grains/vcctl, MIT licence).

use sph_harmonics::curvature::gauss_bonnet;
use sph_harmonics::integrals::{default_gauss_nodes, gauss_integrals};
use sph_harmonics::vcctl::read_anm;
use std::f64::consts::PI;

/// The ten complete (n ≤ 30) Ottawa grains.
const FULL: &[(u32, &str)] = &[
    (
        20001,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20001.dat"),
    ),
    (
        20037,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20037.dat"),
    ),
    (
        20066,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20066.dat"),
    ),
    (
        20097,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20097.dat"),
    ),
    (
        20124,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20124.dat"),
    ),
    (
        20145,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20145.dat"),
    ),
    (
        20185,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20185.dat"),
    ),
    (
        20217,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20217.dat"),
    ),
    (
        20260,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20260.dat"),
    ),
    (
        20334,
        include_str!("../../../../fixtures/grains/vcctl/ottawa-full/Ottawa-sand-anm-20334.dat"),
    ),
];

const GEOM: &str = include_str!("../../../../fixtures/grains/vcctl/Ottawa-sand-geom-shipped.txt");

/// (volume ×1e6, area ×1e4, normalised area, Nnn) of a grain from NIST's geom table.
fn geom_row(id: u32) -> (f64, f64, f64, usize) {
    let name = format!("Ottawa-sand-anm-{id}.dat");
    let line = GEOM
        .lines()
        .find(|l| l.split_whitespace().next() == Some(name.as_str()))
        .expect("grain listed in the geom table");
    let f: Vec<&str> = line.split_whitespace().collect();
    let num = |i: usize| f[i].parse::<f64>().expect("number");
    (
        num(7) * 1e6,
        num(8) * 1e4,
        num(9),
        f[12].parse().expect("Nnn"),
    )
}

/// Grains whose geom rows are reproduced at degree 30 (area and volume to 1e-5), not at their
/// `Nnn` = 28, with today's area deviation at `Nnn`: NIST evidently computed these rows with all
/// 30 degrees. Checked separately below; every other complete grain is checked at `Nnn`.
const ROWS_AT_DEGREE_30: &[(u32, f64)] = &[(20037, -0.0079), (20185, -0.00297), (20217, -0.00267)];

#[test]
fn full_ottawa_grains_match_nist_geometry_at_nnn() {
    for &(id, text) in FULL {
        if ROWS_AT_DEGREE_30.iter().any(|(g, _)| *g == id) {
            continue;
        }
        let coeffs = read_anm(text.as_bytes()).expect("parse");
        assert_eq!(coeffs.degree, 30);
        assert!(coeffs.max_asymmetry() < 1e-8, "grain {id} asymmetric");
        let (v_ref, a_ref, na_ref, nnn) = geom_row(id);
        let (model, used) = coeffs.to_model(nnn).expect("model");
        assert_eq!(used, nnn);
        let i = gauss_integrals(&model, default_gauss_nodes(nnn)).expect("integrals");
        let dv = (i.volume / v_ref - 1.0).abs();
        let da = (i.area / a_ref - 1.0).abs();
        let dna = (i.normalised_area() / na_ref - 1.0).abs();
        assert!(
            dv < 5e-4,
            "grain {id} Nnn {nnn}: volume {} vs {v_ref} ({dv:e})",
            i.volume
        );
        assert!(
            da < 3e-3,
            "grain {id} Nnn {nnn}: area {} vs {a_ref} ({da:e})",
            i.area
        );
        assert!(
            dna < 3e-3,
            "grain {id} Nnn {nnn}: normalised area {} vs {na_ref} ({dna:e})",
            i.normalised_area()
        );
    }
}

#[test]
fn rows_computed_at_degree_30_are_reproduced_there() {
    for &(id, deviation_at_nnn) in ROWS_AT_DEGREE_30 {
        let text = FULL.iter().find(|(g, _)| *g == id).expect("grain").1;
        let coeffs = read_anm(text.as_bytes()).expect("parse");
        let (v_ref, a_ref, _, nnn) = geom_row(id);
        assert_eq!(nnn, 28);
        let (m30, _) = coeffs.to_model(30).expect("model");
        let i30 = gauss_integrals(&m30, default_gauss_nodes(30)).expect("integrals");
        assert!((i30.area / a_ref - 1.0).abs() < 1e-4, "grain {id}");
        assert!((i30.volume / v_ref - 1.0).abs() < 1e-4, "grain {id}");
        let (m28, _) = coeffs.to_model(nnn).expect("model");
        let i28 = gauss_integrals(&m28, default_gauss_nodes(nnn)).expect("integrals");
        // Today's deviation at Nnn, kept so a change of behaviour is noticed.
        let da = i28.area / a_ref - 1.0;
        assert!(
            (da - deviation_at_nnn).abs() < 2e-4,
            "grain {id}: area deviation at Nnn = {da}"
        );
        assert!((i28.volume / v_ref - 1.0).abs() < 5e-4, "grain {id}");
    }
}

#[test]
fn gauss_bonnet_on_real_grain_20001() {
    let coeffs = read_anm(FULL[0].1.as_bytes()).expect("parse");
    let (_, _, _, nnn) = geom_row(20001);
    let (model, _) = coeffs.to_model(nnn).expect("model");
    let (total, _) = gauss_bonnet(&model, 1024).expect("gauss-bonnet");
    let err = (total - 4.0 * PI).abs();
    assert!(err < 1e-6, "integral of K dA = {total}, |error| = {err:e}");
}
