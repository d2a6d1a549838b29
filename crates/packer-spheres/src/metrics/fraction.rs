//! Solid fractions over the container and over a core region away from
//! the walls (exact for boxes and cylinders, voxel-sampled for meshes).

use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::grid::{Axes, Buckets};
use super::volumes::{sphere_box_volume, sphere_cylinder_volume};
use super::walls::Walls;
use super::{chunked_sum, sphere_volume, validate_spheres};
use crate::error::{Error, Result};
use crate::{Container, Sphere};

/// Overall solid fraction: the sum of the sphere volumes over the container
/// volume. Spheres are taken whole (inside by construction; in a periodic
/// box a sphere crossing a periodic face still counts whole, its outer part
/// being the image that re-enters on the other side).
///
/// # Errors
/// Container validation errors; [`Error::NonFinite`] / [`Error::NonPositive`]
/// for a bad sphere.
pub fn solid_fraction(container: &Container, spheres: &[Sphere]) -> Result<f64> {
    container.validate()?;
    validate_spheres(spheres)?;
    let (solid, _) = chunked_sum(spheres, |s| sphere_volume(s.radius));
    Ok(solid / container.volume())
}

/// Solid fraction of the core region of a container: the points at
/// distance at least `margin` from every wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoreFraction {
    /// Solid volume in the core over the core volume.
    pub fraction: f64,
    /// Volume of the core region (exact for boxes and cylinders; the voxel
    /// estimate for meshes).
    pub core_volume: f64,
    /// Spheres reaching into the core (for meshes: spheres holding at least
    /// one core sample of the voxel estimate).
    pub n_spheres_touching: usize,
}

/// Most sample points of the voxel estimate for mesh containers.
const MAX_VOXEL_SAMPLES: f64 = 16_777_216.0;

/// Solid fraction of the core region, the points at distance `≥ margin`
/// from every wall: a box shrunk by `margin` on its walled sides (periodic
/// x/y sides are not walls; spheres crossing them count whole), a cylinder
/// of radius `R − margin` and height `H − 2·margin`, or the points of a
/// mesh container with clearance `≥ margin`.
///
/// Boxes and cylinders are exact (module docs). Meshes are a documented
/// estimate: the core is sampled at the cell centres of a grid of spacing
/// `d_min / 8` (`d_min` the smallest sphere diameter; coarser if that
/// would exceed 2²⁴ samples) over the bounding box shrunk by `margin`; a
/// sample is in the core when parry's signed distance to the mesh is
/// `≥ margin` (8³ blocks whose centre is farther than their half-diagonal
/// from the core boundary are classified at once, the distance being
/// 1-Lipschitz) and solid when it lies in a sphere (spheres binned by a
/// cell grid). The fraction is the ratio of the counts, the core volume
/// the core count times the sample cell volume. A single sphere is
/// resolved by its lattice points to a few per cent (the lattice-point
/// error of a ball of 4–8 spacings radius); over many spheres at random
/// offsets the errors average out (below 1 % for a hundred spheres).
///
/// # Errors
/// Container validation errors; [`Error::NonFinite`] / [`Error::NonPositive`]
/// for a bad sphere; [`Error::Parameter`] for a negative or non-finite
/// margin; [`Error::EmptyCore`] when the margin leaves no core;
/// [`Error::CheckerMesh`] if parry rejects a container mesh.
pub fn core_solid_fraction(
    container: &Container,
    spheres: &[Sphere],
    margin: f64,
) -> Result<CoreFraction> {
    container.validate()?;
    validate_spheres(spheres)?;
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(Error::Parameter {
            what: "core margin",
            value: margin,
            range: "[0, inf)",
        });
    }
    let empty = || Error::EmptyCore { margin };
    match container {
        Container::Box { min, max, periodic } => {
            let mut lo = [0.0; 3];
            let mut hi = [0.0; 3];
            let mut core_volume = 1.0;
            for k in 0..3 {
                if k < 2 && periodic[k] {
                    lo[k] = f64::NEG_INFINITY;
                    hi[k] = f64::INFINITY;
                    core_volume *= max[k] - min[k];
                } else {
                    lo[k] = min[k] + margin;
                    hi[k] = max[k] - margin;
                    if hi[k] <= lo[k] {
                        return Err(empty());
                    }
                    core_volume *= hi[k] - lo[k];
                }
            }
            let (solid, touching) = chunked_sum(spheres, |s| sphere_box_volume(s, lo, hi));
            Ok(CoreFraction {
                fraction: solid / core_volume,
                core_volume,
                n_spheres_touching: touching,
            })
        }
        Container::Cylinder {
            base,
            radius,
            height,
        } => {
            let big = radius - margin;
            let (z0, z1) = (base.z + margin, base.z + height - margin);
            if big <= 0.0 || z1 <= z0 {
                return Err(empty());
            }
            let core_volume = PI * big * big * (z1 - z0);
            let (solid, touching) = chunked_sum(spheres, |s| {
                sphere_cylinder_volume(s, base.x, base.y, big, z0, z1)
            });
            Ok(CoreFraction {
                fraction: solid / core_volume,
                core_volume,
                n_spheres_touching: touching,
            })
        }
        Container::Mesh(_) => {
            let walls = Walls::new(container)?;
            mesh_core(container, &walls, spheres, margin)
        }
    }
}

/// The voxel estimate of [`core_solid_fraction`] for mesh containers.
fn mesh_core(
    container: &Container,
    walls: &Walls,
    spheres: &[Sphere],
    margin: f64,
) -> Result<CoreFraction> {
    let (blo, bhi) = container.bbox();
    let a = [blo.x + margin, blo.y + margin, blo.z + margin];
    let b = [bhi.x - margin, bhi.y - margin, bhi.z - margin];
    if (0..3).any(|k| b[k] <= a[k]) {
        return Err(Error::EmptyCore { margin });
    }
    let box_volume = (b[0] - a[0]) * (b[1] - a[1]) * (b[2] - a[2]);
    let floor = (box_volume / MAX_VOXEL_SAMPLES).cbrt();
    let dmin = spheres
        .iter()
        .map(|s| 2.0 * s.radius)
        .fold(f64::INFINITY, f64::min);
    let h = if spheres.is_empty() {
        floor
    } else {
        (dmin / 8.0).max(floor)
    };
    let mut n = [0usize; 3];
    let mut step = [0.0; 3];
    for k in 0..3 {
        n[k] = (((b[k] - a[k]) / h).ceil() as usize).max(1);
        step[k] = (b[k] - a[k]) / n[k] as f64;
    }
    let point = |i: [usize; 3]| -> [f64; 3] {
        [
            a[0] + (i[0] as f64 + 0.5) * step[0],
            a[1] + (i[1] as f64 + 0.5) * step[1],
            a[2] + (i[2] as f64 + 0.5) * step[2],
        ]
    };

    // Spheres binned into every cell their bounding box meets.
    let rmax = spheres.iter().map(|s| s.radius).fold(0.0, f64::max);
    let (mut slo, mut shi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for s in spheres {
        for k in 0..3 {
            slo[k] = slo[k].min(s.center[k] - s.radius);
            shi[k] = shi[k].max(s.center[k] + s.radius);
        }
    }
    if spheres.is_empty() {
        slo = [0.0; 3];
        shi = [0.0; 3];
    }
    let axes = Axes::new(
        slo,
        shi,
        [false; 3],
        (2.0 * rmax).max(f64::MIN_POSITIVE),
        (4 * spheres.len()).max(64),
    );
    let ranges: Vec<([usize; 3], [usize; 3])> = spheres
        .iter()
        .map(|s| {
            let c = [s.center.x, s.center.y, s.center.z];
            let lo = c.map(|v| v - s.radius);
            let hi = c.map(|v| v + s.radius);
            (axes.coord(lo), axes.coord(hi))
        })
        .collect();
    let buckets = Buckets::from_ranges(&axes, &ranges);
    // Spheres holding a core sample (a set: the order of the stores does
    // not matter).
    let hit: Vec<AtomicBool> = spheres.iter().map(|_| AtomicBool::new(false)).collect();
    let solid_at = |p: [f64; 3]| -> bool {
        if spheres.is_empty() {
            return false;
        }
        let c = axes.flat(axes.coord(p));
        let mut solid = false;
        for q in buckets.cell(c) {
            let i = buckets.items[q];
            let s = &spheres[i];
            let (dx, dy, dz) = (p[0] - s.center.x, p[1] - s.center.y, p[2] - s.center.z);
            if dx * dx + dy * dy + dz * dz <= s.radius * s.radius {
                solid = true;
                hit[i].store(true, Ordering::Relaxed);
            }
        }
        solid
    };

    const B: usize = 8;
    let nb = n.map(|v| v.div_ceil(B));
    let nblocks = nb[0] * nb[1] * nb[2];
    let (core, solid) = (0..nblocks)
        .into_par_iter()
        .map(|blk| {
            let bi = [blk % nb[0], (blk / nb[0]) % nb[1], blk / (nb[0] * nb[1])];
            let i0 = bi.map(|v| v * B);
            let i1 = [
                (i0[0] + B).min(n[0]),
                (i0[1] + B).min(n[1]),
                (i0[2] + B).min(n[2]),
            ];
            let p0 = point(i0);
            let p1 = point([i1[0] - 1, i1[1] - 1, i1[2] - 1]);
            let centre = [
                0.5 * (p0[0] + p1[0]),
                0.5 * (p0[1] + p1[1]),
                0.5 * (p0[2] + p1[2]),
            ];
            let half_diag = 0.5
                * ((p1[0] - p0[0]).powi(2) + (p1[1] - p0[1]).powi(2) + (p1[2] - p0[2]).powi(2))
                    .sqrt();
            let c = walls.clearance(centre);
            if c + half_diag < margin {
                return (0u64, 0u64);
            }
            let all_in = c - half_diag >= margin;
            let (mut core, mut solid) = (0u64, 0u64);
            for z in i0[2]..i1[2] {
                for y in i0[1]..i1[1] {
                    for x in i0[0]..i1[0] {
                        let p = point([x, y, z]);
                        if all_in || walls.clearance(p) >= margin {
                            core += 1;
                            if solid_at(p) {
                                solid += 1;
                            }
                        }
                    }
                }
            }
            (core, solid)
        })
        .reduce(|| (0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
    if core == 0 {
        return Err(Error::EmptyCore { margin });
    }
    let touching = hit.iter().filter(|h| h.load(Ordering::Relaxed)).count();
    Ok(CoreFraction {
        fraction: solid as f64 / core as f64,
        core_volume: core as f64 * step[0] * step[1] * step[2],
        n_spheres_touching: touching,
    })
}
