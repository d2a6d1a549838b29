//! Sampling strategies and error norms of Radvilaitė 2016 §2.2, §3.3 (Eqs. 2.21–2.26).
//!
//! The thesis samples one octant (θ, φ ∈ [0, π/2]) of shapes with three symmetry planes: a
//! pole point plus `n_theta` polar nodes × `n_phi + 1` azimuths, `N_k = (n_phi + 1)·n_theta + 1`
//! points (verified against every N_k of Tables 3.1–3.4). The text names the strategies but
//! not their formulas; our reading, documented as a design choice:
//!
//! * q = 1 equiangular: `θ_i = i·(π/2)/n`;
//! * q = 2 equidistant: nodes at equal steps `(a + c)/n` along the bounding-box profile
//!   (top face, then side face), projected to θ ("Δl = (a + c)/n", §2.2);
//! * q = 3 adaptive with local correction: the q = 2 nodes with the node nearest to the
//!   profile's corner `θ_e = atan(a/c)` (Eq. 3.1) moved onto it;
//! * q = 4 Gauss points: Gauss–Legendre nodes in θ ∈ (0, π/2);
//! * q = 5..8 (§3.3.1): (θ strategy, φ strategy) = (2, 1), (3, 1), (2, 3), (3, 3), where the
//!   φ strategies are the same rules applied to the square cross-section (corner atan(b/a)).
//!   For q = 1..4 the azimuths are equiangular.
//!
//! The fitted octant model is extended to the sphere by mirror symmetry ([`fold`]).

use crate::error::Error;
use crate::fit::{FitDiagnostics, least_squares};
use crate::grid::{RingGrid, gauss_legendre_nodes};
use crate::integrals::{CellDomain, cell_integration};
use crate::model::{ShModel, direction, to_angles};
use crate::shapes::Shape;
use std::f64::consts::FRAC_PI_2;

/// Maps a direction into the first octant (x, y, z ≥ 0) by the three symmetry planes.
#[must_use]
pub fn fold(theta: f64, phi: f64) -> (f64, f64) {
    let u = direction(theta, phi);
    to_angles(&u.map(f64::abs))
}

/// Nodes along [0, π/2] on a two-segment box profile (first leg `first`, second leg `second`):
/// equal steps in length, projected to the angle from the first leg's start axis.
fn box_profile_nodes(first: f64, second: f64, n: usize, include_zero: bool) -> Vec<f64> {
    let total = first + second;
    let start = if include_zero { 0 } else { 1 };
    (start..=n)
        .map(|i| {
            let s = total * i as f64 / n as f64;
            // Leg 1: from the axis point (0, second) to the corner (first, second).
            let (across, along) = if s <= first {
                (s, second)
            } else {
                (first, second - (s - first))
            };
            across.atan2(along)
        })
        .collect()
}

fn snap_to(nodes: &mut [f64], target: f64) {
    if let Some(k) = (0..nodes.len()).min_by(|&i, &j| {
        (nodes[i] - target)
            .abs()
            .total_cmp(&(nodes[j] - target).abs())
    }) {
        nodes[k] = target;
    }
}

/// Directions (θ, φ) of the reference model R_qk in the first octant (see the module docs).
/// `half_sizes` = (a, b, c): bounding-box half sizes along x, y, z.
///
/// # Errors
/// [`Error::InvalidParameter`] for q ∉ 1..=8 or non-positive sizes, [`Error::InvalidGrid`] for
/// zero node counts.
pub fn reference_grid(
    q: u8,
    n_theta: usize,
    n_phi: usize,
    half_sizes: [f64; 3],
) -> Result<Vec<(f64, f64)>, Error> {
    if !(1..=8).contains(&q) {
        return Err(Error::InvalidParameter {
            what: "strategy q",
            value: f64::from(q),
        });
    }
    if n_theta == 0 || n_phi == 0 {
        return Err(Error::InvalidGrid {
            what: "reference grid size",
            value: 0.0,
        });
    }
    for &s in &half_sizes {
        if !(s.is_finite() && s > 0.0) {
            return Err(Error::InvalidParameter {
                what: "half size",
                value: s,
            });
        }
    }
    let [a, b, c] = half_sizes;
    let (tq, pq) = match q {
        5 => (2, 1),
        6 => (3, 1),
        7 => (2, 3),
        8 => (3, 3),
        q => (q, 1),
    };
    let thetas: Vec<f64> = match tq {
        1 => (1..=n_theta)
            .map(|i| FRAC_PI_2 * i as f64 / n_theta as f64)
            .collect(),
        2 | 3 => {
            let mut t = box_profile_nodes(a, c, n_theta, false);
            if tq == 3 {
                snap_to(&mut t, a.atan2(c));
            }
            t
        }
        _ => {
            let (x, _) = gauss_legendre_nodes(n_theta);
            x.iter().map(|xi| FRAC_PI_2 * 0.5 * (1.0 + xi)).collect()
        }
    };
    let phis: Vec<f64> = match pq {
        1 => (0..=n_phi)
            .map(|j| FRAC_PI_2 * j as f64 / n_phi as f64)
            .collect(),
        _ => {
            // Square cross-section path from (a, 0) up to the corner (a, b), then to (0, b):
            // the angle measured from +x is atan2(y, x).
            let mut p: Vec<f64> = box_profile_nodes(b, a, n_phi, true);
            if pq == 3 {
                snap_to(&mut p, b.atan2(a));
            }
            p
        }
    };
    let mut out = Vec::with_capacity(n_theta * (n_phi + 1) + 1);
    out.push((0.0, 0.0));
    for &t in &thetas {
        for &p in &phis {
            out.push((t, p));
        }
    }
    Ok(out)
}

/// Error norms of a model against the original surface on a threshold grid
/// (Eqs. 2.21–2.26, with R = 1: absolute lengths).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorNorms {
    /// Number of threshold points.
    pub n_points: usize,
    /// `‖E‖ = (Σ D²)^½` (Eqs. 2.22/2.24).
    pub ls_error: f64,
    /// `‖E‖ / N` (the tables' "average deviation").
    pub average: f64,
    /// `max D` (Eq. 2.25).
    pub max_error: f64,
    /// `min(−D)` (Eq. 2.26).
    pub min_error: f64,
}

/// Error norms of `actual` against `original` at the threshold grid's points, D = A − S.
#[must_use]
pub fn error_norms(
    actual: impl Fn(f64, f64) -> f64,
    original: impl Fn(f64, f64) -> f64,
    threshold: &RingGrid,
) -> ErrorNorms {
    let mut ss = 0.0;
    let mut max_error = f64::NEG_INFINITY;
    let mut min_error = f64::INFINITY;
    let pts = threshold.points();
    for &(t, p) in &pts {
        let d = actual(t, p) - original(t, p);
        ss += d * d;
        max_error = max_error.max(d);
        min_error = min_error.min(-d);
    }
    let ls = ss.sqrt();
    ErrorNorms {
        n_points: pts.len(),
        ls_error: ls,
        average: ls / pts.len() as f64,
        max_error,
        min_error,
    }
}

/// One reference-model study of Tables 3.1–3.4: fit on R_qk, norms on the threshold grid,
/// area and volume by the thesis' cell integration of the mirrored model.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyResult {
    /// Number of sampling points N_k.
    pub n_points: usize,
    /// Fit diagnostics (the octant design is well posed for L ≤ 3 on these grids).
    pub diagnostics: FitDiagnostics,
    /// Error norms on the threshold grid.
    pub norms: ErrorNorms,
    /// Area (cell integration, 64 × 64 cells per octant).
    pub area: f64,
    /// Volume (cell integration, 64 × 64 cells per octant).
    pub volume: f64,
    /// The fitted (octant) model.
    pub model: ShModel,
}

/// Runs one study (see [`StudyResult`]); the model is mirrored to the sphere by [`fold`].
///
/// # Errors
/// From [`reference_grid`], [`least_squares`] and [`cell_integration`] (e.g. a model radius ≤ 0).
pub fn octant_study(
    shape: &Shape,
    half_sizes: [f64; 3],
    q: u8,
    n_theta: usize,
    n_phi: usize,
    degree: usize,
    threshold: &RingGrid,
) -> Result<StudyResult, Error> {
    shape.validate()?;
    let dirs = reference_grid(q, n_theta, n_phi, half_sizes)?;
    let radii: Vec<f64> = dirs.iter().map(|&(t, p)| shape.radius(t, p)).collect();
    let fit = least_squares(&dirs, &radii, None, degree)?;
    let model = fit.model;
    let leg = crate::basis::Legendre::new(degree)?;
    let mut buf = leg.buffer(0);
    let mirrored = |t: f64, p: f64| {
        let (tf, pf) = fold(t, p);
        model.radius_with_buffer(&leg, &mut buf, tf, pf)
    };
    let cell = std::cell::RefCell::new(mirrored);
    let norms = error_norms(
        |t, p| (cell.borrow_mut())(t, p),
        |t, p| shape.radius(t, p),
        threshold,
    );
    let (area, volume) = cell_integration(
        |t, p| (cell.borrow_mut())(t, p),
        64,
        64,
        CellDomain::SymmetricOctant,
    )?;
    Ok(StudyResult {
        n_points: dirs.len(),
        diagnostics: fit.diagnostics,
        norms,
        area,
        volume,
        model,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn node_counts_match_the_thesis() {
        for (n_theta, n_phi, expected) in [(4, 16, 69), (8, 16, 137), (16, 16, 273), (32, 16, 545)]
        {
            for q in 1..=4 {
                let g = reference_grid(q, n_theta, n_phi, [2.0, 2.0, 1.0]).expect("grid");
                assert_eq!(g.len(), expected);
            }
        }
        for (n, expected) in [(8, 73), (12, 157), (16, 273), (24, 601), (32, 1057)] {
            for q in 5..=8 {
                let g = reference_grid(q, n, n, [2.0, 2.0, 1.0]).expect("grid");
                assert_eq!(g.len(), expected);
            }
        }
    }

    #[test]
    fn strategies_stay_in_the_octant_and_hit_the_edge() {
        let g = reference_grid(3, 8, 16, [2.0, 2.0, 1.0]).expect("grid");
        assert!(
            g.iter()
                .all(|&(t, p)| (0.0..=FRAC_PI_2 + 1e-12).contains(&t)
                    && (0.0..=FRAC_PI_2 + 1e-12).contains(&p))
        );
        assert!(g.iter().any(|&(t, _)| (t - 2.0_f64.atan()).abs() < 1e-15));
        assert!(reference_grid(9, 4, 4, [1.0; 3]).is_err());
        assert!(reference_grid(1, 0, 4, [1.0; 3]).is_err());
    }

    #[test]
    fn fold_is_a_symmetry() {
        let (t, p) = fold(2.5, -2.0);
        let u = direction(t, p);
        let v = direction(2.5, -2.0);
        assert_relative_eq!(u.x, v.x.abs(), epsilon = 1e-15);
        assert_relative_eq!(u.z, v.z.abs(), epsilon = 1e-15);
    }

    #[test]
    fn sphere_study_is_exact() {
        let s = Shape::Sphere { r: 1.5 };
        let r = octant_study(&s, [1.5; 3], 1, 4, 16, 1, &RingGrid::threshold()).expect("study");
        assert!(r.norms.ls_error < 1e-10);
        assert!(!r.diagnostics.rank_deficient);
    }
}
