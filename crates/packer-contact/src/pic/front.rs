//! The advancing front of [`pack_pic`]: the packer state, candidate
//! contact positions around a front grain (sets of grains and walls, first
//! guesses, refinement, feasibility) and the placement loop.

use std::collections::BTreeSet;

use nalgebra::{Point2, Point3, SVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::approx::Elements;
use super::grid::Grid;
use super::params::{ContactMethod, PicParams};
use super::wrap::{Wrap, intersect};
use crate::error::{Error, Result};
use crate::gap::{self, Obstacle};
use crate::shapes::{Geometry, Grain, GrainShape};

/// A placed grain.
#[derive(Debug, Clone)]
pub struct Placed<const D: usize> {
    /// Position of the reference point.
    pub centre: SVector<f64, D>,
    /// The grain (world orientation, relative to `centre`).
    pub grain: Grain<D>,
}

/// Result of [`pack_pic`].
#[derive(Debug, Clone)]
pub struct PicPacking<const D: usize> {
    /// Placed grains in placement order.
    pub grains: Vec<Placed<D>>,
    /// Side of the domain.
    pub side: f64,
    /// Grains drawn but discarded because they fit nowhere.
    pub rejected: usize,
}

impl<const D: usize> PicPacking<D> {
    /// Solid fraction: total grain area/volume over the domain's.
    #[must_use]
    pub fn fraction(&self) -> f64 {
        let solid: f64 = self.grains.iter().map(|g| g.grain.measure).sum();
        solid / self.side.powi(D as i32)
    }
}

/// Order-preserving key of a float (for the front's `BTreeSet`).
fn key(v: f64) -> u64 {
    let b = v.to_bits();
    if b >> 63 == 0 { b | (1 << 63) } else { !b }
}

/// An obstacle of the candidate search: a placed grain or a wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Obj {
    Grain(u32),
    Wall { axis: usize, upper: bool },
}

/// The state of a packing under way: placed grains on a cell grid.
pub(super) struct Packer<'a, const D: usize> {
    pub(super) params: &'a PicParams,
    pub(super) grains: Vec<Placed<D>>,
    pub(super) grid: Grid<D>,
    pub(super) rmax_placed: f64,
    pub(super) tol_rel: f64,
    pub(super) neighbours: usize,
    /// Every placed element, for [`ContactMethod::ApproxWrappers`].
    pub(super) elems: Option<Elements<D>>,
}

impl<'a, const D: usize> Packer<'a, D> {
    /// An empty packer (with the element grid of
    /// [`ContactMethod::ApproxWrappers`] for disks/spheres and clusters).
    fn new(params: &'a PicParams) -> Self {
        let mut pk = Self {
            params,
            grains: Vec::new(),
            grid: Grid::new(params.side, 2.0 * params.radius_max),
            rmax_placed: 0.0,
            tol_rel: 1e-10,
            neighbours: params.neighbours,
            elems: None,
        };
        if params.method == ContactMethod::ApproxWrappers {
            let elem_max = match params.shape {
                GrainShape::Ball => Some(params.radius_max),
                GrainShape::Cluster { aspect, .. } => Some(aspect * params.radius_max),
                _ => None,
            };
            pk.elems = elem_max.map(|r| Elements {
                centre: Vec::new(),
                radius: Vec::new(),
                first: Vec::new(),
                grid: Grid::new(params.side, 2.0 * r),
                rmax: 0.0,
            });
        }
        pk
    }
}

impl<const D: usize> Packer<'_, D> {
    fn obstacle(&self, o: Obj) -> Obstacle<'_, D> {
        match o {
            Obj::Grain(i) => Obstacle::Grain {
                centre: self.grains[i as usize].centre,
                grain: &self.grains[i as usize].grain,
            },
            Obj::Wall { axis, upper } => Obstacle::Wall {
                axis,
                at: if upper { self.params.side } else { 0.0 },
                upper,
            },
        }
    }

    /// Whether `m` at `x` stays inside and overlaps no placed grain.
    fn feasible(&self, m: &Grain<D>, x: &SVector<f64, D>) -> bool {
        let tol = self.tol_rel * m.circumradius;
        for i in 0..D {
            if x[i] + m.lo[i] < -tol || x[i] + m.hi[i] > self.params.side + tol {
                return false;
            }
        }
        let mut ok = true;
        let reach = m.circumradius + self.rmax_placed;
        self.grid.query(x, reach, |id| {
            if !ok {
                return;
            }
            let p = &self.grains[id as usize];
            let d2 = (p.centre - x).norm_squared();
            let rr = p.grain.circumradius + m.circumradius;
            if d2 >= rr * rr {
                return;
            }
            let o = Obstacle::Grain {
                centre: p.centre,
                grain: &p.grain,
            };
            match gap::gap(&o, m, x) {
                Some((g, _)) if g >= -tol => {}
                _ => ok = false,
            }
        });
        ok
    }

    /// First guesses of the contact positions of `m` touching the `D`
    /// objects `set`; `true` when they are exact (closed forms).
    fn guesses(&self, set: &[Obj], m: &Grain<D>, out: &mut Vec<SVector<f64, D>>) -> bool {
        out.clear();
        let is = |f: fn(&Grain<D>) -> bool| {
            f(m) && set.iter().all(|o| match o {
                Obj::Grain(i) => f(&self.grains[*i as usize].grain),
                Obj::Wall { .. } => true,
            })
        };
        let mut w = [Wrap::Plane(SVector::zeros(), 0.0); 3];
        if is(Grain::is_ball) {
            let r = m.circumradius;
            for (k, &o) in set.iter().enumerate() {
                let rf = match o {
                    Obj::Grain(i) => self.grains[i as usize].grain.circumradius,
                    Obj::Wall { .. } => 0.0,
                };
                w[k] = self.wrap(o, rf + r, &SVector::zeros(), r);
            }
            intersect(&w[..D], out);
            return true;
        }
        if self.params.method == ContactMethod::Wrappers && is(Grain::is_sphere_cluster) {
            self.cluster_wrappers(set, m, out);
            return true;
        }
        // Closed form with effective radii (mean of in- and circumscribed).
        let eff = |g: &Grain<D>| 0.5 * (g.inradius + g.circumradius);
        let rm = eff(m);
        for (k, &o) in set.iter().enumerate() {
            let rf = match o {
                Obj::Grain(i) => eff(&self.grains[i as usize].grain),
                Obj::Wall { .. } => 0.0,
            };
            w[k] = self.wrap(o, rf + rm, &SVector::zeros(), rm);
        }
        intersect(&w[..D], out);
        false
    }

    /// The exact contact position of `m` touching `set`, from a first guess
    /// (Newton's method, or the seed's Nelder–Mead).
    fn refine(
        &self,
        set: &[Obj],
        m: &Grain<D>,
        guess: &SVector<f64, D>,
    ) -> Option<SVector<f64, D>> {
        let mut obstacles = [Obstacle::Wall {
            axis: 0,
            at: 0.0,
            upper: false,
        }; 3];
        for (k, &o) in set.iter().enumerate() {
            obstacles[k] = self.obstacle(o);
        }
        match self.params.method {
            ContactMethod::NelderMead => {
                let side = self.side_restriction(set, guess);
                gap::nelder_mead(&obstacles[..D], m, *guess, side, 1e-10 * m.circumradius)
            }
            _ => gap::newton(&obstacles[..D], m, *guess, 1e-13 * m.circumradius),
        }
    }

    /// The seed's half-space restriction (§3.2): the side, where `guess`
    /// lies, of the line (2D) or plane (3D) through the obstacles'
    /// reference points (a wall contributes the foot of `guess` on it).
    fn side_restriction(
        &self,
        set: &[Obj],
        guess: &SVector<f64, D>,
    ) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        let pts: Vec<SVector<f64, D>> = set
            .iter()
            .map(|&o| match o {
                Obj::Grain(i) => self.grains[i as usize].centre,
                Obj::Wall { axis, upper } => {
                    let mut q = *guess;
                    q[axis] = if upper { self.params.side } else { 0.0 };
                    q
                }
            })
            .collect();
        let mut n = SVector::<f64, D>::zeros();
        if D == 2 {
            let d = pts[1] - pts[0];
            n[0] = -d[1];
            n[1] = d[0];
        } else {
            let a = pts[1] - pts[0];
            let b = pts[2] - pts[0];
            n[0] = a[1] * b[2] - a[2] * b[1];
            n[1] = a[2] * b[0] - a[0] * b[2];
            n[2] = a[0] * b[1] - a[1] * b[0];
        }
        let s = n.dot(&(guess - pts[0]));
        if n.norm() == 0.0 || s == 0.0 {
            return None;
        }
        Some((n * s.signum(), pts[0]))
    }

    /// Wrapper of object `o` for a mobile element of radius `r_elem` at
    /// offset `m_off`; `rho` is the grain wrapper radius (fixed + mobile).
    pub(super) fn wrap(&self, o: Obj, rho: f64, m_off: &SVector<f64, D>, r_elem: f64) -> Wrap<D> {
        match o {
            Obj::Grain(i) => Wrap::Sphere(self.grains[i as usize].centre - m_off, rho),
            Obj::Wall { axis, upper } => {
                let mut n = SVector::<f64, D>::zeros();
                let (sign, at) = if upper {
                    (-1.0, self.params.side)
                } else {
                    (1.0, 0.0)
                };
                n[axis] = sign;
                // n·(x + m_off) = sign·at + r_elem.
                Wrap::Plane(n, sign * at + r_elem - n.dot(m_off))
            }
        }
    }

    /// Every combination of elements (seed §3.1, clusters).
    fn cluster_wrappers(&self, set: &[Obj], m: &Grain<D>, out: &mut Vec<SVector<f64, D>>) {
        let Geometry::Swept(me) = &m.geometry else {
            return;
        };
        let atoms = |o: Obj| -> Vec<(SVector<f64, D>, f64)> {
            match o {
                Obj::Grain(i) => match &self.grains[i as usize].grain.geometry {
                    Geometry::Swept(e) => e
                        .iter()
                        .map(|s| (self.grains[i as usize].centre + s.a, s.radius))
                        .collect(),
                    Geometry::Convex { .. } => Vec::new(),
                },
                Obj::Wall { .. } => vec![(SVector::zeros(), 0.0)],
            }
        };
        let lists: Vec<Vec<(SVector<f64, D>, f64)>> = set.iter().map(|&o| atoms(o)).collect();
        let mut idx = vec![(0usize, 0usize); D];
        let mut tmp = Vec::with_capacity(2);
        loop {
            let mut w = [Wrap::Plane(SVector::zeros(), 0.0); 3];
            for k in 0..D {
                let (ai, mi) = idx[k];
                let (c, r) = lists[k][ai];
                let e = me[mi];
                w[k] = match set[k] {
                    Obj::Grain(_) => Wrap::Sphere(c - e.a, r + e.radius),
                    Obj::Wall { .. } => self.wrap(set[k], 0.0, &e.a, e.radius),
                };
            }
            intersect(&w[..D], &mut tmp);
            // The seed's filter: discard positions overlapping a grain of
            // the set itself.
            let tol = self.tol_rel * m.circumradius;
            for x in &tmp {
                let own_ok = set.iter().all(|&o| match o {
                    Obj::Grain(_) => {
                        gap::gap(&self.obstacle(o), m, x).is_some_and(|(g, _)| g >= -tol)
                    }
                    Obj::Wall { .. } => true,
                });
                if own_ok && !out.iter().any(|q| (q - x).norm() <= 1e-9 * m.circumradius) {
                    out.push(*x);
                }
            }
            // Next combination.
            let mut k = 0;
            loop {
                if k == D {
                    return;
                }
                idx[k].1 += 1;
                if idx[k].1 < me.len() {
                    break;
                }
                idx[k].1 = 0;
                idx[k].0 += 1;
                if idx[k].0 < lists[k].len() {
                    break;
                }
                idx[k].0 = 0;
                k += 1;
            }
        }
    }

    /// The lowest feasible position of `m` touching `P = grains[p]`: the
    /// `neighbours` grains nearest to `P` (surface distance) and the walls
    /// within reach form the sets; their first guesses are sorted by height
    /// and refined in that order until a guess is higher than the best
    /// position found plus a margin (`0` for closed forms, `R_mob/2` else).
    fn around(&self, p: u32, m: &Grain<D>) -> Option<SVector<f64, D>> {
        if let Some(el) = &self.elems
            && m.is_sphere_cluster()
        {
            return self.around_approx(el, p, m);
        }
        let pc = self.grains[p as usize].centre;
        let pr = self.grains[p as usize].grain.circumradius;
        let rm = m.circumradius;
        let last = D - 1;
        let mut near: Vec<(f64, u32)> = Vec::new();
        self.grid
            .query(&pc, pr + self.rmax_placed + 2.0 * rm, |id| {
                if id == p {
                    return;
                }
                let q = &self.grains[id as usize];
                let d = (q.centre - pc).norm();
                if d <= pr + q.grain.circumradius + 2.0 * rm {
                    near.push((d - q.grain.circumradius, id));
                }
            });
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        near.truncate(self.neighbours);
        let mut objs: Vec<Obj> = near.iter().map(|&(_, id)| Obj::Grain(id)).collect();
        for axis in 0..D {
            for upper in [false, true] {
                let d = if upper {
                    self.params.side - pc[axis]
                } else {
                    pc[axis]
                };
                if d <= pr + 2.0 * rm {
                    objs.push(Obj::Wall { axis, upper });
                }
            }
        }
        let reach_pair = |a: Obj, b: Obj| -> bool {
            match (a, b) {
                (Obj::Grain(i), Obj::Grain(j)) => {
                    let (gi, gj) = (&self.grains[i as usize], &self.grains[j as usize]);
                    let reach = gi.grain.circumradius + gj.grain.circumradius + 2.0 * rm;
                    (gi.centre - gj.centre).norm_squared() <= reach * reach
                }
                (Obj::Wall { axis: a1, .. }, Obj::Wall { axis: a2, .. }) => a1 != a2,
                (Obj::Grain(i), Obj::Wall { axis, upper })
                | (Obj::Wall { axis, upper }, Obj::Grain(i)) => {
                    let g = &self.grains[i as usize];
                    let d = if upper {
                        self.params.side - g.centre[axis]
                    } else {
                        g.centre[axis]
                    };
                    d <= g.grain.circumradius + 2.0 * rm
                }
            }
        };
        let pobj = Obj::Grain(p);
        let mut cands: Vec<(f64, [Obj; 3], SVector<f64, D>, bool)> = Vec::new();
        let mut tmp = Vec::with_capacity(4);
        let mut add = |set: [Obj; 3], tmp: &mut Vec<SVector<f64, D>>| {
            let exact = self.guesses(&set[..D], m, tmp);
            for x in tmp.iter() {
                cands.push((x[last], set, *x, exact));
            }
        };
        if D == 2 {
            for &a in &objs {
                add([pobj, a, a], &mut tmp);
            }
        } else {
            for (i, &a) in objs.iter().enumerate() {
                for &b in &objs[i + 1..] {
                    if reach_pair(a, b) {
                        add([pobj, a, b], &mut tmp);
                    }
                }
            }
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best: Option<SVector<f64, D>> = None;
        let mut best_h = f64::INFINITY;
        for (h, set, g, exact) in cands {
            let margin = if exact { 0.0 } else { 0.5 * rm };
            if h >= best_h + margin {
                break;
            }
            let x = if exact {
                Some(g)
            } else {
                self.refine(&set[..D], m, &g)
            };
            if let Some(x) = x
                && x[last] < best_h
                && self.feasible(m, &x)
            {
                best_h = x[last];
                best = Some(x);
            }
        }
        best
    }

    fn place(&mut self, x: SVector<f64, D>, g: Grain<D>) -> u32 {
        let id = self.grains.len() as u32;
        self.rmax_placed = self.rmax_placed.max(g.circumradius);
        self.grid.insert(&x, id);
        if let (Some(el), Geometry::Swept(e)) = (self.elems.as_mut(), &g.geometry) {
            el.first.push(el.centre.len() as u32);
            for s in e {
                let c = x + s.a;
                let k = el.centre.len() as u32;
                el.grid.insert(&c, k);
                el.centre.push(c);
                el.radius.push(s.radius);
                el.rmax = el.rmax.max(s.radius);
            }
        }
        self.grains.push(Placed {
            centre: x,
            grain: g,
        });
        id
    }
}

/// The per-grain random stream `(seed, index)`.
fn stream(seed: u64, index: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    rng
}

/// Packs the square (`D = 2`) or cube (`D = 3`) `[0, side]^D` with grains
/// of `params.shape` (see the module docs for the algorithm).
///
/// # Errors
/// [`PicParams::validate`]; [`Error::Parameter`] for `D` other than 2 or 3.
pub fn pack_pic<const D: usize>(params: &PicParams, seed: u64) -> Result<PicPacking<D>> {
    if D != 2 && D != 3 {
        return Err(Error::Parameter {
            what: "dimension",
            value: D as f64,
            range: "2 or 3",
        });
    }
    params.validate(D)?;
    let mut pk = Packer::<D>::new(params);
    // Grain `i`: its size, then `orientations` orientations of it, all
    // from the stream (seed, i).
    let draw = |i: u64| -> Result<Vec<Grain<D>>> {
        let mut rng = stream(seed, i);
        let r = params.radius_min + (params.radius_max - params.radius_min) * rng.random::<f64>();
        let k = if params.shape == GrainShape::Ball {
            1
        } else {
            params.orientations.max(1)
        };
        (0..k)
            .map(|_| params.shape.sample::<D>(r, &mut rng))
            .collect()
    };
    let mut front: BTreeSet<(u64, u32)> = BTreeSet::new();
    let first = draw(0)?.swap_remove(0);
    let x0 = -first.lo;
    if !pk.feasible(&first, &x0) {
        return Err(Error::DomainTooSmall {
            domain: params.side,
            particle: 2.0 * first.circumradius,
        });
    }
    let id = pk.place(x0, first);
    front.insert((key(x0[D - 1]), id));
    // Smallest circumscribed radius that failed around each front grain:
    // larger grains skip it.
    let mut failed_r: Vec<f64> = vec![f64::INFINITY];
    let mut index = 1u64;
    let mut rejects_in_row = 0usize;
    let mut rejected = 0usize;
    while pk.grains.len() < params.max_grains && !front.is_empty() && rejects_in_row < 400 {
        let mut ms = draw(index)?;
        index += 1;
        let big_r = ms[0].circumradius;
        let mut placed: Option<(SVector<f64, D>, usize)> = None;
        let mut cursor: Option<(u64, u32)> = None;
        let mut tries = 0;
        while tries < 32 {
            let next = match cursor {
                None => front.iter().next().copied(),
                Some(c) => front
                    .range((std::ops::Bound::Excluded(c), std::ops::Bound::Unbounded))
                    .next()
                    .copied(),
            };
            let Some(entry) = next else { break };
            cursor = Some(entry);
            if big_r >= failed_r[entry.1 as usize] {
                continue;
            }
            tries += 1;
            for (k, m) in ms.iter().enumerate() {
                if let Some(x) = pk.around(entry.1, m)
                    && placed.is_none_or(|(b, _)| x[D - 1] < b[D - 1])
                {
                    placed = Some((x, k));
                }
            }
            if placed.is_some() {
                break;
            }
            failed_r[entry.1 as usize] = big_r;
            // Does the smallest grain of this orientation fit around P?
            // (Approximate wrappers skip the probe, which costs a full
            // search, and drop P at its first failure once the front holds
            // 32 grains.)
            let keep = if pk.elems.is_some() && front.len() >= 32 {
                false
            } else {
                scaled(&ms[0], params.radius_min / big_r)
                    .as_ref()
                    .is_some_and(|s| pk.around(entry.1, s).is_some())
            };
            if !keep {
                front.remove(&entry);
            }
        }
        match placed {
            Some((x, k)) => {
                let id = pk.place(x, ms.swap_remove(k));
                failed_r.push(f64::INFINITY);
                front.insert((key(x[D - 1]), id));
                rejects_in_row = 0;
            }
            None => {
                rejected += 1;
                rejects_in_row += 1;
            }
        }
    }
    Ok(PicPacking {
        grains: pk.grains,
        side: params.side,
        rejected,
    })
}

/// The grain scaled by `f` about its reference point (`None` if `f ≥ 1`).
fn scaled<const D: usize>(g: &Grain<D>, f: f64) -> Option<Grain<D>> {
    if f >= 1.0 - 1e-12 {
        return None;
    }
    match &g.geometry {
        Geometry::Swept(e) => Some(Grain::from_swept(
            e.iter()
                .map(|s| crate::shapes::Swept {
                    a: s.a * f,
                    b: s.b * f,
                    radius: s.radius * f,
                })
                .collect(),
        )),
        Geometry::Convex { vertices, .. } => {
            if D == 2 {
                let v: Vec<Point2<f64>> = vertices
                    .iter()
                    .map(|p| Point2::new(p[0] * f, p[1] * f))
                    .collect();
                Grain::<2>::polygon(&v).ok().map(recast)
            } else {
                let v: Vec<Point3<f64>> = vertices
                    .iter()
                    .map(|p| Point3::new(p[0] * f, p[1] * f, p[2] * f))
                    .collect();
                Grain::<3>::polyhedron(&v).ok().map(recast)
            }
        }
    }
}

fn recast<const E: usize, const D: usize>(g: Grain<E>) -> Grain<D> {
    crate::shapes::recast(g)
}
