//! Site generation and site tests: the open sites of a new sphere (its
//! neighbours and nearby walls, the candidates of every pair, the feasible
//! ones one per pocket) and the position and fit of a site for a radius.

// Coordinates are `[f64; 3]` triples indexed in step with periods:
// index loops read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

use nalgebra::Vector3;

use super::sites::Site;
use super::solve::{
    Nb, Pts, circle_cylinder, circle_cylinder_horizontal, sphere_sphere_plane, sphere_two_planes,
    three_spheres,
};
use super::{CYL, FREE, Front3, Plane, WALL, Walls};

/// Sites of one generation closer than `DEDUP · r_min` are one pocket.
pub(super) const DEDUP: f64 = 1.0;

impl Front3<'_> {
    /// A sphere of radius `r` at `p` is inside and overlaps no sphere.
    pub(super) fn feasible(&mut self, p: &[f64; 3], r: f64) -> bool {
        if !self.inside(p, r) {
            return false;
        }
        let tol = self.tol;
        let xs = &self.xs;
        !self.grid.any_near(p, r + self.r_max, |id, s| {
            let o = xs[id as usize];
            let (dx, dy, dz) = (p[0] - o[0] - s[0], p[1] - o[1] - s[1], p[2] - o[2] - s[2]);
            let m = r + o[3] - tol;
            dx * dx + dy * dy + dz * dz < m * m
        })
    }

    /// Open sites of the new sphere `f` for the smallest size: the common
    /// points of its halo with two more halos or offset walls that are
    /// inside the container and outside every halo.
    pub(super) fn generate(&mut self, f: u32, g: f64, out: &mut Vec<Site>) {
        self.stats.evaluations += 1;
        let r = self.r_min;
        let q = self.xs[f as usize];
        let cf = [q[0], q[1], q[2]];
        let rho_f = q[3] + r;
        let rho_f2 = rho_f * rho_f;
        self.gather_neighbours(f, q, rho_f2);
        let cfv = Vector3::from(cf);
        let cyl = self.near_walls(q, &cfv);
        self.fill_halos();
        self.candidates(cf, &cfv, rho_f2, cyl);
        self.stats.neighbours += self.nb.len() as u64;
        self.stats.candidates += self.cands.len() as u64;
        self.keep_sites(f, g, cf, out);
    }

    /// The spheres whose halo (radius `r_j + r_min`) can meet the halo of
    /// sphere `f` (`q`), relative to its centre, into `self.nb`.
    fn gather_neighbours(&mut self, f: u32, q: [f64; 4], rho_f2: f64) {
        let r = self.r_min;
        let cf = [q[0], q[1], q[2]];
        let reach = q[3] + 2.0 * r + self.r_max;
        self.nb.clear();
        let xs = &self.xs;
        let nb = &mut self.nb;
        self.grid.for_each_near(&cf, reach, |id, s| {
            if id == f && s == [0.0; 3] {
                return;
            }
            let o = xs[id as usize];
            let d = [
                o[0] + s[0] - cf[0],
                o[1] + s[1] - cf[1],
                o[2] + s[2] - cf[2],
            ];
            let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let lim = q[3] + o[3] + 2.0 * r;
            if dd <= lim * lim {
                let rho = o[3] + r;
                nb.push(Nb {
                    d,
                    dd,
                    rho,
                    b: 0.5 * (dd + rho_f2 - rho * rho),
                    id,
                });
            }
        });
    }

    /// The wall planes within reach of the generating sphere `q` (centre
    /// `cfv`) into `self.planes`; the cylinder side's axis and radius when
    /// it is within reach too.
    fn near_walls(&mut self, q: [f64; 4], cfv: &Vector3<f64>) -> Option<([f64; 2], f64)> {
        let r = self.r_min;
        self.planes.clear();
        let mut cyl: Option<([f64; 2], f64)> = None;
        let wall_reach = q[3] + 2.0 * r;
        match &self.walls {
            Walls::Planes(pl) => {
                for (i, w) in pl.iter().enumerate() {
                    if w.n.dot(cfv) - w.o <= wall_reach {
                        self.planes.push((*w, WALL + i as u32));
                    }
                }
            }
            Walls::Cylinder {
                planes,
                axis,
                radius,
            } => {
                for (i, w) in planes.iter().enumerate() {
                    if w.n.dot(cfv) - w.o <= wall_reach {
                        self.planes.push((*w, WALL + i as u32));
                    }
                }
                let rho = (q[0] - axis[0]).hypot(q[1] - axis[1]);
                if radius - rho <= wall_reach {
                    cyl = Some((*axis, *radius));
                }
            }
            Walls::Mesh(mw) => {
                let cf = [q[0], q[1], q[2]];
                if let Some(c) = mw.cell(&cf) {
                    for &i in mw.near(c) {
                        let w = mw.planes[i as usize];
                        let s = w.n.dot(cfv) - w.o;
                        if s <= wall_reach && s >= -q[3] {
                            self.planes.push((w, WALL + i));
                        }
                    }
                }
            }
        }
        cyl
    }

    /// The neighbour halos as `[dx, dy, dz, (ρ − tol)²]`, padded to a
    /// multiple of 4 (see [`Front3::free`]).
    fn fill_halos(&mut self) {
        self.halos.clear();
        let tol = self.tol;
        self.halos.extend(self.nb.iter().map(|o| {
            let m = o.rho - tol;
            [o.d[0], o.d[1], o.d[2], m * m]
        }));
        while !self.halos.len().is_multiple_of(4) {
            self.halos.push([f64::INFINITY, 0.0, 0.0, -1.0]);
        }
    }

    /// Every candidate centre (relative to `cf`) with its two obstacles,
    /// into `self.cands`: sphere pairs, sphere and plane, plane pairs, and
    /// the cylinder side with a plane or a sphere.
    fn candidates(
        &mut self,
        cf: [f64; 3],
        cfv: &Vector3<f64>,
        rho_f2: f64,
        cyl: Option<([f64; 2], f64)>,
    ) {
        let r = self.r_min;
        self.cands.clear();
        let nb = &self.nb;
        let n = nb.len();
        let mut tmp = Pts::default();
        for i in 0..n {
            let a = nb[i];
            for bj in &nb[i + 1..] {
                let (ex, ey, ez) = (bj.d[0] - a.d[0], bj.d[1] - a.d[1], bj.d[2] - a.d[2]);
                let s = a.rho + bj.rho;
                if ex * ex + ey * ey + ez * ez > s * s {
                    continue;
                }
                tmp.clear();
                three_spheres(&a, bj, rho_f2, &mut tmp);
                for y in tmp.as_slice() {
                    self.cands.push((*y, a.id, bj.id));
                }
            }
        }
        for (w, wid) in &self.planes {
            let pw = Plane {
                n: w.n,
                o: w.o + r - w.n.dot(cfv),
            };
            for a in nb {
                tmp.clear();
                sphere_sphere_plane(a, &pw, rho_f2, &mut tmp);
                for y in tmp.as_slice() {
                    self.cands.push((*y, a.id, *wid));
                }
            }
        }
        for (i, (w1, id1)) in self.planes.iter().enumerate() {
            for (w2, id2) in &self.planes[i + 1..] {
                let p1 = w1.o + r - w1.n.dot(cfv);
                let p2 = w2.o + r - w2.n.dot(cfv);
                tmp.clear();
                sphere_two_planes(&w1.n, p1, &w2.n, p2, rho_f2, &mut tmp);
                for y in tmp.as_slice() {
                    self.cands.push((*y, *id1, *id2));
                }
            }
        }
        if let Some((axis, radius)) = cyl {
            let rr = radius - r;
            if rr > 0.0 {
                let ax = [axis[0] - cf[0], axis[1] - cf[1]];
                for (w, wid) in &self.planes {
                    let zc = (w.o + r) / w.n[2] - cf[2];
                    tmp.clear();
                    circle_cylinder_horizontal(zc, rho_f2, ax, rr, &mut tmp);
                    for y in tmp.as_slice() {
                        self.cands.push((*y, *wid, CYL));
                    }
                }
                for a in nb {
                    tmp.clear();
                    circle_cylinder(a, rho_f2, ax, rr, &mut tmp);
                    for y in tmp.as_slice() {
                        self.cands.push((*y, a.id, CYL));
                    }
                }
            }
        }
    }

    /// The feasible candidates (free of the halos, inside the container),
    /// one per pocket, as sites of sphere `f` (centre `cf`, secondary key
    /// `g`) into `out`.
    fn keep_sites(&mut self, f: u32, g: f64, cf: [f64; 3], out: &mut Vec<Site>) {
        let r = self.r_min;
        let mut cands = std::mem::take(&mut self.cands);
        let mut kept = std::mem::take(&mut self.kept);
        kept.clear();
        for (y, a, b) in &cands {
            let p = [y[0] + cf[0], y[1] + cf[1], y[2] + cf[2]];
            if self.free(y) && self.inside(&p, r) {
                kept.push((p, *a, *b));
            }
        }
        // One site per pocket: sites of this batch closer than `DEDUP ·
        // r_min` describe the same hole; the lowest is kept.
        kept.sort_by(|x, y| {
            x.0[2]
                .total_cmp(&y.0[2])
                .then(x.0[0].total_cmp(&y.0[0]))
                .then(x.0[1].total_cmp(&y.0[1]))
                .then((x.1, x.2).cmp(&(y.1, y.2)))
        });
        let eps2 = (DEDUP * r).powi(2);
        for i in 0..kept.len() {
            let (p, a, b) = kept[i];
            let dup = kept[..i].iter().any(|(q, _, _)| {
                (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2) < eps2
            });
            if dup {
                continue;
            }
            self.stats.sites += 1;
            out.push(Site {
                k: p,
                ids: [f, a, b],
                g,
                cap: f64::INFINITY,
                slot: 0,
            });
        }
        cands.clear();
        self.cands = cands;
        self.kept = kept;
    }

    /// `y` (relative to the generating sphere) outside every neighbour halo.
    #[inline]
    pub(super) fn free(&self, y: &[f64; 3]) -> bool {
        // Chunks of four halos without early exit inside a chunk (the
        // compiler vectorises them); padding halos never hit.
        let h = &self.halos;
        for c in h.chunks_exact(4) {
            let mut hit = false;
            for o in c {
                let (dx, dy, dz) = (y[0] - o[0], y[1] - o[1], y[2] - o[2]);
                hit |= dx * dx + dy * dy + dz * dz < o[3];
            }
            if hit {
                return false;
            }
        }
        true
    }

    /// Centre of a sphere of radius `r` at `site` (the solution nearest to
    /// the site's key), or `None` when the obstacles no longer have a
    /// common point at this radius.
    pub(super) fn site_position(&self, site: &Site, r: f64) -> Option<[f64; 3]> {
        let q0 = self.xs[site.ids[0] as usize];
        let c0 = [q0[0], q0[1], q0[2]];
        let rho0 = q0[3] + r;
        let rho02 = rho0 * rho0;
        // Obstacle sphere `id` relative to c0 (nearest periodic image).
        let rel = |id: u32| -> Nb {
            let o = self.xs[id as usize];
            let mut d = [o[0] - c0[0], o[1] - c0[1], o[2] - c0[2]];
            for k in 0..2 {
                if self.periodic[k] {
                    let l = self.period[k];
                    d[k] -= (d[k] / l).round() * l;
                }
            }
            let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let rho = o[3] + r;
            Nb {
                d,
                dd,
                rho,
                b: 0.5 * (dd + rho02 - rho * rho),
                id,
            }
        };
        let cv = Vector3::from(c0);
        let plane = |id: u32| -> Plane {
            let w = self.all_planes[(id - WALL) as usize];
            Plane {
                n: w.n,
                o: w.o + r - w.n.dot(&cv),
            }
        };
        let mut tmp = Pts::default();
        let [_, a, b] = site.ids;
        if b == FREE {
            let w = self.all_planes[(a - WALL) as usize];
            let zc = (w.o + r) / w.n[2] - c0[2];
            let s2 = rho02 - zc * zc;
            return (s2 >= 0.0).then(|| [c0[0] + s2.sqrt(), c0[1], c0[2] + zc]);
        }
        match (a < WALL, b < WALL, b == CYL) {
            (true, true, _) => three_spheres(&rel(a), &rel(b), rho02, &mut tmp),
            (true, false, false) => sphere_sphere_plane(&rel(a), &plane(b), rho02, &mut tmp),
            (false, false, false) => {
                let (p1, p2) = (plane(a), plane(b));
                sphere_two_planes(&p1.n, p1.o, &p2.n, p2.o, rho02, &mut tmp);
            }
            (_, _, true) => {
                let Walls::Cylinder { axis, radius, .. } = &self.walls else {
                    return None;
                };
                let rr = radius - r;
                if rr <= 0.0 {
                    return None;
                }
                let ax = [axis[0] - c0[0], axis[1] - c0[1]];
                if a < WALL {
                    circle_cylinder(&rel(a), rho02, ax, rr, &mut tmp);
                } else {
                    let w = self.all_planes[(a - WALL) as usize];
                    let zc = (w.o + r) / w.n[2] - c0[2];
                    circle_cylinder_horizontal(zc, rho02, ax, rr, &mut tmp);
                }
            }
            _ => return None,
        }
        let key = [site.k[0] - c0[0], site.k[1] - c0[1], site.k[2] - c0[2]];
        tmp.as_slice()
            .iter()
            .map(|y| {
                let e = (y[0] - key[0]).powi(2) + (y[1] - key[1]).powi(2) + (y[2] - key[2]).powi(2);
                (e, y)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, y)| [y[0] + c0[0], y[1] + c0[1], y[2] + c0[2]])
    }

    /// The site's centre for radius `r` if a sphere fits there.
    pub(super) fn try_site(&mut self, site: &Site, r: f64) -> Option<[f64; 3]> {
        self.stats.site_tests += 1;
        let p = self.site_position(site, r)?;
        self.feasible(&p, r).then_some(p)
    }

    /// Gathers the spheres near `site` for the capacity bisection on
    /// `[r_min, r]`: those within `r + r_max + δ` of the site's centre `c`
    /// for `r_min`, with `δ` the distance between its centres for `r_min` and
    /// `r` (the site moves little between the two). The capacity is only an
    /// estimate (a placement is always checked against the full index), so
    /// a sphere missed by a curving path costs at most a retry.
    pub(super) fn gather_local(&mut self, site: &Site, c: &[f64; 3], r: f64) {
        let c = *c;
        let delta = self.site_position(site, r).map_or(r - self.r_min, |q| {
            ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2) + (q[2] - c[2]).powi(2)).sqrt()
        });
        let reach = r + self.r_max + delta;
        self.local.clear();
        let xs = &self.xs;
        let local = &mut self.local;
        self.grid.for_each_near(&c, reach, |id, s| {
            let o = xs[id as usize];
            let p = [o[0] + s[0], o[1] + s[1], o[2] + s[2], o[3]];
            let (dx, dy, dz) = (p[0] - c[0], p[1] - c[1], p[2] - c[2]);
            let lim = r + delta + o[3];
            if dx * dx + dy * dy + dz * dz <= lim * lim {
                local.push(p);
            }
        });
    }

    /// [`Front3::try_site`] against the gathered spheres (radius at most
    /// the one gathered for).
    pub(super) fn try_local(&mut self, site: &Site, r: f64) -> bool {
        self.stats.site_tests += 1;
        let Some(p) = self.site_position(site, r) else {
            return false;
        };
        if !self.inside(&p, r) {
            return false;
        }
        let tol = self.tol;
        self.local.iter().all(|o| {
            let (dx, dy, dz) = (p[0] - o[0], p[1] - o[1], p[2] - o[2]);
            let m = r + o[3] - tol;
            dx * dx + dy * dy + dz * dz >= m * m
        })
    }
}
