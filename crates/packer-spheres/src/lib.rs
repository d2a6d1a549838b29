//! Dense 3D sphere packing: the advancing front of Pinto 2009 (Ch. 3, 2D)
//! carried to 3D with the closed-form three-sphere wrapper of
//! [`packer_contact::contact3d`] (Pérez Morales et al. 2016, §3.1), in a box (walls
//! or periodic in x/y), a vertical cylinder or a closed mesh
//! ([`Container`]), with metrics, an independent overlap checker and
//! writers and readers for LAMMPS/LIGGGHTS, Yade, CSV and VTU.
//!
//! # Method
//! Gravity is along −z. In 2D the seed's front is a list of *particles*,
//! and evaluating one intersects its halo with every pair of neighbour
//! halos. In 3D that costs `O(k²)` wrapper solves per evaluation (k ≈ 20
//! neighbours), and a particle is evaluated many times; a first port of
//! the 2D loop took 85 evaluations and ≈ 1.2 ms per sphere. Here the
//! front is a set of **open sites**: when a sphere is placed, every common
//! point of its halo with two more halos or offset walls (sphere–sphere–
//! sphere by the closed form, sphere–sphere–plane, sphere–plane–plane,
//! and for the cylinder the circle of two halos meeting the offset
//! cylinder, bracketed and refined to round-off) that is inside the
//! container and outside every halo becomes a site `(sphere, obstacle,
//! obstacle)`, computed for the smallest size. Sites of one placement
//! closer than `r_min` describe the same hole; the lowest is kept.
//!
//! The next sphere goes to the lowest open site ([`FrontOrder::LowestCandidate`],
//! the default: a geometric gravity deposition; ties by x then y), whose
//! centre is recomputed in closed form for the actual radius and checked
//! against the index (exact container clearance, every sphere within
//! reach). A site that cannot take the size is given a *capacity* (the
//! largest radius it takes, by bisection to 1/16 of the size range against
//! the spheres gathered once) and waits in one of 16 capacity levels; a
//! site that cannot take even the smallest size is dropped. The next site
//! for a radius `r` is the lowest among the levels of capacity ≥ `r`, so a
//! size change never re-queues anything.
//!
//! Choices the seed leaves open (or that 3D adds), made here:
//! * **size order**: sizes are drawn in advance (as the seed's size list)
//!   and a site takes the oldest of the next [`Pack3Params::lookahead`]
//!   sizes that fits it (8 by default, 1 = the seed's strict order): a
//!   small size is never more than 8 draws early, so the placed sizes are
//!   the drawn sizes in a locally permuted order;
//! * **end**: the packing ends when no site takes any size of the window
//!   ([`Pack3Params::max_skips`] = 0, the seed's rule) or, in the dense
//!   preset, after up to 256 skipped sizes fill the last pockets under the
//!   lid with small spheres (reported in [`Pack3Stats::sizes_skipped`]);
//! * **first sphere**: in a corner (box), touching the floor and the side
//!   (cylinder), at the lowest feasible corner of three face planes
//!   (mesh); a box periodic in x and y bootstraps with a second sphere
//!   beside the first on the floor;
//! * **walls**: exact: sphere–plane (box faces, cylinder ends, mesh face
//!   planes), sphere–cylinder; mesh edges and vertices are not tangency
//!   objects (a sphere touches faces only), but every placement is checked
//!   against the exact mesh clearance (levelset's BVH distance with
//!   pseudonormals), so nothing crosses an edge;
//! * **feasibility tolerance**: a centre may enter a halo by `1e-11 ·
//!   d_max` (round-off of the closed forms), far below the `1e-9 · d`
//!   overlap criterion of the checker;
//! * **front orders** for comparison (and the dense portfolio):
//!   [`FrontOrder::LowestFirst`] (sites of the lowest generating sphere
//!   first, the seed's sorted front list) and [`FrontOrder::Stack`]
//!   (newest sphere's sites first, the seed's stack); [`FrontOrder::Best`]
//!   runs the three in parallel and keeps the densest.
//!
//! The index is a uniform cell grid of cell `d_max` (intrusive lists,
//! periodic wrap); a sphere's neighbours are within `r + 2 r_new + r_max`,
//! at most two cells away, so a tree (the 2D MX quadtree, or an octree)
//! would only add depth: the 2D comparison found the grid faster at every
//! size, and 3D sphere sizes of a grading are as uniform.
//!
//! **Slabs** ([`Pack3Params::slabs`], 4 in `default`, off in `dense`): a
//! box (a cylinder with [`Pack3Params::slab_cylinders`]) at least 12 `d_max`
//! wide is cut along `x` into slabs
//! (a slab's first sphere sits in a corner of the box, or against the
//! cylinder's side at the slab's middle); the even slabs are
//! packed in parallel, each by its own front whose sites stop at the slab's
//! faces, then the odd slabs in parallel against their packed neighbours.
//! The sequential front fills the whole cross-section layer by layer, so
//! its working set grows with the box and falls out of the caches at 10⁶
//! spheres (18 µs per sphere against 11 µs at 10⁵); a slab's is a fraction
//! of it, and two slabs pack at once. The price is a thin layering at each
//! face (an even slab's face acts on centres as a wall): the core solid
//! fraction of d ~ U[1, 2] drops by about 0.003 in a box of 40 `d_max`
//! and 0.0013 in one of 74 `d_max`, of monodisperse spheres by 0.013–0.024
//! (the sequential front orders them partly from the walls). Details in
//! `slabs.rs`.
//!
//! Determinism: sizes come from the caller's RNG (for slabs: one seed from
//! it, then the ChaCha8 stream of the slab's index); the front is
//! sequential and deterministic, slabs of one phase do not interact and are
//! assembled in slab order; the portfolio runs in parallel and keeps the
//! densest (ties: the earlier order), so the result is identical for any
//! thread count.

// Seeded randomised tests print their seed (house style).
#![cfg_attr(test, allow(clippy::print_stdout))]

mod container;
mod densify;
mod error;
mod io;
mod metrics;
mod slabs;

pub use container::{Container, MeshContainer};
pub use densify::{
    Boundary, DensePacking3, Densified, DensifyParams, DensifyStats, FireControl, Target, densify,
    max_overlap, pack3d_dense,
};
pub use io::{
    LammpsData3, read_csv3, read_lammps_data3, read_vtu3, read_yade3, write_csv3,
    write_lammps_data3, write_vtu3, write_yade3,
};
pub use metrics::{
    CoreFraction, GradingReport, GradingStats, RadialBin, SphereReport, check_spheres,
    core_solid_fraction, grading_report, radial_profile, solid_fraction,
};

use nalgebra::Point3;

/// A placed sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Point3<f64>,
    /// Radius.
    pub radius: f64,
}

mod front;
mod grid;

pub use front::Pack3Stats;

pub use error::{Error, Result};
pub use packer_quadtree::{FrontOrder, Grading};
use rand::Rng;
use rayon::prelude::*;

/// Parameters of the 3D packer (plain data with `Default`, validated at
/// entry).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pack3Params {
    /// Front order; [`FrontOrder::Best`] runs the three orders on the same
    /// sizes (in parallel) and keeps the densest packing.
    pub front_order: FrontOrder,
    /// A site takes the oldest of the next `lookahead` sizes that fits it
    /// (`1`: sizes strictly in draw order, as the seed's size list).
    pub lookahead: usize,
    /// When no open site takes any size of the window, the oldest size is
    /// skipped (counted in [`Pack3Stats::sizes_skipped`]) up to this many
    /// times in a row before the packing ends. `0` (default) ends the
    /// packing at the first size nothing takes, so the sizes placed are
    /// exactly the drawn ones minus the window left over; larger values
    /// fill the last pockets under the lid with small spheres (denser,
    /// finer at the top).
    pub max_skips: usize,
    /// Generate each new sphere's open sites on a second thread while the
    /// next sphere is being placed (when rayon has at least two threads).
    /// The sites of a sphere become available from the placement after
    /// next (the lag-one rule, applied with or without the thread), so the
    /// packing is the same for any thread count.
    pub pipeline: bool,
    /// Upper bound on the number of spheres (guards against a unit mistake
    /// exhausting memory; checked against the estimate before any work).
    pub max_particles: usize,
    /// Slabs of the slab-parallel packing of a box (or cylinder, see
    /// [`Pack3Params::slab_cylinders`]) by [`pack3d`] (`0` or
    /// `1`: off; default 4, two per phase for two cores): the box is cut
    /// along `x` into this many slabs (fewer if a slab would be narrower
    /// than 6 `d_max`, even if the box is periodic in `x`), packed even
    /// ones first and odd ones against them, each phase in parallel (see
    /// the module docs). The count never depends on the thread count.
    /// Meshes and [`pack3d_sizes`] (whose size order is the caller's) pack
    /// sequentially.
    pub slabs: usize,
    /// Slabs in a cylinder too (default `false`): a slab face through the
    /// specimen is a thin planar layering (see the module docs) that a
    /// triaxial test should not have to meet; in the validate case
    /// `pack3d/cylinder-h2d` it doubles the spread of the interior annuli's
    /// fractions (0.006 → 0.020).
    pub slab_cylinders: bool,
}

impl Default for Pack3Params {
    fn default() -> Self {
        Self {
            front_order: FrontOrder::LowestCandidate,
            lookahead: 8,
            max_skips: 0,
            pipeline: true,
            max_particles: 50_000_000,
            slabs: 4,
            slab_cylinders: false,
        }
    }
}

impl Pack3Params {
    /// The densest configuration: the portfolio of front orders (run in
    /// parallel, densest kept), a look-ahead of 32 sizes, up to 256
    /// skipped sizes to fill the last pockets, and no slabs (a slab face
    /// costs solid fraction, see the module docs).
    pub fn dense() -> Self {
        Self {
            front_order: FrontOrder::Best,
            lookahead: 32,
            max_skips: 256,
            slabs: 0,
            ..Self::default()
        }
    }

    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::Parameter`] for a zero look-ahead or particle limit.
    pub fn validate(&self) -> Result<()> {
        if self.lookahead == 0 {
            return Err(Error::Parameter {
                what: "lookahead",
                value: 0.0,
                range: "[1, inf)",
            });
        }
        if self.max_particles == 0 {
            return Err(Error::Parameter {
                what: "max_particles",
                value: 0.0,
                range: "[1, inf)",
            });
        }
        Ok(())
    }
}

/// A 3D packing.
#[derive(Debug, Clone)]
pub struct Packing3 {
    /// Placed spheres, in placement order.
    pub spheres: Vec<Sphere>,
    /// The front order that produced it (the winner of the portfolio).
    pub front_order: FrontOrder,
    /// Run counters.
    pub stats: Pack3Stats,
}

/// Mean sphere volume `π/6 · E[d³]` of a grading (by number), by the
/// midpoint rule on 4096 quantiles.
fn mean_volume(grading: &Grading) -> f64 {
    let n = 4096;
    let s: f64 = (0..n)
        .map(|i| grading.diameter_at((i as f64 + 0.5) / n as f64).powi(3))
        .sum();
    std::f64::consts::PI / 6.0 * s / n as f64
}

/// Packs `container` with spheres whose diameters follow `grading` (by
/// number), drawn by inverse-transform sampling from `rng` and used in
/// draw order (per slab from streams of one seed drawn from `rng` when
/// the box is slabbed, see [`Pack3Params::slabs`]).
///
/// # Errors
/// Validation errors of the container, grading and parameters;
/// [`Error::DomainTooSmall`] when the container cannot hold one sphere of
/// the largest size; [`Error::TooManyParticles`] when the count estimate
/// (a solid fraction of 0.94 of the container in spheres of the mean
/// volume) exceeds `params.max_particles`.
pub fn pack3d(
    container: &Container,
    grading: &Grading,
    params: &Pack3Params,
    rng: &mut impl Rng,
) -> Result<Packing3> {
    container.validate()?;
    grading.validate()?;
    params.validate()?;
    let (d_min, d_max) = (grading.d_min(), grading.d_max());
    let inscribed = check_room(container, d_max)?;
    let est = (0.75 * 1.25 * container.volume() / mean_volume(grading)).ceil() + 64.0;
    if !est.le(&(params.max_particles as f64)) {
        return Err(Error::TooManyParticles {
            estimate: est,
            limit: params.max_particles,
        });
    }
    let n_slabs = match container {
        Container::Cylinder { .. } if !params.slab_cylinders => 1,
        _ => slabs::slab_count(container, d_max, params.slabs),
    };
    if n_slabs > 1 {
        let seed = rng.next_u64();
        let (min, max) = container.bbox();
        let periodic = container.periodic();
        return pack_slabbed(
            |order| slabs::SlabJob {
                container,
                min,
                max,
                periodic,
                n: n_slabs,
                d_lo: d_min,
                d_hi: d_max,
                grading,
                seed,
                opts: front::RunOpts {
                    order,
                    max: params.max_particles,
                    lookahead: params.lookahead,
                    max_skips: params.max_skips,
                    pipeline: params.pipeline && params.front_order != FrontOrder::Best,
                },
                estimate: est as usize,
            },
            params,
            inscribed,
            d_max,
        );
    }
    let sizes: Vec<f64> = (0..est as usize).map(|_| grading.sample(rng)).collect();
    // Validated above: every drawn size lies in [d_min, d_max].
    pack_checked(container, &sizes, d_min, d_max, inscribed, params)
}

/// The container holds a sphere of diameter `d_max`, and a periodic side is
/// at least `4 d_max` (a sphere must not meet its own image through the
/// index); returns the inscribed diameter (a lattice of exact clearances
/// for meshes, so computed once per packing).
fn check_room(container: &Container, d_max: f64) -> Result<f64> {
    let inscribed = container.inscribed_diameter();
    if inscribed < d_max {
        return Err(Error::DomainTooSmall {
            domain: inscribed,
            particle: d_max,
        });
    }
    if let Container::Box { min, max, periodic } = container {
        for k in 0..2 {
            if periodic[k] && max[k] - min[k] < 4.0 * d_max {
                return Err(Error::DomainTooSmall {
                    domain: max[k] - min[k],
                    particle: 4.0 * d_max,
                });
            }
        }
    }
    Ok(inscribed)
}

/// [`pack3d`] with a ChaCha8 generator seeded by `seed`.
///
/// # Errors
/// As [`pack3d`].
pub fn pack3d_seeded(
    container: &Container,
    grading: &Grading,
    params: &Pack3Params,
    seed: u64,
) -> Result<Packing3> {
    use rand::SeedableRng;
    pack3d(
        container,
        grading,
        params,
        &mut rand_chacha::ChaCha8Rng::seed_from_u64(seed),
    )
}

/// Packs with the given diameters, used in order (`d_min`, `d_max`: the
/// grading's bounds; `d_min` is the size tried before a front is removed).
///
/// # Errors
/// As [`pack3d`], plus [`Error::Empty`] for no sizes and
/// [`Error::NonPositive`] / [`Error::NonFinite`] for a bad size.
pub fn pack3d_sizes(
    container: &Container,
    sizes: &[f64],
    d_min: f64,
    d_max: f64,
    params: &Pack3Params,
) -> Result<Packing3> {
    container.validate()?;
    params.validate()?;
    if sizes.is_empty() {
        return Err(Error::Empty { what: "size list" });
    }
    let mut lo = crate::error::positive("d_min", d_min)?;
    let mut hi = crate::error::positive("d_max", d_max)?;
    for &d in sizes {
        crate::error::positive("sphere diameter", d)?;
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let inscribed = check_room(container, hi)?;
    pack_checked(container, sizes, lo, hi, inscribed, params)
}

/// The slab-parallel packing ([`slabs`]) for each front order of
/// `params`, densest kept.
fn pack_slabbed<'a>(
    job: impl Fn(FrontOrder) -> slabs::SlabJob<'a> + Sync,
    params: &Pack3Params,
    inscribed: f64,
    d_max: f64,
) -> Result<Packing3> {
    let runs: Vec<Packing3> = orders_of(params)
        .par_iter()
        .map(|&order| {
            let (xs, stats) = job(order).pack();
            Packing3 {
                spheres: xs
                    .iter()
                    .map(|q| Sphere {
                        center: Point3::new(q[0], q[1], q[2]),
                        radius: q[3],
                    })
                    .collect(),
                front_order: order,
                stats,
            }
        })
        .collect();
    densest(runs, inscribed, d_max)
}

/// The front orders a parameter set runs.
fn orders_of(params: &Pack3Params) -> Vec<FrontOrder> {
    if params.front_order == FrontOrder::Best {
        vec![
            FrontOrder::LowestCandidate,
            FrontOrder::Stack,
            FrontOrder::LowestFirst,
        ]
    } else {
        vec![params.front_order]
    }
}

/// The densest run; ties keep the earlier order.
fn densest(runs: Vec<Packing3>, inscribed: f64, d: f64) -> Result<Packing3> {
    let mut best: Option<(f64, Packing3)> = None;
    for p in runs {
        let v: f64 = p.spheres.iter().map(|s| s.radius.powi(3)).sum();
        if best.as_ref().is_none_or(|(b, _)| v > *b) {
            best = Some((v, p));
        }
    }
    match best {
        Some((_, p)) if !p.spheres.is_empty() => Ok(p),
        _ => Err(Error::DomainTooSmall {
            domain: inscribed,
            particle: d,
        }),
    }
}

/// The packing proper, on validated input.
fn pack_checked(
    container: &Container,
    sizes: &[f64],
    lo: f64,
    hi: f64,
    inscribed: f64,
    params: &Pack3Params,
) -> Result<Packing3> {
    let orders = orders_of(params);
    let runs: Vec<Packing3> = orders
        .par_iter()
        .map(|&order| {
            let mut f = front::Front3::new(container, 0.5 * lo, 0.5 * hi, sizes.len());
            let mut next = |k: usize| sizes.get(k).copied();
            f.run(
                &mut next,
                front::RunOpts {
                    order,
                    max: params.max_particles,
                    lookahead: params.lookahead,
                    max_skips: params.max_skips,
                    pipeline: params.pipeline && orders.len() == 1,
                },
                front::Start::default(),
            );
            let stats = f.stats;
            Packing3 {
                spheres: f
                    .xs
                    .iter()
                    .map(|q| Sphere {
                        center: Point3::new(q[0], q[1], q[2]),
                        radius: q[3],
                    })
                    .collect(),
                front_order: order,
                stats,
            }
        })
        .collect();
    densest(runs, inscribed, sizes[0])
}

#[cfg(test)]
mod tests;
