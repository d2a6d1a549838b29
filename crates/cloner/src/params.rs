//! Parameters of a cloning run, validated once ([`Params::validate`]) and
//! serialisable to RON (the calibrated configuration in
//! `fixtures/calibrated/`).

use serde::{Deserialize, Serialize};

use morph_dna::SphericalMesh;

use crate::error::{Error, Result};
use crate::surface::Interpolation;

/// How the clone's target DNA (aspect ratio, minimum principal dimension,
/// flatness, roundness, volume/surface ratio) is drawn from the parents.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum TargetModel {
    /// The seed (Medina 2018, §2.1–2.4): `(aspect ratio, S)` from the bicubic
    /// interpolation of their 2D histogram by acceptance–rejection;
    /// roundness and flatness from their 1D histograms (independent; the seed
    /// does not say how the intermediate axis is chosen); the quality-control
    /// volume/surface ratio from the `(S, V/S)` PDF conditional on `S`.
    Seed,
    /// A Gaussian copula over the parents' empirical marginals of all five
    /// (`morph_dna::GaussianCopula`): every pairwise correlation kept, not
    /// only the two "high enough" ones; the quality-control V/S is drawn
    /// conditional on the other four. Default.
    #[default]
    Copula,
}

/// Where the roundness check (`Params::roundness_tolerance`) measures a
/// candidate's roundness.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum RoundnessCheck {
    /// On the candidate's rasterised level set, exactly as the clone is
    /// judged (`morph_dna::measure`): one level set and its roundness per
    /// checked candidate, with `roundness_repairs` re-steered repairs.
    #[default]
    LevelSet,
    /// By the roundness predicted from the candidate's surface DNA and its
    /// estimated inscribed radius (`SteeringMap::roundness_prediction`,
    /// least squares on the pilot clones' level sets): after the
    /// `roundness_predictions` re-steered passes, a candidate whose
    /// predicted miss exceeds the tolerance is rejected. No level set is
    /// built unless the outputs ask for one. Needs `pilot_clones` and
    /// `roundness_predictions > 0`.
    Predicted,
}

/// How the radii of the mesh nodes are drawn (normalised by the embryo
/// ellipsoid's radius in the node's direction).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum RadiiModel {
    /// The seed (Medina 2018, §2.3): for every node, one draw from its own
    /// histogram and one from each stencil neighbour's, averaged with the
    /// parents' node-neighbour correlations as weights (self weight 1,
    /// negative correlations count as 0).
    SeedNeighbourhood,
    /// A Gaussian-copula random field: normal scores of the parents' node
    /// radii, whose full node-node correlation (shrunk towards the identity
    /// by `shrinkage` so it is positive definite) is sampled through the
    /// low-rank parent factor, mapped through every node's own histogram.
    /// Per-node marginals and all spatial correlations are kept (the seed's
    /// average of independent draws narrows both). Default.
    CopulaField {
        /// Weight of the identity in the correlation, in [0, 1).
        shrinkage: f64,
    },
}

impl Default for RadiiModel {
    fn default() -> Self {
        Self::CopulaField { shrinkage: 0.05 }
    }
}

/// The Laplacian polishing that raises roundness to the sampled value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Smoothing {
    /// Umbrella-operator step λ in (0, 1].
    pub lambda: f64,
    /// Iterations after which a candidate that is still too sharp is
    /// rejected (≥ 1).
    pub max_iterations: usize,
    /// Inverse (sharpening) steps allowed for a candidate rounder than its
    /// target before it is rejected (0 = the seed: rejected at once).
    pub max_sharpening: usize,
}

impl Default for Smoothing {
    fn default() -> Self {
        Self {
            lambda: 0.5,
            max_iterations: 64,
            max_sharpening: 8,
        }
    }
}

/// What a run returns besides the clones' mesh radii and targets. Nothing is
/// computed for an output nobody asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Outputs {
    /// Keep each clone's level set (`levelset::Grid`).
    pub level_set: bool,
    /// Measure each clone's DNA on its level set (builds the level set).
    pub dna: bool,
}

impl Default for Outputs {
    fn default() -> Self {
        Self {
            level_set: false,
            dna: true,
        }
    }
}

/// Parameters of GSC 2.0 cloning. Defaults are the seed's trial 4 (mesh
/// 28 × (18 + 2), 50 bins, 45³, 1 % tolerance) with this crate's default
/// methods; [`Params::seed_faithful`] switches every method to the seed's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// The spherical mesh of the radii.
    pub mesh: SphericalMesh,
    /// Histogram bins (per axis for 2D histograms; per node for radii).
    pub bins: usize,
    /// Level-set nodes per axis of the rasterised clone.
    pub level_set_resolution: usize,
    /// Half-width of the clone's grid cube over its largest radius (> 1).
    pub grid_margin: f64,
    /// Relative tolerance of the volume/surface-ratio quality control.
    pub tolerance: f64,
    /// Laplacian polishing.
    pub smoothing: Smoothing,
    /// Target DNA model.
    pub targets: TargetModel,
    /// Radii model.
    pub radii: RadiiModel,
    /// Radius interpolation between nodes.
    pub interpolation: Interpolation,
    /// Fixed-point corrections of the embryo's semi-axes after polishing so
    /// that the surface's principal dimensions meet the sampled ones (0 = the
    /// seed, which keeps the embryo's axes).
    pub axis_corrections: usize,
    /// Pilot clones (on reserved streams) that calibrate the map from the
    /// cheap surface DNA to the DNA measured on level sets, so targets can be
    /// drawn from the parents' measured DNA (0 = no pilot: measured targets
    /// are steered as if the two measures agreed, as the seed does).
    pub pilot_clones: usize,
    /// Largest |measured − target| roundness of an accepted clone, checked on
    /// its level set (`None` = the surface-DNA steering alone, the default).
    pub roundness_tolerance: Option<f64>,
    /// Where the roundness check of `roundness_tolerance` measures a
    /// candidate: on its rasterised level set (the default, as calibrated
    /// before) or by the pilot-fitted prediction from its surface
    /// ([`RoundnessCheck::Predicted`]), which builds no level set.
    #[serde(default)]
    pub roundness_check: RoundnessCheck,
    /// With `roundness_tolerance`: re-steered polishing passes of a candidate
    /// whose measured roundness misses (the same raw field polished again
    /// toward a surface roundness moved against the miss, then quality
    /// control and a new level set) before it is rejected (0 = reject at the
    /// first miss).
    #[serde(default)]
    pub roundness_repairs: usize,
    /// With `roundness_tolerance`: re-steered polishing passes *before* the
    /// level set is built, while the predicted level-set roundness misses the
    /// target by more than `roundness_prediction_margin` × the tolerance. The prediction
    /// ([`crate::SteeringMap::roundness_prediction`], fitted on the pilot
    /// clones) adds the estimated inscribed radius over `r_min` to the surface
    /// roundness; a pass costs a polish and the surface DNA, far less than a
    /// level set and its roundness (0 = no prediction, the default).
    #[serde(default)]
    pub roundness_predictions: usize,
    /// The predicted miss, as a fraction of `roundness_tolerance`, above which
    /// a predicted-roundness pass runs (in (0, 2]; default 0.5). Smaller
    /// values save more level sets; larger ones leave alone the candidates
    /// likely to pass, so the prediction's own bias moves fewer clones.
    #[serde(default = "default_prediction_margin")]
    pub roundness_prediction_margin: f64,
    /// Radii fields tried for one draw of the targets before the targets are
    /// redrawn (1 = the seed: a rejected grain is discarded whole).
    pub fields_per_target: usize,
    /// Candidates per clone index before [`Error::TooManyRejections`].
    pub max_attempts: usize,
    /// Master seed; clone `i` uses the stream `(seed, i)`.
    pub seed: u64,
    /// Outputs to produce.
    pub outputs: Outputs,
}

fn default_prediction_margin() -> f64 {
    0.5
}

impl Default for Params {
    fn default() -> Self {
        Self {
            mesh: SphericalMesh::default(),
            bins: 50,
            level_set_resolution: 45,
            grid_margin: 1.1,
            tolerance: 0.01,
            smoothing: Smoothing::default(),
            targets: TargetModel::default(),
            radii: RadiiModel::default(),
            interpolation: Interpolation::default(),
            axis_corrections: 2,
            pilot_clones: 96,
            roundness_tolerance: None,
            roundness_check: RoundnessCheck::LevelSet,
            roundness_repairs: 0,
            roundness_predictions: 0,
            roundness_prediction_margin: default_prediction_margin(),
            fields_per_target: 64,
            max_attempts: 20_000,
            seed: 2018,
            outputs: Outputs::default(),
        }
    }
}

impl Params {
    /// The seed's methods at its trial-4 configuration: pairwise histogram
    /// PDFs, neighbourhood-averaged radii, bilinear interpolation, no axis
    /// correction.
    pub fn seed_faithful() -> Self {
        Self {
            targets: TargetModel::Seed,
            radii: RadiiModel::SeedNeighbourhood,
            interpolation: Interpolation::Bilinear,
            axis_corrections: 0,
            pilot_clones: 0,
            fields_per_target: 1,
            smoothing: Smoothing {
                max_sharpening: 0,
                ..Smoothing::default()
            },
            ..Self::default()
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::MeshTooCoarse`] for a mesh below `4 × (2 + 2)`,
    /// [`Error::InvalidParameter`] for any other field out of its domain.
    pub fn validate(&self) -> Result<()> {
        if self.mesh.n_az < 4 || self.mesh.n_pol < 2 {
            return Err(Error::MeshTooCoarse {
                n_az: self.mesh.n_az,
                n_pol: self.mesh.n_pol,
            });
        }
        let bad = |name, value: f64, reason| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        if self.mesh.n_az > 4096 || self.mesh.n_pol > 4096 {
            return bad(
                "mesh",
                self.mesh.n_az.max(self.mesh.n_pol) as f64,
                "at most 4096 divisions per direction",
            );
        }
        if !(2..=10_000).contains(&self.bins) {
            return bad("bins", self.bins as f64, "between 2 and 10000");
        }
        if !(8..=1024).contains(&self.level_set_resolution) {
            return bad(
                "level_set_resolution",
                self.level_set_resolution as f64,
                "between 8 and 1024 nodes per axis",
            );
        }
        if !(self.grid_margin.is_finite() && self.grid_margin > 1.0 && self.grid_margin <= 4.0) {
            return bad("grid_margin", self.grid_margin, "in (1, 4]");
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            return bad("tolerance", self.tolerance, "in (0, 1)");
        }
        let s = self.smoothing;
        if !(s.lambda.is_finite() && s.lambda > 0.0 && s.lambda <= 1.0) {
            return bad("smoothing.lambda", s.lambda, "in (0, 1]");
        }
        if !(1..=100_000).contains(&s.max_iterations) {
            return bad(
                "smoothing.max_iterations",
                s.max_iterations as f64,
                "between 1 and 100000",
            );
        }
        if s.max_sharpening > 1000 {
            return bad(
                "smoothing.max_sharpening",
                s.max_sharpening as f64,
                "at most 1000",
            );
        }
        if let RadiiModel::CopulaField { shrinkage } = self.radii
            && !(shrinkage.is_finite() && (0.0..1.0).contains(&shrinkage))
        {
            return bad("radii.shrinkage", shrinkage, "in [0, 1)");
        }
        if self.axis_corrections > 100 {
            return bad(
                "axis_corrections",
                self.axis_corrections as f64,
                "at most 100",
            );
        }
        if self.pilot_clones != 0 && !(8..=100_000).contains(&self.pilot_clones) {
            return bad(
                "pilot_clones",
                self.pilot_clones as f64,
                "0, or between 8 and 100000",
            );
        }
        if let Some(t) = self.roundness_tolerance
            && !(t.is_finite() && t > 0.0 && t < 1.0)
        {
            return bad("roundness_tolerance", t, "in (0, 1)");
        }
        if self.roundness_check == RoundnessCheck::Predicted
            && self.roundness_tolerance.is_some()
            && (self.pilot_clones == 0 || self.roundness_predictions == 0)
        {
            return bad(
                "roundness_check",
                self.pilot_clones as f64,
                "Predicted needs pilot_clones > 0 and roundness_predictions > 0 (the prediction is fitted on the pilot)",
            );
        }
        if self.roundness_repairs > 16 {
            return bad(
                "roundness_repairs",
                self.roundness_repairs as f64,
                "at most 16",
            );
        }
        if !(self.roundness_prediction_margin > 0.0 && self.roundness_prediction_margin <= 2.0) {
            return bad(
                "roundness_prediction_margin",
                self.roundness_prediction_margin,
                "in (0, 2]",
            );
        }
        if self.roundness_predictions > 16 {
            return bad(
                "roundness_predictions",
                self.roundness_predictions as f64,
                "at most 16",
            );
        }
        if self.fields_per_target == 0 {
            return bad("fields_per_target", 0.0, "at least 1");
        }
        if self.max_attempts == 0 {
            return bad("max_attempts", 0.0, "at least 1");
        }
        Ok(())
    }

    /// The parameters as pretty RON.
    ///
    /// # Errors
    /// [`Error::Ron`] (cannot happen for these plain fields).
    pub fn to_ron(&self) -> Result<String> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).map_err(|e| {
            Error::Ron {
                message: e.to_string(),
            }
        })
    }

    /// Parses and validates RON parameters.
    ///
    /// # Errors
    /// [`Error::Ron`] for malformed text (with its position), and those of
    /// [`Params::validate`].
    pub fn from_ron(text: &str) -> Result<Self> {
        let p: Self = ron::from_str(text).map_err(|e| Error::Ron {
            message: e.to_string(),
        })?;
        p.validate()?;
        Ok(p)
    }
}
