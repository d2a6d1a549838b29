//! Slab-parallel packing of a box or a cylinder.
//!
//! The box is cut along `x` into `n` slabs of equal width `W ≥ 6 d_max`.
//! The even slabs are packed first, in parallel: each is a front of its
//! own (its own size stream, sites kept only when their key lies in the
//! slab, no wall at a slab end that is not a box wall), so they cannot
//! meet: a sphere centre lies at most `r_max` outside its slab, and the odd
//! slab between two even ones is wider than `2 d_max`. Then the odd slabs
//! are packed, in parallel: the spheres of the neighbouring slabs within
//! `2 d_max` of the slab are placed first as obstacles, and the sites of
//! those within `d_max` start the front, which then fills the slab lowest
//! first against the two rough faces, as the sequential front fills against
//! its own spheres. In a box periodic in `x` the slab count is even and the
//! last slab's neighbour is the first, shifted by the period.
//!
//! Why: the sequential front fills the whole cross-section layer by layer,
//! so its working set (the spheres, sites and cells of the top layer) grows
//! with the box's cross-section; at 10⁶ spheres it falls out of the caches
//! and the cost per sphere rose from 11 to 18 µs. A slab's layer is `W/L_x`
//! of it, and two slabs pack at once on two cores. The faces between slabs
//! are filled by the same front, so the solid fraction is that of the
//! sequential packing within the measurement noise (tested).
//!
//! Determinism: slab `j` draws its sizes from the ChaCha8 stream `j` of one
//! seed drawn from the caller's generator; the slabs of a phase do not
//! interact, and the result is assembled in slab order, so the packing is
//! the same for any thread count.

use nalgebra::{Point3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::container::Container;
use super::front::{Front3, Pack3Stats, RunOpts, Start};
use packer_quadtree::Grading;

/// Smallest slab width in units of `d_max` (slabs of one phase must be
/// more than `2 d_max` apart, and an odd slab's imports must not meet their
/// own periodic images).
pub(super) const MIN_SLAB: f64 = 6.0;

/// Number of slabs for a container: `requested`, lowered until every slab
/// is at least `MIN_SLAB · d_max` wide and made even when the box is
/// periodic in `x` (the last slab's neighbour is then the first); 1 (no
/// slabs) for a mesh, or when fewer than 2 remain.
pub(super) fn slab_count(container: &Container, d_max: f64, requested: usize) -> usize {
    let (min, max, periodic) = match container {
        Container::Box { min, max, periodic } => (*min, *max, *periodic),
        Container::Cylinder { .. } => {
            let (lo, hi) = container.bbox();
            (lo, hi, [false; 2])
        }
        Container::Mesh(_) => return 1,
    };
    let fit = ((max.x - min.x) / (MIN_SLAB * d_max)).floor();
    let mut n = if fit.is_finite() && fit >= 0.0 {
        requested.min(fit as usize)
    } else {
        0
    };
    if periodic[0] {
        n -= n % 2;
    }
    if n < 2 { 1 } else { n }
}

/// What one slab run needs.
pub(super) struct SlabJob<'a> {
    /// A box or a cylinder.
    pub(super) container: &'a Container,
    pub(super) min: Point3<f64>,
    pub(super) max: Point3<f64>,
    pub(super) periodic: [bool; 2],
    pub(super) n: usize,
    pub(super) d_lo: f64,
    pub(super) d_hi: f64,
    pub(super) grading: &'a Grading,
    pub(super) seed: u64,
    /// The front settings of every slab (`max` counts own spheres; the
    /// pipeline runs only in a phase of one slab).
    pub(super) opts: RunOpts,
    /// Expected number of spheres of the whole box.
    pub(super) estimate: usize,
}

impl SlabJob<'_> {
    fn bounds(&self, j: usize) -> [f64; 2] {
        let w = (self.max.x - self.min.x) / self.n as f64;
        let x0 = self.min.x + j as f64 * w;
        let x1 = if j + 1 == self.n {
            self.max.x
        } else {
            self.min.x + (j + 1) as f64 * w
        };
        [x0, x1]
    }

    /// Packs slab `j` against the `imported` spheres; returns its own
    /// spheres and counters.
    fn run_slab(
        &self,
        j: usize,
        imported: Vec<[f64; 4]>,
        pipeline: bool,
    ) -> (Vec<[f64; 4]>, Pack3Stats) {
        let [x0, x1] = self.bounds(j);
        let pad = 3.0 * self.d_hi;
        let wall_lo = !self.periodic[0] && j == 0;
        let wall_hi = !self.periodic[0] && j + 1 == self.n;
        let lo_x = if wall_lo { self.min.x } else { x0 - pad };
        let hi_x = if wall_hi { self.max.x } else { x1 + pad };
        // A box slab: the pads are empty space closed by walls no sphere
        // reaches (a centre stays within r_max of its slab, walls are seen
        // within 3 r_max of a generating sphere). A cylinder slab: the
        // whole cylinder, the sites cut to the slab.
        let sub = match self.container {
            Container::Box { .. } => Container::Box {
                min: Point3::new(lo_x, self.min.y, self.min.z),
                max: Point3::new(hi_x, self.max.y, self.max.z),
                periodic: [false, self.periodic[1]],
            },
            c => c.clone(),
        };
        // The first sphere (even slabs): in the corner at the slab's left
        // end (box), touching the floor and the side at the slab's middle
        // (cylinder).
        let seed_x = match self.container {
            Container::Box { .. } if wall_lo => self.min.x,
            Container::Box { .. } => x0,
            _ => 0.5 * (x0 + x1),
        };
        let region = [
            if wall_lo { f64::NEG_INFINITY } else { x0 },
            if wall_hi { f64::INFINITY } else { x1 },
        ];
        let n_imp = imported.len();
        let cap = self.estimate / self.n + self.estimate / (4 * self.n) + n_imp + 64;
        let mut f = Front3::new(&sub, 0.5 * self.d_lo, 0.5 * self.d_hi, cap);
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(j as u64);
        let grading = self.grading;
        let mut next = |_k: usize| Some(grading.sample(&mut rng));
        f.run(
            &mut next,
            RunOpts {
                max: self.opts.max.saturating_add(n_imp),
                pipeline,
                ..self.opts
            },
            Start {
                region: Some(region),
                seed_x: Some(seed_x),
                imported,
            },
        );
        let stats = f.stats;
        let mut own = f.xs;
        own.drain(..n_imp);
        (own, stats)
    }

    /// Spheres of the neighbouring slabs within `2 d_max` of slab `j`
    /// (periodic images shifted).
    fn imports(&self, j: usize, done: &[Option<Vec<[f64; 4]>>]) -> Vec<[f64; 4]> {
        let [x0, x1] = self.bounds(j);
        let reach = 2.0 * self.d_hi;
        let l = self.max.x - self.min.x;
        let mut nbrs: Vec<usize> = Vec::with_capacity(2);
        let n = self.n;
        if j > 0 {
            nbrs.push(j - 1);
        } else if self.periodic[0] {
            nbrs.push(n - 1);
        }
        if j + 1 < n {
            nbrs.push(j + 1);
        } else if self.periodic[0] {
            nbrs.push(0);
        }
        nbrs.sort_unstable();
        nbrs.dedup();
        let shifts: &[f64] = if self.periodic[0] {
            &[0.0, -l, l]
        } else {
            &[0.0]
        };
        let mut out = Vec::new();
        for &nb in &nbrs {
            let Some(xs) = &done[nb] else { continue };
            for &s in shifts {
                out.extend(xs.iter().filter_map(|q| {
                    let x = q[0] + s;
                    (x >= x0 - reach && x < x1 + reach).then_some([x, q[1], q[2], q[3]])
                }));
            }
        }
        out
    }

    /// Packs the box: even slabs in parallel, then odd slabs in parallel.
    pub(super) fn pack(&self) -> (Vec<[f64; 4]>, Pack3Stats) {
        let n = self.n;
        let mut done: Vec<Option<Vec<[f64; 4]>>> = vec![None; n];
        let mut stats = Pack3Stats {
            slabs: n as u64,
            ..Pack3Stats::default()
        };
        for parity in [0usize, 1] {
            let ids: Vec<usize> = (parity..n).step_by(2).collect();
            let pipeline = self.opts.pipeline && ids.len() == 1;
            let runs: Vec<(Vec<[f64; 4]>, Pack3Stats)> = ids
                .par_iter()
                .map(|&j| {
                    let imported = if parity == 0 {
                        Vec::new()
                    } else {
                        self.imports(j, &done)
                    };
                    self.run_slab(j, imported, pipeline)
                })
                .collect();
            for (&j, (xs, st)) in ids.iter().zip(runs) {
                add_stats(&mut stats, &st);
                done[j] = Some(xs);
            }
        }
        let l = Vector3::new(self.max.x - self.min.x, 0.0, 0.0);
        let mut out = Vec::with_capacity(done.iter().flatten().map(Vec::len).sum());
        for xs in done.into_iter().flatten() {
            for mut q in xs {
                if self.periodic[0] {
                    let mut x = q[0] - self.min.x;
                    x -= (x / l.x).floor() * l.x;
                    if x >= l.x {
                        x = 0.0;
                    }
                    q[0] = self.min.x + x;
                }
                out.push(q);
            }
        }
        (out, stats)
    }
}

fn add_stats(a: &mut Pack3Stats, b: &Pack3Stats) {
    a.evaluations += b.evaluations;
    a.fronts_removed += b.fronts_removed;
    a.sizes_drawn += b.sizes_drawn;
    a.sizes_skipped += b.sizes_skipped;
    a.peak_bytes += b.peak_bytes;
    a.neighbours += b.neighbours;
    a.candidates += b.candidates;
    a.site_tests += b.site_tests;
    a.pops += b.pops;
    a.sites += b.sites;
}
