//! The cloning pipeline (Medina 2018, §2.2–2.5), one function per stage, and
//! the parallel, deterministic driver.
//!
//! A candidate for clone index `i` runs, on the random stream `(seed, i)`:
//!
//! 1. **targets** — aspect ratio, `S`, flatness, roundness and the
//!    quality-control V/S from the population model ([`crate::TargetModel`]);
//!    the embryo is the ellipsoid with semi-axes `(L, I, S)/2`. The targets
//!    are kept for up to `fields_per_target` candidates and only the radii
//!    are redrawn after a rejection, so the quality control tilts the
//!    accepted targets towards the easy ones far less than the seed's
//!    `fields_per_target = 1` (redraw everything). Redrawing the V/S target
//!    with every field (conditional on the other four) was tried and is
//!    worse: it accepts V/S from the product of the construction's and the
//!    parents' conditional densities (mean V/S error 7.5 % against 2.4 % on
//!    the Ottawa parents);
//! 2. **radii** — normalised node radii `ρ` ([`crate::RadiiModel`]); the
//!    candidate's radii are `r = r_ellipsoid · ρ`;
//! 3. **polishing** — umbrella-Laplacian steps on `ρ` until the surface
//!    roundness reaches the target (the last step is interpolated so the
//!    target is met, not overshot), or, for a raw candidate already rounder
//!    than its target, inverse steps that sharpen it (`max_sharpening`; the
//!    seed can only smooth and rejects such candidates); rejected after
//!    `max_iterations` / `max_sharpening` steps;
//! 4. **quality control** — optional fixed-point corrections of the embryo
//!    axes so the surface's principal dimensions meet the targets, then the
//!    V/S test `|V/S − V/S*| ≤ tol · V/S*` (Medina 2018, §2.4);
//! 5. **rasterisation** of accepted candidates (only if a level set or DNA
//!    was asked for) through `levelset::Grid::from_star`;
//! 6. **DNA** of the level set through a `morph_dna::Measurement` (only if asked
//!    for, or if `roundness_tolerance` is set: then a clone whose measured
//!    roundness misses its target by more than that is rejected too, which
//!    removes the scatter between the cheap surface roundness and the
//!    level-set one at the price of rasterising the rejected candidates).
//!    The roundness is measured first, alone; an accepted clone's other
//!    descriptors reuse the surface it extracted (no second pass over the
//!    grid; the same values as measuring them alone).
//!    With `roundness_repairs` > 0 a miss first re-steers the candidate: the
//!    same raw field is polished again toward a surface roundness moved
//!    against the miss (divided by the steering map's slope), then stages
//!    4–6 run again. The miss of one radii field is mostly its own bias
//!    between the two roundness measures, so one repair rescues nearly all
//!    of them (calibration: measured-roundness rejections 636 → 19 per 500
//!    clones) instead of paying a new search of ≈ 40 candidates; no random
//!    draws, so determinism is unchanged.
//!    With `roundness_predictions` > 0 the candidate is first re-steered the
//!    same way *before* stage 5 while the level-set roundness predicted from
//!    its surface ([`crate::SteeringMap::roundness_prediction`]: the surface
//!    roundness and the estimated inscribed radius over `r_min`) misses by
//!    more than `roundness_prediction_margin` × the tolerance: a pass costs a polish and the surface
//!    DNA instead of a level set and its roundness (calibration: repairs
//!    208 → 87 per 500 clones, 18 % less CPU per clone).
//!
//! Candidates are rejected in this order, so a rejection costs only the
//! stages before it. The library reads no clock: stage times come from the
//! caller's [`Clock`].

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

use levelset::{Grid, GridSpec, StarParams};
use morph_dna::{Descriptor, DnaTable, MeasureParams, Measurement};
use nalgebra::Point3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::{CloneModel, DNA, Mode, Targets};
use crate::params::{Outputs, RoundnessCheck};
pub use crate::rejections::Rejections;
use crate::surface::SurfaceDna;

/// A monotonic clock supplied by the caller (the library reads none).
pub trait Clock: Sync {
    /// Nanoseconds since an arbitrary fixed origin.
    fn now_ns(&self) -> u64;
}

/// A clock that always reads 0 (no timings).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoClock;

impl Clock for NoClock {
    fn now_ns(&self) -> u64 {
        0
    }
}

/// Progress of a run, passed to the caller's callback after every finished
/// clone index (from worker threads, in completion order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Clone indices finished so far.
    pub done: u64,
    /// Clone indices of the run.
    pub total: u64,
}

/// Callbacks and clock of a run.
#[derive(Clone, Copy)]
pub struct Hooks<'a> {
    /// Stage timings come from this clock.
    pub clock: &'a dyn Clock,
    /// Called after every finished clone index.
    pub progress: Option<&'a (dyn Fn(Progress) + Sync)>,
}

impl std::fmt::Debug for Hooks<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hooks")
            .field("progress", &self.progress.is_some())
            .finish_non_exhaustive()
    }
}

impl Default for Hooks<'_> {
    fn default() -> Self {
        Self {
            clock: &NoClock,
            progress: None,
        }
    }
}

impl Rejections {
    fn count(&mut self, r: Reject) {
        match r {
            Reject::TargetUnavailable => self.target_unavailable += 1,
            Reject::TooRound => self.too_round += 1,
            Reject::RoundnessUnreached => self.roundness_unreached += 1,
            Reject::Degenerate => self.degenerate += 1,
            Reject::QualityControl => self.quality_control += 1,
            Reject::MeasuredRoundness => self.measured_roundness += 1,
            Reject::PredictedRoundness => self.predicted_roundness += 1,
        }
    }

    fn add(&mut self, o: &Self) {
        self.target_unavailable += o.target_unavailable;
        self.too_round += o.too_round;
        self.roundness_unreached += o.roundness_unreached;
        self.degenerate += o.degenerate;
        self.quality_control += o.quality_control;
        self.measured_roundness += o.measured_roundness;
        self.predicted_roundness += o.predicted_roundness;
    }
}

/// Time spent per stage, summed over threads, in nanoseconds (all zero with
/// [`NoClock`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct StageTimes {
    /// Target draws.
    pub targets_ns: u64,
    /// Radii draws.
    pub radii_ns: u64,
    /// Laplacian polishing.
    pub polishing_ns: u64,
    /// Axis correction and quality control.
    pub quality_ns: u64,
    /// Level-set rasterisation.
    pub rasterise_ns: u64,
    /// DNA measurement of the level set.
    pub measure_ns: u64,
}

impl StageTimes {
    /// Sum of all stages.
    pub fn total_ns(&self) -> u64 {
        self.targets_ns
            + self.radii_ns
            + self.polishing_ns
            + self.quality_ns
            + self.rasterise_ns
            + self.measure_ns
    }

    fn add(&mut self, o: &Self) {
        self.targets_ns += o.targets_ns;
        self.radii_ns += o.radii_ns;
        self.polishing_ns += o.polishing_ns;
        self.quality_ns += o.quality_ns;
        self.rasterise_ns += o.rasterise_ns;
        self.measure_ns += o.measure_ns;
    }
}

/// Statistics of a run (or of one clone).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct RunStats {
    /// Accepted clones.
    pub accepted: u64,
    /// Candidates drawn.
    pub attempts: u64,
    /// Rejected candidates by reason.
    pub rejections: Rejections,
    /// Laplacian steps over all candidates.
    pub polishing_steps: u64,
    /// Re-steered polishing passes after a measured-roundness miss
    /// (`Params::roundness_repairs`).
    #[serde(default)]
    pub roundness_repairs: u64,
    /// Re-steered polishing passes on a predicted-roundness miss, before any
    /// level set (`Params::roundness_predictions`).
    #[serde(default)]
    pub roundness_predictions: u64,
    /// Level sets rasterised (first passes and repairs): the dominant cost
    /// of a run, independent of the machine.
    #[serde(default)]
    pub level_sets: u64,
    /// Stage times.
    pub times: StageTimes,
}

impl RunStats {
    /// Accepted over attempted candidates.
    pub fn acceptance_rate(&self) -> f64 {
        if self.attempts == 0 {
            0.0
        } else {
            self.accepted as f64 / self.attempts as f64
        }
    }

    fn add(&mut self, o: &Self) {
        self.accepted += o.accepted;
        self.attempts += o.attempts;
        self.rejections.add(&o.rejections);
        self.polishing_steps += o.polishing_steps;
        self.roundness_repairs += o.roundness_repairs;
        self.roundness_predictions += o.roundness_predictions;
        self.level_sets += o.level_sets;
        self.times.add(&o.times);
    }
}

/// A clone's level set, alone or inside the measurement that holds its
/// surface and measured descriptors.
enum Held {
    Grid(Grid),
    Measured(Box<Measurement<'static>>),
}

impl Held {
    fn into_grid(self) -> Grid {
        match self {
            Self::Grid(g) => g,
            Self::Measured(m) => m.into_grid(),
        }
    }
}

/// One accepted clone.
#[derive(Debug, Clone, PartialEq)]
pub struct ClonedGrain {
    /// Clone index (its random stream).
    pub index: u64,
    /// Candidates drawn for this index.
    pub attempts: usize,
    /// Radii at the mesh nodes (flat order of `morph_dna::SphericalMesh`),
    /// in the clone's frame: major axis +x, minor axis +z, centre at the
    /// origin.
    pub radii: Vec<f64>,
    /// The sampled targets, in the measure of the parents' DNA (level sets).
    pub targets: Targets,
    /// The same targets in surface-DNA measure (what polishing and the
    /// quality control steered to; see [`crate::model::SteeringMap`]).
    pub steering: Targets,
    /// Surface DNA of the accepted radii.
    pub surface: SurfaceDna,
    /// The clone's level set, if [`crate::Outputs::level_set`].
    pub grid: Option<Grid>,
    /// The clone's [`DNA`] measured on its level set, if
    /// [`crate::Outputs::dna`].
    pub dna: Option<Vec<f64>>,
}

/// The result of [`CloneModel::run`].
#[derive(Debug, Clone)]
pub struct Run {
    /// Accepted clones in index order.
    pub clones: Vec<ClonedGrain>,
    /// Totals over the run.
    pub stats: RunStats,
}

impl Run {
    /// The clones' measured [`DNA`] as a table.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the run did not measure DNA; table
    /// errors.
    pub fn dna_table(&self) -> Result<DnaTable> {
        let mut t = DnaTable::new(DNA.to_vec())?;
        for c in &self.clones {
            let Some(d) = &c.dna else {
                return Err(Error::InvalidParameter {
                    name: "outputs.dna",
                    value: 0.0,
                    reason: "the run must measure DNA for a DNA table",
                });
            };
            t.push_row(d)?;
        }
        Ok(t)
    }
}

impl CloneModel {
    /// The [`DNA`] of each clone measured on its level set at the model's
    /// resolution ([`CloneModel::rasterise`], then `morph_dna::measure`, in
    /// parallel): the values a run with [`crate::Outputs::dna`] stores, bit
    /// for bit, for clones made without them (a calibration scores its clones
    /// this way, outside the cloning it times). Rows in the order of `clones`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for radii of the wrong length or not
    /// finite and positive; level-set and measurement errors of the first
    /// failing clone.
    pub fn measure_dna(&self, clones: &[ClonedGrain]) -> Result<DnaTable> {
        let rows: Vec<Result<Vec<f64>>> = clones
            .par_iter()
            .map(|c| {
                let g = self.rasterise(&c.radii)?;
                let mut m = Measurement::owned(g, &MeasureParams::default())?;
                Ok(m.get(&DNA)?)
            })
            .collect();
        let mut t = DnaTable::new(DNA.to_vec())?;
        for r in rows {
            t.push_row(&r?)?;
        }
        Ok(t)
    }
}

/// The index range of shard `k` of `n` (1-based) of `0..total`: contiguous,
/// the first `total mod n` shards one longer. Shards together are exactly
/// `0..total`, so a sharded run equals the unsharded one.
///
/// # Errors
/// [`Error::InvalidShard`].
pub fn shard_range(total: u64, k: u64, n: u64) -> Result<Range<u64>> {
    if n == 0 || k == 0 || k > n {
        return Err(Error::InvalidShard { k, n });
    }
    let base = total / n;
    let extra = total % n;
    let start = (k - 1) * base + (k - 1).min(extra);
    let len = base + u64::from(k <= extra);
    Ok(start..start + len)
}

/// The random stream of clone `index`: ChaCha8 seeded with `seed`, stream
/// `index` (portable and independent of thread count and sharding).
pub fn clone_rng(seed: u64, index: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    rng
}

enum Reject {
    TargetUnavailable,
    TooRound,
    RoundnessUnreached,
    Degenerate,
    QualityControl,
    MeasuredRoundness,
    PredictedRoundness,
}

struct Candidate {
    radii: Vec<f64>,
    targets: Targets,
    steering: Targets,
    surface: SurfaceDna,
    /// The embryo's semi-axes (before axis corrections) and the raw field's
    /// surface roundness, for a re-steered pass ([`CloneModel::shape`]).
    semi: [f64; 3],
    raw_roundness: Option<f64>,
}

struct Scratch {
    rho: Vec<f64>,
    raw: Vec<f64>,
    prev: Vec<f64>,
    next: Vec<f64>,
    r_ell: Vec<f64>,
    r: Vec<f64>,
}

impl CloneModel {
    fn radii_from(&self, r_ell: &[f64], rho: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(r_ell.iter().zip(rho).map(|(a, b)| a * b));
    }

    fn ellipsoid(&self, semi: [f64; 3], out: &mut Vec<f64>) {
        out.clear();
        out.extend((0..self.geom.n_nodes()).map(|k| self.geom.ellipsoid_radius(k, semi)));
    }

    /// Stages 1–4 for one candidate.
    fn candidate(
        &self,
        rng: &mut ChaCha8Rng,
        s: &mut Scratch,
        stats: &mut RunStats,
        clock: &dyn Clock,
        mode: Mode,
        held: &mut Option<(Targets, Targets)>,
    ) -> std::result::Result<Candidate, Reject> {
        let p = &self.params;
        let (res, margin) = (p.level_set_resolution, p.grid_margin);
        let t0 = clock.now_ns();
        let (goal_targets, targets) = match held {
            Some(t) => *t,
            None => {
                let t = self
                    .sample_targets(mode, rng)
                    .map_err(|_| Reject::TargetUnavailable)?;
                *held = Some(t);
                t
            }
        };
        let semi = targets.semi_axes();
        self.ellipsoid(semi, &mut s.r_ell);
        let t1 = clock.now_ns();
        stats.times.targets_ns += t1 - t0;
        self.sample_radii(rng, &mut s.rho);
        let t2 = clock.now_ns();
        stats.times.radii_ns += t2 - t1;
        let goal = targets.roundness;
        s.raw.clone_from(&s.rho);
        // early rejection: smoothing only raises V/S, so a raw candidate that
        // needs smoothing and is already well above its V/S target fails
        let mut raw_roundness = None;
        if p.axis_corrections > 0 {
            self.radii_from(&s.r_ell, &s.raw, &mut s.r);
            if let Some(raw) = self.geom.surface_dna(&s.r, res, margin) {
                let ratio = raw.volume_surface_ratio() / raw.dims[2];
                let want = targets.volume_surface_ratio / targets.min_dimension;
                if raw.roundness < goal && ratio > want * (1.0 + 3.0 * p.tolerance) {
                    stats.times.polishing_ns += clock.now_ns() - t2;
                    return Err(Reject::QualityControl);
                }
                raw_roundness = Some(raw.roundness);
            }
        }
        stats.times.polishing_ns += clock.now_ns() - t2;
        self.shape(goal_targets, targets, semi, raw_roundness, s, stats, clock)
    }

    /// Polishing of the raw field `s.raw` on the embryo `s.r_ell` (of
    /// semi-axes `semi`) toward the surface goals `targets`, axis correction
    /// and quality control; no random draws.
    #[allow(clippy::too_many_arguments)]
    fn shape(
        &self,
        goal_targets: Targets,
        targets: Targets,
        semi: [f64; 3],
        raw_roundness: Option<f64>,
        s: &mut Scratch,
        stats: &mut RunStats,
        clock: &dyn Clock,
    ) -> std::result::Result<Candidate, Reject> {
        let p = &self.params;
        let (res, margin) = (p.level_set_resolution, p.grid_margin);
        let goal = targets.roundness;
        let t2 = clock.now_ns();
        let polished = self.polish(goal, raw_roundness, s, stats);
        let t3 = clock.now_ns();
        stats.times.polishing_ns += t3 - t2;
        polished?;
        // axis correction and quality control
        let result = (|| {
            // the quality control needs no curvature: moments and area only,
            // the full surface DNA once for an accepted candidate
            self.radii_from(&s.r_ell, &s.rho, &mut s.r);
            let mut surf = self
                .geom
                .surface_dna_with(&s.r, res, margin, false)
                .ok_or(Reject::Degenerate)?;
            // early rejection on the scale-free ratio (V/S)/S, which the axis
            // corrections barely change: 3× the tolerance
            let ratio = surf.volume_surface_ratio() / surf.dims[2];
            let want_ratio = targets.volume_surface_ratio / targets.min_dimension;
            if p.axis_corrections > 0 && (ratio - want_ratio).abs() > 3.0 * p.tolerance * want_ratio
            {
                return Err(Reject::QualityControl);
            }
            let goal_dims = [2.0 * semi[0], 2.0 * semi[1], 2.0 * semi[2]];
            let mut semi_c = semi;
            for _ in 0..p.axis_corrections {
                for a in 0..3 {
                    semi_c[a] *= goal_dims[a] / surf.dims[a];
                }
                self.ellipsoid(semi_c, &mut s.r_ell);
                self.radii_from(&s.r_ell, &s.rho, &mut s.r);
                surf = self
                    .geom
                    .surface_dna_with(&s.r, res, margin, false)
                    .ok_or(Reject::Degenerate)?;
            }
            let vs = surf.volume_surface_ratio();
            let want = targets.volume_surface_ratio;
            if (vs - want).abs() > p.tolerance * want {
                return Err(Reject::QualityControl);
            }
            let surf = self
                .geom
                .surface_dna(&s.r, res, margin)
                .ok_or(Reject::Degenerate)?;
            Ok(Candidate {
                radii: s.r.clone(),
                targets: goal_targets,
                steering: targets,
                surface: surf,
                semi,
                raw_roundness,
            })
        })();
        stats.times.quality_ns += clock.now_ns() - t3;
        result
    }

    /// Laplacian polishing of `s.raw` until the surface roundness reaches
    /// `goal`, the last step interpolated; the result is in `s.rho`.
    fn polish(
        &self,
        goal: f64,
        raw_roundness: Option<f64>,
        s: &mut Scratch,
        stats: &mut RunStats,
    ) -> std::result::Result<(), Reject> {
        let p = &self.params;
        let (res, margin) = (p.level_set_resolution, p.grid_margin);
        let mut r_prev = match raw_roundness {
            Some(r) => r,
            None => {
                self.radii_from(&s.r_ell, &s.raw, &mut s.r);
                self.geom.roundness(&s.r, res, margin)
            }
        };
        if r_prev > goal {
            return self.sharpen(goal, r_prev, s, stats);
        }
        s.prev.clone_from(&s.raw);
        if r_prev >= goal {
            s.rho.clone_from(&s.raw);
            return Ok(());
        }
        for _ in 0..p.smoothing.max_iterations {
            s.next.resize(s.prev.len(), 0.0);
            self.geom
                .smooth_into(&s.prev, p.smoothing.lambda, &mut s.next);
            stats.polishing_steps += 1;
            self.radii_from(&s.r_ell, &s.next, &mut s.r);
            let r_next = self.geom.roundness(&s.r, res, margin);
            if r_next >= goal {
                let alpha = if r_next > r_prev {
                    ((goal - r_prev) / (r_next - r_prev)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                s.rho.clear();
                s.rho
                    .extend(s.prev.iter().zip(&s.next).map(|(a, b)| a + alpha * (b - a)));
                return Ok(());
            }
            std::mem::swap(&mut s.prev, &mut s.next);
            r_prev = r_next;
        }
        Err(Reject::RoundnessUnreached)
    }

    /// Inverse umbrella steps (`λ = −λ_smooth / 2`, which amplify the
    /// deviation from the neighbour mean) on a candidate rounder than its
    /// target, until the roundness falls to it (last step interpolated);
    /// [`Reject::TooRound`] after `max_sharpening` steps (0 = the seed, which
    /// can only smooth).
    fn sharpen(
        &self,
        goal: f64,
        mut r_prev: f64,
        s: &mut Scratch,
        stats: &mut RunStats,
    ) -> std::result::Result<(), Reject> {
        let p = &self.params;
        let (res, margin) = (p.level_set_resolution, p.grid_margin);
        s.prev.clone_from(&s.raw);
        for _ in 0..p.smoothing.max_sharpening {
            s.next.resize(s.prev.len(), 0.0);
            self.geom
                .smooth_into(&s.prev, -0.5 * p.smoothing.lambda, &mut s.next);
            stats.polishing_steps += 1;
            if s.next.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                break;
            }
            self.radii_from(&s.r_ell, &s.next, &mut s.r);
            let r_next = self.geom.roundness(&s.r, res, margin);
            if r_next <= goal {
                let alpha = if r_prev > r_next {
                    ((r_prev - goal) / (r_prev - r_next)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                s.rho.clear();
                s.rho
                    .extend(s.prev.iter().zip(&s.next).map(|(a, b)| a + alpha * (b - a)));
                return Ok(());
            }
            std::mem::swap(&mut s.prev, &mut s.next);
            r_prev = r_next;
        }
        Err(Reject::TooRound)
    }

    /// The level set of node radii `radii` at the model's resolution: a cube
    /// of `level_set_resolution³` nodes spanning `±grid_margin · max r` about
    /// the origin.
    ///
    /// # Errors
    /// Level-set construction errors.
    pub fn rasterise(&self, radii: &[f64]) -> Result<Grid> {
        self.rasterise_at(radii, self.params.level_set_resolution)
    }

    /// As [`CloneModel::rasterise`] at another resolution.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a radii vector of the wrong length or
    /// with a non-positive entry; level-set construction errors.
    pub fn rasterise_at(&self, radii: &[f64], resolution: usize) -> Result<Grid> {
        if radii.len() != self.geom.n_nodes() {
            return Err(Error::InvalidParameter {
                name: "radii",
                value: radii.len() as f64,
                reason: "one radius per mesh node",
            });
        }
        if let Some(bad) = radii.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
            return Err(Error::InvalidParameter {
                name: "radii",
                value: *bad,
                reason: "finite and positive",
            });
        }
        let r_max = radii.iter().fold(0.0f64, |a, b| a.max(*b));
        let half = self.params.grid_margin * r_max;
        let spec = GridSpec::cube(resolution, -half, half)?;
        // the cube-map table by the precomputed plans: the radius function's values at
        // the table's directions, bit for bit (tested)
        let table: Vec<f64> = self.cube.iter().map(|p| self.geom.eval(p, radii)).collect();
        let (grid, _) =
            Grid::from_star_table(spec, &Point3::origin(), &table, &StarParams::default())?;
        Ok(grid)
    }

    /// The clone's surface as a cube-map radius table: `out[t]` is the
    /// radius in direction `levelset::cube_map_directions(face_cells)[t]` of
    /// the clone frame (major axis +x, minor +z, centre at the origin), by
    /// the model's interpolation of the node radii — the table
    /// [`CloneModel::rasterise_at`] hands to `levelset::Grid::from_star_table`
    /// when `face_cells` is 32 (bit for bit), coarser or finer otherwise.
    /// For packers that keep a compact star-shaped surface instead of a grid
    /// (e.g. `packer_grains::StarGrain::from_table(face_cells, &table)`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a radii vector of the wrong length or
    /// with a non-positive entry; levelset's error for `face_cells` outside
    /// 2..=4096.
    pub fn star_table(&self, radii: &[f64], face_cells: usize) -> Result<Vec<f64>> {
        if radii.len() != self.geom.n_nodes() {
            return Err(Error::InvalidParameter {
                name: "radii",
                value: radii.len() as f64,
                reason: "one radius per mesh node",
            });
        }
        if let Some(bad) = radii.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
            return Err(Error::InvalidParameter {
                name: "radii",
                value: *bad,
                reason: "finite and positive",
            });
        }
        if face_cells == 32 && self.cube.len() == 6 * 33 * 33 {
            return Ok(self.cube.iter().map(|p| self.geom.eval(p, radii)).collect());
        }
        let dirs = levelset::cube_map_directions(face_cells).map_err(Error::from)?;
        Ok(self
            .geom
            .plans(&dirs, self.params.interpolation)
            .iter()
            .map(|p| self.geom.eval(p, radii))
            .collect())
    }

    /// Clone `index`: candidates on the stream `(seed, index)` until one is
    /// accepted.
    ///
    /// # Errors
    /// [`Error::TooManyRejections`] after `max_attempts` candidates.
    pub fn clone_one(&self, index: u64, clock: &dyn Clock) -> Result<(ClonedGrain, RunStats)> {
        self.clone_with(index, Mode::Production, self.params.outputs, clock)
    }

    /// The candidate's raw field polished again toward a surface roundness
    /// `shift` below its steering target, then quality control ([`Self::shape`]):
    /// the re-steered pass of a roundness repair or prediction.
    fn resteer(
        &self,
        cand: &Candidate,
        shift: f64,
        s: &mut Scratch,
        stats: &mut RunStats,
        clock: &dyn Clock,
    ) -> std::result::Result<Candidate, Reject> {
        let mut steer = cand.steering;
        steer.roundness -= shift;
        self.ellipsoid(cand.semi, &mut s.r_ell);
        self.shape(
            cand.targets,
            steer,
            cand.semi,
            cand.raw_roundness,
            s,
            stats,
            clock,
        )
    }

    /// The predicted level-set roundness of `cand` minus its target
    /// (`SteeringMap::roundness_prediction` `pred`: the surface roundness and
    /// the estimated inscribed radius); `None` when the inscribed radius
    /// cannot be estimated. Timed as quality control.
    fn predicted_miss(
        &self,
        cand: &Candidate,
        pred: [f64; 3],
        stats: &mut RunStats,
        clock: &dyn Clock,
    ) -> Option<f64> {
        let t0 = clock.now_ns();
        let ins = self.geom.inscribed_radius(&cand.radii);
        let r_surface = match (self.params.roundness_check, ins) {
            (RoundnessCheck::Predicted, Some(r_ins)) => {
                let p = &self.params;
                self.geom
                    .roundness_about(&cand.radii, p.level_set_resolution, p.grid_margin, r_ins)
            }
            _ => cand.surface.roundness,
        };
        stats.times.quality_ns += clock.now_ns() - t0;
        let predicted = pred[0] + pred[1] * r_surface + pred[2] * ins? / cand.surface.r_min;
        // the surface check holds the prediction to the pulled target (the
        // prediction's residual then restores the parents' spread); the
        // level-set check's passes aim at the target itself, as calibrated
        let target = match self.params.roundness_check {
            RoundnessCheck::LevelSet => cand.targets.roundness,
            RoundnessCheck::Predicted => self.map.pulled(3, cand.targets.roundness),
        };
        let miss = predicted - target;
        miss.is_finite().then_some(miss)
    }

    /// Predicted-roundness passes (`Params::roundness_predictions`): re-steers
    /// `cand` before any level set while the roundness predicted from its
    /// surface DNA and inscribed radius misses its target by more than the
    /// margin (a fraction of the tolerance `t`). Returns the predicted miss
    /// of the candidate as it leaves (`None` if it cannot be predicted, and
    /// after the last pass of the level-set check, which measures instead).
    fn predicted_roundness_passes(
        &self,
        cand: &mut Candidate,
        t: f64,
        pred: [f64; 3],
        s: &mut Scratch,
        stats: &mut RunStats,
        clock: &dyn Clock,
    ) -> Option<f64> {
        let margin = self.params.roundness_prediction_margin * t;
        let passes = self.params.roundness_predictions;
        let mut miss = self.predicted_miss(cand, pred, stats, clock)?;
        for pass in 1..=passes {
            if miss.abs() <= margin {
                break;
            }
            stats.roundness_predictions += 1;
            // a pass that fails (quality control, polishing) keeps the
            // candidate as it was
            match self.resteer(cand, miss / pred[1], s, stats, clock) {
                Ok(c) => *cand = c,
                Err(_) => break,
            }
            // the level-set check measures after the last pass: no prediction
            if pass == passes && self.params.roundness_check == RoundnessCheck::LevelSet {
                return None;
            }
            miss = self.predicted_miss(cand, pred, stats, clock)?;
        }
        Some(miss)
    }

    /// The candidate's level set and, with a roundness tolerance
    /// `check_roundness`, its measured roundness checked against the target,
    /// with up to `Params::roundness_repairs` re-steered repairs of `cand`.
    /// Returns the level set (inside its measurement once measured) and the
    /// measured roundness.
    fn checked_level_set(
        &self,
        cand: &mut Candidate,
        check_roundness: Option<f64>,
        s: &mut Scratch,
        stats: &mut RunStats,
        clock: &dyn Clock,
    ) -> std::result::Result<(Held, Option<f64>), Reject> {
        let mut repairs = 0;
        loop {
            let t0 = clock.now_ns();
            let g = self.rasterise(&cand.radii);
            let t1 = clock.now_ns();
            stats.times.rasterise_ns += t1 - t0;
            stats.level_sets += 1;
            let Ok(g) = g else {
                break Err(Reject::Degenerate);
            };
            let Some(t) = check_roundness else {
                break Ok((Held::Grid(g), None));
            };
            // the roundness check first, on roundness alone (morph-dna
            // computes each descriptor identically alone or in a set),
            // so a rejected clone does not pay for the volume pass; the
            // measurement keeps the surface it extracted for the rest
            let Ok(mut m) = Measurement::owned(g, &MeasureParams::default()) else {
                break Err(Reject::Degenerate);
            };
            let r = m.get(&[Descriptor::Roundness]);
            stats.times.measure_ns += clock.now_ns() - t1;
            let r = match r {
                Ok(r) => r[0],
                Err(_) => break Err(Reject::Degenerate),
            };
            let miss = r - cand.targets.roundness;
            if miss.abs() <= t {
                break Ok((Held::Measured(Box::new(m)), Some(r)));
            }
            if repairs == self.params.roundness_repairs {
                break Err(Reject::MeasuredRoundness);
            }
            // re-steer: polish the same raw field again toward a surface
            // roundness moved against the miss (through the steering
            // map's slope), then quality control and measure again
            repairs += 1;
            stats.roundness_repairs += 1;
            let slope = self.steering_map().slope[3];
            let shift = miss / if slope > 0.1 { slope } else { 1.0 };
            match self.resteer(cand, shift, s, stats, clock) {
                Ok(c) => *cand = c,
                Err(r) => break Err(r),
            }
        }
    }

    /// The clone of `index` in `mode` with the `outputs` asked: candidates
    /// (stages 1–4), predicted-roundness passes, the checked level set and the
    /// DNA, until one is accepted or `max_attempts` candidates are spent.
    pub(crate) fn clone_with(
        &self,
        index: u64,
        mode: Mode,
        outputs: Outputs,
        clock: &dyn Clock,
    ) -> Result<(ClonedGrain, RunStats)> {
        let mut rng = clone_rng(self.params.seed, index);
        let mut stats = RunStats::default();
        let mut s = Scratch {
            rho: Vec::new(),
            raw: Vec::new(),
            prev: Vec::new(),
            next: Vec::new(),
            r_ell: Vec::new(),
            r: Vec::new(),
        };
        let mut held = None;
        let mut fields = 0;
        for attempt in 1..=self.params.max_attempts {
            stats.attempts += 1;
            fields += 1;
            if fields > self.params.fields_per_target {
                held = None;
                fields = 1;
            }
            let mut cand =
                match self.candidate(&mut rng, &mut s, &mut stats, clock, mode, &mut held) {
                    Ok(c) => c,
                    Err(r) => {
                        stats.rejections.count(r);
                        continue;
                    }
                };
            let (mut grid, mut dna) = (None, None);
            let check_roundness = match (mode, self.params.roundness_tolerance) {
                (Mode::Production, Some(t)) => Some(t),
                _ => None,
            };
            if let (Some(t), Some(pred)) = (check_roundness, self.map.roundness_prediction) {
                let miss =
                    self.predicted_roundness_passes(&mut cand, t, pred, &mut s, &mut stats, clock);
                if self.params.roundness_check == RoundnessCheck::Predicted
                    && !miss.is_some_and(|m| m.abs() <= t)
                {
                    stats.rejections.count(Reject::PredictedRoundness);
                    continue;
                }
            }
            let check_roundness = match self.params.roundness_check {
                RoundnessCheck::LevelSet => check_roundness,
                RoundnessCheck::Predicted => None,
            };
            let measure_dna = outputs.dna || check_roundness.is_some();
            if outputs.level_set || measure_dna {
                let g =
                    self.checked_level_set(&mut cand, check_roundness, &mut s, &mut stats, clock);
                let (held, roundness) = match g {
                    Ok(v) => v,
                    Err(r) => {
                        stats.rejections.count(r);
                        continue;
                    }
                };
                let held = if measure_dna && (outputs.dna || roundness.is_none()) {
                    match measure_held_dna(held, &mut stats, clock) {
                        Some((d, m)) => {
                            dna = Some(d);
                            Held::Measured(m)
                        }
                        None => {
                            stats.rejections.degenerate += 1;
                            continue;
                        }
                    }
                } else {
                    held
                };
                if outputs.level_set {
                    grid = Some(held.into_grid());
                }
            }
            stats.accepted += 1;
            return Ok((
                ClonedGrain {
                    index,
                    attempts: attempt,
                    radii: cand.radii,
                    targets: cand.targets,
                    steering: cand.steering,
                    surface: cand.surface,
                    grid,
                    dna,
                },
                stats,
            ));
        }
        Err(Error::TooManyRejections {
            index,
            attempts: self.params.max_attempts,
            rejections: stats.rejections,
        })
    }

    /// Clones every index of `range` in parallel (rayon's current pool). The
    /// clones, and every statistic except the stage times, are identical for
    /// any thread count and any split of the range.
    ///
    /// Performance note (glibc): each level set allocates and frees ≈ 4 MiB,
    /// which glibc's malloc hands back to the kernel after every clone at its
    /// default trim threshold, so the next clone faults the pages in again
    /// (≈ 10 % of the CPU time in the kernel on the 2-vCPU machine). A program
    /// that allocates and frees one 16 MiB block before cloning raises the
    /// threshold (`cargo xtask` does: ≈ 15–20 % more clones per second).
    ///
    /// # Errors
    /// [`Error::InvalidRange`] for an empty or reversed range, and the first
    /// (lowest-index) error of [`CloneModel::clone_one`].
    pub fn run(&self, range: Range<u64>, hooks: Hooks<'_>) -> Result<Run> {
        if range.start >= range.end {
            return Err(Error::InvalidRange {
                start: range.start,
                end: range.end,
            });
        }
        let total = range.end - range.start;
        let done = AtomicU64::new(0);
        let results: Vec<Result<(ClonedGrain, RunStats)>> = range
            .into_par_iter()
            .map(|i| {
                let r = self.clone_one(i, hooks.clock);
                let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                if let Some(cb) = hooks.progress {
                    cb(Progress { done: d, total });
                }
                r
            })
            .collect();
        let mut clones = Vec::with_capacity(results.len());
        let mut stats = RunStats::default();
        for r in results {
            let (c, s) = r?;
            stats.add(&s);
            clones.push(c);
        }
        Ok(Run { clones, stats })
    }
}

/// The DNA of a clone's level set, reusing the roundness and the surface
/// when the roundness check measured them; `None` for a degenerate level set.
fn measure_held_dna(
    held: Held,
    stats: &mut RunStats,
    clock: &dyn Clock,
) -> Option<(Vec<f64>, Box<Measurement<'static>>)> {
    let t1 = clock.now_ns();
    let m = match held {
        Held::Measured(m) => Ok(m),
        Held::Grid(g) => Measurement::owned(g, &MeasureParams::default()).map(Box::new),
    };
    let d = m.and_then(|mut m| m.get(&DNA).map(|d| (d, m)));
    stats.times.measure_ns += clock.now_ns() - t1;
    d.ok()
}

#[cfg(test)]
mod tests;
