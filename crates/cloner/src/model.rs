//! The parents and the population model fitted to them (Medina 2018,
//! §2.1–2.3): measured DNA, principal frames, radial profiles on the
//! spherical mesh, the surface DNA of those profiles, the target sampler and
//! the radii sampler.

use levelset::nalgebra::{Matrix3, Vector3};
use levelset::{DirectionTable, Grid, StarParams};
use morph_dna::{
    AcceptanceRejection2d, BicubicPdf, Descriptor, DnaTable, GaussianCopula, Histogram1d,
    Histogram2d, InverseCdfSampler1d, MeasureParams, PrincipalFrame, measure_with_frame,
    radial_profile,
};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::params::{Params, RadiiModel, RoundnessCheck, TargetModel};
use crate::surface::{DirectionPlan, MeshGeometry, SurfaceDna};

/// The DNA measured on every parent and on every clone, in this order:
/// aspect ratio, grain (equivalent) diameter, roundness, volume/surface
/// ratio (Medina 2018, Tables 4–5), the minimum principal dimension
/// (Table 1) and the flatness `S / I` (the embryo's intermediate axis).
pub const DNA: [Descriptor; 6] = [
    Descriptor::AspectRatio,
    Descriptor::EquivalentDiameter,
    Descriptor::Roundness,
    Descriptor::VolumeSurfaceRatio,
    Descriptor::MinPrincipalDimension,
    Descriptor::Flatness,
];

/// Positions of [`TARGETS`] in [`DNA`].
pub(crate) const TARGET_IN_DNA: [usize; 5] = [0, 4, 5, 2, 3];

/// The four parameters of Medina 2018, Tables 4–5, in their order.
pub const TABLES_4_5: [Descriptor; 4] = [
    Descriptor::AspectRatio,
    Descriptor::EquivalentDiameter,
    Descriptor::Roundness,
    Descriptor::VolumeSurfaceRatio,
];

/// The descriptors a clone's targets are drawn for, in this order.
pub const TARGETS: [Descriptor; 5] = [
    Descriptor::AspectRatio,
    Descriptor::MinPrincipalDimension,
    Descriptor::Flatness,
    Descriptor::Roundness,
    Descriptor::VolumeSurfaceRatio,
];

/// Minimum number of parents of a population model.
pub const MIN_PARENTS: usize = 2;

/// Measured parent grains (level sets, any common length unit).
#[derive(Debug, Clone)]
pub struct Parents {
    grids: Vec<Grid>,
    frames: Vec<PrincipalFrame>,
    dna: DnaTable,
}

impl Parents {
    /// Measures the [`DNA`] and principal frame of every parent (in parallel;
    /// the result does not depend on the thread count).
    ///
    /// # Errors
    /// [`Error::NoParents`], [`Error::TooFewParents`], and
    /// [`Error::DegenerateParent`] naming the first grain that cannot be
    /// measured (empty or all-inside grid, flat body, non-finite descriptor).
    pub fn from_grids(grids: Vec<Grid>, params: &MeasureParams) -> Result<Self> {
        if grids.is_empty() {
            return Err(Error::NoParents {
                required: MIN_PARENTS,
            });
        }
        if grids.len() < MIN_PARENTS {
            return Err(Error::TooFewParents {
                found: grids.len(),
                required: MIN_PARENTS,
            });
        }
        let measured: Vec<Result<(PrincipalFrame, Vec<f64>)>> = grids
            .par_iter()
            .enumerate()
            .map(|(index, g)| {
                let degenerate = |e: morph_dna::Error| Error::DegenerateParent {
                    index,
                    reason: e.to_string(),
                };
                let (dna, frame) = measure_with_frame(g, &DNA, params).map_err(degenerate)?;
                Ok((frame, dna))
            })
            .collect();
        let mut frames = Vec::with_capacity(grids.len());
        let mut rows = Vec::with_capacity(grids.len());
        for m in measured {
            let (f, d) = m?;
            frames.push(f);
            rows.push(d);
        }
        let dna = DnaTable::from_rows(DNA.to_vec(), &rows)?;
        Ok(Self { grids, frames, dna })
    }

    /// Number of parents.
    pub fn len(&self) -> usize {
        self.grids.len()
    }

    /// Always false (a parent set has at least [`MIN_PARENTS`] grains).
    pub fn is_empty(&self) -> bool {
        self.grids.is_empty()
    }

    /// The measured [`DNA`] table.
    pub fn dna(&self) -> &DnaTable {
        &self.dna
    }

    /// The parents' level sets.
    pub fn grids(&self) -> &[Grid] {
        &self.grids
    }

    /// The parents' principal frames.
    pub fn frames(&self) -> &[PrincipalFrame] {
        &self.frames
    }
}

/// Sampled targets of one clone.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Targets {
    /// Aspect ratio `S / L`.
    pub aspect_ratio: f64,
    /// Minimum principal dimension `S`.
    pub min_dimension: f64,
    /// Flatness `S / I`.
    pub flatness: f64,
    /// Roundness (surface-DNA measure).
    pub roundness: f64,
    /// Volume/surface ratio of the quality control.
    pub volume_surface_ratio: f64,
}

impl Targets {
    /// The targets as an array in [`TARGETS`] order.
    pub fn to_array(&self) -> [f64; 5] {
        [
            self.aspect_ratio,
            self.min_dimension,
            self.flatness,
            self.roundness,
            self.volume_surface_ratio,
        ]
    }

    /// Targets from an array in [`TARGETS`] order.
    pub fn from_array(v: [f64; 5]) -> Self {
        Self {
            aspect_ratio: v[0],
            min_dimension: v[1],
            flatness: v[2],
            roundness: v[3],
            volume_surface_ratio: v[4],
        }
    }

    /// Full semi-axes `(L/2, I/2, S/2)` of the embryo ellipsoid (`I` clamped
    /// into `[S, L]`).
    pub fn semi_axes(&self) -> [f64; 3] {
        let s = self.min_dimension;
        let l = s / self.aspect_ratio;
        let i = (s / self.flatness).clamp(s, l);
        [0.5 * l, 0.5 * i, 0.5 * s]
    }
}

// two per model, never in a collection: the size difference does not matter
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
enum TargetSampler {
    Seed {
        ar_s: AcceptanceRejection2d<BicubicPdf>,
        s_vs: AcceptanceRejection2d<BicubicPdf>,
        flatness: InverseCdfSampler1d,
        roundness: InverseCdfSampler1d,
    },
    Copula(GaussianCopula),
}

#[derive(Debug, Clone)]
enum RadiiSampler {
    Seed {
        marginals: Vec<InverseCdfSampler1d>,
        /// Per ring node: correlation weights of its four neighbours.
        weights: Vec<[f64; 4]>,
    },
    Copula {
        marginals: Vec<InverseCdfSampler1d>,
        /// `P × n` standardised normal scores, row-major by parent, divided
        /// by `√(P − 1)` and scaled by `√(1 − shrinkage)`.
        factor: Vec<f64>,
        parents: usize,
        noise: f64,
    },
}

/// Why a candidate draw failed inside the target sampler.
pub(crate) struct TargetUnavailable;

/// The target sampler of `model` on columns in [`TARGETS`] order.
fn target_sampler(model: TargetModel, cols: &[Vec<f64>], bins: usize) -> Result<TargetSampler> {
    Ok(match model {
        TargetModel::Copula => TargetSampler::Copula(GaussianCopula::fit(
            &DnaTable::from_columns(TARGETS.to_vec(), cols.to_vec())?,
        )?),
        TargetModel::Seed => {
            let pdf = |x: &[f64], y: &[f64]| -> Result<AcceptanceRejection2d<BicubicPdf>> {
                let h = Histogram2d::new(x, y, (bins, bins), None, None)?;
                Ok(AcceptanceRejection2d::new(BicubicPdf::from_histogram(
                    &h, 4,
                )?)?)
            };
            let one = |x: &[f64]| -> Result<InverseCdfSampler1d> {
                Ok(InverseCdfSampler1d::from_histogram(&Histogram1d::new(
                    x, bins, None,
                )?)?)
            };
            TargetSampler::Seed {
                ar_s: pdf(&cols[0], &cols[1])?,
                s_vs: pdf(&cols[1], &cols[4])?,
                flatness: one(&cols[2])?,
                roundness: one(&cols[3])?,
            }
        }
    })
}

impl TargetSampler {
    fn sample(&self, rng: &mut impl Rng) -> std::result::Result<Targets, TargetUnavailable> {
        match self {
            Self::Copula(c) => {
                let v = c.sample(rng);
                Ok(Targets {
                    aspect_ratio: v[0],
                    min_dimension: v[1],
                    flatness: v[2].max(v[0]),
                    roundness: v[3],
                    volume_surface_ratio: v[4],
                })
            }
            Self::Seed {
                ar_s,
                s_vs,
                flatness,
                roundness,
            } => {
                let (ar, s) = ar_s.sample(rng);
                let vs = s_vs
                    .sample_y_given_x(s, 100_000, rng)
                    .map_err(|_| TargetUnavailable)?;
                Ok(Targets {
                    aspect_ratio: ar,
                    min_dimension: s,
                    flatness: flatness.sample(rng).max(ar),
                    roundness: roundness.sample(rng),
                    volume_surface_ratio: vs,
                })
            }
        }
    }
}

/// The population model: everything a clone is sampled from.
#[derive(Debug, Clone)]
pub struct CloneModel {
    pub(crate) params: Params,
    pub(crate) geom: MeshGeometry,
    surface: Vec<SurfaceDna>,
    profiles: Vec<Vec<f64>>,
    /// Targets in surface-DNA measure (the pilot's).
    surface_targets: TargetSampler,
    /// Targets in measured (level-set) DNA (production).
    measured_targets: TargetSampler,
    radii: RadiiSampler,
    pub(crate) map: SteeringMap,
    /// The radius function's plans at the directions of the level-set builder's cube map
    /// (`levelset::cube_map_directions`): a clone's table is a sparse product, not 6534
    /// calls with trigonometry.
    pub(crate) cube: Vec<DirectionPlan>,
}

/// Which target distribution a candidate draws from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    /// The parents' surface DNA, steered directly (the pilot).
    Pilot,
    /// The parents' measured DNA, mapped into surface measure through the
    /// [`SteeringMap`].
    Production,
}

/// The affine map from the surface DNA of a clone to the DNA measured on
/// its level set, fitted on pilot clones ([`crate::Params::pilot_clones`]),
/// per target descriptor ([`TARGETS`] order): `measured ≈ offset + slope ·
/// surface`, with the residual standard deviation.
///
/// A measured-space target `m*` is first pulled towards the parents' mean
/// by `shrink = √(1 − σ_res² / σ_parents²)` — so that the residual scatter
/// added on the way from surface to level set does not widen the clones'
/// distribution — and then steered as the surface target
/// `(m* − offset) / slope`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SteeringMap {
    /// Offsets.
    pub offset: [f64; 5],
    /// Slopes (> 0).
    pub slope: [f64; 5],
    /// Residual standard deviations of the fit.
    pub residual_sd: [f64; 5],
    /// Parents' measured means.
    pub parent_mean: [f64; 5],
    /// Variance-preserving pull factors in (0, 1].
    pub shrink: [f64; 5],
    /// Pilot clones the map was fitted on (0: identity map).
    pub pilot_clones: usize,
    /// Descriptors whose fit failed (slope not clearly positive) and which
    /// keep the identity map.
    pub unfitted: [bool; 5],
    /// Prediction of the level-set roundness from the surface roundness and
    /// the estimated inscribed radius over `r_min`
    /// ([`crate::MeshGeometry::inscribed_radius`]): `[c₀, c₁, c₂]` with
    /// `R ≈ c₀ + c₁ R_surface + c₂ r_ins / r_min`, least squares on the pilot
    /// clones (`None` without pilot or when `c₁` is not clearly positive).
    /// The level set's inscribed sphere sets the corner threshold and the
    /// scale of its roundness; the surface DNA's `r_min` stands for it, and
    /// their ratio is most of what the affine map leaves unexplained
    /// (residual 0.029 → 0.018 on Ottawa clones).
    #[serde(default)]
    pub roundness_prediction: Option<[f64; 3]>,
    /// Residual standard deviation of [`SteeringMap::roundness_prediction`].
    #[serde(default)]
    pub roundness_prediction_sd: f64,
}

impl SteeringMap {
    fn identity(parent_mean: [f64; 5]) -> Self {
        Self {
            offset: [0.0; 5],
            slope: [1.0; 5],
            residual_sd: [0.0; 5],
            parent_mean,
            shrink: [1.0; 5],
            pilot_clones: 0,
            unfitted: [false; 5],
            roundness_prediction: None,
            roundness_prediction_sd: 0.0,
        }
    }

    /// The measured-space target `m*` of descriptor `k` ([`TARGETS`] order)
    /// pulled towards the parents' mean (`mean + shrink · (m* − mean)`),
    /// before the affine map: what a check in measured space compares
    /// with.
    pub fn pulled(&self, k: usize, measured: f64) -> f64 {
        self.parent_mean[k] + self.shrink[k] * (measured - self.parent_mean[k])
    }

    /// The surface-measure target of a measured-space target.
    pub fn steer(&self, measured: &Targets) -> Targets {
        let m = measured.to_array();
        let mut out = [0.0; 5];
        for k in 0..5 {
            let pulled = self.parent_mean[k] + self.shrink[k] * (m[k] - self.parent_mean[k]);
            out[k] = (pulled - self.offset[k]) / self.slope[k];
        }
        Targets::from_array(out)
    }
}

/// One pilot clone: its surface DNA and measured DNA (target order) and its
/// estimated inscribed radius over the surface `r_min`.
/// The last entry is the surface roundness about the estimated inscribed
/// radius ([`MeshGeometry::roundness_about`]), the predictor of
/// `RoundnessCheck::Predicted`.
type PilotSample = ([f64; 5], [f64; 5], f64, f64);

/// Least squares `R ≈ c₀ + c₁ R_surface + c₂ ρ` over pilot clones
/// `(surface DNA, measured DNA, ρ = r_ins / r_min)` (roundness at index 3),
/// and its residual standard deviation; `None` for fewer than 8 finite
/// triples, a singular system or `c₁ ≤ 0.05`.
fn fit_roundness_prediction(
    triples: &[PilotSample],
    check: RoundnessCheck,
) -> (Option<[f64; 3]>, f64) {
    let rows: Vec<([f64; 3], f64)> = triples
        .iter()
        .map(|(s, m, rho, about)| {
            let r_surface = match check {
                RoundnessCheck::LevelSet => s[3],
                RoundnessCheck::Predicted => *about,
            };
            ([1.0, r_surface, *rho], m[3])
        })
        .filter(|(x, y)| x.iter().all(|v| v.is_finite()) && y.is_finite())
        .collect();
    if rows.len() < 8 {
        return (None, 0.0);
    }
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for (x, y) in &rows {
        let x = Vector3::from(*x);
        a += x * x.transpose();
        b += x * *y;
    }
    let Some(c) = a.lu().solve(&b) else {
        return (None, 0.0);
    };
    if !(c.iter().all(|v| v.is_finite()) && c[1] > 0.05) {
        return (None, 0.0);
    }
    let ss: f64 = rows
        .iter()
        .map(|(x, y)| (y - c.dot(&Vector3::from(*x))).powi(2))
        .sum();
    let sd = (ss / (rows.len() as f64 - 3.0).max(1.0)).sqrt();
    (Some([c[0], c[1], c[2]]), sd)
}

/// A surface roundness check needs the pilot's roundness prediction.
fn predicted_check_ready(params: &Params, map: &SteeringMap) -> Result<()> {
    if params.roundness_check == RoundnessCheck::Predicted
        && params.roundness_tolerance.is_some()
        && map.roundness_prediction.is_none()
    {
        return Err(Error::InvalidParameter {
            name: "roundness_check",
            value: map.pilot_clones as f64,
            reason: "Predicted: the pilot clones gave no roundness prediction (too few, or their surface roundness does not predict the measured one); use LevelSet",
        });
    }
    Ok(())
}

fn check_spread(what: &'static str, x: &[f64]) -> Result<()> {
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::ConstantParents { what, value: lo });
    }
    Ok(())
}

fn pearson_or_zero(a: &[f64], b: &[f64]) -> f64 {
    morph_dna::stats::pearson(a, b).map_or(0.0, |r| if r.is_finite() { r.max(0.0) } else { 0.0 })
}

/// Normal scores `Φ⁻¹((rank − ½)/P)`-type (average ranks over `P + 1`).
fn normal_scores(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut ranks = vec![0.0; n];
    let mut k = 0;
    while k < n {
        let mut e = k;
        while e + 1 < n && x[order[e + 1]] == x[order[k]] {
            e += 1;
        }
        let r = 0.5 * (k + e) as f64 + 1.0;
        for &o in &order[k..=e] {
            ranks[o] = r;
        }
        k = e + 1;
    }
    ranks
        .into_iter()
        .map(|r| morph_dna::stats::normal_quantile(r / (n as f64 + 1.0)))
        .collect()
}

impl CloneModel {
    /// Fits the model of `params` to the parents: radial profiles on the
    /// mesh (in each parent's principal frame), their surface DNA, the
    /// target sampler and the radii sampler.
    ///
    /// # Errors
    /// [`Params::validate`]'s errors, [`Error::TooManyBins`] for more bins
    /// than parents, [`Error::DegenerateParent`] for a parent whose radial
    /// profile or surface DNA cannot be computed (centroid outside the grain,
    /// a ray that never leaves it), [`Error::ConstantParents`] when a target
    /// descriptor or a node radius does not vary across parents.
    pub fn fit(parents: &Parents, params: &Params) -> Result<Self> {
        params.validate()?;
        let p = parents.len();
        if params.bins > p {
            return Err(Error::TooManyBins {
                bins: params.bins,
                parents: p,
            });
        }
        let geom = MeshGeometry::new(params.mesh);
        let n = geom.n_nodes();
        let measured: Vec<Result<(Vec<f64>, SurfaceDna)>> = parents
            .grids
            .par_iter()
            .zip(&parents.frames)
            .enumerate()
            .map(|(index, (g, f))| {
                let r =
                    radial_profile(g, f, &params.mesh).map_err(|e| Error::DegenerateParent {
                        index,
                        reason: e.to_string(),
                    })?;
                let s = geom
                    .surface_dna(&r, params.level_set_resolution, params.grid_margin)
                    .ok_or_else(|| Error::DegenerateParent {
                        index,
                        reason: "its radial profile is not a valid star surface".into(),
                    })?;
                Ok((r, s))
            })
            .collect();
        let mut profiles = Vec::with_capacity(p);
        let mut surface = Vec::with_capacity(p);
        for m in measured {
            let (r, s) = m?;
            profiles.push(r);
            surface.push(s);
        }
        // targets in surface-DNA measure
        let cols: Vec<Vec<f64>> = vec![
            surface.iter().map(SurfaceDna::aspect_ratio).collect(),
            surface.iter().map(|s| s.dims[2]).collect(),
            surface.iter().map(SurfaceDna::flatness).collect(),
            surface.iter().map(|s| s.roundness).collect(),
            surface
                .iter()
                .map(SurfaceDna::volume_surface_ratio)
                .collect(),
        ];
        for (d, c) in TARGETS.iter().zip(&cols) {
            check_spread(d.name(), c)?;
        }
        let bins = params.bins;
        let surface_targets = target_sampler(params.targets, &cols, bins)?;
        let measured_cols: Vec<Vec<f64>> = TARGET_IN_DNA
            .iter()
            .map(|&k| parents.dna.columns()[k].clone())
            .collect();
        for (d, c) in TARGETS.iter().zip(&measured_cols) {
            check_spread(d.name(), c)?;
        }
        let measured_targets = target_sampler(params.targets, &measured_cols, bins)?;
        let parent_mean = std::array::from_fn(|k| {
            measured_cols[k].iter().sum::<f64>() / measured_cols[k].len() as f64
        });
        let parent_sd: [f64; 5] =
            std::array::from_fn(|k| morph_dna::stats::sample_std(&measured_cols[k]).unwrap_or(0.0));
        // normalised radii ρ = r / r_ellipsoid per node
        let rho: Vec<Vec<f64>> = profiles
            .iter()
            .zip(&surface)
            .map(|(r, s)| {
                let semi = [0.5 * s.dims[0], 0.5 * s.dims[1], 0.5 * s.dims[2]];
                (0..n)
                    .map(|k| r[k] / geom.ellipsoid_radius(k, semi))
                    .collect()
            })
            .collect();
        let node_cols: Vec<Vec<f64>> = (0..n).map(|k| rho.iter().map(|r| r[k]).collect()).collect();
        for c in &node_cols {
            check_spread("normalised node radius", c)?;
        }
        let marginals = node_cols
            .iter()
            .map(|c| {
                Ok(InverseCdfSampler1d::from_histogram(&Histogram1d::new(
                    c, bins, None,
                )?)?)
            })
            .collect::<Result<Vec<_>>>()?;
        let radii = match params.radii {
            RadiiModel::SeedNeighbourhood => {
                let weights = (0..n)
                    .map(|k| match geom.neighbours(k) {
                        Some(nb) => nb.map(|m| pearson_or_zero(&node_cols[k], &node_cols[m])),
                        None => [0.0; 4],
                    })
                    .collect();
                RadiiSampler::Seed { marginals, weights }
            }
            RadiiModel::CopulaField { shrinkage } => {
                let scale = ((1.0 - shrinkage) / (p as f64 - 1.0)).sqrt();
                let mut factor = vec![0.0; p * n];
                for (k, c) in node_cols.iter().enumerate() {
                    let z = normal_scores(c);
                    let mean = z.iter().sum::<f64>() / p as f64;
                    let var =
                        z.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (p as f64 - 1.0);
                    let sd = var.sqrt();
                    for (g, v) in z.iter().enumerate() {
                        factor[g * n + k] = if sd > 0.0 {
                            (v - mean) / sd * scale
                        } else {
                            0.0
                        };
                    }
                }
                RadiiSampler::Copula {
                    marginals,
                    factor,
                    parents: p,
                    noise: shrinkage.sqrt(),
                }
            }
        };
        let face_cells = match StarParams::default().table {
            DirectionTable::CubeMap { face_cells } => face_cells,
            DirectionTable::Exact => 32,
        };
        let dirs = levelset::cube_map_directions(face_cells).map_err(Error::from)?;
        let cube = geom.plans(&dirs, params.interpolation);
        let mut model = Self {
            params: *params,
            cube,
            geom,
            surface,
            profiles,
            surface_targets,
            measured_targets,
            radii,
            map: SteeringMap::identity(parent_mean),
        };
        if params.pilot_clones > 0 {
            model.map = model.fit_steering_map(parent_mean, parent_sd)?;
        }
        predicted_check_ready(params, &model.map)?;
        Ok(model)
    }

    /// Pilot clones on reserved streams (`u64::MAX − i`), steered in surface
    /// measure, measured on their level sets; least-squares fit of measured
    /// on surface DNA per target descriptor.
    fn fit_steering_map(&self, parent_mean: [f64; 5], parent_sd: [f64; 5]) -> Result<SteeringMap> {
        let k = self.params.pilot_clones as u64;
        let samples: Vec<Result<PilotSample>> = (0..k)
            .into_par_iter()
            .map(|i| {
                let (c, _) = self.clone_with(
                    u64::MAX - i,
                    Mode::Pilot,
                    crate::params::Outputs {
                        level_set: false,
                        dna: true,
                    },
                    &crate::pipeline::NoClock,
                )?;
                let s = c.surface;
                let surf = [
                    s.aspect_ratio(),
                    s.dims[2],
                    s.flatness(),
                    s.roundness,
                    s.volume_surface_ratio(),
                ];
                let d = c.dna.unwrap_or_default();
                let meas =
                    std::array::from_fn(|t| d.get(TARGET_IN_DNA[t]).copied().unwrap_or(f64::NAN));
                let r_ins = self.geom.inscribed_radius(&c.radii).unwrap_or(f64::NAN);
                let (res, margin) = (self.params.level_set_resolution, self.params.grid_margin);
                let about = match self.params.roundness_check {
                    RoundnessCheck::LevelSet => f64::NAN,
                    RoundnessCheck::Predicted => {
                        self.geom.roundness_about(&c.radii, res, margin, r_ins)
                    }
                };
                Ok((surf, meas, r_ins / s.r_min, about))
            })
            .collect();
        let pairs = samples.into_iter().collect::<Result<Vec<_>>>()?;
        let (prediction, prediction_sd) =
            fit_roundness_prediction(&pairs, self.params.roundness_check);
        let mut map = SteeringMap::identity(parent_mean);
        map.pilot_clones = pairs.len();
        map.roundness_prediction = prediction;
        map.roundness_prediction_sd = prediction_sd;
        #[allow(clippy::needless_range_loop)] // t indexes five parallel arrays
        for t in 0..5 {
            let x: Vec<f64> = pairs.iter().map(|p| p.0[t]).collect();
            let y: Vec<f64> = pairs.iter().map(|p| p.1[t]).collect();
            let n = x.len() as f64;
            let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
            let sxx: f64 = x.iter().map(|v| (v - mx) * (v - mx)).sum();
            let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
            let slope = sxy / sxx;
            if !(slope.is_finite() && slope > 0.05) {
                // the surface DNA does not predict the measured one: keep
                // the identity for this descriptor and say so
                map.unfitted[t] = true;
                continue;
            }
            let offset = my - slope * mx;
            let ss: f64 = x
                .iter()
                .zip(&y)
                .map(|(a, b)| (b - offset - slope * a).powi(2))
                .sum();
            let mut res = (ss / (n - 2.0).max(1.0)).sqrt();
            // a level-set roundness check truncates the roundness scatter to
            // ±tolerance (a uniform-like residual of sd ≈ tol / √3)
            if t == 3
                && let Some(rt) = self.params.roundness_tolerance
            {
                res = match self.params.roundness_check {
                    RoundnessCheck::LevelSet => res.min(rt / 3f64.sqrt()),
                    // the surface check truncates the predicted roundness to
                    // ±margin·tolerance; the prediction's own residual adds
                    RoundnessCheck::Predicted => {
                        let w = self.params.roundness_prediction_margin * rt;
                        res.min((prediction_sd * prediction_sd + w * w / 3.0).sqrt())
                    }
                };
            }
            map.offset[t] = offset;
            map.slope[t] = slope;
            map.residual_sd[t] = res;
            let ratio = if parent_sd[t] > 0.0 {
                res / parent_sd[t]
            } else {
                0.0
            };
            map.shrink[t] = (1.0 - ratio * ratio).max(0.25).sqrt();
        }
        Ok(map)
    }

    /// The fitted steering map (identity without pilot clones).
    pub fn steering_map(&self) -> &SteeringMap {
        &self.map
    }

    /// The parameters the model was fitted with.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The mesh geometry.
    pub fn geometry(&self) -> &MeshGeometry {
        &self.geom
    }

    /// Surface DNA of every parent's radial profile.
    pub fn parent_surface_dna(&self) -> &[SurfaceDna] {
        &self.surface
    }

    /// Every parent's radii at the mesh nodes (principal frame).
    pub fn parent_profiles(&self) -> &[Vec<f64>] {
        &self.profiles
    }

    /// One production draw of a candidate's targets, as [`CloneModel::run`]
    /// draws them: `(targets in the parents' measure, steering targets in
    /// surface measure)`; `None` when the draw found a conditional slice
    /// without mass (the run draws again). For stage benches and studies of
    /// the target model.
    pub fn draw_targets(&self, rng: &mut impl Rng) -> Option<(Targets, Targets)> {
        self.sample_targets(Mode::Production, rng).ok()
    }

    /// One draw of a candidate's normalised node radii (ratios to the
    /// embryo ellipsoid, flat node order of the mesh) into `out`, as
    /// [`CloneModel::run`] draws them.
    pub fn draw_radii(&self, rng: &mut impl Rng, out: &mut Vec<f64>) {
        self.sample_radii(rng, out);
    }

    /// Draws the targets of one candidate: `(measured-space targets,
    /// surface-measure steering targets)`; in the pilot both are the
    /// surface targets.
    pub(crate) fn sample_targets(
        &self,
        mode: Mode,
        rng: &mut impl Rng,
    ) -> std::result::Result<(Targets, Targets), TargetUnavailable> {
        match mode {
            Mode::Pilot => {
                let t = self.surface_targets.sample(rng)?;
                Ok((t, t))
            }
            Mode::Production => {
                let t = self.measured_targets.sample(rng)?;
                let mut s = self.map.steer(&t);
                s.flatness = s.flatness.max(s.aspect_ratio);
                // a roundness beyond 1 is met by the smoothest surface
                s.roundness = s.roundness.min(1.0);
                if s.to_array().iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                    return Err(TargetUnavailable);
                }
                Ok((t, s))
            }
        }
    }

    /// Draws the normalised node radii of one candidate into `out`.
    pub(crate) fn sample_radii(&self, rng: &mut impl Rng, out: &mut Vec<f64>) {
        let n = self.geom.n_nodes();
        out.clear();
        match &self.radii {
            RadiiSampler::Seed { marginals, weights } => {
                for k in 0..n {
                    let own = marginals[k].sample(rng);
                    match self.geom.neighbours(k) {
                        Some(nb) => {
                            let w = weights[k];
                            let mut s = own;
                            let mut sw = 1.0;
                            for (m, wm) in nb.iter().zip(w) {
                                s += wm * marginals[*m].sample(rng);
                                sw += wm;
                            }
                            out.push(s / sw);
                        }
                        None => out.push(own),
                    }
                }
            }
            RadiiSampler::Copula {
                marginals,
                factor,
                parents,
                noise,
            } => {
                let xi: Vec<f64> = (0..*parents).map(|_| StandardNormal.sample(rng)).collect();
                out.resize(n, 0.0);
                for (g, x) in xi.iter().enumerate() {
                    let row = &factor[g * n..(g + 1) * n];
                    for (o, f) in out.iter_mut().zip(row) {
                        *o += x * f;
                    }
                }
                for (k, o) in out.iter_mut().enumerate() {
                    let e: f64 = StandardNormal.sample(rng);
                    let z = *o + noise * e;
                    *o = marginals[k].quantile(morph_dna::stats::normal_cdf(z));
                }
            }
        }
    }
}

/// The level set of a spherical-harmonic grain (e.g. a NIST/VCCTL scan): a
/// cube of `resolution³` nodes spanning `±margin · r_max` about the model's
/// centre, `r_max` from a 65 × 128 direction sample (the construction of
/// `cargo xtask dna`).
///
/// # Errors
/// [`Error::InvalidParameter`] for a margin outside (1, 4]; SH evaluation
/// errors ([`Error::DegenerateParent`] with index 0) and level-set errors.
pub fn grid_from_sh(
    model: &sph_harmonics::ShModel,
    resolution: usize,
    margin: f64,
) -> Result<Grid> {
    if !(margin.is_finite() && margin > 1.0 && margin <= 4.0) {
        return Err(Error::InvalidParameter {
            name: "margin",
            value: margin,
            reason: "in (1, 4]",
        });
    }
    let sh = |e: sph_harmonics::Error| Error::DegenerateParent {
        index: 0,
        reason: e.to_string(),
    };
    let mut dirs = Vec::with_capacity(65 * 128);
    for i in 0..=64 {
        for j in 0..128 {
            dirs.push((
                std::f64::consts::PI * i as f64 / 64.0,
                std::f64::consts::TAU * j as f64 / 128.0,
            ));
        }
    }
    let r_max = model
        .evaluate(&dirs)
        .map_err(sh)?
        .into_iter()
        .fold(0.0f64, f64::max);
    let spec = levelset::GridSpec::cube(resolution, -margin * r_max, margin * r_max)?;
    let radius = |u: nalgebra::Unit<nalgebra::Vector3<f64>>| {
        let (theta, phi) = sph_harmonics::model::to_angles(&u.into_inner());
        model.radius(theta, phi).unwrap_or(f64::NAN)
    };
    let (grid, _) = Grid::from_star(
        spec,
        &nalgebra::Point3::origin(),
        radius,
        &levelset::StarParams::default(),
    )?;
    Ok(grid)
}

/// The level set of a closed triangle mesh of one grain (e.g. a Sand Atlas
/// or LS-DEM STL): a cube of `resolution³` nodes spanning `±margin · r_max`
/// about the mesh's volume centroid, `r_max` the farthest vertex from it —
/// the construction of [`grid_from_sh`], so mesh and SH parents are
/// rasterised alike — with the exact signed distance of the mesh within
/// `levelset::MESH_BAND_CELLS` cells of the surface and a swept far field of
/// exact sign ([`Grid::from_mesh_banded`]: 3–6× faster than the exact
/// [`Grid::from_mesh`], with identical volume, area and mass properties).
///
/// The mesh must be closed and outward oriented (see
/// `levelset::TriMesh::prepare_closed`, which checks and repairs it).
///
/// # Errors
/// [`Error::InvalidParameter`] for a margin outside (1, 4];
/// [`Error::DegenerateParent`] (index 0) for a mesh of non-positive or
/// non-finite volume; level-set errors (an open mesh).
pub fn grid_from_mesh(mesh: &levelset::TriMesh, resolution: usize, margin: f64) -> Result<Grid> {
    if !(margin.is_finite() && margin > 1.0 && margin <= 4.0) {
        return Err(Error::InvalidParameter {
            name: "margin",
            value: margin,
            reason: "in (1, 4]",
        });
    }
    let degenerate = |reason: String| Error::DegenerateParent { index: 0, reason };
    let volume = mesh.signed_volume();
    if !(volume.is_finite() && volume > 0.0) {
        return Err(degenerate(format!(
            "mesh volume {volume} (not closed, inverted or flat)"
        )));
    }
    let centre = mesh.centroid()?;
    let spec = levelset::GridSpec::around_points(mesh.vertices(), centre, resolution, margin)?;
    Ok(Grid::from_mesh_banded(
        spec,
        mesh,
        levelset::MESH_BAND_CELLS,
    )?)
}
