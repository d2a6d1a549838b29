//! The relaxation's state: FIRE velocities and forces, the Verlet
//! neighbour list with periodic image codes, and the deterministic chunked
//! sums of the force pass.

use rayon::prelude::*;

use super::geom::Geom;
use super::{DensifyStats, FireControl};
use crate::Sphere;

/// Spheres per chunk of the deterministic global sums.
const CHUNK: usize = 1024;
/// Bits of a neighbour entry holding the sphere index; the 5 bits above hold the
/// periodic image (a code in 0..27 of the shift `n · period`, `n ∈ {−1, 0, 1}` per axis).
const INDEX_BITS: u32 = 27;
/// Mask of the sphere index in a neighbour entry.
pub(super) const INDEX_MASK: u32 = (1 << INDEX_BITS) - 1;

/// The 27 image shifts of the neighbour codes.
fn image_shifts(periods: &[f64; 3]) -> [[f64; 3]; 27] {
    std::array::from_fn(|code| {
        let n = [code % 3, (code / 3) % 3, code / 9];
        std::array::from_fn(|k| (n[k] as f64 - 1.0) * periods[k])
    })
}

/// FIRE state and the neighbour list.
pub(super) struct System {
    /// Centre and radius of every sphere.
    pub(super) xr: Vec<[f64; 4]>,
    v: Vec<[f64; 3]>,
    f: Vec<[f64; 3]>,
    pub(super) geom: Geom,
    /// Neighbour list, each pair once from its lower-numbered sphere (CSR,
    /// each sphere's entries in increasing neighbour index).
    start: Vec<u32>,
    list: Vec<u32>,
    /// For each sphere, the entries of `list` in which it is the higher-numbered
    /// sphere (CSR, in increasing entry order).
    lstart: Vec<u32>,
    lref: Vec<u32>,
    /// Force of each listed pair on its lower sphere (the higher one takes the opposite).
    pf: Vec<[f64; 3]>,
    /// Centres at the last build.
    x_build: Vec<[f64; 3]>,
    /// Input index of each sphere (the spheres are kept in cell order).
    pub(super) ids: Vec<u32>,
    skin: f64,
    r_max: f64,
    /// Overlap accepted by the relaxation, over the pair's centre distance (a wall's:
    /// over the sphere's clearance).
    tol: f64,
    built: bool,
}

/// The sums of the force pass.
#[derive(Clone, Copy)]
struct Sums {
    power: f64,
    ff: f64,
    vv: f64,
    worst: f64,
}

impl System {
    pub(super) fn new(
        spheres: &[Sphere],
        geom: Geom,
        r_min: f64,
        r_max: f64,
        tolerance: f64,
    ) -> Self {
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
            lstart: Vec::new(),
            lref: Vec::new(),
            pf: Vec::new(),
            x_build: Vec::new(),
            ids: (0..n as u32).collect(),
            skin: 0.25 * d_min,
            r_max,
            tol: tolerance,
            built: false,
        }
    }

    /// Forgets velocities and the neighbour list (after a restore).
    pub(super) fn reset(&mut self) {
        self.built = false;
        for v in &mut self.v {
            *v = [0.0; 3];
        }
    }

    /// Scales centres and domain by `s` about the centre, keeping velocities.
    pub(super) fn scale_keep(&mut self, s: f64) {
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
    pub(super) fn compress(&mut self, s: f64) {
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
        // each pair once, from the sphere of the lower index: the spheres are numbered in cell
        // order, so a neighbouring cell of a lower number holds only lower indices
        let upper: Vec<Vec<u32>> = (0..xr.len())
            .into_par_iter()
            .map(|i| {
                let c = cell_of(&xr[i]);
                let own = (c[2] * dims[1] + c[1]) * dims[0] + c[0];
                let mut out = Vec::with_capacity(12);
                let (zs, nz) = span(2, c[2]);
                let (ys, ny) = span(1, c[1]);
                let (xs, nx) = span(0, c[0]);
                for &cz in &zs[..nz] {
                    for &cy in &ys[..ny] {
                        for &cx in &xs[..nx] {
                            let cell = (cz * dims[1] + cy) * dims[0] + cx;
                            if cell < own {
                                continue;
                            }
                            let first = if cell == own {
                                i + 1
                            } else {
                                head[cell] as usize
                            };
                            for j in first..head[cell + 1] as usize {
                                let d = Self::delta(&periods, &xr[i], &xr[j]);
                                let cut = xr[i][3] + xr[j][3] + skin;
                                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < cut * cut {
                                    // the image of j nearest to i, as a shift code
                                    let mut code = 0u32;
                                    for k in (0..3).rev() {
                                        let raw = xr[i][k] - xr[j][k];
                                        let h = 0.5 * periods[k];
                                        let n: i32 = if periods[k] > 0.0 && raw > h {
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
                out.sort_unstable_by_key(|e| e & INDEX_MASK);
                out
            })
            .collect();
        self.set_lists(&upper);
        self.x_build.clear();
        self.x_build
            .extend(self.xr.iter().map(|p| [p[0], p[1], p[2]]));
        self.built = true;
    }

    /// The lists from each sphere's pairs with higher-numbered ones: `start`/`list`, the
    /// entries of each sphere as the higher one (`lstart`/`lref`), and room for the pair
    /// forces.
    fn set_lists(&mut self, upper: &[Vec<u32>]) {
        self.start.clear();
        self.list.clear();
        self.start.push(0);
        for u in upper {
            self.list.extend_from_slice(u);
            self.start.push(self.list.len() as u32);
        }
        // each sphere's entries as the higher-numbered sphere, in entry order
        let n = self.xr.len();
        let mut count = vec![0u32; n + 1];
        for &e in &self.list {
            count[(e & INDEX_MASK) as usize + 1] += 1;
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        self.lref.clear();
        self.lref.resize(self.list.len(), 0);
        let mut fill = count.clone();
        for (at, &e) in self.list.iter().enumerate() {
            let j = (e & INDEX_MASK) as usize;
            self.lref[fill[j] as usize] = at as u32;
            fill[j] += 1;
        }
        self.lstart = count;
        self.pf.clear();
        self.pf.resize(self.list.len(), [0.0; 3]);
    }

    /// Forces into `self.f`, with the chunk sums of `F·v`, `|F|²`, `|v|²` and the largest
    /// overlap (pairs and walls), added in chunk order. Two passes: each listed pair once
    /// (its force added to its lower sphere and stored), then each sphere takes the
    /// opposite of the stored forces of the pairs in which it is the higher sphere, in a
    /// fixed order; so every sum is the same for any thread count.
    fn forces(&mut self) -> Sums {
        let worst = self.pair_pass();
        let [power, ff, vv] = self.completing_pass();
        Sums {
            power,
            ff,
            vv,
            worst,
        }
    }

    /// The pair pass of [`System::forces`]: each sphere's wall force and its listed pairs'
    /// forces into `self.f`, the pairs' stored in `self.pf`; the largest overlap ratio.
    fn pair_pass(&mut self) -> f64 {
        let shifts = image_shifts(&self.geom.periods());
        let geom = self.geom;
        let walled = geom.has_walls();
        let n = self.xr.len();
        let (xr, start, list) = (&self.xr, &self.start, &self.list);
        // the stored pair forces of each chunk of spheres: a contiguous range of the list
        let mut pf_parts: Vec<&mut [[f64; 3]]> = Vec::with_capacity(n.div_ceil(CHUNK));
        let mut rest: &mut [[f64; 3]] = &mut self.pf;
        let mut at = 0;
        for c in 0..n.div_ceil(CHUNK) {
            let end = start[((c + 1) * CHUNK).min(n)] as usize;
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(end - at);
            pf_parts.push(head);
            rest = tail;
            at = end;
        }
        self.f
            .par_chunks_mut(CHUNK)
            .zip(pf_parts.into_par_iter())
            .enumerate()
            .map(|(c, (fs, pfs))| {
                let base = start[c * CHUNK] as usize;
                let mut chunk_worst = f64::NEG_INFINITY;
                for (o, f) in fs.iter_mut().enumerate() {
                    let i = c * CHUNK + o;
                    let a = &xr[i];
                    let (mut acc, ow) = if walled {
                        geom.wall(a, a[3])
                    } else {
                        ([0.0; 3], f64::NEG_INFINITY)
                    };
                    // a wall's overlap over the sphere's clearance (r − overlap)
                    let mut worst = if ow > 0.0 {
                        ow / (a[3] - ow).max(1e-12)
                    } else {
                        0.0
                    };
                    let (e0, e1) = (start[i] as usize, start[i + 1] as usize);
                    // branch-free, two pairs at a time (the square roots and divisions of
                    // the two pairs go through the vector units together): half of the
                    // listed pairs touch, unpredictably
                    let mut pairs = list[e0..e1].chunks_exact(2);
                    let mut outs = pfs[e0 - base..e1 - base].chunks_exact_mut(2);
                    let mut acc2 = [[0.0f64; 2]; 3];
                    let mut worst2 = [f64::NEG_INFINITY; 2];
                    for (jj, out) in (&mut pairs).zip(&mut outs) {
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
                        let k = [
                            (if ov[0] > 0.0 { ov[0] } else { 0.0 }) / dist[0],
                            (if ov[1] > 0.0 { ov[1] } else { 0.0 }) / dist[1],
                        ];
                        for l in 0..2 {
                            worst2[l] = if k[l] > worst2[l] { k[l] } else { worst2[l] };
                        }
                        let g0 = [k[0] * d0[0], k[0] * d0[1], k[0] * d0[2]];
                        let g1 = [k[1] * d1[0], k[1] * d1[1], k[1] * d1[2]];
                        for c in 0..3 {
                            acc2[c][0] += g0[c];
                            acc2[c][1] += g1[c];
                        }
                        out[0] = g0;
                        out[1] = g1;
                    }
                    for (&j, out) in pairs.remainder().iter().zip(outs.into_remainder()) {
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
                        let k = (if ov > 0.0 { ov } else { 0.0 }) / dist;
                        worst2[0] = if k > worst2[0] { k } else { worst2[0] };
                        let g = [k * d[0], k * d[1], k * d[2]];
                        for c in 0..3 {
                            acc2[c][0] += g[c];
                        }
                        *out = g;
                    }
                    for c in 0..3 {
                        acc[c] += acc2[c][0] + acc2[c][1];
                    }
                    worst = worst.max(worst2[0]).max(worst2[1]);
                    *f = acc;
                    chunk_worst = chunk_worst.max(worst);
                }
                chunk_worst
            })
            .reduce(|| f64::NEG_INFINITY, f64::max)
    }

    /// The completing pass of [`System::forces`]: each sphere takes the opposite of the
    /// stored forces of the pairs it is the higher sphere of, in entry order; the chunk sums
    /// of `F·v`, `|F|²` and `|v|²` in chunk order.
    fn completing_pass(&mut self) -> [f64; 3] {
        let (v, pf, lstart, lref) = (&self.v, &self.pf, &self.lstart, &self.lref);
        let parts: Vec<[f64; 3]> = self
            .f
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, fs)| {
                // F·v, |F|², |v|²
                let mut s = [0.0; 3];
                for (o, f) in fs.iter_mut().enumerate() {
                    let i = c * CHUNK + o;
                    let mut acc = *f;
                    for &e in &lref[lstart[i] as usize..lstart[i + 1] as usize] {
                        let g = &pf[e as usize];
                        for c in 0..3 {
                            acc[c] -= g[c];
                        }
                    }
                    *f = acc;
                    let w = &v[i];
                    s[0] += acc[0] * w[0] + acc[1] * w[1] + acc[2] * w[2];
                    s[1] += acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2];
                    s[2] += w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
                }
                s
            })
            .collect();
        let mut t = [0.0; 3];
        for p in &parts {
            for (t, p) in t.iter_mut().zip(p) {
                *t += p;
            }
        }
        t
    }

    /// FIRE until the largest overlap is at most the tolerance; `false`
    /// when `max_iter` iterations did not get there.
    pub(super) fn relax(&mut self, max_iter: usize, stats: &mut DensifyStats) -> bool {
        let mut fire = FireControl::with_delay(0.1, 0.5, FireControl::N_DELAY_2);
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
            let dt_last = fire.dt();
            let (mix, a, dt) = fire.update(s.power, s.vv, s.ff);
            // velocity mixing (or FIRE 2.0's half step back), semi-implicit Euler, and whether a
            // centre left half the skin (centres are wrapped only at a build, so the plain
            // difference from the build's centre is the displacement)
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
                                None => {
                                    // FIRE 2.0: half of the last step back before the
                                    // velocity is zeroed
                                    x[k] -= 0.5 * dt_last * v[k];
                                    0.0
                                }
                            } + dt * f[k];
                            x[k] += dt * v[k];
                        }
                        let d = [x[0] - b[0], x[1] - b[1], x[2] - b[2]];
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
    pub(super) fn expand_free(&mut self) {
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
    pub(super) fn overlapping_pairs(&mut self) -> usize {
        self.build();
        let periods = self.geom.periods();
        let mut n = 0;
        for i in 0..self.xr.len() {
            let a = self.xr[i];
            if self.geom.wall_ratio(&a, a[3]) > self.tol {
                n += 1;
            }
            // each pair is listed once, from its lower sphere
            for &j in &self.list[self.start[i] as usize..self.start[i + 1] as usize] {
                let b = &self.xr[(j & INDEX_MASK) as usize];
                let d = Self::delta(&periods, &a, b);
                let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if (a[3] + b[3] - dist) / dist > self.tol {
                    n += 1;
                }
            }
        }
        n
    }
}

#[cfg(test)]
mod tests {
    //! The half list's forces against a brute-force sum over all pairs (minimum image).

    use nalgebra::Point3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::super::{Boundary, DensifyStats};
    use super::{Geom, System};
    use crate::{Container, Sphere};

    /// Random spheres (r in [0.5, 1]) crowded into `boundary` so that many overlap.
    fn crowd(n: usize, lo: f64, hi: f64, seed: u64) -> Vec<Sphere> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| Sphere {
                center: Point3::new(
                    rng.random_range(lo..hi),
                    rng.random_range(lo..hi),
                    rng.random_range(lo..hi),
                ),
                radius: rng.random_range(0.5..1.0),
            })
            .collect()
    }

    /// Brute force: `Σ_j (r_i + r_j − d)₊ d̂` over every other sphere's nearest image plus
    /// the walls' force, and the largest overlap over centre distance.
    fn brute(sys: &System) -> (Vec<[f64; 3]>, f64) {
        let periods = sys.geom.periods();
        let mut worst = 0.0_f64;
        let f = (0..sys.xr.len())
            .map(|i| {
                let a = sys.xr[i];
                let (mut acc, ow) = if sys.geom.has_walls() {
                    sys.geom.wall(&a, a[3])
                } else {
                    ([0.0; 3], f64::NEG_INFINITY)
                };
                if ow > 0.0 {
                    worst = worst.max(ow / (a[3] - ow));
                }
                for (j, b) in sys.xr.iter().enumerate() {
                    if j == i {
                        continue;
                    }
                    let mut d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
                    for k in 0..3 {
                        if periods[k] > 0.0 {
                            d[k] -= periods[k] * (d[k] / periods[k]).round();
                        }
                    }
                    let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    let ov = a[3] + b[3] - dist;
                    if ov > 0.0 {
                        worst = worst.max(ov / dist);
                        for k in 0..3 {
                            acc[k] += ov / dist * d[k];
                        }
                    }
                }
                acc
            })
            .collect();
        (f, worst)
    }

    fn check(boundary: &Boundary, spheres: &[Sphere]) {
        let geom = Geom::new(boundary).expect("geometry");
        let mut sys = System::new(spheres, geom, 0.5, 1.0, 1e-3);
        // a few FIRE steps move the centres off their build positions (and wrap none)
        let mut stats = DensifyStats::default();
        sys.relax(5, &mut stats);
        sys.build();
        let s = sys.forces();
        let (f, worst) = brute(&sys);
        assert!(worst > 0.05, "the test must have overlaps: {worst}");
        assert!((s.worst - worst).abs() <= 1e-12, "{} vs {worst}", s.worst);
        let scale = f
            .iter()
            .map(|g| g[0].abs() + g[1].abs() + g[2].abs())
            .fold(0.0, f64::max);
        for (i, (a, b)) in sys.f.iter().zip(&f).enumerate() {
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-12 * scale,
                    "sphere {i}: {a:?} vs {b:?}"
                );
            }
        }
        // Newton's third law: the forces sum to the walls' share (zero when fully periodic)
        if !sys.geom.has_walls() {
            for k in 0..3 {
                let total: f64 = sys.f.iter().map(|g| g[k]).sum();
                assert!(total.abs() <= 1e-10 * scale, "net force {total}");
            }
        }
    }

    #[test]
    fn half_list_forces_match_the_brute_force_sum() {
        let l = 9.0;
        let periodic = Boundary::Periodic {
            min: Point3::origin(),
            max: Point3::new(l, l, l),
        };
        check(&periodic, &crowd(150, 0.0, l, 1));
        let walled = Boundary::Walls(Container::Box {
            min: Point3::origin(),
            max: Point3::new(l, l, l),
            periodic: [true, false],
        });
        check(&walled, &crowd(150, 0.5, l - 0.5, 2));
        let cylinder = Boundary::Walls(Container::Cylinder {
            base: Point3::new(4.5, 4.5, 0.0),
            radius: 4.5,
            height: l,
        });
        check(&cylinder, &crowd(100, 2.0, 7.0, 3));
    }
}
