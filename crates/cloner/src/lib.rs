//! Geometric Stochastic Cloning 2.0 (Medina 2018, after Jerves et al. 2017):
//! new grains statistically indistinguishable from real parents.
//!
//! # Pipeline
//!
//! [`Parents::from_grids`] measures the parents' DNA ([`DNA`]) and principal
//! frames; [`CloneModel::fit`] builds the population model for [`Params`]:
//! each parent's radii on the `n_az × (n_pol + 2)` spherical mesh aligned with
//! its principal axes (`morph_dna::radial_profile`), their surface DNA
//! ([`surface`]), a target sampler ([`TargetModel`]) and a radii sampler
//! ([`RadiiModel`]). [`CloneModel::run`] then clones an index range in
//! parallel: embryo ellipsoid from the sampled aspect ratio and minimum
//! principal dimension, correlated node radii, Laplacian polishing to the
//! sampled roundness, the volume/surface quality control, the roundness
//! check, and — only for accepted candidates and only if asked for
//! ([`Outputs`]) — the level set
//! (`levelset::Grid::from_star`) and its measured DNA. The stages and their
//! rejection order are documented in [`pipeline`].
//!
//! # Design choices the seed leaves open
//!
//! * **Normalised radii.** Node radii are sampled as ratios `ρ = r / r_ell`
//!   to the parent's own inertia-equivalent ellipsoid, so size and aspect
//!   ratio come from the embryo and the node distributions carry only the
//!   shape's deviation from it; the Laplacian polishes `ρ`, so it rounds the
//!   grain without shrinking the embryo.
//! * **The intermediate axis** (the seed samples only aspect ratio and `S`)
//!   comes from the flatness `S / I`, drawn with the other targets.
//! * **Steering measure.** Polishing and the quality control compare the
//!   candidate's *surface DNA* (computed from its node radii in
//!   microseconds) with its targets, so no level set is built for a rejected
//!   candidate. Targets are drawn from the parents' DNA *measured on their
//!   level sets* and mapped into surface measure by a [`SteeringMap`] fitted
//!   on pilot clones (`Params::pilot_clones`; the map's pull towards the mean
//!   keeps the surface-to-level-set scatter from widening the clones'
//!   distributions). Accepted clones are measured on their level sets exactly
//!   like the parents (`morph_dna::measure`), and that is what calibration
//!   compares.
//! * **Rejection without tilt.** The targets are held for up to
//!   `Params::fields_per_target` radii fields, so the quality control does
//!   not favour easy targets; a candidate rounder than its target is sharpened
//!   (inverse Laplacian steps) instead of rejected; an optional level-set
//!   roundness check (`Params::roundness_tolerance`) removes the residual
//!   scatter of the surface roundness, and re-steered repairs
//!   (`Params::roundness_repairs`) rescue the candidates it would reject;
//!   predicted-roundness passes (`Params::roundness_predictions`) re-steer
//!   before the level set is built, from a pilot-fitted prediction that adds
//!   the estimated inscribed radius to the surface roundness.
//! * **Roundness checked on the surface** ([`RoundnessCheck::Predicted`],
//!   the committed Ottawa calibration since issue 30): the check holds the
//!   *predicted* level-set roundness — least squares on the pilot clones'
//!   level sets of the surface roundness computed about the estimated
//!   inscribed radius, as `morph-dna` computes it about the level set's — to
//!   the target pulled towards the parents' mean by the prediction's
//!   residual, so a clone needs no level set at all (≈ 0.1 ms of surface
//!   measures instead of a 45³ level set and its roundness, ≈ 6 ms). The
//!   level-set check ([`RoundnessCheck::LevelSet`]) stays selectable. A run
//!   rasterises only what its [`Outputs`] ask for; a calibration scores its
//!   clones afterwards ([`CloneModel::measure_dna`]), outside the cloning.
//! * **Seed methods kept.** [`Params::seed_faithful`] selects the seed's
//!   pairwise-PDF targets, neighbourhood-averaged radii, bilinear
//!   interpolation and untouched embryo axes, for comparison.
//!
//! # Determinism
//!
//! Clone `i` draws from [`clone_rng`]`(seed, i)` only; a run's clones (and
//! every count of its statistics) are identical for any thread count and for
//! any sharding of the index range ([`shard_range`]).
//!
//! # Example
//!
//! ```
//! use cloner::{CloneModel, Hooks, Params, Parents};
//! use levelset::{Grid, GridSpec, StarParams};
//! use levelset::nalgebra::Point3;
//! use morph_dna::{MeasureParams, SphericalMesh};
//!
//! // twelve bumpy ellipsoidal "parents" of varying size and shape
//! let parents: Vec<Grid> = (0..12)
//!     .map(|k| {
//!         let (a, b, c) = (1.0 + 0.04 * k as f64, 0.8, 0.55 + 0.03 * (k % 5) as f64);
//!         let radius = move |u: levelset::nalgebra::Unit<levelset::nalgebra::Vector3<f64>>| {
//!             let e = 1.0 / ((u.x / a).powi(2) + (u.y / b).powi(2) + (u.z / c).powi(2)).sqrt();
//!             e * (1.0 + 0.04 * (3.0 * u.x + k as f64).sin() * (2.0 * u.y).cos())
//!         };
//!         let spec = GridSpec::cube(24, -1.7, 1.7).unwrap();
//!         Grid::from_star(spec, &Point3::origin(), radius, &StarParams::default()).unwrap().0
//!     })
//!     .collect();
//! let parents = Parents::from_grids(parents, &MeasureParams::default())?;
//! let params = Params {
//!     mesh: SphericalMesh { n_az: 12, n_pol: 6 },
//!     bins: 6,
//!     level_set_resolution: 24,
//!     tolerance: 0.05,
//!     ..Params::default()
//! };
//! let model = CloneModel::fit(&parents, &params)?;
//! let run = model.run(0..4, Hooks::default())?;
//! assert_eq!(run.clones.len(), 4);
//! # Ok::<(), cloner::Error>(())
//! ```
//!
//! # References
//!
//! * Medina, D. (2018). A geometry-based algorithm for cloning real grains
//!   2.0. USFQ thesis.
//! * Jerves, A. X., Kawamoto, R. Y., Andrade, J. E. (2017). A geometry-based
//!   algorithm for cloning real grains. Granular Matter 19(2),
//!   doi:10.1007/s10035-017-0716-7.
//! * Vlahinić, I., Andò, E., Viggiani, G., Andrade, J. E. (2014). Towards a
//!   more accurate characterization of granular media: extracting quantitative
//!   descriptors from tomographic images. Granular Matter 16, 9–21,
//!   doi:10.1007/s10035-013-0460-6.
//!
//! Layer 2: depends on `morph-dna`, `levelset` (and may use `sph-harmonics`).

pub mod calibration;
pub mod error;
pub mod model;
pub mod output;
pub mod params;
pub mod pipeline;
mod rejections;
pub mod surface;

pub use calibration::{Calibrated, Scores, score};
pub use error::{Error, Result};
pub use model::{
    CloneModel, DNA, MIN_PARENTS, Parents, SteeringMap, TABLES_4_5, TARGETS, Targets,
    grid_from_mesh, grid_from_sh,
};
pub use output::{Format, write_grid};
pub use params::{Outputs, Params, RadiiModel, RoundnessCheck, Smoothing, TargetModel};
pub use pipeline::{
    Clock, ClonedGrain, Hooks, NoClock, Progress, Rejections, Run, RunStats, StageTimes, clone_rng,
    shard_range,
};
pub use surface::{DirectionPlan, Interpolation, MeshGeometry, SurfaceDna};
