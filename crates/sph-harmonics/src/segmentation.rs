//! Piecewise models on angular patches (Radvilaitė 2016, §4.1, Eqs. 4.1–4.2).
//!
//! φ ∈ [0, 2π) is split into `n_phi` equal intervals and θ ∈ [0, π] into `n_theta` equal
//! intervals (the last θ interval closed), giving `n_s = n_phi · n_theta` patches W_i. Each
//! patch gets its own expansion fitted by least squares to the samples inside it (Eq. 4.1); the
//! surface is the patch-wise sum (Eq. 4.2), i.e. the model of the patch containing (θ, φ).
//! Patch models are only meaningful inside their patch; a small patch usually makes the design
//! rank deficient, which each patch's [`FitDiagnostics`] reports (Moore–Penrose solution).
//! The surface is not continuous across patch borders (as in the thesis).

use crate::error::{Error, check_angles};
use crate::fit::{FitDiagnostics, least_squares};
use crate::model::ShModel;
use std::f64::consts::{PI, TAU};

/// A surface described by one expansion per angular patch.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentedModel {
    n_phi: usize,
    n_theta: usize,
    models: Vec<ShModel>,
    diagnostics: Vec<FitDiagnostics>,
}

fn patch_of(n_phi: usize, n_theta: usize, theta: f64, phi: f64) -> usize {
    let p = phi.rem_euclid(TAU);
    let i = ((p / TAU * n_phi as f64) as usize).min(n_phi - 1);
    let j = ((theta / PI * n_theta as f64) as usize).min(n_theta - 1);
    j * n_phi + i
}

impl SegmentedModel {
    /// Fits `n_phi × n_theta` patch models of degree `degree` to radii sampled at directions.
    ///
    /// # Errors
    /// [`Error::InvalidGrid`] for zero segment counts, [`Error::LengthMismatch`],
    /// [`Error::AngleOutOfRange`], and the errors of [`least_squares`] per patch (e.g.
    /// [`Error::DegreeTooHighForGrid`] when a patch holds fewer samples than coefficients).
    pub fn fit(
        directions: &[(f64, f64)],
        radii: &[f64],
        degree: usize,
        n_phi: usize,
        n_theta: usize,
    ) -> Result<Self, Error> {
        if n_phi == 0 || n_theta == 0 {
            return Err(Error::InvalidGrid {
                what: "segment count",
                value: 0.0,
            });
        }
        if radii.len() != directions.len() {
            return Err(Error::LengthMismatch {
                what: "radii",
                expected: directions.len(),
                got: radii.len(),
            });
        }
        let n_s = n_phi * n_theta;
        let mut dirs = vec![Vec::new(); n_s];
        let mut vals = vec![Vec::new(); n_s];
        for (&(t, p), &r) in directions.iter().zip(radii) {
            check_angles(t, p)?;
            let k = patch_of(n_phi, n_theta, t, p);
            dirs[k].push((t, p));
            vals[k].push(r);
        }
        let mut models = Vec::with_capacity(n_s);
        let mut diagnostics = Vec::with_capacity(n_s);
        for k in 0..n_s {
            let fit = least_squares(&dirs[k], &vals[k], None, degree)?;
            models.push(fit.model);
            diagnostics.push(fit.diagnostics);
        }
        Ok(Self {
            n_phi,
            n_theta,
            models,
            diagnostics,
        })
    }

    /// Number of patches n_s.
    #[must_use]
    pub fn segment_count(&self) -> usize {
        self.models.len()
    }

    /// Patch models, patch index `j·n_phi + i` (θ interval j, φ interval i).
    #[must_use]
    pub fn models(&self) -> &[ShModel] {
        &self.models
    }

    /// Fit diagnostics per patch.
    #[must_use]
    pub fn diagnostics(&self) -> &[FitDiagnostics] {
        &self.diagnostics
    }

    /// Radius from the model of the patch containing (θ, φ) (Eq. 4.2).
    ///
    /// # Errors
    /// [`Error::AngleOutOfRange`].
    pub fn radius(&self, theta: f64, phi: f64) -> Result<f64, Error> {
        check_angles(theta, phi)?;
        self.models[patch_of(self.n_phi, self.n_theta, theta, phi)].radius(theta, phi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::RingGrid;
    use crate::shapes::Shape;

    #[test]
    fn patches_reduce_the_error_of_a_low_degree_fit() {
        let shape = Shape::Cylinder { a: 2.0, c: 1.0 };
        let pts = RingGrid::equiangular_with_poles(48, 48)
            .expect("grid")
            .points();
        let radii: Vec<f64> = pts.iter().map(|&(t, p)| shape.radius(t, p)).collect();
        let rms = |f: &dyn Fn(f64, f64) -> f64| {
            (pts.iter()
                .zip(&radii)
                .map(|(&(t, p), r)| (f(t, p) - r).powi(2))
                .sum::<f64>()
                / pts.len() as f64)
                .sqrt()
        };
        let global = least_squares(&pts, &radii, None, 3).expect("fit").model;
        let seg = SegmentedModel::fit(&pts, &radii, 3, 2, 2).expect("segments");
        assert_eq!(seg.segment_count(), 4);
        let e_global = rms(&|t, p| global.radius(t, p).expect("r"));
        let e_seg = rms(&|t, p| seg.radius(t, p).expect("r"));
        assert!(
            e_seg < 0.7 * e_global,
            "segmented {e_seg} vs global {e_global}"
        );
    }

    #[test]
    fn bad_input() {
        let pts = vec![(0.5, 0.5); 3];
        assert!(SegmentedModel::fit(&pts, &[1.0; 3], 0, 0, 1).is_err());
        assert!(SegmentedModel::fit(&pts, &[1.0; 2], 0, 1, 1).is_err());
        // Second patch has no samples: degree too high for its grid.
        assert!(matches!(
            SegmentedModel::fit(&pts, &[1.0; 3], 0, 2, 1),
            Err(Error::DegreeTooHighForGrid { .. })
        ));
    }
}
