//! Densification of sphere packings: affine compression of the domain with
//! overlap relaxation by FIRE, from the advancing front's packing to a
//! requested solid fraction or to jamming, in a fully periodic box, a box
//! (walls, or periodic in x/y) or a cylinder.
//!
//! # Method
//! The front leaves a valid, overlap-free packing at φ ≈ 0.60–0.62 (U[1, 2])
//! in which every sphere rests on three others: a gravity deposition, not a
//! jammed state. The jammed random packing of that grading is near 0.65. The
//! stage closes that gap the way the jamming literature produces jammed soft
//! spheres (O'Hern, Silbert, Liu & Nagel 2003, *Phys. Rev. E* 68, 011306),
//! with hard-sphere output:
//! 1. **compress**: the domain and the centres are scaled about the domain's
//!    centre by `s < 1` (radii unchanged, so the grading is kept exactly),
//!    raising φ by a step `Δφ`; this creates small overlaps everywhere;
//! 2. **relax**: the overlaps are removed by minimising the harmonic overlap
//!    energy `E = ½ Σ (r_i + r_j − d_ij)₊² + ½ Σ (r_i − clearance_i)₊²` with
//!    FIRE (Bitzek et al. 2006, *Phys. Rev. Lett.* 97, 170201: damped
//!    dynamics with velocity mixing and an adaptive step), until every
//!    overlap is at most [`DensifyParams::tolerance`] times the pair's centre
//!    distance (a wall's: times the sphere's clearance), so that one affine
//!    expansion by `1 + tolerance` at most clears them all. Below
//!    jamming the minimum has `E = 0` and FIRE reaches it in a few hundred
//!    steps; at and above jamming it does not;
//! 3. a step that does not relax within [`DensifyParams::max_iterations`]
//!    is undone (the last overlap-free state is restored) and retried with
//!    half the `Δφ`; a step that relaxes lets the next one grow by 1.5×.
//!
//! [`Target::Fraction`] ends at that fraction exactly (the last step lands on
//! it) or fails with [`Error::FractionNotReached`] naming the fraction
//! reached when `Δφ` falls below [`DensifyParams::min_step`];
//! [`Target::Jammed`] ends there (the jamming point, bracketed to `min_step`).
//!
//! Why this and not the peers' methods: the force-biased algorithm
//! (Mościński & Bargieł 1989) and Lubachevsky–Stillinger event-driven
//! growth (1990) both start from a random, heavily overlapping or dilute
//! configuration and spend most of their time building the structure that
//! the front already provides at φ ≈ 0.61 in 0.1 s; from there only a few
//! percent of compression remain, and energy minimisation of small overlaps
//! is a local, embarrassingly parallel sweep (one neighbour list, three
//! passes per step). Collective rearrangement with random jiggles (Jodrey–Tory)
//! converges more slowly than FIRE's inertial descent on the same energy.
//!
//! Choices: unit masses and unit spring constants (the minimum, not the
//! path, matters); FIRE's standard constants (`f_inc` = 1.1, `f_dec` = 0.5,
//! `α₀` = 0.1, `f_α` = 0.99) with two changes of FIRE 2.0 (Guénolé et al.
//! 2020, *Comput. Mater. Sci.* 175, 109584): at a negative power the
//! centres go half of the last step back before the velocities are zeroed,
//! and the step grows only after `N_delay` = 20 positive steps (FIRE's
//! `N_min` = 5): over 6 seeds of 10⁴ spheres to 0.64, 25,169 FIRE iterations
//! with FIRE, 23,146 with the half step back alone, 22,722 with both (−9.7 %;
//! FIRE 2.0's `α₀` = 0.25 was no better: 24,172 alone, 27,674 with the
//! others; the standard constants are a local optimum: 15,501 iterations at
//! the present tolerance against 15,965 / 18,037 for `f_inc` = 1.2 / 1.05,
//! 16,927 / 17,151 for `f_dec` = 0.3 / 0.7, 16,180 / 17,763 for `f_α` =
//! 0.995 / 0.98, 16,943 / 18,822 for `α₀` = 0.15 / 0.05); time step 0.1 growing to 0.5
//! (with unit mass and stiffness the time unit is independent of the length
//! scale; a Gershgorin bound on the stiffest mode of ≈ 12 contacts gives
//! ω ≈ √24 and 2/ω ≈ 0.41, but 0.5 is stable in practice and 0.7 is not:
//! 10⁴ spheres to 0.64 took 3,400 iterations at 0.5, 4,100 at 0.35, at the
//! earlier tolerance of 1e-4 `d_min`; at the present default, 0.6 saves
//! 1.3 % of the iterations over 6 seeds, too little beside 0.7's failure; masses
//! proportional to the contact count, a preconditioner, took 4,600–5,100;
//! masses ∝ r^p about the mean radius, at the present tolerance over 6 seeds:
//! 16,046 / 16,507 iterations for p = 0.5 / −1, 16,489 for p = −0.5 and
//! 20,106 for p = 1 (with a step of at most 0.4), against 15,501 for unit masses); a Verlet neighbour list with skin 0.25 `d_min`,
//! rebuilt when a sphere moved more than half of it, spheres renumbered in
//! cell order at each build and each pair's periodic image stored as a
//! shift code (no minimum-image test in the force loop); each pair listed
//! once, from its lower-numbered sphere (a build scans only the cells of
//! higher number, half of the candidates), and its force computed once,
//! stored, and taken with the opposite sign by the other sphere in a second
//! pass (Newton's third law: half of the square roots and divisions, the
//! force pass's cost; 10⁴ spheres to 0.64: −30 % wall time with the
//! half-scan build and no wall test in a periodic box);
//! compression about the domain's centre (isotropic, so the front's
//! fabric is not sheared).
//!
//! # Determinism
//! Forces are summed per sphere in a fixed order (its own pairs in list
//! order, then the stored forces of the pairs it is the higher sphere of),
//! and every global sum (power, norms) is over fixed chunks of 1024 spheres
//! added in order, so the result is identical for any thread count.

use nalgebra::{Point3, Vector3};

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

use super::{Container, Pack3Params, Sphere};
use crate::error::{Error, Result, finite, positive};
use packer_quadtree::Grading;

mod fire;
mod geom;
mod system;

pub use fire::FireControl;

use geom::Geom;
use system::{INDEX_MASK, System};

/// The domain of a densification.
#[derive(Debug, Clone)]
pub enum Boundary {
    /// The box `[min, max]`, periodic in x, y and z (each side at least
    /// 4 `d_max`).
    Periodic {
        /// Lower corner.
        min: Point3<f64>,
        /// Upper corner.
        max: Point3<f64>,
    },
    /// A box (walled, or periodic in x/y) or a cylinder; meshes are refused.
    Walls(Container),
}

impl Boundary {
    /// Volume.
    pub fn volume(&self) -> f64 {
        match self {
            Self::Periodic { min, max } => (max - min).product(),
            Self::Walls(c) => c.volume(),
        }
    }
}

/// What the densification aims at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// This solid fraction (spheres' volume over the domain's), in (0, 0.74].
    Fraction(f64),
    /// The densest state the relaxation can free of overlaps (jamming,
    /// bracketed to [`DensifyParams::min_step`]).
    Jammed,
}

/// Parameters of [`densify`] (plain data with `Default`, validated at entry).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DensifyParams {
    /// The target.
    pub target: Target,
    /// First compression step `Δφ` (default 0.1: a reachable target is
    /// reached in one step, the cheapest path measured — 10⁴ spheres from the
    /// front's 0.594 to 0.64: 3,400 iterations in one step, 31,000 in steps
    /// of 0.01 with a budget of 3,000).
    pub first_step: f64,
    /// Largest compression step (default 0.1).
    pub max_step: f64,
    /// The smallest step before the target is declared unreachable (or the
    /// jamming point found); default 2e-4.
    pub min_step: f64,
    /// FIRE iterations allowed per compression step (default 20,000; the
    /// relaxation time grows steeply towards jamming).
    pub max_iterations: usize,
    /// Largest overlap the relaxation may leave, over the pair's centre
    /// distance (a wall's: over the sphere's clearance), in (0, 1e-3]; a final
    /// affine expansion by one plus the largest such ratio removes them
    /// exactly, and the compression aims `(1 + tolerance)³` higher, so the
    /// requested fraction is still met. Default 1e-3: the looser the
    /// tolerance, the fewer iterations to reach it but the nearer to jamming
    /// the aim; 10⁴ spheres to 0.64 over 6 seeds: 20,711 FIRE iterations at
    /// 1e-4, 16,836 at 4e-4, 15,501 at 1e-3, 20,026 at 2e-3. For
    /// [`Target::Jammed`] the final expansion gives up at most that relative
    /// size of the jamming point (3 · tolerance in φ).
    pub tolerance: f64,
}

impl Default for DensifyParams {
    fn default() -> Self {
        Self {
            target: Target::Jammed,
            first_step: 0.1,
            max_step: 0.1,
            min_step: 2e-4,
            max_iterations: 20_000,
            tolerance: 1e-3,
        }
    }
}

impl DensifyParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::Parameter`] naming the first value out of range (a target
    /// fraction outside (0, 0.74], steps not `0 < min ≤ first ≤ max`, no
    /// iterations, a tolerance outside (0, 1e-3]); [`Error::NonFinite`] for NaN.
    pub fn validate(&self) -> Result<()> {
        if let Target::Fraction(f) = self.target {
            finite("target fraction", f)?;
            if !(f > 0.0 && f <= 0.74) {
                return Err(Error::Parameter {
                    what: "target fraction",
                    value: f,
                    range: "(0, 0.74]",
                });
            }
        }
        positive("min_step", self.min_step)?;
        positive("first_step", self.first_step)?;
        positive("max_step", self.max_step)?;
        if self.first_step < self.min_step || self.first_step > self.max_step {
            return Err(Error::Parameter {
                what: "first_step",
                value: self.first_step,
                range: "[min_step, max_step]",
            });
        }
        if self.max_iterations == 0 {
            return Err(Error::Parameter {
                what: "max_iterations",
                value: 0.0,
                range: "[1, inf)",
            });
        }
        positive("tolerance", self.tolerance)?;
        if self.tolerance > 1e-3 {
            return Err(Error::Parameter {
                what: "tolerance",
                value: self.tolerance,
                range: "(0, 1e-3]",
            });
        }
        Ok(())
    }
}

/// Counters of a densification.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DensifyStats {
    /// Solid fraction at the start.
    pub initial_fraction: f64,
    /// Compression steps that relaxed.
    pub steps_accepted: usize,
    /// Compression steps undone (did not relax within the iteration budget).
    pub steps_rejected: usize,
    /// FIRE iterations in all.
    pub iterations: usize,
    /// Neighbour-list builds.
    pub neighbour_builds: usize,
    /// Largest overlap of the result (after the final expansion), as a
    /// fraction of the pair's smaller diameter: 0 up to round-off.
    pub max_overlap: f64,
}

/// A densified packing.
#[derive(Debug, Clone)]
pub struct Densified {
    /// The spheres (same order and radii as the input; centres wrapped into
    /// the box along periodic directions).
    pub spheres: Vec<Sphere>,
    /// The compressed domain (the input's scaled about its centre).
    pub boundary: Boundary,
    /// Solid fraction: spheres' volume over the domain's.
    pub fraction: f64,
    /// Counters.
    pub stats: DensifyStats,
}

/// Compresses a packing to `params.target` (module docs).
///
/// The input must be free of overlaps (to the tolerance) and inside the
/// domain; it is typically the advancing front's packing of the same
/// domain. A target below the input's fraction is an error (the stage only
/// compresses).
///
/// # Errors
/// [`Error::Empty`] for no sphere; [`Error::NonFinite`] /
/// [`Error::NonPositive`] for a bad centre, radius or domain;
/// [`Error::Parameter`] for bad parameters or a target below the input's
/// fraction; [`Error::DomainTooSmall`] for a periodic side under 4 `d_max`;
/// [`Error::WrongContainer`](crate::Error::WrongContainer) for a mesh;
/// [`Error::NotConverged`] when the input itself has overlaps the
/// relaxation cannot remove; [`Error::FractionNotReached`] when the target
/// fraction lies beyond jamming.
pub fn densify(
    spheres: &[Sphere],
    boundary: &Boundary,
    params: &DensifyParams,
) -> Result<Densified> {
    params.validate()?;
    if spheres.is_empty() {
        return Err(Error::Empty {
            what: "sphere list",
        });
    }
    if spheres.len() > INDEX_MASK as usize {
        return Err(Error::TooManyParticles {
            estimate: spheres.len() as f64,
            limit: INDEX_MASK as usize,
        });
    }
    let geom = Geom::new(boundary)?;
    let (mut r_min, mut r_max) = (f64::MAX, 0.0_f64);
    let mut solid = 0.0;
    for s in spheres {
        for k in 0..3 {
            finite("sphere centre", s.center[k])?;
        }
        positive("sphere radius", s.radius)?;
        r_min = r_min.min(s.radius);
        r_max = r_max.max(s.radius);
        solid += 4.0 / 3.0 * std::f64::consts::PI * s.radius.powi(3);
    }
    geom.check_room(2.0 * r_max)?;
    let phi0 = solid / geom.volume();
    let mut sys = System::new(spheres, geom, r_min, r_max, params.tolerance);
    let mut stats = DensifyStats {
        initial_fraction: phi0,
        ..DensifyStats::default()
    };
    // the input must be (nearly) free of overlaps: one relaxation may remove what is left
    if !sys.relax(params.max_iterations, &mut stats) {
        return Err(Error::NotConverged {
            sweeps: stats.iterations,
            overlapping_pairs: sys.overlapping_pairs(),
            scale: 1.0,
        });
    }
    sys.expand_free();
    let phi_in = solid / sys.geom.volume();
    // the relaxation leaves every overlap at most the tolerance times the pair's centre
    // distance (a wall's: times the sphere's clearance), so the final expansion, by one plus
    // the largest of those ratios, gives up at most (1 + tolerance)³; aim that much higher
    let headroom = (1.0 + params.tolerance).powi(3);
    let goal = match params.target {
        Target::Fraction(f) => {
            if f < phi_in - 1e-12 {
                return Err(Error::Parameter {
                    what: "target fraction (below the packing's own)",
                    value: f,
                    range: "[the input's fraction, 0.74]",
                });
            }
            f * headroom
        }
        Target::Jammed => 0.74,
    };
    let mut phi = phi_in;
    let mut step = params.first_step;
    let mut good = (sys.xr.clone(), sys.ids.clone());
    let mut good_geom = sys.geom;
    while phi < goal * (1.0 - 1e-15) {
        let next = (phi + step).min(goal);
        sys.compress((phi / next).cbrt());
        if sys.relax(params.max_iterations, &mut stats) {
            stats.steps_accepted += 1;
            phi = solid / sys.geom.volume();
            good.0.clone_from(&sys.xr);
            good.1.clone_from(&sys.ids);
            good_geom = sys.geom;
            step = (1.5 * step).min(params.max_step);
        } else {
            stats.steps_rejected += 1;
            sys.xr.clone_from(&good.0);
            sys.ids.clone_from(&good.1);
            sys.geom = good_geom;
            sys.reset();
            step *= 0.5;
            if step < params.min_step {
                if let Target::Fraction(f) = params.target {
                    return Err(Error::FractionNotReached {
                        requested: f,
                        reached: phi / headroom,
                    });
                }
                break;
            }
        }
    }
    // the overlaps left (at most the tolerance) go by one affine expansion, and what is left
    // of the headroom by another (expanding never creates an overlap)
    sys.expand_free();
    if let Target::Fraction(f) = params.target {
        let phi = solid / sys.geom.volume();
        if phi > f {
            sys.scale_keep((phi / f).cbrt());
        }
    }
    let boundary = sys.geom.boundary(boundary);
    let mut out = vec![
        Sphere {
            center: Point3::origin(),
            radius: 0.0
        };
        sys.xr.len()
    ];
    for (p, &id) in sys.xr.iter().zip(&sys.ids) {
        out[id as usize] = Sphere {
            center: Point3::new(p[0], p[1], p[2]),
            radius: p[3],
        };
    }
    stats.max_overlap = max_overlap(&out, &boundary)?;
    let fraction = solid / boundary.volume();
    Ok(Densified {
        fraction,
        spheres: out,
        boundary,
        stats,
    })
}

/// A dense packing of a domain: the front's packing, thinned and densified.
#[derive(Debug, Clone)]
pub struct DensePacking3 {
    /// The spheres.
    pub spheres: Vec<Sphere>,
    /// The domain they fill: the requested one for [`Target::Fraction`], the
    /// requested one scaled about its centre to the jamming point for
    /// [`Target::Jammed`].
    pub boundary: Boundary,
    /// Solid fraction of the domain (for [`Target::Fraction`] `f`: in
    /// `[f, f + v_max / V]`, `v_max` the largest sphere's volume).
    pub fraction: f64,
    /// Front counters (of the last front run).
    pub front: super::Pack3Stats,
    /// Spheres the front placed.
    pub placed: usize,
    /// Spheres removed at random to meet the target.
    pub removed: usize,
    /// Densification counters.
    pub densify: DensifyStats,
}

/// Fraction below which a front packing is assumed to fall when the domain it
/// packs is sized (walls included); a shortfall re-packs a larger domain.
const FRONT_FRACTION_GUESS: f64 = 0.59;

/// Packs `boundary` densely: the advancing front ([`super::pack3d`]) in the
/// domain enlarged about its centre (so that it holds enough spheres for the
/// target), spheres removed uniformly at random (ChaCha8 stream of `seed`)
/// until their volume is the target's (a random thinning keeps the grading's
/// distribution), then [`densify`] back to exactly the requested domain.
/// A fully periodic domain is packed by the front as a box periodic in x and
/// y with walls in z, which densify then treats as periodic (spheres clear of
/// the z walls cannot overlap through them). [`Target::Jammed`] packs the
/// requested domain and compresses it to jamming (the domain shrinks).
///
/// # Errors
/// As [`super::pack3d`] and [`densify`]; [`Error::FractionNotReached`] when
/// the target lies beyond jamming.
pub fn pack3d_dense(
    boundary: &Boundary,
    grading: &Grading,
    params: &Pack3Params,
    dense: &DensifyParams,
    seed: u64,
) -> Result<DensePacking3> {
    dense.validate()?;
    grading.validate()?;
    let want = Geom::new(boundary)?;
    let front_container = |s: f64| want.scaled(s).container();
    let volume = want.volume();
    let f = match dense.target {
        Target::Fraction(f) => f,
        Target::Jammed => {
            let p = super::pack3d_seeded(&front_container(1.0), grading, params, seed)?;
            let d = densify(&p.spheres, boundary, dense)?;
            return Ok(DensePacking3 {
                placed: p.spheres.len(),
                spheres: d.spheres,
                boundary: d.boundary,
                fraction: d.fraction,
                front: p.stats,
                removed: 0,
                densify: d.stats,
            });
        }
    };
    let need = f * volume;
    let mut scale = (f / FRONT_FRACTION_GUESS).cbrt().max(1.0);
    for _ in 0..4 {
        let p = super::pack3d_seeded(&front_container(scale), grading, params, seed)?;
        let vol = |s: &Sphere| 4.0 / 3.0 * std::f64::consts::PI * s.radius.powi(3);
        let total: f64 = p.spheres.iter().map(vol).sum();
        if total < need {
            // the front packed looser than guessed: a larger domain, 2 % of volume to spare
            scale *= (1.02 * need / total).cbrt();
            continue;
        }
        // remove spheres in a random order while the rest still holds the target volume
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9_7f4a_7c15);
        let mut order: Vec<usize> = (0..p.spheres.len()).collect();
        order.shuffle(&mut rng);
        let mut keep = vec![true; p.spheres.len()];
        let mut left = total;
        let mut removed = 0;
        for &i in &order {
            let v = vol(&p.spheres[i]);
            if left - v >= need {
                keep[i] = false;
                left -= v;
                removed += 1;
            }
        }
        let spheres: Vec<Sphere> = p
            .spheres
            .iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(s, _)| *s)
            .collect();
        let enlarged = want.scaled(scale).boundary(boundary);
        let exact = left / volume;
        let d = densify(
            &spheres,
            &enlarged,
            &DensifyParams {
                target: Target::Fraction(exact.min(0.74)),
                ..*dense
            },
        )?;
        return Ok(DensePacking3 {
            placed: p.spheres.len(),
            spheres: d.spheres,
            // the requested domain to round-off (the enlarged one compressed back)
            boundary: d.boundary,
            fraction: d.fraction,
            front: p.stats,
            removed,
            densify: d.stats,
        });
    }
    Err(Error::FractionNotReached {
        requested: f,
        reached: 0.0,
    })
}

/// Largest overlap of a packing in a periodic box or container, as a
/// fraction of the smaller diameter of the pair (or the sphere's, for a
/// wall); `0` when nothing overlaps. Independent of [`densify`]'s own
/// neighbour lists: a hash of cells of side `d_max` and the minimum image by
/// rounding.
///
/// # Errors
/// [`Error::NonFinite`] / [`Error::NonPositive`] for a bad centre, radius or
/// domain; [`Error::WrongContainer`](crate::Error::WrongContainer) for a mesh.
pub fn max_overlap(spheres: &[Sphere], boundary: &Boundary) -> Result<f64> {
    let geom = Geom::new(boundary)?;
    let mut d_max = 0.0_f64;
    for s in spheres {
        for k in 0..3 {
            finite("sphere centre", s.center[k])?;
        }
        positive("sphere radius", s.radius)?;
        d_max = d_max.max(2.0 * s.radius);
    }
    if spheres.is_empty() {
        return Ok(0.0);
    }
    let periods = geom.periods();
    let image = |mut d: Vector3<f64>| {
        for k in 0..3 {
            if periods[k] > 0.0 {
                d[k] -= periods[k] * (d[k] / periods[k]).round();
            }
        }
        d
    };
    // cells per periodic axis (the last one takes the remainder); unbounded on walled axes
    let ncell: [Option<i64>; 3] = std::array::from_fn(|k| {
        (periods[k] > 0.0).then(|| (periods[k] / d_max).floor().max(1.0) as i64)
    });
    let key = |p: &Point3<f64>| -> [i64; 3] {
        std::array::from_fn(|k| match ncell[k] {
            Some(n) => ((p[k].rem_euclid(periods[k]) / d_max).floor() as i64).min(n - 1),
            None => (p[k] / d_max).floor() as i64,
        })
    };
    let mut cells: std::collections::BTreeMap<[i64; 3], Vec<usize>> =
        std::collections::BTreeMap::new();
    for (i, s) in spheres.iter().enumerate() {
        cells.entry(key(&s.center)).or_default().push(i);
    }
    let mut worst = 0.0_f64;
    for (i, a) in spheres.iter().enumerate() {
        worst = worst
            .max(geom.wall(&[a.center.x, a.center.y, a.center.z], a.radius).1 / (2.0 * a.radius));
        let c = key(&a.center);
        let mut seen: Vec<[i64; 3]> = Vec::with_capacity(27);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let o = [dx, dy, dz];
                    let q: [i64; 3] = std::array::from_fn(|k| match ncell[k] {
                        Some(n) => (c[k] + o[k]).rem_euclid(n),
                        None => c[k] + o[k],
                    });
                    if seen.contains(&q) {
                        continue;
                    }
                    seen.push(q);
                    for &j in cells.get(&q).map_or(&[][..], Vec::as_slice) {
                        if j <= i {
                            continue;
                        }
                        let b = &spheres[j];
                        let dist = image(a.center - b.center).norm();
                        let ov = a.radius + b.radius - dist;
                        worst = worst.max(ov / (2.0 * a.radius.min(b.radius)));
                    }
                }
            }
        }
    }
    Ok(worst)
}

#[cfg(test)]
mod tests;
