//! The 3D advancing front (Pinto 2009, Ch. 3, carried to 3D).
//!
//! Every placed sphere is a *front*. Evaluating a front `f` for the next
//! radius `r` gathers the obstacles whose halo (radius `r_j + r`) can meet
//! the front's halo (`r_f + r`): spheres with `|c_j − c_f| ≤ r_f + r_j + 2r`
//! and walls within `r_f + 2r`. The candidate centres are the common points
//! of the front's halo with two more halos or offset walls: the closed-form
//! three-sphere wrapper of Pérez Morales et al. 2016, §3.1
//! ([`packer_contact::contact3d`]), spheres and planes, and for the cylinder the
//! intersection of the front/obstacle circle with the offset cylinder. A
//! candidate is feasible when it lies inside the container (exact
//! clearance) and outside every obstacle halo; the feasible candidate with
//! the lowest `z` (ties: `x`, then `y`) receives the sphere. A front without
//! a feasible candidate is tried with the smallest size of the grading;
//! when even that fails it is removed, otherwise it waits for the next
//! placement (the size is kept for the other fronts, as in 2D). A size that
//! no front can take is skipped (counted in [`Pack3Stats::sizes_skipped`]).

// Coordinates are `[f64; 3]` triples indexed in step with box bounds,
// periods and cell counts: index loops read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

use super::container::Container;
use super::grid::Grid3;
use packer_quadtree::FrontOrder;

mod generate;
mod run;
mod sites;
mod solve;
mod walls;

use sites::Site;
use solve::Nb;
use walls::{Plane, Walls};

/// Relative tolerance of the feasibility test: a candidate may enter an
/// obstacle halo by `FEAS_TOL · d_max` (round-off of the intersection), far
/// below the `1e-9 · d` overlap criterion of the checker.
const FEAS_TOL: f64 = 1e-11;

/// Counters of one packing run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Pack3Stats {
    /// Site generations (one per placed sphere).
    pub evaluations: u64,
    /// Sites dropped (no room even for the smallest size).
    pub fronts_removed: u64,
    /// Sizes drawn from the grading.
    pub sizes_drawn: u64,
    /// Sizes skipped because no front could take them (at the end of the
    /// packing, when only small pockets are left).
    pub sizes_skipped: u64,
    /// Peak heap bytes of the packer's own structures.
    pub peak_bytes: u64,
    /// Neighbours gathered over all evaluations.
    pub neighbours: u64,
    /// Candidates generated over all evaluations.
    pub candidates: u64,
    /// Site tests (closed-form position and feasibility).
    pub site_tests: u64,
    /// Sites popped.
    pub pops: u64,
    /// Sites generated.
    pub sites: u64,
    /// Slabs of a slab-parallel packing (0 or 1: one front).
    pub slabs: u64,
}

/// Obstacle ids at or above `WALL` are walls: `WALL + i` is plane `i`,
/// [`CYL`] the cylinder side.
const WALL: u32 = 0xFFFF_0000;
const CYL: u32 = u32::MAX;
/// Third obstacle of the bootstrap site of a box periodic in x and y: the
/// second sphere touches the first and the floor on the first's `+x` side.
const FREE: u32 = u32::MAX - 1;

/// Sizes tried for the first sphere before the container is declared too
/// small.
const MAX_SKIPS: usize = 256;

#[derive(Clone)]
pub(crate) struct Front3<'a> {
    container: &'a Container,
    walls: Walls,
    /// Every wall plane (box faces, cylinder ends, mesh faces).
    all_planes: Vec<Plane>,
    periodic: [bool; 2],
    period: [f64; 2],
    box_lo: [f64; 3],
    r_min: f64,
    r_max: f64,
    tol: f64,
    grid: Grid3,
    pub(crate) xs: Vec<[f64; 4]>,
    nb: Vec<Nb>,
    planes: Vec<(Plane, u32)>,
    cands: Vec<([f64; 3], u32, u32)>,
    /// Spheres near a site (periodic images applied), for repeated tests.
    local: Vec<[f64; 4]>,
    /// Feasible sites of one generation.
    kept: Vec<([f64; 3], u32, u32)>,
    /// Sites of one placement (sequential mode).
    batch: Vec<Site>,
    /// Neighbour halos of the generating sphere as `[dx, dy, dz, (ρ −
    /// tol)²]`, padded to a multiple of 4 with halos nothing enters.
    halos: Vec<[f64; 4]>,
    /// `x` of the first sphere: its wall side in a box (default: the box's
    /// `min.x`; a slab's left end), its centre in a cylinder (default: on
    /// the `+x` side).
    seed_x: Option<f64>,
    pub(crate) stats: Pack3Stats,
}

/// Settings of one front run (see [`crate::Pack3Params`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RunOpts {
    pub(crate) order: FrontOrder,
    /// Upper bound on the spheres held (imported ones included).
    pub(crate) max: usize,
    pub(crate) lookahead: usize,
    pub(crate) max_skips: usize,
    /// Site generation on a second thread.
    pub(crate) pipeline: bool,
}

/// How a run starts: the whole container from a seed sphere (default), or
/// one slab of a slab-parallel packing (sites restricted to `region`;
/// `imported`: spheres of the neighbouring slabs, placed first as
/// obstacles, whose sites near the slab start the front).
#[derive(Debug, Clone, Default)]
pub(crate) struct Start {
    pub(crate) region: Option<[f64; 2]>,
    pub(crate) seed_x: Option<f64>,
    pub(crate) imported: Vec<[f64; 4]>,
}

impl<'a> Front3<'a> {
    pub(crate) fn new(container: &'a Container, r_min: f64, r_max: f64, capacity: usize) -> Self {
        let (lo, hi) = container.bbox();
        let periodic = container.periodic();
        let grid = Grid3::new(lo, hi, 2.0 * r_max, periodic, 64_000_000);
        let walls = Walls::new(container, r_max);
        let all_planes = match &walls {
            Walls::Planes(p) => p.clone(),
            Walls::Cylinder { planes, .. } => planes.to_vec(),
            Walls::Mesh(m) => m.planes.clone(),
        };
        Self {
            container,
            walls,
            all_planes,
            periodic,
            period: [hi.x - lo.x, hi.y - lo.y],
            box_lo: [lo.x, lo.y, lo.z],
            r_min,
            r_max,
            tol: FEAS_TOL * 2.0 * r_max,
            grid,
            xs: Vec::with_capacity(capacity),
            nb: Vec::with_capacity(64),
            planes: Vec::with_capacity(16),
            cands: Vec::with_capacity(1024),
            local: Vec::with_capacity(128),
            kept: Vec::with_capacity(64),
            batch: Vec::with_capacity(64),
            halos: Vec::with_capacity(64),
            seed_x: None,
            stats: Pack3Stats::default(),
        }
    }

    fn place(&mut self, mut p: [f64; 3], r: f64) -> u32 {
        for k in 0..2 {
            if self.periodic[k] {
                let l = self.period[k];
                let mut x = p[k] - self.box_lo[k];
                x -= (x / l).floor() * l;
                if x >= l {
                    x = 0.0;
                }
                p[k] = self.box_lo[k] + x;
            }
        }
        let id = self.xs.len() as u32;
        let q = [p[0], p[1], p[2], r];
        self.xs.push(q);
        self.grid.insert(id, &q);
        id
    }

    fn note_memory(&mut self, extra: usize) {
        let b = self.xs.capacity() * 32 + self.grid.heap_bytes() + extra;
        self.stats.peak_bytes = self.stats.peak_bytes.max(b as u64);
    }
}

/// Test access to the closed forms.
#[cfg(test)]
pub(crate) mod tests_api {
    use super::solve::{Nb, Pts, three_spheres};
    use nalgebra::{Point3, Vector3};

    /// Centres of a sphere of radius `r` tangent to three spheres, through
    /// the packer's inlined closed form.
    pub(crate) fn three(c: &[(Point3<f64>, f64)], r: f64) -> Vec<Point3<f64>> {
        let f = c[0];
        let rho_f = f.1 + r;
        let nb = |o: (Point3<f64>, f64)| {
            let d = o.0 - f.0;
            let dd = d.norm_squared();
            let rho = o.1 + r;
            Nb {
                d: [d.x, d.y, d.z],
                dd,
                rho,
                b: 0.5 * (dd + rho_f * rho_f - rho * rho),
                id: 0,
            }
        };
        let mut out = Pts::default();
        three_spheres(&nb(c[1]), &nb(c[2]), rho_f * rho_f, &mut out);
        out.as_slice()
            .iter()
            .map(|y| f.0 + Vector3::new(y[0], y[1], y[2]))
            .collect()
    }

    /// Centres touching a front sphere, an obstacle sphere and the inside
    /// of a cylinder of `radius` around the z axis.
    pub(crate) fn circle_cylinder(
        cf: [f64; 3],
        rf: f64,
        ca: [f64; 3],
        ra: f64,
        r: f64,
        radius: f64,
    ) -> Vec<[f64; 3]> {
        let rho_f = rf + r;
        let d = [ca[0] - cf[0], ca[1] - cf[1], ca[2] - cf[2]];
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let rho = ra + r;
        let a = Nb {
            d,
            dd,
            rho,
            b: 0.5 * (dd + rho_f * rho_f - rho * rho),
            id: 0,
        };
        let mut out = Pts::default();
        super::solve::circle_cylinder(&a, rho_f * rho_f, [-cf[0], -cf[1]], radius - r, &mut out);
        out.as_slice()
            .iter()
            .map(|y| [y[0] + cf[0], y[1] + cf[1], y[2] + cf[2]])
            .collect()
    }
}
