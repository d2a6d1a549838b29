//! sph-harmonics reproductions (issue 4): Radvilaitė 2016 Tables 3.1–3.4, 3.6, 3.7 at the
//! thesis' degree and sampling; NIST/VCCTL Ottawa grains against NIST's geom table at `Nnn`;
//! Gauss–Bonnet on a real grain; our own convergence table (error vs degree).

use std::f64::consts::PI;

use sph_harmonics::contact::hertz;
use sph_harmonics::curvature::{CurvatureEvaluator, gauss_bonnet};
use sph_harmonics::fit::quadrature_transform;
use sph_harmonics::grid::RingGrid;
use sph_harmonics::integrals::{default_gauss_nodes, gauss_integrals};
use sph_harmonics::sampling::octant_study;
use sph_harmonics::shapes::Shape;
use sph_harmonics::vcctl::read_anm;

use crate::fixtures::{self, Table};
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "sph-harmonics/table3.1-ellipsoid-L1",
            description: "oblate ellipsoid a = 2, c = 1, L = 1, strategies q = 1..4 × k = 1..4 on the octant: S, V, ‖E‖ vs printed (S, V relative 0.5 %, ‖E‖ relative 5 %)",
            fast: true,
            heavy: false,
            run: table_3_1,
        },
        Case {
            name: "sph-harmonics/table3.2-cylinder-L3",
            description: "cylinder a = 2, c = 1, L = 3, q = 1..4 × k = 1..4: S, V, ‖E‖ vs printed",
            fast: true,
            heavy: false,
            run: table_3_2,
        },
        Case {
            name: "sph-harmonics/table3.3-cylinder-L2",
            description: "cylinder a = 2, c = 1, L = 2, best grid per strategy: S, V, ‖E‖ vs printed",
            fast: true,
            heavy: false,
            run: table_3_3,
        },
        Case {
            name: "sph-harmonics/table3.4-box-L3",
            description: "parallelepiped 4 × 4 × 2, L = 3, q = 5..8 × five grids: A, V, ‖E‖ vs printed",
            fast: true,
            heavy: false,
            run: table_3_4,
        },
        Case {
            name: "sph-harmonics/table3.6-contact",
            description: "Hertz contact with curvature correction, analytic rows: c_cor, ρ_e (±0.5e-4), F̄ (±0.5 in the printed 4th digit); rows 1 and 3 radii from our own curvature of a degree-60 spheroid",
            fast: true,
            heavy: false,
            run: table_3_6,
        },
        Case {
            name: "sph-harmonics/table3.7-elongation",
            description: "δ_S, δ_V (%) of ellipsoid (L = 1, q3 8×16), cylinder (L = 3, q3 32×16), box (L = 3, q6 32×32) for c/a = 0.4, 0.5, 0.75, 1 vs printed (±0.1 points)",
            fast: true,
            heavy: false,
            run: table_3_7,
        },
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
        Case {
            name: "sph-harmonics/convergence",
            description: "our convergence table: relative volume and area error of quadrature fits, degrees 1..30, five shapes; smooth shapes must converge below 1e-6 by degree 30, edged shapes below 1 %",
            fast: false,
            heavy: false,
            run: convergence,
        },
    ]
}

const R_TABLE3_1_ELLIPSOID_L1: &str = "the thesis does not define its sampling rules q = 1..4 beyond names, the octant/threshold set-up or the R of Eq. 2.24 (NOTES R1, R9); under our documented reading (sampling.rs) the L = 1 octant fits differ from the printed S, V and ‖E‖; the printed row set is also internally inconsistent (R1a, R1b)";
const R_TABLE3_2_CYLINDER_L3: &str = "sampling rules q = 1..4 and the 16,250-point threshold grid are not specified (NOTES R2, R9d); the printed columns are misaligned (R2a); our documented reading of the strategies gives different S, V and ‖E‖";
const R_TABLE3_3_CYLINDER_L2: &str = "sampling rules and threshold grid not specified (NOTES R3, R9d); rows q=1 and q=2 print identical errors (R3c, likely a copy error); our reading gives different values";
const R_TABLE3_4_BOX_L3: &str = "the box dimensions are missing from the text (4 × 4 × 2 inferred from V = 32, S = 64, NOTES R4d), the 16,380-point threshold grid and strategies q = 5..8 are not specified beyond names (R9d); our reading gives different V and ‖E‖";
const R_TABLE3_7_ELONGATION: &str = "the ellipsoid and cylinder rows are identical (NOTES R7a, a copy error), the k = 1 ellipsoid is a sphere yet printed with 1 % errors (R7b), and the reference models per shape are not given; our octant studies with the Table 3.1–3.4 best grids differ";
const R_VCCTL_OTTAWA_FULL: &str = "NIST's geom row for this grain is reproduced to 1e-5 at degree 30, not at its Nnn = 28 (20037 area −0.79 %, 20185 area −0.297 % and normalised area −0.32 % at Nnn): the row was evidently computed with all 30 degrees; see tests/it/main.rs";
const R_CONVERGENCE: &str = "Gibbs oscillation: a degree-30 Gauss-quadrature interpolation of a shape with edges/corners overshoots near them, area error 2–4 % (cylinder, box) and volume 1.4–1.9 % (bicone, octahedron); least squares on a dense grid or higher degree is needed for edged shapes";

pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k1/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k1/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k1/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k2/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k2/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k2/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k3/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k3/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k3/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k4/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k4/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q1k4/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k1/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k1/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k1/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k2/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k2/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k2/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k3/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k3/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k3/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k4/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k4/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q2k4/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k1/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k1/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k2/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k2/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k2/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k3/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k3/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k3/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k4/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q3k4/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k1/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k1/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k1/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k2/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k2/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k2/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k3/S",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k3/V",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k3/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.1-ellipsoid-L1",
        metric: "q4k4/LS_error",
        reason: R_TABLE3_1_ELLIPSOID_L1,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k1/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k1/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k1/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k2/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k2/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k3/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k3/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k4/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q1k4/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k1/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k1/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k1/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k2/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k2/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k2/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k3/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k3/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k3/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k4/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k4/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q2k4/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k1/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k1/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k1/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k2/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k2/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k2/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k3/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k3/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k3/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k4/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k4/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q3k4/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k1/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k1/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k1/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k2/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k2/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k2/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k3/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k3/V",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k3/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k4/S",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.2-cylinder-L3",
        metric: "q4k4/LS_error",
        reason: R_TABLE3_2_CYLINDER_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q1k4/S",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q1k4/V",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q1k4/LS_error",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q2k4/S",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q2k4/LS_error",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q3k3/S",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q3k3/V",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q3k3/LS_error",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q4k4/S",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.3-cylinder-L2",
        metric: "q4k4/V",
        reason: R_TABLE3_3_CYLINDER_L2,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k5/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k5/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k6/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k6/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k3/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k3/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k7/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k7/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k7/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k8/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q5k8/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k5/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k5/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k5/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k6/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k6/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k6/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k3/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k3/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k3/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k7/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k7/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k7/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k8/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k8/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q6k8/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k5/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k5/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k5/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k6/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k6/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k6/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k3/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k3/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k3/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k7/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k7/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k7/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k8/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k8/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q7k8/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k5/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k5/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k6/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k6/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k6/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k3/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k3/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k3/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k7/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k7/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k7/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k8/S",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k8/V",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.4-box-L3",
        metric: "q8k8/LS_error",
        reason: R_TABLE3_4_BOX_L3,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/0.4/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/0.4/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/0.5/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/0.5/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/0.75/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/0.75/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/1/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "ellipsoid/1/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "cylinder/0.4/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "cylinder/0.4/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "cylinder/0.5/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "cylinder/0.5/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "cylinder/0.75/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "cylinder/1/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "cylinder/1/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "parallelepiped/0.4/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "parallelepiped/0.4/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "parallelepiped/0.5/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "parallelepiped/0.75/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "parallelepiped/0.75/delta_V_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
    ExpectedFailure {
        case: "sph-harmonics/table3.7-elongation",
        metric: "parallelepiped/1/delta_S_pct",
        reason: R_TABLE3_7_ELONGATION,
    },
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
    ExpectedFailure {
        case: "sph-harmonics/convergence",
        metric: "cylinder/L30/rel_area_error",
        reason: R_CONVERGENCE,
    },
    ExpectedFailure {
        case: "sph-harmonics/convergence",
        metric: "box/L30/rel_area_error",
        reason: R_CONVERGENCE,
    },
    ExpectedFailure {
        case: "sph-harmonics/convergence",
        metric: "bicone/L30/rel_volume_error",
        reason: R_CONVERGENCE,
    },
    ExpectedFailure {
        case: "sph-harmonics/convergence",
        metric: "bicone/L30/rel_area_error",
        reason: R_CONVERGENCE,
    },
    ExpectedFailure {
        case: "sph-harmonics/convergence",
        metric: "octahedron/L30/rel_volume_error",
        reason: R_CONVERGENCE,
    },
    ExpectedFailure {
        case: "sph-harmonics/convergence",
        metric: "octahedron/L30/rel_area_error",
        reason: R_CONVERGENCE,
    },
];

fn err(e: sph_harmonics::Error) -> Error {
    Error::computation(e)
}

/// Runs the octant studies of a Table 3.1–3.4 CSV and compares S, V, ‖E‖.
fn octant_table(
    file: &str,
    shape: Shape,
    half: [f64; 3],
    degree: usize,
    area_col: &str,
) -> Result<Vec<Check>, Error> {
    let t = Table::reference(file)?;
    let threshold = RingGrid::threshold();
    let mut checks = Vec::new();
    for row in t.rows_where("row_type", "model")? {
        let q = t.number(row, "q_strategy")? as u8;
        let k = t.number(row, "k_reference_model")? as u32;
        let nt = t.number(row, "grid_n_theta")? as usize;
        let np = t.number(row, "grid_n_phi")? as usize;
        let r = octant_study(&shape, half, q, nt, np, degree, &threshold).map_err(err)?;
        let tag = format!("q{q}k{k}");
        checks.push(Check::new(
            format!("{tag}/N_k"),
            t.number(row, "N_k_points")?,
            r.n_points as f64,
            Tolerance::Within(0.0),
        ));
        checks.push(Check::new(
            format!("{tag}/S"),
            t.number(row, area_col)?,
            r.area,
            Tolerance::Relative(0.005),
        ));
        checks.push(Check::new(
            format!("{tag}/V"),
            t.number(row, "V_volume")?,
            r.volume,
            Tolerance::Relative(0.005),
        ));
        checks.push(Check::new(
            format!("{tag}/LS_error"),
            t.number(row, "LS_error_norm")?,
            r.norms.ls_error,
            Tolerance::Relative(0.05),
        ));
    }
    Ok(checks)
}

fn table_3_1() -> Result<Vec<Check>, Error> {
    let shape = Shape::Ellipsoid {
        a: 2.0,
        b: 2.0,
        c: 1.0,
    };
    octant_table(
        "radvilaite2016_table3_1_ellipsoid_L1.csv",
        shape,
        [2.0, 2.0, 1.0],
        1,
        "S_surface_area",
    )
}

fn table_3_2() -> Result<Vec<Check>, Error> {
    octant_table(
        "radvilaite2016_table3_2_cylinder_L3.csv",
        Shape::Cylinder { a: 2.0, c: 1.0 },
        [2.0, 2.0, 1.0],
        3,
        "S_surface_area",
    )
}

fn table_3_3() -> Result<Vec<Check>, Error> {
    octant_table(
        "radvilaite2016_table3_3_cylinder_L2.csv",
        Shape::Cylinder { a: 2.0, c: 1.0 },
        [2.0, 2.0, 1.0],
        2,
        "S_surface_area",
    )
}

fn table_3_4() -> Result<Vec<Check>, Error> {
    octant_table(
        "radvilaite2016_table3_4_parallelepiped_L3.csv",
        Shape::Box {
            a: 2.0,
            b: 2.0,
            c: 1.0,
        },
        [2.0, 2.0, 1.0],
        3,
        "A_surface_area",
    )
}

fn table_3_6() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_6_contact_analysis.csv")?;
    let mut checks = Vec::new();
    // Our own curvature radii of the oblate spheroid a = 2, c = 1 (R = b = 2), degree 60.
    let shape = Shape::Ellipsoid {
        a: 2.0,
        b: 2.0,
        c: 1.0,
    };
    let grid = RingGrid::gauss_legendre(60).map_err(err)?;
    let values: Vec<f64> = grid
        .points()
        .iter()
        .map(|&(th, p)| shape.radius(th, p))
        .collect();
    let model = quadrature_transform(&grid, &values, 60).map_err(err)?;
    let ev = CurvatureEvaluator::new(&model).map_err(err)?;
    let equator = ev.at(PI / 2.0, 0.0).map_err(err)?.principal_radii();
    let pole = ev.at(0.0, 0.0).map_err(err)?.principal_radii();
    let ours_radii = [
        ("1", equator[0] / 2.0, equator[1] / 2.0),
        ("3", pole[0] / 2.0, pole[1] / 2.0),
    ];
    for (no, rn, rt) in ours_radii {
        let row = t.row_where("no", no)?;
        checks.push(Check::new(
            format!("row{no}/rho_n_from_sh_curvature"),
            t.number(row, "rho_n_rel")?,
            rn,
            Tolerance::Within(0.5e-3),
        ));
        checks.push(Check::new(
            format!("row{no}/rho_t_from_sh_curvature"),
            t.number(row, "rho_t_rel")?,
            rt,
            Tolerance::Within(0.5e-3),
        ));
    }
    for row in t.rows_where("solution_type", "analytical")? {
        let no = t.text(row, "no")?.to_owned();
        let rn = t.number(row, "rho_n_rel")?;
        let rt = t.number(row, "rho_t_rel")?;
        let h = hertz([rn, rt], [f64::INFINITY; 2], 0.0).map_err(err)?;
        checks.push(Check::new(
            format!("row{no}/c_cor"),
            t.number(row, "c_cor")?,
            h.c_cor,
            Tolerance::Within(0.5e-4),
        ));
        checks.push(Check::new(
            format!("row{no}/rho_e"),
            t.number(row, "rho_e_rel")?,
            h.rho_eff,
            Tolerance::Within(0.5e-4),
        ));
        let f = t.number(row, "F_rel_nondim")?;
        checks.push(Check::new(
            format!("row{no}/F_rel"),
            f,
            h.force(1.0, 0.01),
            Tolerance::Relative(6e-4),
        ));
    }
    Ok(checks)
}

fn table_3_7() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_7_elongation_errors_pct.csv")?;
    let threshold = RingGrid::threshold();
    let mut checks = Vec::new();
    for row in 0..t.rows.len() {
        let name = t.text(row, "shape")?.to_owned();
        let k = t.number(row, "k_elon")?;
        let c = 2.0 * k;
        let (shape, degree, q, nt, np) = match name.as_str() {
            "ellipsoid" => (Shape::Ellipsoid { a: 2.0, b: 2.0, c }, 1, 3, 8, 16),
            "cylinder" => (Shape::Cylinder { a: 2.0, c }, 3, 3, 32, 16),
            _ => (Shape::Box { a: 2.0, b: 2.0, c }, 3, 6, 32, 32),
        };
        let r = octant_study(&shape, [2.0, 2.0, c], q, nt, np, degree, &threshold).map_err(err)?;
        let ds = 100.0 * (r.area / shape.area() - 1.0).abs();
        let dv = 100.0 * (r.volume / shape.volume() - 1.0).abs();
        checks.push(Check::new(
            format!("{name}/{k}/delta_S_pct"),
            t.number(row, "delta_S_pct")?,
            ds,
            Tolerance::Within(0.1),
        ));
        checks.push(Check::new(
            format!("{name}/{k}/delta_V_pct"),
            t.number(row, "delta_V_pct")?,
            dv,
            Tolerance::Within(0.1),
        ));
    }
    Ok(checks)
}

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

fn convergence() -> Result<Vec<Check>, Error> {
    let shapes = [
        (
            "ellipsoid",
            Shape::Ellipsoid {
                a: 2.0,
                b: 2.0,
                c: 1.0,
            },
            1e-6,
        ),
        (
            "triaxial",
            Shape::Ellipsoid {
                a: 2.0,
                b: 1.5,
                c: 1.0,
            },
            1e-6,
        ),
        ("cylinder", Shape::Cylinder { a: 2.0, c: 1.0 }, 1e-2),
        (
            "box",
            Shape::Box {
                a: 2.0,
                b: 2.0,
                c: 1.0,
            },
            1e-2,
        ),
        ("bicone", Shape::Bicone { a: 2.0, c: 1.0 }, 1e-2),
        (
            "octahedron",
            Shape::Octahedron {
                a: 2.0,
                b: 2.0,
                c: 1.0,
            },
            1e-2,
        ),
    ];
    let mut checks = Vec::new();
    // Judged rows: degree 30 against the shape's bound; and at the doubling
    // checkpoints 4, 8, 16 the error must not exceed the previous
    // checkpoint's (convergence, not merely reporting). Degree 1 is left out:
    // a centred sphere plus a dipole has accidental cancellations in V.
    let checkpoints = [2usize, 4, 8, 16, 30];
    for (name, shape, bound) in shapes {
        let mut previous: Option<(usize, f64, f64)> = None;
        for degree in checkpoints {
            let grid = RingGrid::gauss_legendre(degree).map_err(err)?;
            let values: Vec<f64> = grid
                .points()
                .iter()
                .map(|&(t, p)| shape.radius(t, p))
                .collect();
            let model = quadrature_transform(&grid, &values, degree).map_err(err)?;
            // Low degrees of edged shapes may not be star-shaped: that is a finding, not an error.
            let Ok(i) = gauss_integrals(&model, default_gauss_nodes(degree) * 2) else {
                continue;
            };
            let dv = (i.volume / shape.volume() - 1.0).abs();
            let da = (i.area / shape.area() - 1.0).abs();
            if degree == 30 {
                checks.push(Check::new(
                    format!("{name}/L30/rel_volume_error"),
                    0.0,
                    dv,
                    Tolerance::AtMost(bound),
                ));
                checks.push(Check::new(
                    format!("{name}/L30/rel_area_error"),
                    0.0,
                    da,
                    Tolerance::AtMost(bound),
                ));
            } else if let Some((l0, v0, a0)) = previous {
                // a rounding floor: errors already at 1e-12 need not decrease further
                let floor = 1e-12;
                checks.push(Check::new(
                    format!("{name}/L{degree}/rel_volume_error <= L{l0}"),
                    v0.max(floor),
                    dv,
                    Tolerance::AtMost(0.0),
                ));
                checks.push(Check::new(
                    format!("{name}/L{degree}/rel_area_error <= L{l0}"),
                    a0.max(floor),
                    da,
                    Tolerance::AtMost(0.0),
                ));
            }
            previous = Some((degree, dv, da));
        }
    }
    Ok(checks)
}
