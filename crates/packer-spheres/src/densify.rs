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
//!    dynamics with velocity mixing and an adaptive step), until the largest
//!    overlap is at most [`DensifyParams::tolerance`] · `d_min`. Below
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
//! is a local, embarrassingly parallel sweep (one neighbour list, one pass
//! per step). Collective rearrangement with random jiggles (Jodrey–Tory)
//! converges more slowly than FIRE's inertial descent on the same energy.
//!
//! Choices: unit masses and unit spring constants (the minimum, not the
//! path, matters); FIRE's standard constants (`N_min` = 5, `f_inc` = 1.1,
//! `f_dec` = 0.5, `α₀` = 0.1, `f_α` = 0.99), time step 0.1 growing to 0.5
//! (with unit mass and stiffness the time unit is independent of the length
//! scale; a Gershgorin bound on the stiffest mode of ≈ 12 contacts gives
//! ω ≈ √24 and 2/ω ≈ 0.41, but 0.5 is stable in practice and 0.7 is not:
//! 10⁴ spheres to 0.64 took 3,400 iterations at 0.5, 4,100 at 0.35; masses
//! proportional to the contact count, a preconditioner, took 4,600–5,100); a Verlet neighbour list with skin 0.25 `d_min`,
//! rebuilt when a sphere moved more than half of it, spheres renumbered in
//! cell order at each build and each pair's periodic image stored as a
//! shift code (no minimum-image test in the force loop);
//! compression about the domain's centre (isotropic, so the front's
//! fabric is not sheared).
//!
//! # Determinism
//! Forces are summed per sphere over its neighbour list in a fixed order,
//! and every global sum (power, norms) is over fixed chunks of 1024 spheres
//! added in order, so the result is identical for any thread count.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

use super::{Container, Pack3Params, Sphere};
use crate::error::{Error, Result, finite, positive};
use packer_quadtree::Grading;

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
    /// Largest overlap the relaxation may leave, as a fraction of the
    /// smallest diameter (default 1e-4); a final affine expansion of at most
    /// this relative size removes it exactly, and the compression aims that
    /// much higher, so the requested fraction is still met.
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
            tolerance: 1e-4,
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
    /// Largest overlap left, as a fraction of `d_min` (≤ the tolerance).
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
    // the final expansion gives up at most (1 + 2 tolerance)³ (a wall's clearance may be as
    // small as r_min = d_min / 2); aim that much higher
    let headroom = (1.0 + 2.0 * params.tolerance).powi(3);
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

/// The domain in the form the relaxation uses.
#[derive(Debug, Clone, Copy)]
enum Geom {
    Box {
        lo: [f64; 3],
        hi: [f64; 3],
        periodic: [bool; 3],
    },
    Cylinder {
        centre: [f64; 3],
        radius: f64,
        height: f64,
    },
}

impl Geom {
    fn new(b: &Boundary) -> Result<Self> {
        let g = match b {
            Boundary::Periodic { min, max } => Self::Box {
                lo: [min.x, min.y, min.z],
                hi: [max.x, max.y, max.z],
                periodic: [true; 3],
            },
            Boundary::Walls(Container::Box { min, max, periodic }) => Self::Box {
                lo: [min.x, min.y, min.z],
                hi: [max.x, max.y, max.z],
                periodic: [periodic[0], periodic[1], false],
            },
            Boundary::Walls(Container::Cylinder {
                base,
                radius,
                height,
            }) => Self::Cylinder {
                centre: [base.x, base.y, base.z + 0.5 * height],
                radius: *radius,
                height: *height,
            },
            Boundary::Walls(Container::Mesh(_)) => {
                return Err(Error::WrongContainer {
                    what: "densify",
                    expected: "box or cylinder",
                    got: "mesh",
                });
            }
        };
        match g {
            Self::Box { lo, hi, .. } => {
                for k in 0..3 {
                    finite("box min", lo[k])?;
                    finite("box max", hi[k])?;
                    positive("box side (max - min)", hi[k] - lo[k])?;
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => {
                for c in centre {
                    finite("cylinder base", c)?;
                }
                positive("cylinder radius", radius)?;
                positive("cylinder height", height)?;
            }
        }
        Ok(g)
    }

    fn check_room(&self, d_max: f64) -> Result<()> {
        match *self {
            Self::Box { lo, hi, periodic } => {
                for k in 0..3 {
                    let side = hi[k] - lo[k];
                    let need = if periodic[k] { 4.0 * d_max } else { d_max };
                    if side < need {
                        return Err(Error::DomainTooSmall {
                            domain: side,
                            particle: need,
                        });
                    }
                }
            }
            Self::Cylinder { radius, height, .. } => {
                let inscribed = (2.0 * radius).min(height);
                if inscribed < d_max {
                    return Err(Error::DomainTooSmall {
                        domain: inscribed,
                        particle: d_max,
                    });
                }
            }
        }
        Ok(())
    }

    fn volume(&self) -> f64 {
        match *self {
            Self::Box { lo, hi, .. } => (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]),
            Self::Cylinder { radius, height, .. } => {
                std::f64::consts::PI * radius * radius * height
            }
        }
    }

    fn centre(&self) -> [f64; 3] {
        match *self {
            Self::Box { lo, hi, .. } => [
                0.5 * (lo[0] + hi[0]),
                0.5 * (lo[1] + hi[1]),
                0.5 * (lo[2] + hi[2]),
            ],
            Self::Cylinder { centre, .. } => centre,
        }
    }

    /// The domain scaled by `s` about its centre.
    fn scaled(&self, s: f64) -> Self {
        let c = self.centre();
        match *self {
            Self::Box { lo, hi, periodic } => {
                let f = |k: usize, v: f64| c[k] + s * (v - c[k]);
                Self::Box {
                    lo: [f(0, lo[0]), f(1, lo[1]), f(2, lo[2])],
                    hi: [f(0, hi[0]), f(1, hi[1]), f(2, hi[2])],
                    periodic,
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => Self::Cylinder {
                centre,
                radius: s * radius,
                height: s * height,
            },
        }
    }

    /// Periods of the periodic axes (0 for walled ones).
    fn periods(&self) -> [f64; 3] {
        match *self {
            Self::Box { lo, hi, periodic } => {
                let mut p = [0.0; 3];
                for k in 0..3 {
                    if periodic[k] {
                        p[k] = hi[k] - lo[k];
                    }
                }
                p
            }
            Self::Cylinder { .. } => [0.0; 3],
        }
    }

    /// Wraps `p` into the box along periodic axes.
    fn wrap(&self, p: &mut [f64]) {
        if let Self::Box { lo, hi, periodic } = *self {
            for k in 0..3 {
                if periodic[k] {
                    let l = hi[k] - lo[k];
                    p[k] = lo[k] + (p[k] - lo[k]).rem_euclid(l);
                    if p[k] >= hi[k] {
                        p[k] = lo[k];
                    }
                }
            }
        }
    }

    /// The wall force on a sphere (overlap times the inward normal, summed
    /// over walls) and its largest wall overlap.
    fn wall(&self, p: &[f64], r: f64) -> ([f64; 3], f64) {
        let mut f = [0.0; 3];
        let mut worst = f64::NEG_INFINITY;
        match *self {
            Self::Box { lo, hi, periodic } => {
                for k in 0..3 {
                    if periodic[k] {
                        continue;
                    }
                    let a = r - (p[k] - lo[k]);
                    let b = r - (hi[k] - p[k]);
                    worst = worst.max(a).max(b);
                    if a > 0.0 {
                        f[k] += a;
                    }
                    if b > 0.0 {
                        f[k] -= b;
                    }
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => {
                let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
                let rho = dx.hypot(dy);
                let side = rho + r - radius;
                worst = worst.max(side);
                if side > 0.0 && rho > 0.0 {
                    f[0] -= side * dx / rho;
                    f[1] -= side * dy / rho;
                }
                let z0 = centre[2] - 0.5 * height;
                let a = r - (p[2] - z0);
                let b = r - (z0 + height - p[2]);
                worst = worst.max(a).max(b);
                if a > 0.0 {
                    f[2] += a;
                }
                if b > 0.0 {
                    f[2] -= b;
                }
            }
        }
        (f, worst)
    }

    /// The largest `ov / clearance` of a sphere against the walls (the
    /// relative expansion about the centre that clears it), 0 when clear.
    fn wall_ratio(&self, p: &[f64], r: f64) -> f64 {
        let mut w = 0.0_f64;
        let mut one = |clearance: f64| {
            if clearance < r {
                w = w.max(if clearance > 0.0 {
                    (r - clearance) / clearance
                } else {
                    f64::INFINITY
                });
            }
        };
        match *self {
            Self::Box { lo, hi, periodic } => {
                for k in 0..3 {
                    if !periodic[k] {
                        let c = 0.5 * (lo[k] + hi[k]);
                        // the wall is at distance h from the centre; the sphere's centre at
                        // |p - c|; scaling by s moves both, so the clearance scales by s
                        let h = 0.5 * (hi[k] - lo[k]);
                        one(h - (p[k] - c).abs());
                    }
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => {
                one(radius - (p[0] - centre[0]).hypot(p[1] - centre[1]));
                one(0.5 * height - (p[2] - centre[2]).abs());
            }
        }
        w
    }

    /// Bounding box `(lo, hi)`.
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match *self {
            Self::Box { lo, hi, .. } => (lo, hi),
            Self::Cylinder {
                centre,
                radius,
                height,
            } => (
                [
                    centre[0] - radius,
                    centre[1] - radius,
                    centre[2] - 0.5 * height,
                ],
                [
                    centre[0] + radius,
                    centre[1] + radius,
                    centre[2] + 0.5 * height,
                ],
            ),
        }
    }

    /// The input boundary with this geometry's extents.
    fn boundary(&self, like: &Boundary) -> Boundary {
        match (*self, like) {
            (Self::Box { lo, hi, .. }, Boundary::Periodic { .. }) => Boundary::Periodic {
                min: Point3::from(lo),
                max: Point3::from(hi),
            },
            _ => Boundary::Walls(self.container()),
        }
    }

    /// The container of this geometry (a box keeps its x/y periodicity and
    /// has walls in z: what the front packs).
    fn container(&self) -> Container {
        match *self {
            Self::Box { lo, hi, periodic } => Container::Box {
                min: Point3::from(lo),
                max: Point3::from(hi),
                periodic: [periodic[0], periodic[1]],
            },
            Self::Cylinder {
                centre,
                radius,
                height,
            } => Container::Cylinder {
                base: Point3::new(centre[0], centre[1], centre[2] - 0.5 * height),
                radius,
                height,
            },
        }
    }
}

/// Spheres per chunk of the deterministic global sums.
const CHUNK: usize = 1024;
/// Bits of a neighbour entry holding the sphere index; the 5 bits above hold the
/// periodic image (a code in 0..27 of the shift `n · period`, `n ∈ {−1, 0, 1}` per axis).
const INDEX_BITS: u32 = 27;
/// Mask of the sphere index in a neighbour entry.
const INDEX_MASK: u32 = (1 << INDEX_BITS) - 1;

/// The 27 image shifts of the neighbour codes.
fn image_shifts(periods: &[f64; 3]) -> [[f64; 3]; 27] {
    std::array::from_fn(|code| {
        let n = [code % 3, (code / 3) % 3, code / 9];
        std::array::from_fn(|k| (n[k] as f64 - 1.0) * periods[k])
    })
}

/// FIRE state and the neighbour list.
struct System {
    /// Centre and radius of every sphere.
    xr: Vec<[f64; 4]>,
    v: Vec<[f64; 3]>,
    f: Vec<[f64; 3]>,
    geom: Geom,
    /// Neighbour list (CSR, both directions).
    start: Vec<u32>,
    list: Vec<u32>,
    /// Centres at the last build.
    x_build: Vec<[f64; 3]>,
    /// Input index of each sphere (the spheres are kept in cell order).
    ids: Vec<u32>,
    skin: f64,
    r_max: f64,
    /// Overlap accepted by the relaxation (absolute).
    tol: f64,
    built: bool,
}

/// Partial sums of one chunk of the force pass.
#[derive(Clone, Copy)]
struct Sums {
    power: f64,
    ff: f64,
    vv: f64,
    worst: f64,
}

impl System {
    fn new(spheres: &[Sphere], geom: Geom, r_min: f64, r_max: f64, tolerance: f64) -> Self {
        let n = spheres.len();
        let d_min = 2.0 * r_min;
        let mut xr: Vec<[f64; 4]> = spheres
            .iter()
            .map(|s| [s.center.x, s.center.y, s.center.z, s.radius])
            .collect();
        for p in &mut xr {
            geom.wrap(p);
        }
        Self {
            xr,
            v: vec![[0.0; 3]; n],
            f: vec![[0.0; 3]; n],
            geom,
            start: Vec::new(),
            list: Vec::new(),
            x_build: Vec::new(),
            ids: (0..n as u32).collect(),
            skin: 0.25 * d_min,
            r_max,
            tol: tolerance * d_min,
            built: false,
        }
    }

    /// Forgets velocities and the neighbour list (after a restore).
    fn reset(&mut self) {
        self.built = false;
        for v in &mut self.v {
            *v = [0.0; 3];
        }
    }

    /// Scales centres and domain by `s` about the centre, keeping velocities.
    fn scale_keep(&mut self, s: f64) {
        let c = self.geom.centre();
        for p in &mut self.xr {
            for k in 0..3 {
                p[k] = c[k] + s * (p[k] - c[k]);
            }
        }
        self.geom = self.geom.scaled(s);
        self.built = false;
    }

    /// Scales the domain and the centres by `s` about the domain's centre,
    /// forgetting the velocities.
    fn compress(&mut self, s: f64) {
        self.scale_keep(s);
        self.reset();
    }

    /// Minimum-image difference `a − b`.
    #[inline]
    fn delta(periods: &[f64; 3], a: &[f64], b: &[f64]) -> [f64; 3] {
        // centres are wrapped at each neighbour build and move less than the skin between
        // builds, so one period at most separates a difference from its minimum image
        let mut d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        for k in 0..3 {
            let p = periods[k];
            // selects, not branches (p = 0 on walled axes leaves d unchanged)
            let up = if d[k] > 0.5 * p { p } else { 0.0 };
            let down = if d[k] < -0.5 * p { p } else { 0.0 };
            d[k] += down - up;
        }
        d
    }

    /// Builds the neighbour list: pairs closer than `r_i + r_j + skin`.
    fn build(&mut self) {
        for p in &mut self.xr {
            self.geom.wrap(p);
        }
        let (lo, hi) = self.geom.bounds();
        let periods = self.geom.periods();
        let reach = 2.0 * self.r_max + self.skin;
        // cells of side >= reach; centres slightly outside a walled domain go to its edge cells
        let mut dims = [1usize; 3];
        let mut side = [0.0; 3];
        for k in 0..3 {
            let l = hi[k] - lo[k];
            dims[k] = ((l / reach).floor() as usize).max(1);
            side[k] = l / dims[k] as f64;
        }
        let cell_of = |p: &[f64; 4]| -> [usize; 3] {
            let mut c = [0usize; 3];
            for k in 0..3 {
                let i = ((p[k] - lo[k]) / side[k]).floor();
                c[k] = if i < 0.0 {
                    0
                } else {
                    (i as usize).min(dims[k] - 1)
                };
            }
            c
        };
        let ncell = dims[0] * dims[1] * dims[2];
        let mut head = vec![0u32; ncell + 1];
        let cells: Vec<usize> = self
            .xr
            .iter()
            .map(|p| {
                let c = cell_of(p);
                (c[2] * dims[1] + c[1]) * dims[0] + c[0]
            })
            .collect();
        for &c in &cells {
            head[c + 1] += 1;
        }
        for i in 0..ncell {
            head[i + 1] += head[i];
        }
        let mut fill = head.clone();
        let mut order = vec![0u32; self.xr.len()];
        for (i, &c) in cells.iter().enumerate() {
            order[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        // renumber the spheres in cell order (neighbours close in memory); `ids` maps back
        self.xr = order.iter().map(|&i| self.xr[i as usize]).collect();
        self.v = order.iter().map(|&i| self.v[i as usize]).collect();
        self.ids = order.iter().map(|&i| self.ids[i as usize]).collect();
        let xr = &self.xr;
        let skin = self.skin;
        // neighbouring cells along one axis: wrapped on periodic axes, deduplicated when an
        // axis has fewer than three cells
        let span = |k: usize, c: usize| -> ([usize; 3], usize) {
            let n = dims[k] as isize;
            let mut v = [0usize; 3];
            let mut m = 0;
            for o in -1..=1isize {
                let j = c as isize + o;
                let j = if periods[k] > 0.0 {
                    j.rem_euclid(n)
                } else if j < 0 || j >= n {
                    continue;
                } else {
                    j
                };
                if !v[..m].contains(&(j as usize)) {
                    v[m] = j as usize;
                    m += 1;
                }
            }
            (v, m)
        };
        let lists: Vec<Vec<u32>> = (0..xr.len())
            .into_par_iter()
            .map(|i| {
                let c = cell_of(&xr[i]);
                let mut out = Vec::with_capacity(24);
                let (zs, nz) = span(2, c[2]);
                let (ys, ny) = span(1, c[1]);
                let (xs, nx) = span(0, c[0]);
                for &cz in &zs[..nz] {
                    for &cy in &ys[..ny] {
                        for &cx in &xs[..nx] {
                            let cell = (cz * dims[1] + cy) * dims[0] + cx;
                            for j in head[cell] as usize..head[cell + 1] as usize {
                                if j == i {
                                    continue;
                                }
                                let d = Self::delta(&periods, &xr[i], &xr[j]);
                                let cut = xr[i][3] + xr[j][3] + skin;
                                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < cut * cut {
                                    // the image of j nearest to i, as a shift code
                                    let mut code = 0u32;
                                    for k in (0..3).rev() {
                                        let raw = xr[i][k] - xr[j][k];
                                        let h = 0.5 * periods[k];
                                        let n = if periods[k] > 0.0 && raw > h {
                                            1
                                        } else if periods[k] > 0.0 && raw < -h {
                                            -1
                                        } else {
                                            0
                                        };
                                        code = 3 * code + (n + 1) as u32;
                                    }
                                    out.push(j as u32 | code << INDEX_BITS);
                                }
                            }
                        }
                    }
                }
                out.sort_unstable();
                out
            })
            .collect();
        self.start.clear();
        self.list.clear();
        self.start.push(0);
        for l in &lists {
            self.list.extend_from_slice(l);
            self.start.push(self.list.len() as u32);
        }
        self.x_build.clear();
        self.x_build
            .extend(self.xr.iter().map(|p| [p[0], p[1], p[2]]));
        self.built = true;
    }

    /// Forces into `self.f`, with the chunk sums of `F·v`, `|F|²`, `|v|²` and the largest
    /// overlap (pairs and walls), added in chunk order.
    fn forces(&mut self) -> Sums {
        let shifts = image_shifts(&self.geom.periods());
        let geom = self.geom;
        let (xr, v, start, list) = (&self.xr, &self.v, &self.start, &self.list);
        let parts: Vec<Sums> = self
            .f
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, fs)| {
                let mut s = Sums {
                    power: 0.0,
                    ff: 0.0,
                    vv: 0.0,
                    worst: f64::NEG_INFINITY,
                };
                for (o, f) in fs.iter_mut().enumerate() {
                    let i = c * CHUNK + o;
                    let a = &xr[i];
                    let (mut acc, ow) = geom.wall(a, a[3]);
                    let mut worst = ow;
                    // branch-free, two pairs at a time (the square roots and divisions of
                    // the two pairs go through the vector units together): half of the
                    // listed pairs touch, unpredictably
                    let nb = &list[start[i] as usize..start[i + 1] as usize];
                    let mut pairs = nb.chunks_exact(2);
                    let mut acc2 = [[0.0f64; 2]; 3];
                    let mut worst2 = [f64::NEG_INFINITY; 2];
                    for jj in &mut pairs {
                        let (b0, s0) = (
                            &xr[(jj[0] & INDEX_MASK) as usize],
                            &shifts[(jj[0] >> INDEX_BITS) as usize],
                        );
                        let (b1, s1) = (
                            &xr[(jj[1] & INDEX_MASK) as usize],
                            &shifts[(jj[1] >> INDEX_BITS) as usize],
                        );
                        let d0 = [
                            a[0] - b0[0] - s0[0],
                            a[1] - b0[1] - s0[1],
                            a[2] - b0[2] - s0[2],
                        ];
                        let d1 = [
                            a[0] - b1[0] - s1[0],
                            a[1] - b1[1] - s1[1],
                            a[2] - b1[2] - s1[2],
                        ];
                        let dd = [
                            d0[0] * d0[0] + d0[1] * d0[1] + d0[2] * d0[2],
                            d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2],
                        ];
                        // coincident centres (a broken input) get no force, not a NaN
                        let dist = [dd[0].sqrt().max(1e-12), dd[1].sqrt().max(1e-12)];
                        let ov = [a[3] + b0[3] - dist[0], a[3] + b1[3] - dist[1]];
                        for l in 0..2 {
                            worst2[l] = if ov[l] > worst2[l] { ov[l] } else { worst2[l] };
                        }
                        let k = [
                            (if ov[0] > 0.0 { ov[0] } else { 0.0 }) / dist[0],
                            (if ov[1] > 0.0 { ov[1] } else { 0.0 }) / dist[1],
                        ];
                        for c in 0..3 {
                            acc2[c][0] += k[0] * d0[c];
                            acc2[c][1] += k[1] * d1[c];
                        }
                    }
                    for &j in pairs.remainder() {
                        let (b, sh) = (
                            &xr[(j & INDEX_MASK) as usize],
                            &shifts[(j >> INDEX_BITS) as usize],
                        );
                        let d = [
                            a[0] - b[0] - sh[0],
                            a[1] - b[1] - sh[1],
                            a[2] - b[2] - sh[2],
                        ];
                        let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-12);
                        let ov = a[3] + b[3] - dist;
                        worst2[0] = if ov > worst2[0] { ov } else { worst2[0] };
                        let k = (if ov > 0.0 { ov } else { 0.0 }) / dist;
                        for c in 0..3 {
                            acc2[c][0] += k * d[c];
                        }
                    }
                    for c in 0..3 {
                        acc[c] += acc2[c][0] + acc2[c][1];
                    }
                    worst = worst.max(worst2[0]).max(worst2[1]);
                    *f = acc;
                    s.worst = s.worst.max(worst);
                    let w = &v[i];
                    s.power += acc[0] * w[0] + acc[1] * w[1] + acc[2] * w[2];
                    s.ff += acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2];
                    s.vv += w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
                }
                s
            })
            .collect();
        let mut t = Sums {
            power: 0.0,
            ff: 0.0,
            vv: 0.0,
            worst: f64::NEG_INFINITY,
        };
        for p in &parts {
            t.power += p.power;
            t.ff += p.ff;
            t.vv += p.vv;
            t.worst = t.worst.max(p.worst);
        }
        t
    }

    /// FIRE until the largest overlap is at most the tolerance; `false`
    /// when `max_iter` iterations did not get there.
    fn relax(&mut self, max_iter: usize, stats: &mut DensifyStats) -> bool {
        const N_MIN: usize = 5;
        const F_INC: f64 = 1.1;
        const F_DEC: f64 = 0.5;
        const ALPHA0: f64 = 0.1;
        const F_ALPHA: f64 = 0.99;
        const DT0: f64 = 0.1;
        const DT_MAX: f64 = 0.5;
        let mut dt = DT0;
        let mut alpha = ALPHA0;
        let mut npos = 0usize;
        for v in &mut self.v {
            *v = [0.0; 3];
        }
        let lim = 0.25 * self.skin * self.skin;
        let mut stale = !self.built;
        for it in 0..=max_iter {
            if stale || !self.built {
                self.build();
                stats.neighbour_builds += 1;
            }
            let s = self.forces();
            if s.worst <= self.tol {
                return true;
            }
            if it == max_iter {
                break;
            }
            stats.iterations += 1;
            let mix = if s.power > 0.0 {
                npos += 1;
                if npos > N_MIN {
                    dt = (dt * F_INC).min(DT_MAX);
                    alpha *= F_ALPHA;
                }
                Some(if s.ff > 0.0 {
                    alpha * (s.vv / s.ff).sqrt()
                } else {
                    0.0
                })
            } else {
                npos = 0;
                dt *= F_DEC;
                alpha = ALPHA0;
                None
            };
            let a = alpha;
            let periods = self.geom.periods();
            // velocity mixing, semi-implicit Euler, and whether a centre left half the skin
            stale = self
                .v
                .par_chunks_mut(CHUNK)
                .zip(self.xr.par_chunks_mut(CHUNK))
                .zip(self.f.par_chunks(CHUNK))
                .zip(self.x_build.par_chunks(CHUNK))
                .map(|(((vs, xs), fs), bs)| {
                    let mut moved = false;
                    for (((v, x), f), b) in vs.iter_mut().zip(xs).zip(fs).zip(bs) {
                        for k in 0..3 {
                            v[k] = match mix {
                                Some(m) => (1.0 - a) * v[k] + m * f[k],
                                None => 0.0,
                            } + dt * f[k];
                            x[k] += dt * v[k];
                        }
                        let d = Self::delta(&periods, x, b);
                        moved |= d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > lim;
                    }
                    moved
                })
                .reduce(|| false, |p, q| p || q);
        }
        false
    }

    /// Scales centres and domain about the centre by the least factor that leaves no
    /// overlap: `1 + max(ov / d)` over pairs (centre distance `d`) and walls (clearance),
    /// so every pair and wall gap grows to at least contact.
    fn expand_free(&mut self) {
        self.build();
        let periods = self.geom.periods();
        let geom = self.geom;
        let (xr, start, list) = (&self.xr, &self.start, &self.list);
        let delta = (0..xr.len())
            .into_par_iter()
            .map(|i| {
                let a = &xr[i];
                let mut w = geom.wall_ratio(a, a[3]);
                for &j in &list[start[i] as usize..start[i + 1] as usize] {
                    let b = &xr[(j & INDEX_MASK) as usize];
                    let d = Self::delta(&periods, a, b);
                    let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    let ov = a[3] + b[3] - dist;
                    if ov > 0.0 {
                        w = w.max(ov / dist);
                    }
                }
                w
            })
            .reduce(|| 0.0, f64::max);
        if delta > 0.0 {
            self.scale_keep((1.0 + delta) * (1.0 + 4.0 * f64::EPSILON));
        }
    }

    /// Pairs (and walls) overlapping by more than the tolerance.
    fn overlapping_pairs(&mut self) -> usize {
        self.build();
        let periods = self.geom.periods();
        let mut n = 0;
        for i in 0..self.xr.len() {
            let a = self.xr[i];
            if self.geom.wall(&a, a[3]).1 > self.tol {
                n += 1;
            }
            for &j in &self.list[self.start[i] as usize..self.start[i + 1] as usize] {
                let j = (j & INDEX_MASK) as usize;
                if j > i {
                    let b = &self.xr[j];
                    let d = Self::delta(&periods, &a, b);
                    let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    if a[3] + b[3] - dist > self.tol {
                        n += 1;
                    }
                }
            }
        }
        n
    }
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
