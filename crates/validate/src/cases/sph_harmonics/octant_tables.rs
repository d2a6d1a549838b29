//! Radvilaitė 2016 Tables 3.1–3.4: octant studies of an ellipsoid, two
//! cylinders and a parallelepiped at the thesis' degree and sampling, S, V
//! and ‖E‖ against the printed rows.

use sph_harmonics::grid::RingGrid;
use sph_harmonics::sampling::octant_study;
use sph_harmonics::shapes::Shape;

use super::err;
use crate::fixtures::Table;
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

/// The group's cases, in registration order.
pub(super) fn cases() -> Vec<Case> {
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
    ]
}

const R_TABLE3_1_ELLIPSOID_L1: &str = "the thesis does not define its sampling rules q = 1..4 beyond names, the octant/threshold set-up or the R of Eq. 2.24 (NOTES R1, R9); under our documented reading (sampling.rs) the L = 1 octant fits differ from the printed S, V and ‖E‖; the printed row set is also internally inconsistent (R1a, R1b)";
const R_TABLE3_2_CYLINDER_L3: &str = "sampling rules q = 1..4 and the 16,250-point threshold grid are not specified (NOTES R2, R9d); the printed columns are misaligned (R2a); our documented reading of the strategies gives different S, V and ‖E‖";
const R_TABLE3_3_CYLINDER_L2: &str = "sampling rules and threshold grid not specified (NOTES R3, R9d); rows q=1 and q=2 print identical errors (R3c, likely a copy error); our reading gives different values";
const R_TABLE3_4_BOX_L3: &str = "the box dimensions are missing from the text (4 × 4 × 2 inferred from V = 32, S = 64, NOTES R4d), the 16,380-point threshold grid and strategies q = 5..8 are not specified beyond names (R9d); our reading gives different V and ‖E‖";

/// The group's expected failures, in the order of the ratchet list.
pub(super) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
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
];

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
