//! Our own convergence table: relative volume and area error of quadrature
//! fits against degree for smooth and edged shapes.

use sph_harmonics::fit::quadrature_transform;
use sph_harmonics::grid::RingGrid;
use sph_harmonics::integrals::{default_gauss_nodes, gauss_integrals};
use sph_harmonics::shapes::Shape;

use super::err;
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

/// The group's cases, in registration order.
pub(super) fn cases() -> Vec<Case> {
    vec![Case {
        name: "sph-harmonics/convergence",
        description: "our convergence table: relative volume and area error of quadrature fits, degrees 1..30, five shapes; smooth shapes must converge below 1e-6 by degree 30, edged shapes below 1 %",
        fast: false,
        heavy: false,
        run: convergence,
    }]
}

const R_CONVERGENCE: &str = "Gibbs oscillation: a degree-30 Gauss-quadrature interpolation of a shape with edges/corners overshoots near them, area error 2–4 % (cylinder, box) and volume 1.4–1.9 % (bicone, octahedron); least squares on a dense grid or higher degree is needed for edged shapes";

/// The group's expected failures, in the order of the ratchet list.
pub(super) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
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
