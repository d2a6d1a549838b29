//! [`ContactMethod::ApproxWrappers`]: the seed's approximate wrappers on a
//! cell grid of every placed element (disk/sphere clusters).

use nalgebra::SVector;

use super::front::{Obj, Packer};
use super::grid::Grid;
#[cfg(doc)]
use super::params::ContactMethod;
use super::wrap::{Wrap, intersect, tangent3};
use crate::shapes::{Geometry, Grain};

/// The placed disks/spheres of every grain (approximate wrappers): centres,
/// radii, the first element of each grain and a cell grid of them.
pub(super) struct Elements<const D: usize> {
    pub(super) centre: Vec<SVector<f64, D>>,
    pub(super) radius: Vec<f64>,
    pub(super) first: Vec<u32>,
    pub(super) grid: Grid<D>,
    pub(super) rmax: f64,
}

/// An element or a wall, contact partner of the approximate wrappers.
#[derive(Debug, Clone, Copy)]
enum Atom {
    Elem(u32),
    Wall { axis: usize, upper: bool },
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
    pub(super) fn around_approx(
        &self,
        el: &Elements<D>,
        p: u32,
        m: &Grain<D>,
    ) -> Option<SVector<f64, D>> {
        let Geometry::Swept(me) = &m.geometry else {
            return None;
        };
        let s = me[0].radius;
        let rm = m.circumradius;
        let side = self.params.side;
        let tol = self.tol_rel * rm;
        let last = D - 1;
        // Placed elements that may meet the cluster at any candidate (the
        // candidates lie within `R_P + R_m` of P's centre) or be a partner.
        let pc = self.grains[p as usize].centre;
        let reach = self.grains[p as usize].grain.circumradius + 2.0 * rm + el.rmax;
        let local = self.local_elements(el, &pc, reach);
        // Possible partners of P's elements: within `R_P + 2s + r_max`.
        let pr = self.grains[p as usize].grain.circumradius + 2.0 * s + el.rmax;
        let close: Vec<(SVector<f64, D>, f64, u32)> = local
            .iter()
            .filter(|e| (e.0 - pc).norm_squared() <= pr * pr)
            .copied()
            .collect();
        let ys = self.tangent_centres(el, p, s, tol, &close);
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

    /// Placed elements (centre, radius, index) within `reach` of `pc`:
    /// through the (coarser) grain grid, then each grain's elements.
    fn local_elements(
        &self,
        el: &Elements<D>,
        pc: &SVector<f64, D>,
        reach: f64,
    ) -> Vec<(SVector<f64, D>, f64, u32)> {
        let pc = *pc;
        let mut local: Vec<(SVector<f64, D>, f64, u32)> = Vec::new();
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
        local
    }

    /// Centres `y` of a mobile element of radius `s` tangent to an element
    /// `a` of `P = grains[p]` and one (2D) or two (3D) of its partners
    /// among `close` and the walls, clear of `a`'s partners, each with the
    /// sum of its contact normals.
    fn tangent_centres(
        &self,
        el: &Elements<D>,
        p: u32,
        s: f64,
        tol: f64,
        close: &[(SVector<f64, D>, f64, u32)],
    ) -> Vec<(SVector<f64, D>, SVector<f64, D>)> {
        let lo_e = el.first[p as usize] as usize;
        let hi_e = el
            .first
            .get(p as usize + 1)
            .map_or(el.centre.len(), |&k| k as usize);
        let mut ys: Vec<(SVector<f64, D>, SVector<f64, D>)> = Vec::new();
        let mut near: Vec<(f64, Atom)> = Vec::new();
        let mut wraps: Vec<Wrap<D>> = Vec::new();
        let mut tmp = Vec::with_capacity(2);
        for a in lo_e..hi_e {
            let ca = el.centre[a];
            let ra = el.radius[a];
            self.partners(el, a, lo_e, s, close, &mut near);
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
        ys
    }

    /// The partners of element `a` (of the grain whose elements start at
    /// `lo_e`) into `near`: its `neighbours` nearest elements of `close`
    /// (surface distance) within `2s`, then the walls within `2s`.
    fn partners(
        &self,
        el: &Elements<D>,
        a: usize,
        lo_e: usize,
        s: f64,
        close: &[(SVector<f64, D>, f64, u32)],
        near: &mut Vec<(f64, Atom)>,
    ) {
        let side = self.params.side;
        let ca = el.centre[a];
        let ra = el.radius[a];
        near.clear();
        for &(c, r, q) in close {
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

/// A sort key of an [`Atom`] (ties of the nearest-element selection).
fn atom_id(a: Atom) -> u64 {
    match a {
        Atom::Elem(q) => u64::from(q),
        Atom::Wall { axis, upper } => u64::MAX - 2 * axis as u64 - u64::from(upper),
    }
}
