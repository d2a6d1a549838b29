//! Advancing-front packings of general grains in a square (2D) or cube (3D)
//! with the particle-in-contact solvers (Pérez Morales et al. 2016,
//! Pseudocode 1 and §3), and an independent overlap checker built on
//! parry's exact distances.
//!
//! Algorithm (choices the seed leaves open are ours):
//! 1. the first grain sits in the corner touching the `D` lower walls;
//! 2. the front holds placed grains ordered by height (last axis; gravity
//!    along −y in 2D, −z in 3D); the new grain (circumscribed radius
//!    `U[r_min, r_max]`, random orientation, both from the ChaCha8 stream
//!    `(seed, index)`) is tried around the lowest front grain `P`: every set
//!    of `P` plus `D − 1` reachable grains or walls gives up to two contact
//!    positions ([`ContactMethod`]); the lowest position that overlaps
//!    nothing and stays in the domain wins;
//! 3. if nothing fits around `P`, a grain of the smallest size with the
//!    same orientation is tried there: if it does not fit either, `P`
//!    leaves the front, else the next front grain is tried (up to 32);
//!    a grain that fits nowhere is discarded (counted in
//!    [`PicPacking::rejected`]);
//! 4. the packing ends when the front is empty, after 400 discards in a
//!    row, or at [`PicParams::max_grains`].
//!
//! [`ContactMethod::ApproxWrappers`] (disk/sphere clusters only) replaces
//! step 2's grain-level sets by element-level ones on a cell grid of every
//! placed element and drops a front grain at its first failure once the
//! front holds 32 grains (no smallest-grain probe); see its docs.
//!
//! Overlap tolerance: a candidate is accepted with every gap
//! `≥ −1e-10·R_mob`; contacts are solved to `1e-13·R_mob` (closed forms
//! and Newton) or `1e-10·R_mob` (Nelder–Mead).

use std::collections::BTreeSet;

use nalgebra::{Point2, Point3, SVector, Unit};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::contact2d::{self, Solutions, Wrapper2};
use crate::contact3d::{self, Wrapper3};
use crate::error::{Error, Result};
use crate::gap::{self, Obstacle};
use crate::shapes::{Geometry, Grain, GrainShape, ParryConvex};

/// How the contact positions are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactMethod {
    /// Closed-form wrapper intersections (seed §3.1): exact for disks,
    /// spheres and their clusters (every element combination, as the
    /// seed); other shapes fall back to [`ContactMethod::Newton`].
    Wrappers,
    /// Closed form for single disks/spheres, otherwise Newton's method on
    /// exact gaps from closed-form first guesses (the fast method).
    #[default]
    Newton,
    /// The seed's Nelder–Mead minimisation of the gaps (§3.2), from the
    /// same first guesses, for comparison.
    NelderMead,
    /// The seed's "approximate wrappers method" (P5) for disks/spheres and
    /// their clusters of equal elements: one element of the new cluster is
    /// placed tangent to one element of the front grain and one (2D) or two
    /// (3D) elements or walls among the nearest placed elements (closed
    /// form), the cluster follows rigidly in its drawn orientation (each of
    /// its elements is tried as the contact one), and candidates, lowest
    /// first, are rejected by element–element overlap tests on a cell grid
    /// of all placed elements. Approximate: the cluster touches one set of
    /// elements, not the lowest exact contact of the whole cluster, so
    /// packings are looser than [`ContactMethod::Newton`]'s, but two
    /// orders of magnitude faster. Other shapes fall back to
    /// [`ContactMethod::Newton`].
    ApproxWrappers,
}

/// Parameters of a particle-in-contact packing.
#[derive(Debug, Clone, PartialEq)]
pub struct PicParams {
    /// Side of the square or cube domain `[0, side]^D`.
    pub side: f64,
    /// Smallest circumscribed radius.
    pub radius_min: f64,
    /// Largest circumscribed radius.
    pub radius_max: f64,
    /// Grain family.
    pub shape: GrainShape,
    /// Contact solver.
    pub method: ContactMethod,
    /// Stop after this many placed grains.
    pub max_grains: usize,
    /// How many grains nearest to the front grain may be contact partners
    /// (with the walls); more is slower and slightly denser.
    pub neighbours: usize,
    /// Orientations tried per grain (the drawn one first; the lowest
    /// placement wins). 1 keeps every grain's random orientation, as the
    /// seed's "without making rotations".
    pub orientations: usize,
}

impl Default for PicParams {
    /// The seed's Fig. 6 setting in 2D: side 20, `R ~ U[1, 2]`, capsules of
    /// aspect ratio 0.5.
    fn default() -> Self {
        Self {
            side: 20.0,
            radius_min: 1.0,
            radius_max: 2.0,
            shape: GrainShape::Capsule { aspect: 0.5 },
            method: ContactMethod::Newton,
            max_grains: 1_000_000,
            neighbours: 16,
            orientations: 1,
        }
    }
}

impl PicParams {
    /// Checks every field for dimension `dim`.
    ///
    /// # Errors
    /// [`Error::NonPositive`], [`Error::NonFinite`], [`Error::InvertedRange`],
    /// [`Error::DomainTooSmall`] when the side is below the largest
    /// circumscribed diameter, and the shape's [`GrainShape::validate`].
    pub fn validate(&self, dim: usize) -> Result<()> {
        crate::error::positive("side", self.side)?;
        crate::error::positive("radius_min", self.radius_min)?;
        crate::error::positive("radius_max", self.radius_max)?;
        if self.radius_min > self.radius_max {
            return Err(Error::InvertedRange {
                min: self.radius_min,
                max: self.radius_max,
            });
        }
        if self.side < 2.0 * self.radius_max {
            return Err(Error::DomainTooSmall {
                domain: self.side,
                particle: 2.0 * self.radius_max,
            });
        }
        self.shape.validate(dim)
    }
}

impl PicParams {
    /// The configuration we use for a row of Pérez Morales et al. 2016
    /// (`fixtures/reference/perezmorales2016_packings.csv`), with its
    /// dimension: side 20 (2D) or 40 (3D), `R ~ U[1, 2]`, aspect ratio
    /// `r/R = 0.5` (see [`crate::GrainShape`]). Our choices where the seed
    /// is silent: P1 half disks, half regular 4–8-gons, Newton on parry
    /// contacts; P2 4-disk clusters by the seed's wrappers, 8 orientations
    /// tried per grain; P3 exact capsules by Newton, 64 orientations; P4
    /// exact capsules by Newton, the drawn orientation only, 10 partners;
    /// P5 4-sphere clusters by the seed's approximate wrappers
    /// ([`ContactMethod::ApproxWrappers`], 6 nearest elements per element
    /// of the front grain; Newton with 10 partners packs 0.54 at ~220
    /// grains/s, the approximate method ~0.38 at ~15 000 grains/s).
    ///
    /// # Errors
    /// [`Error::Parameter`] for an unknown row id.
    pub fn perezmorales2016(row: &str) -> Result<(usize, Self)> {
        let base = Self::default();
        let capsule = GrainShape::Capsule { aspect: 0.5 };
        let cluster = GrainShape::Cluster {
            aspect: 0.5,
            spheres: 4,
        };
        Ok(match row {
            "P1" => (
                2,
                Self {
                    shape: GrainShape::Mix {
                        polygon_share: 0.5,
                        sides_min: 4,
                        sides_max: 8,
                    },
                    ..base
                },
            ),
            "P2" => (
                2,
                Self {
                    shape: cluster,
                    method: ContactMethod::Wrappers,
                    orientations: 8,
                    ..base
                },
            ),
            "P3" => (
                2,
                Self {
                    shape: capsule,
                    orientations: 64,
                    ..base
                },
            ),
            "P4" => (
                3,
                Self {
                    side: 40.0,
                    shape: capsule,
                    neighbours: 10,
                    ..base
                },
            ),
            "P5" => (
                3,
                Self {
                    side: 40.0,
                    shape: cluster,
                    method: ContactMethod::ApproxWrappers,
                    neighbours: 6,
                    ..base
                },
            ),
            _ => {
                return Err(Error::Parameter {
                    what: "perezmorales2016 row (P1..P5)",
                    value: f64::NAN,
                    range: "P1, P2, P3, P4, P5",
                });
            }
        })
    }
}

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

/// Uniform grid of the placed grains (cell side `2·r_max`).
struct Grid<const D: usize> {
    cell: f64,
    n: usize,
    cells: Vec<Vec<u32>>,
}

impl<const D: usize> Grid<D> {
    fn new(side: f64, cell: f64) -> Self {
        let n = ((side / cell).ceil() as usize).max(1);
        Self {
            cell,
            n,
            cells: vec![Vec::new(); n.pow(D as u32)],
        }
    }

    fn coord(&self, v: f64) -> usize {
        ((v / self.cell).floor().max(0.0) as usize).min(self.n - 1)
    }

    fn insert(&mut self, c: &SVector<f64, D>, id: u32) {
        let mut k = 0;
        for i in (0..D).rev() {
            k = k * self.n + self.coord(c[i]);
        }
        self.cells[k].push(id);
    }

    /// Calls `f` for every id in cells meeting the box around `c` of half
    /// side `r`.
    fn query(&self, c: &SVector<f64, D>, r: f64, mut f: impl FnMut(u32)) {
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        for i in 0..D {
            lo[i] = self.coord(c[i] - r);
            hi[i] = self.coord(c[i] + r);
        }
        let mut idx = lo;
        loop {
            let mut k = 0;
            for i in (0..D).rev() {
                k = k * self.n + idx[i];
            }
            for &id in &self.cells[k] {
                f(id);
            }
            let mut i = 0;
            loop {
                if i == D {
                    return;
                }
                if idx[i] < hi[i] {
                    idx[i] += 1;
                    break;
                }
                idx[i] = lo[i];
                i += 1;
            }
        }
    }
}

/// Order-preserving key of a float (for the front's `BTreeSet`).
fn key(v: f64) -> u64 {
    let b = v.to_bits();
    if b >> 63 == 0 { b | (1 << 63) } else { !b }
}

/// An obstacle of the candidate search: a placed grain or a wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Obj {
    Grain(u32),
    Wall { axis: usize, upper: bool },
}

struct Packer<'a, const D: usize> {
    params: &'a PicParams,
    grains: Vec<Placed<D>>,
    grid: Grid<D>,
    rmax_placed: f64,
    tol_rel: f64,
    neighbours: usize,
    /// Every placed element, for [`ContactMethod::ApproxWrappers`].
    elems: Option<Elements<D>>,
}

/// The placed disks/spheres of every grain (approximate wrappers): centres,
/// radii, the first element of each grain and a cell grid of them.
struct Elements<const D: usize> {
    centre: Vec<SVector<f64, D>>,
    radius: Vec<f64>,
    first: Vec<u32>,
    grid: Grid<D>,
    rmax: f64,
}

/// An element or a wall, contact partner of the approximate wrappers.
#[derive(Debug, Clone, Copy)]
enum Atom {
    Elem(u32),
    Wall { axis: usize, upper: bool },
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
    fn wrap(&self, o: Obj, rho: f64, m_off: &SVector<f64, D>, r_elem: f64) -> Wrap<D> {
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

impl<const D: usize> Packer<'_, D> {
    /// [`ContactMethod::ApproxWrappers`]: the lowest candidate position of
    /// the cluster `m` (equal elements) around `P = grains[p]` that
    /// overlaps no placed element and stays in the domain. For each element
    /// `a` of `P`, its `neighbours` nearest placed elements (surface
    /// distance) and the walls within reach are the partners; every pair
    /// (3D) or single partner (2D) reachable together with `a` gives up to
    /// two closed-form centres `y` of a mobile element tangent to all (kept
    /// if it clears `a`'s partners), and the cluster is placed rigidly in
    /// its drawn orientation with the element facing the partners (the
    /// smallest offset along the sum of the contact normals) at `y`.
    /// Candidates are tried lowest first against the placed elements near
    /// `P`, the element that rejected the previous candidate first.
    fn around_approx(&self, el: &Elements<D>, p: u32, m: &Grain<D>) -> Option<SVector<f64, D>> {
        let Geometry::Swept(me) = &m.geometry else {
            return None;
        };
        let s = me[0].radius;
        let rm = m.circumradius;
        let side = self.params.side;
        let tol = self.tol_rel * rm;
        let last = D - 1;
        let lo_e = el.first[p as usize] as usize;
        let hi_e = el
            .first
            .get(p as usize + 1)
            .map_or(el.centre.len(), |&k| k as usize);
        // Placed elements that may meet the cluster at any candidate (the
        // candidates lie within `R_P + R_m` of P's centre) or be a partner.
        let pc = self.grains[p as usize].centre;
        let reach = self.grains[p as usize].grain.circumradius + 2.0 * rm + el.rmax;
        let mut local: Vec<(SVector<f64, D>, f64, u32)> = Vec::new();
        // Through the (coarser) grain grid, then each grain's elements.
        self.grid.query(&pc, reach + self.rmax_placed, |g| {
            let gp = &self.grains[g as usize];
            let rg = reach + gp.grain.circumradius;
            if (gp.centre - pc).norm_squared() > rg * rg {
                return;
            }
            let lo = el.first[g as usize] as usize;
            let hi = el
                .first
                .get(g as usize + 1)
                .map_or(el.centre.len(), |&k| k as usize);
            for q in lo..hi {
                let c = el.centre[q];
                if (c - pc).norm_squared() <= reach * reach {
                    local.push((c, el.radius[q], q as u32));
                }
            }
        });
        let mut ys: Vec<(SVector<f64, D>, SVector<f64, D>)> = Vec::new();
        let mut near: Vec<(f64, Atom)> = Vec::new();
        let mut wraps: Vec<Wrap<D>> = Vec::new();
        let mut tmp = Vec::with_capacity(2);
        // Possible partners of P's elements: within `R_P + 2s + r_max`.
        let pr = self.grains[p as usize].grain.circumradius + 2.0 * s + el.rmax;
        let close: Vec<(SVector<f64, D>, f64, u32)> = local
            .iter()
            .filter(|e| (e.0 - pc).norm_squared() <= pr * pr)
            .copied()
            .collect();
        for a in lo_e..hi_e {
            let ca = el.centre[a];
            let ra = el.radius[a];
            near.clear();
            for &(c, r, q) in &close {
                // Siblings before `a` already had their turn.
                if (q as usize) <= a && (q as usize) >= lo_e {
                    continue;
                }
                let d2 = (c - ca).norm_squared();
                let lim = r + ra + 2.0 * s;
                if d2 <= lim * lim {
                    near.push((d2.sqrt() - r - ra, Atom::Elem(q)));
                }
            }
            if near.len() > self.neighbours {
                near.select_nth_unstable_by(self.neighbours, |x, y| {
                    x.0.total_cmp(&y.0).then(atom_id(x.1).cmp(&atom_id(y.1)))
                });
                near.truncate(self.neighbours);
            }
            for axis in 0..D {
                for upper in [false, true] {
                    let d = if upper { side - ca[axis] } else { ca[axis] } - ra;
                    if d <= 2.0 * s {
                        near.push((d, Atom::Wall { axis, upper }));
                    }
                }
            }
            wraps.clear();
            wraps.extend(near.iter().map(|&(_, b)| self.atom_wrap(el, b, s)));
            let clear = |y: &SVector<f64, D>| {
                near.iter().all(|&(_, q)| match q {
                    Atom::Elem(q) => {
                        let min = el.radius[q as usize] + s - tol;
                        (el.centre[q as usize] - y).norm_squared() >= min * min
                    }
                    Atom::Wall { .. } => true,
                })
            };
            let wa = Wrap::Sphere(ca, ra + s);
            for (i, &(_, b)) in near.iter().enumerate() {
                let pairs = if D == 2 { i..i + 1 } else { i + 1..near.len() };
                for k in pairs {
                    let c = near[k].1;
                    if D == 2 {
                        intersect(&[wa, wraps[i]], &mut tmp);
                    } else if let (Wrap::Sphere(c1, r1), Wrap::Sphere(c2, r2)) =
                        (wraps[i], wraps[k])
                    {
                        if (c1 - c2).norm_squared() > (r1 + r2) * (r1 + r2) {
                            continue;
                        }
                        tangent3(&ca, ra + s, &c1, r1, &c2, r2, &mut tmp);
                    } else if self.atoms_reach(el, b, c, s) {
                        intersect(&[wa, wraps[i], wraps[k]], &mut tmp);
                    } else {
                        continue;
                    }
                    for y in tmp.iter().filter(|y| clear(y)) {
                        let mut n =
                            (y - ca).normalize() + (y - self.atom_point(el, b, y)).normalize();
                        if D == 3 {
                            n += (y - self.atom_point(el, c, y)).normalize();
                        }
                        ys.push((*y, n));
                    }
                }
            }
        }
        // The cluster with its element facing the partners at each centre.
        let mut cands: Vec<(f64, SVector<f64, D>)> = Vec::with_capacity(ys.len());
        for &(y, n) in &ys {
            let mut j = 0;
            let mut best = f64::INFINITY;
            for (k, e) in me.iter().enumerate() {
                let v = e.a.dot(&n);
                if v < best {
                    best = v;
                    j = k;
                }
            }
            let x = y - me[j].a;
            if (0..D).all(|i| x[i] + m.lo[i] >= -tol && x[i] + m.hi[i] <= side + tol) {
                cands.push((x[last], x));
            }
        }
        cands.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut culprit = 0usize;
        'cand: for (_, x) in cands {
            for k in std::iter::once(culprit).chain(0..local.len()) {
                let Some(&(c, r, _)) = local.get(k) else {
                    continue;
                };
                let rel = c - x;
                let big = rm + r;
                if rel.norm_squared() >= big * big {
                    continue;
                }
                for e in me {
                    let min = r + e.radius - tol;
                    if (rel - e.a).norm_squared() < min * min {
                        culprit = k;
                        continue 'cand;
                    }
                }
            }
            return Some(x);
        }
        None
    }

    /// Centre of element `a`, or the foot of `y` on wall `a`.
    fn atom_point(&self, el: &Elements<D>, a: Atom, y: &SVector<f64, D>) -> SVector<f64, D> {
        match a {
            Atom::Elem(q) => el.centre[q as usize],
            Atom::Wall { axis, upper } => {
                let mut f = *y;
                f[axis] = if upper { self.params.side } else { 0.0 };
                f
            }
        }
    }

    /// Wrapper of an element or wall for a mobile element of radius `s`.
    fn atom_wrap(&self, el: &Elements<D>, a: Atom, s: f64) -> Wrap<D> {
        match a {
            Atom::Elem(q) => Wrap::Sphere(el.centre[q as usize], el.radius[q as usize] + s),
            Atom::Wall { axis, upper } => {
                self.wrap(Obj::Wall { axis, upper }, 0.0, &SVector::zeros(), s)
            }
        }
    }

    /// Whether one mobile element of radius `s` can touch both `a` and `b`.
    fn atoms_reach(&self, el: &Elements<D>, a: Atom, b: Atom, s: f64) -> bool {
        let side = self.params.side;
        match (a, b) {
            (Atom::Elem(i), Atom::Elem(j)) => {
                let reach = el.radius[i as usize] + el.radius[j as usize] + 2.0 * s;
                (el.centre[i as usize] - el.centre[j as usize]).norm_squared() <= reach * reach
            }
            (Atom::Wall { axis: a1, .. }, Atom::Wall { axis: a2, .. }) => a1 != a2,
            (Atom::Elem(i), Atom::Wall { axis, upper })
            | (Atom::Wall { axis, upper }, Atom::Elem(i)) => {
                let c = el.centre[i as usize][axis];
                let d = if upper { side - c } else { c };
                d - el.radius[i as usize] <= 2.0 * s
            }
        }
    }
}

/// Centres `x` with `|x − c_i| = ρ_i` for three spheres (3D only; the
/// closed form of [`contact3d::intersect`] without its conversions): none
/// for collinear centres or no intersection, one when tangent.
fn tangent3<const D: usize>(
    c0: &SVector<f64, D>,
    rho0: f64,
    c1: &SVector<f64, D>,
    rho1: f64,
    c2: &SVector<f64, D>,
    rho2: f64,
    out: &mut Vec<SVector<f64, D>>,
) {
    out.clear();
    let cross = |a: &SVector<f64, D>, b: &SVector<f64, D>| {
        SVector::<f64, D>::from_fn(|i, _| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            a[j] * b[k] - a[k] * b[j]
        })
    };
    let a1 = c1 - c0;
    let a2 = c2 - c0;
    let b1 = 0.5 * (rho0 * rho0 - rho1 * rho1 + a1.norm_squared());
    let b2 = 0.5 * (rho0 * rho0 - rho2 * rho2 + a2.norm_squared());
    let u = cross(&a1, &a2);
    let uu = u.norm_squared();
    if !uu.gt(&(1e-24 * a1.norm_squared() * a2.norm_squared())) || !uu.is_finite() {
        return;
    }
    let y0 = (cross(&a2, &u) * b1 + cross(&u, &a1) * b2) / uu;
    let y0n = y0.norm_squared();
    let disc = rho0 * rho0 - y0n;
    let eps = 64.0 * f64::EPSILON * (rho0 * rho0 + y0n);
    if !disc.is_finite() || disc < -eps {
        return;
    }
    if disc <= eps {
        out.push(c0 + y0);
        return;
    }
    let t = (disc / uu).sqrt();
    out.push(c0 + y0 + u * t);
    out.push(c0 + y0 - u * t);
}

/// A sort key of an [`Atom`] (ties of the nearest-element selection).
fn atom_id(a: Atom) -> u64 {
    match a {
        Atom::Elem(q) => u64::from(q),
        Atom::Wall { axis, upper } => u64::MAX - 2 * axis as u64 - u64::from(upper),
    }
}

/// A wrapper of either dimension: sphere `|x − c| = ρ` or plane `n·x = o`.
#[derive(Debug, Clone, Copy)]
enum Wrap<const D: usize> {
    Sphere(SVector<f64, D>, f64),
    Plane(SVector<f64, D>, f64),
}

/// Intersection of `D` wrappers by the closed forms of `contact2d` /
/// `contact3d`.
fn intersect<const D: usize>(w: &[Wrap<D>], out: &mut Vec<SVector<f64, D>>) {
    out.clear();
    let back = |s: &[f64]| SVector::<f64, D>::from_fn(|i, _| s[i]);
    if D == 2 {
        let c = |x: &Wrap<D>| match *x {
            Wrap::Sphere(c, r) => Wrapper2::Circle {
                centre: Point2::new(c[0], c[1]),
                radius: r,
            },
            Wrap::Plane(n, o) => Wrapper2::Line {
                normal: Unit::new_unchecked(nalgebra::Vector2::new(n[0], n[1])),
                offset: o,
            },
        };
        let s: Solutions<Point2<f64>> = contact2d::intersect(&c(&w[0]), &c(&w[1]));
        out.extend(s.iter().map(|p| back(p.coords.as_slice())));
    } else {
        let c = |x: &Wrap<D>| match *x {
            Wrap::Sphere(c, r) => Wrapper3::Sphere {
                centre: Point3::new(c[0], c[1], c[2]),
                radius: r,
            },
            Wrap::Plane(n, o) => Wrapper3::Plane {
                normal: Unit::new_unchecked(nalgebra::Vector3::new(n[0], n[1], n[2])),
                offset: o,
            },
        };
        let s = contact3d::intersect(&[c(&w[0]), c(&w[1]), c(&w[2])]);
        out.extend(s.iter().map(|p| back(p.coords.as_slice())));
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
    let mut pk = Packer::<D> {
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

/// Result of [`check_pic`].
#[derive(Debug, Clone, PartialEq)]
pub struct PicReport {
    /// Smallest signed gap over all grain pairs divided by the smaller
    /// circumscribed diameter of the pair (`+∞` with fewer than two grains).
    pub min_relative_gap: f64,
    /// Smallest signed wall clearance divided by the grain's diameter.
    pub min_relative_wall_gap: f64,
    /// Grain pairs with `gap ≤ contact_tol · d` (contacts).
    pub contacts: usize,
    /// Mean coordination number `2·contacts / n`.
    pub coordination: f64,
}

/// Independent overlap checker on parry's exact queries: every pair of
/// grains whose bounding spheres meet is measured with parry's `contact`
/// (signed distance: balls and capsules exactly, convex shapes by GJK/EPA)
/// element by element; walls with parry's AABBs. It shares no arithmetic
/// with the placement code. Pairs are found by sorting on the first
/// coordinate (sweep and prune).
///
/// # Errors
/// [`Error::Empty`] for an empty packing.
pub fn check_pic<const D: usize>(p: &PicPacking<D>, contact_tol: f64) -> Result<PicReport> {
    if p.grains.is_empty() {
        return Err(Error::Empty { what: "packing" });
    }
    let shapes: Vec<Vec<ParryPart>> = p.grains.iter().map(parts).collect();
    let mut order: Vec<usize> = (0..p.grains.len()).collect();
    order.sort_by(|&a, &b| {
        let ka = p.grains[a].centre[0] - p.grains[a].grain.circumradius;
        let kb = p.grains[b].centre[0] - p.grains[b].grain.circumradius;
        ka.total_cmp(&kb).then(a.cmp(&b))
    });
    let mut min_gap = f64::INFINITY;
    let mut contacts = 0usize;
    let mut min_wall = f64::INFINITY;
    for (k, &i) in order.iter().enumerate() {
        let gi = &p.grains[i];
        let ri = gi.grain.circumradius;
        for (lo, hi) in parts_aabb(&shapes[i]) {
            for a in 0..D {
                min_wall = min_wall
                    .min(lo[a] / (2.0 * ri))
                    .min((p.side - hi[a]) / (2.0 * ri));
            }
        }
        for &j in &order[k + 1..] {
            let gj = &p.grains[j];
            let rj = gj.grain.circumradius;
            if gj.centre[0] - rj > gi.centre[0] + ri {
                break;
            }
            if (gj.centre - gi.centre).norm() > ri + rj {
                continue;
            }
            let d = 2.0 * ri.min(rj);
            let g = pair_gap(&shapes[i], &shapes[j], d);
            min_gap = min_gap.min(g / d);
            if g <= contact_tol * d {
                contacts += 1;
            }
        }
    }
    Ok(PicReport {
        min_relative_gap: min_gap,
        min_relative_wall_gap: min_wall,
        contacts,
        coordination: 2.0 * contacts as f64 / p.grains.len() as f64,
    })
}

/// One parry shape of a grain, placed in the world.
enum ParryPart {
    D2(parry2d_f64::math::Pose, parry2d_f64::shape::SharedShape),
    D3(parry3d_f64::math::Pose, parry3d_f64::shape::SharedShape),
}

fn parts<const D: usize>(g: &Placed<D>) -> Vec<ParryPart> {
    let c = g.centre;
    match &g.grain.geometry {
        Geometry::Swept(e) => e
            .iter()
            .map(|s| {
                if D == 2 {
                    let pose = parry2d_f64::math::Pose::translation(c[0], c[1]);
                    let a = parry2d_f64::math::Vector::new(s.a[0], s.a[1]);
                    let b = parry2d_f64::math::Vector::new(s.b[0], s.b[1]);
                    let sh = if s.a == s.b {
                        parry2d_f64::shape::SharedShape::ball(s.radius)
                    } else {
                        parry2d_f64::shape::SharedShape::capsule(a, b, s.radius)
                    };
                    let pose = if s.a == s.b {
                        parry2d_f64::math::Pose::translation(c[0] + s.a[0], c[1] + s.a[1])
                    } else {
                        pose
                    };
                    ParryPart::D2(pose, sh)
                } else {
                    let a = parry3d_f64::math::Vector::new(s.a[0], s.a[1], s.a[2]);
                    let b = parry3d_f64::math::Vector::new(s.b[0], s.b[1], s.b[2]);
                    if s.a == s.b {
                        ParryPart::D3(
                            parry3d_f64::math::Pose::translation(
                                c[0] + s.a[0],
                                c[1] + s.a[1],
                                c[2] + s.a[2],
                            ),
                            parry3d_f64::shape::SharedShape::ball(s.radius),
                        )
                    } else {
                        ParryPart::D3(
                            parry3d_f64::math::Pose::translation(c[0], c[1], c[2]),
                            parry3d_f64::shape::SharedShape::capsule(a, b, s.radius),
                        )
                    }
                }
            })
            .collect(),
        Geometry::Convex { shape, .. } => match shape {
            ParryConvex::Polygon(poly) => vec![ParryPart::D2(
                parry2d_f64::math::Pose::translation(c[0], c[1]),
                parry2d_f64::shape::SharedShape::new(poly.as_ref().clone()),
            )],
            ParryConvex::Polyhedron(poly) => vec![ParryPart::D3(
                parry3d_f64::math::Pose::translation(c[0], c[1], c[2]),
                parry3d_f64::shape::SharedShape::new(poly.as_ref().clone()),
            )],
        },
    }
}

fn parts_aabb(parts: &[ParryPart]) -> Vec<([f64; 3], [f64; 3])> {
    parts
        .iter()
        .map(|p| match p {
            ParryPart::D2(pose, s) => {
                let b = s.compute_aabb(pose);
                ([b.mins.x, b.mins.y, 0.0], [b.maxs.x, b.maxs.y, 0.0])
            }
            ParryPart::D3(pose, s) => {
                let b = s.compute_aabb(pose);
                (
                    [b.mins.x, b.mins.y, b.mins.z],
                    [b.maxs.x, b.maxs.y, b.maxs.z],
                )
            }
        })
        .collect()
}

/// Smallest signed gap between two grains by parry (`d` sets the contact
/// prediction distance).
fn pair_gap(a: &[ParryPart], b: &[ParryPart], d: f64) -> f64 {
    let mut g = f64::INFINITY;
    for pa in a {
        for pb in b {
            let v = match (pa, pb) {
                (ParryPart::D2(p1, s1), ParryPart::D2(p2, s2)) => {
                    parry2d_f64::query::contact(p1, s1.as_ref(), p2, s2.as_ref(), d)
                        .ok()
                        .flatten()
                        .map(|c| c.dist)
                }
                (ParryPart::D3(p1, s1), ParryPart::D3(p2, s2)) => {
                    parry3d_f64::query::contact(p1, s1.as_ref(), p2, s2.as_ref(), d)
                        .ok()
                        .flatten()
                        .map(|c| c.dist)
                }
                _ => None,
            };
            g = g.min(v.unwrap_or(d));
        }
    }
    g
}

#[cfg(test)]
mod tests;

/// Writes a packing of any shape as a VTK unstructured grid (ParaView):
/// one cell per element, with cell arrays `grain` (index) and `radius`.
/// Disks/spheres are vertex cells, capsule cores line cells (use a Tube
/// filter with `radius`), convex polygons polygon cells and convex
/// polyhedra their hull triangles (radius 0). 2D grains are written at
/// `z = 0`.
///
/// # Errors
/// [`Error::Empty`] for an empty packing, [`Error::Io`].
pub fn write_pic_vtu<const D: usize>(p: &PicPacking<D>, mut w: impl std::io::Write) -> Result<()> {
    if p.grains.is_empty() {
        return Err(Error::Empty { what: "packing" });
    }
    let mut points: Vec<[f64; 3]> = Vec::new();
    // (point indices, VTK cell type, grain, radius)
    let mut cells: Vec<(Vec<usize>, u8, usize, f64)> = Vec::new();
    let pt = |v: SVector<f64, D>| [v[0], v[1], if D == 3 { v[2] } else { 0.0 }];
    for (gi, g) in p.grains.iter().enumerate() {
        match &g.grain.geometry {
            Geometry::Swept(e) => {
                for s in e {
                    let a = points.len();
                    points.push(pt(g.centre + s.a));
                    if s.a == s.b {
                        cells.push((vec![a], 1, gi, s.radius));
                    } else {
                        points.push(pt(g.centre + s.b));
                        cells.push((vec![a, a + 1], 3, gi, s.radius));
                    }
                }
            }
            Geometry::Convex { vertices, shape } => match shape {
                ParryConvex::Polygon(_) => {
                    let a = points.len();
                    points.extend(vertices.iter().map(|v| pt(g.centre + v)));
                    cells.push(((a..a + vertices.len()).collect(), 7, gi, 0.0));
                }
                ParryConvex::Polyhedron(poly) => {
                    let (tv, ti) = poly.to_trimesh();
                    let a = points.len();
                    points
                        .extend(tv.iter().map(|v| {
                            [g.centre[0] + v.x, g.centre[1] + v.y, g.centre[2 % D] + v.z]
                        }));
                    for t in ti {
                        cells.push((t.iter().map(|&k| a + k as usize).collect(), 5, gi, 0.0));
                    }
                }
            },
        }
    }
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
    )?;
    writeln!(w, "<UnstructuredGrid>")?;
    writeln!(
        w,
        r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
        points.len(),
        cells.len()
    )?;
    writeln!(w, r#"<CellData Scalars="radius">"#)?;
    writeln!(w, r#"<DataArray type="Int64" Name="grain" format="ascii">"#)?;
    for c in &cells {
        writeln!(w, "{}", c.2)?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        r#"<DataArray type="Float64" Name="radius" format="ascii">"#
    )?;
    for c in &cells {
        writeln!(w, "{:e}", c.3)?;
    }
    writeln!(w, "</DataArray>\n</CellData>\n<Points>")?;
    writeln!(
        w,
        r#"<DataArray type="Float64" NumberOfComponents="3" format="ascii">"#
    )?;
    for q in &points {
        writeln!(w, "{:e} {:e} {:e}", q[0], q[1], q[2])?;
    }
    writeln!(w, "</DataArray>\n</Points>\n<Cells>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#
    )?;
    for c in &cells {
        let s: Vec<String> = c.0.iter().map(ToString::to_string).collect();
        writeln!(w, "{}", s.join(" "))?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="offsets" format="ascii">"#
    )?;
    let mut off = 0;
    for c in &cells {
        off += c.0.len();
        writeln!(w, "{off}")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(w, r#"<DataArray type="UInt8" Name="types" format="ascii">"#)?;
    for c in &cells {
        writeln!(w, "{}", c.1)?;
    }
    writeln!(
        w,
        "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>"
    )?;
    Ok(())
}
