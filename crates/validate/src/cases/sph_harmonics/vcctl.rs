//! NIST/VCCTL Ottawa-sand grains against NIST's geom table at `Nnn`
//! (complete, first-100 and random sets), and Gauss–Bonnet on grain 20001.

use std::f64::consts::PI;

use sph_harmonics::curvature::gauss_bonnet;
use sph_harmonics::integrals::{default_gauss_nodes, gauss_integrals};
use sph_harmonics::vcctl::read_anm;

use super::err;
use crate::fixtures;
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

/// The group's cases, in registration order.
pub(super) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "sph-harmonics/vcctl-ottawa-full",
            description: "10 complete Ottawa grains at Nnn: volume ±0.05 %, area and normalised area ±0.3 % vs NIST geom table",
            fast: true,
            heavy: false,
            run: vcctl_full,
        },
        Case {
            name: "sph-harmonics/vcctl-ottawa-100",
            description: "100 Ottawa grains (files hold n ≤ 17) at min(Nnn, 17): Nnn ≤ 17 volume ±0.05 %, area ±0.3 %; Nnn > 17 (truncated) volume ±0.3 % and area not above NIST's",
            fast: false,
            heavy: false,
            run: vcctl_100,
        },
        Case {
            name: "sph-harmonics/vcctl-ottawa-random",
            description: "71 randomly drawn Ottawa grains (files hold n ≤ 17) at min(Nnn, 17) vs NIST's rows for them: the same checks as vcctl-ottawa-100",
            fast: false,
            heavy: false,
            run: vcctl_random,
        },
        Case {
            name: "sph-harmonics/gauss-bonnet-20001",
            description: "∫K dA / 4π for Ottawa grain 20001 at Nnn = 16 by 1024-node quadrature: ±1e-6",
            fast: true,
            heavy: false,
            run: gauss_bonnet_case,
        },
    ]
}

const R_VCCTL_OTTAWA_FULL: &str = "NIST's geom row for this grain is reproduced to 1e-5 at degree 30, not at its Nnn = 28 (20037 area −0.79 %, 20185 area −0.297 % and normalised area −0.32 % at Nnn): the row was evidently computed with all 30 degrees; see tests/it/main.rs";

/// The group's expected failures, in the order of the ratchet list.
pub(super) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
    ExpectedFailure {
        case: "sph-harmonics/vcctl-ottawa-full",
        metric: "20037/area",
        reason: R_VCCTL_OTTAWA_FULL,
    },
    ExpectedFailure {
        case: "sph-harmonics/vcctl-ottawa-full",
        metric: "20037/normalised_area",
        reason: R_VCCTL_OTTAWA_FULL,
    },
    ExpectedFailure {
        case: "sph-harmonics/vcctl-ottawa-full",
        metric: "20185/normalised_area",
        reason: R_VCCTL_OTTAWA_FULL,
    },
];

/// NIST geom table: (volume ×1e6, area ×1e4, normalised area, Nnn) by file
/// name, from whichever of the embedded Ottawa tables lists the grain.
fn geom(name: &str) -> Result<(f64, f64, f64, usize), Error> {
    let r = crate::grains::geom_row(name)?
        .ok_or_else(|| Error::computation(format!("{name} not in any geom table")))?;
    Ok((r.volume * 1e6, r.area * 1e4, r.normalised_area, r.nnn))
}

fn grain_checks(folder: &str) -> Result<Vec<Check>, Error> {
    let mut checks = Vec::new();
    for (path, text) in fixtures::grains_in(folder, ".dat") {
        let name = path.rsplit('/').next().unwrap_or(path);
        let id = name
            .trim_start_matches("Ottawa-sand-anm-")
            .trim_end_matches(".dat");
        let (v_ref, a_ref, na_ref, nnn) = geom(name)?;
        let coeffs = read_anm(text.as_bytes()).map_err(err)?;
        let (model, used) = coeffs.to_model(nnn).map_err(err)?;
        let i = gauss_integrals(&model, default_gauss_nodes(used)).map_err(err)?;
        if used == nnn {
            checks.push(Check::new(
                format!("{id}/volume"),
                v_ref,
                i.volume,
                Tolerance::Relative(5e-4),
            ));
            checks.push(Check::new(
                format!("{id}/area"),
                a_ref,
                i.area,
                Tolerance::Relative(3e-3),
            ));
            checks.push(Check::new(
                format!("{id}/normalised_area"),
                na_ref,
                i.normalised_area(),
                Tolerance::Relative(3e-3),
            ));
        } else {
            // File truncated below Nnn: report the deviation (volume within 0.3 %, area lower).
            checks.push(Check::new(
                format!("{id}/volume_truncated_n{used}_of_{nnn}"),
                v_ref,
                i.volume,
                Tolerance::Relative(3e-3),
            ));
            checks.push(Check::new(
                format!("{id}/area_truncated_n{used}_of_{nnn}"),
                a_ref,
                i.area,
                Tolerance::AtMost(0.0),
            ));
        }
    }
    Ok(checks)
}

fn vcctl_full() -> Result<Vec<Check>, Error> {
    grain_checks("vcctl/ottawa-full")
}

fn vcctl_100() -> Result<Vec<Check>, Error> {
    grain_checks("vcctl/ottawa")
}

fn vcctl_random() -> Result<Vec<Check>, Error> {
    grain_checks("vcctl/ottawa-random")
}

fn gauss_bonnet_case() -> Result<Vec<Check>, Error> {
    let name = "Ottawa-sand-anm-20001.dat";
    let text = fixtures::grain(&format!("vcctl/ottawa-full/{name}"))?;
    let (_, _, _, nnn) = geom(name)?;
    let (model, _) = read_anm(text.as_bytes())
        .map_err(err)?
        .to_model(nnn)
        .map_err(err)?;
    let (k, _) = gauss_bonnet(&model, 1024).map_err(err)?;
    Ok(vec![Check::new(
        "integral_K_dA_over_4pi",
        1.0,
        k / (4.0 * PI),
        Tolerance::Within(1e-6 / (4.0 * PI)),
    )])
}
