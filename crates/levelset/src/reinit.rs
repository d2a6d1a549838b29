//! Reinitialisation to a signed-distance field by the fast sweeping method.
//!
//! Method (Zhao 2005, Math. Comp. 74, doi:10.1090/S0025-5718-04-01678-3, Eq. 2.3–2.4):
//! nodes adjacent to a sign change get a first-order distance estimate and stay fixed;
//! every other node solves the upwind Godunov discretisation of |∇u| = 1 in Gauss–Seidel
//! sweeps over the 8 alternating orderings. Two choices the seeds leave open:
//!
//! * **Interface estimate**: `|φ|/|∇φ|` with central differences (exact for a linear φ),
//!   capped by the distance to the nearest linear zero crossing along a grid edge (that
//!   crossing lies on the interpolated interface, so the cap is a true upper bound; it
//!   protects against kinks and tiny gradients).
//! * **Number of sweeps**: exactly one round of the 2³ orderings. For the distance function
//!   (unit speed, no obstacles) the Gauss–Seidel iteration converges in 2ⁿ sweeps in n
//!   dimensions (Zhao 2005, Sec. 3), because every characteristic is a straight ray whose
//!   direction lies in one octant. This was checked on this implementation with a
//!   change-tracking variant: after the 8th sweep no value changed, for the sphere, the
//!   ellipsoid and a lumpy star grain on 45³ grids; the tests compare against exact
//!   distances.
//!
//! Beyond the seeds, two orderings that change no value: each sweep visits a z-slab's
//! diagonals (independent nodes, Detrixhe, Gibou & Min 2013), and a node is recomputed only
//! when a neighbour decreased since its last update (locking, Bak, McLaughlin & Renzi
//! 2010). After a blur most nodes still move in every sweep (85 % in the first, 30 % in the
//! eighth, on the grains of the 512³ synthetic scan), so locking saves about 4 % of the
//! `dna` stage; the test `locked_sweeps_match_plain_sweeps` checks both against plain
//! lexicographic sweeps.

use crate::error::{Error, Result};
use crate::grid::{Grid, GridSpec};

impl Grid {
    /// Turns the grid into a signed-distance field with the same zero level set
    /// (to first order), by fast sweeping. The sign of every node is kept.
    ///
    /// # Errors
    /// [`Error::NoSurface`] if no two neighbouring nodes differ in sign.
    pub fn reinitialise(&mut self) -> Result<()> {
        let spec = *self.spec();
        redistance(&spec, self.values_mut(), false)
    }
}

/// `min` without NaN handling (compiles to one `minsd`); the sweeps never see NaN
/// (values are finite or +∞), and `f64::min`'s NaN checks cost ≈40 % of the sweep time.
#[inline(always)]
fn fmin(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// `max` without NaN handling, see [`fmin`].
#[inline(always)]
fn fmax(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// Redistances `values` in place. With `upper_bound`, the current magnitudes are known to be
/// upper bounds of the distance (e.g. the radial distance of a star-shaped surface) and
/// are used as the initial guess instead of +∞, which shortens the sweeps.
pub(crate) fn redistance(spec: &GridSpec, values: &mut [f64], upper_bound: bool) -> Result<()> {
    let [nx, ny, nz] = spec.dims;
    let h = spec.spacing;
    let (px, py) = (nx + 2, ny + 2);
    let (sy, sz) = (px, px * py);
    let plen = px * py * (nz + 2);
    let mut u = vec![f64::INFINITY; plen];
    // Padding and interface nodes are never updated.
    let mut fixed = vec![true; plen];
    let gs = [1usize, nx, nx * ny];
    let dims = [nx, ny, nz];
    let mut any_interface = false;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let g = i + nx * (j + ny * k);
                let p = (i + 1) + sy * (j + 1) + sz * (k + 1);
                let v = values[g];
                let inside = v < 0.0;
                let idx = [i, j, k];
                // Fast path: interior nodes whose six neighbours share their sign.
                if i > 0 && j > 0 && k > 0 && i + 1 < nx && j + 1 < ny && k + 1 < nz {
                    let same = [g - 1, g + 1, g - nx, g + nx, g - nx * ny, g + nx * ny]
                        .iter()
                        .all(|&q| (values[q] < 0.0) == inside);
                    if same {
                        u[p] = if upper_bound { v.abs() } else { f64::INFINITY };
                        fixed[p] = false;
                        continue;
                    }
                }
                let mut cap = f64::INFINITY;
                let mut grad2 = 0.0;
                for a in 0..3 {
                    let lo = if idx[a] > 0 {
                        Some(values[g - gs[a]])
                    } else {
                        None
                    };
                    let hi = if idx[a] + 1 < dims[a] {
                        Some(values[g + gs[a]])
                    } else {
                        None
                    };
                    for w in [lo, hi].into_iter().flatten() {
                        if (w < 0.0) != inside {
                            // v and w differ in sign, so v − w ≠ 0 unless both are 0.
                            let t = v / (v - w);
                            cap = cap.min(h * t.abs());
                        }
                    }
                    let d = match (lo, hi) {
                        (Some(l), Some(r)) => 0.5 * (r - l),
                        (None, Some(r)) => r - v,
                        (Some(l), None) => v - l,
                        (None, None) => 0.0,
                    } / h;
                    grad2 += d * d;
                }
                if cap.is_finite() {
                    any_interface = true;
                    let est = if grad2 > 0.0 {
                        v.abs() / grad2.sqrt()
                    } else {
                        cap
                    };
                    u[p] = est.min(cap);
                } else {
                    u[p] = if upper_bound { v.abs() } else { f64::INFINITY };
                    fixed[p] = false;
                }
            }
        }
    }
    if !any_interface {
        return Err(Error::NoSurface);
    }
    sweep(spec.dims, h, &mut u, &fixed);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let g = i + nx * (j + ny * k);
                let p = (i + 1) + sy * (j + 1) + sz * (k + 1);
                let d = u[p];
                values[g] = if values[g] < 0.0 { -d } else { d };
            }
        }
    }
    Ok(())
}

/// The 2³ fast sweeps on a padded array: `u` and `fixed` hold `(nx+2)·(ny+2)·(nz+2)`
/// entries (x fastest), node `(i, j, k)` of the grid at padded index
/// `(i+1) + (nx+2)·((j+1) + (ny+2)·(k+1))`; the padding must be `+∞` and fixed. Unsigned
/// distances: fixed nodes are the sources, every other node ends with the minimum of its
/// start value and the Godunov solution from its neighbours.
pub(crate) fn sweep(dims: [usize; 3], h: f64, u: &mut [f64], fixed: &[bool]) {
    let [nx, ny, nz] = dims;
    let (px, py) = (nx + 2, ny + 2);
    let (sy, sz) = (px, px * py);
    let h2 = h * h;
    // Locking (Bak, McLaughlin & Renzi 2010, J. Comput. Phys. 229,
    // doi:10.1016/j.jcp.2010.02.022): a node is recomputed only when one of its six
    // neighbours decreased since its last update. Skipping the others changes nothing: the
    // update is a function of the six neighbours alone and never raises a value, so a node
    // whose neighbours are unchanged would get the value it has. The result is bit for bit
    // that of the plain sweeps; the later sweeps touch only where distances still move.
    let mut dirty: Vec<bool> = fixed.iter().map(|&f| !f).collect();
    for sweep in 0..8 {
        let (fx, fy, fz) = (sweep & 1 == 0, sweep & 2 == 0, sweep & 4 == 0);
        // Slab-wise diagonal ordering: z-slabs in sweep order, and inside a slab the
        // diagonals i'+j' = L in order (i', j' = sweep-oriented indices). The upwind
        // neighbours of a node are on the previous diagonal or the previous slab, so this
        // computes exactly what the lexicographic Gauss–Seidel sweep of the same direction
        // computes, but the nodes of one diagonal are independent (no serial dependency
        // between consecutive updates, ≈ 3× faster) and a slab stays in cache. This is the
        // 2-D form of the hyperplane sweeps of Detrixhe, Gibou & Min 2013 (J. Comput. Phys.
        // 237, doi:10.1016/j.jcp.2012.11.042).
        for kp in 0..nz {
            let k = if fz { kp } else { nz - 1 - kp } + 1;
            for level in 0..=(nx + ny - 2) {
                let j_lo = level.saturating_sub(nx - 1);
                let j_hi = (ny - 1).min(level);
                for jp in j_lo..=j_hi {
                    let ip = level - jp;
                    let j = if fy { jp } else { ny - 1 - jp } + 1;
                    let i = if fx { ip } else { nx - 1 - ip } + 1;
                    let p = i + sy * j + sz * k;
                    if !dirty[p] {
                        continue;
                    }
                    dirty[p] = false;
                    let a = fmin(u[p - 1], u[p + 1]);
                    let b = fmin(u[p - sy], u[p + sy]);
                    let c = fmin(u[p - sz], u[p + sz]);
                    // Sorting network: lo ≤ mid ≤ hi.
                    let (s0, s1) = (fmin(a, b), fmax(a, b));
                    let (lo, t) = (fmin(s0, c), fmax(s0, c));
                    let (mid, hi) = (fmin(s1, t), fmax(s1, t));
                    // Branch-free Godunov update with a single square root: pick the
                    // case by comparisons first (x₂ ≤ hi ⟺ D₂ ≤ (2·hi − lo − mid)²), then
                    // take one root. Unused expressions may be NaN/∞ and are never selected.
                    let x1 = lo + h;
                    let d = lo - mid;
                    let d2 = 2.0 * h2 - d * d;
                    let s = lo + mid + hi;
                    let d3 = s * s - 3.0 * (lo * lo + mid * mid + hi * hi - h2);
                    let room = 2.0 * hi - lo - mid;
                    let two = room >= 0.0 && d2 <= room * room;
                    let (lin, disc, scale) = if two {
                        (lo + mid, d2, 0.5)
                    } else {
                        (s, d3, 1.0 / 3.0)
                    };
                    let xr = scale * (lin + fmax(disc, 0.0).sqrt());
                    let x = if x1 <= mid { x1 } else { xr };
                    // only non-fixed nodes are ever dirty
                    if x < u[p] {
                        u[p] = x;
                        for q in [p - 1, p + 1, p - sy, p + sy, p - sz, p + sz] {
                            dirty[q] = !fixed[q];
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn reinitialise_recovers_sphere_distance_from_a_distorted_field() {
        let spec = GridSpec::cube(41, -1.2, 1.2).expect("spec");
        let h = spec.spacing;
        // Same zero set as the sphere R = 0.8, far from a distance field.
        let mut g = Grid::from_fn(spec, |p: &Point3<f64>| {
            let r2 = p.coords.norm_squared();
            (r2 - 0.64) * (1.0 + p.x * p.x)
        })
        .expect("grid");
        g.reinitialise().expect("has surface");
        let mut worst_band = 0.0f64;
        let mut worst_all = 0.0f64;
        for k in 0..41 {
            for j in 0..41 {
                for i in 0..41 {
                    let p = spec.node(i, j, k);
                    let exact = p.coords.norm() - 0.8;
                    let e = (g.at(i, j, k) - exact).abs();
                    if exact.abs() < 2.0 * h {
                        worst_band = worst_band.max(e);
                    }
                    worst_all = worst_all.max(e);
                }
            }
        }
        // First-order interface estimate and first-order sweeping: band error well below h;
        // far from the surface the first-order upwind error accumulates (measured 1.07·h at
        // the grid corners, 0.5 from the surface).
        assert!(worst_band < 0.25 * h, "band error {worst_band} vs h {h}");
        assert!(worst_all < 1.5 * h, "global error {worst_all} vs h {h}");
    }

    /// The plain sweeps (every node recomputed in every sweep, lexicographic order within
    /// a sweep), the oracle of the locking and diagonal ordering of [`sweep`].
    fn plain_sweeps(dims: [usize; 3], h: f64, u: &mut [f64], fixed: &[bool]) {
        let [nx, ny, nz] = dims;
        let (sy, sz) = (nx + 2, (nx + 2) * (ny + 2));
        for sweep in 0..8 {
            let (fx, fy, fz) = (sweep & 1 == 0, sweep & 2 == 0, sweep & 4 == 0);
            for kp in 0..nz {
                let k = if fz { kp } else { nz - 1 - kp } + 1;
                for jp in 0..ny {
                    let j = if fy { jp } else { ny - 1 - jp } + 1;
                    for ip in 0..nx {
                        let i = if fx { ip } else { nx - 1 - ip } + 1;
                        let p = i + sy * j + sz * k;
                        if fixed[p] {
                            continue;
                        }
                        let mut a = [
                            u[p - 1].min(u[p + 1]),
                            u[p - sy].min(u[p + sy]),
                            u[p - sz].min(u[p + sz]),
                        ];
                        a.sort_by(f64::total_cmp);
                        // Zhao 2005, Eq. 2.4: the smallest root consistent with the sorted
                        // neighbours
                        let mut x = a[0] + h;
                        if x > a[1] {
                            let d = a[0] - a[1];
                            x = 0.5 * (a[0] + a[1] + (2.0 * h * h - d * d).max(0.0).sqrt());
                            if x > a[2] {
                                let s = a[0] + a[1] + a[2];
                                let q = a[0] * a[0] + a[1] * a[1] + a[2] * a[2] - h * h;
                                x = (s + (s * s - 3.0 * q).max(0.0).sqrt()) / 3.0;
                            }
                        }
                        u[p] = u[p].min(x);
                    }
                }
            }
        }
    }

    /// Locking and the diagonal ordering change nothing: the same distances as the plain
    /// sweeps (to rounding of the Godunov formula, which the two write differently) on a
    /// distorted field with sources scattered through the grid.
    #[test]
    fn locked_sweeps_match_plain_sweeps() {
        let dims = [23, 17, 29];
        let (nx, ny, nz) = (dims[0], dims[1], dims[2]);
        let len = (nx + 2) * (ny + 2) * (nz + 2);
        let mut u = vec![f64::INFINITY; len];
        let mut fixed = vec![true; len];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 1..=nz {
            for j in 1..=ny {
                for i in 1..=nx {
                    let p = i + (nx + 2) * (j + (ny + 2) * k);
                    let r = next();
                    if r < 0.02 {
                        u[p] = 0.3 * next();
                    } else {
                        fixed[p] = false;
                        u[p] = if r < 0.5 {
                            40.0 * next()
                        } else {
                            f64::INFINITY
                        };
                    }
                }
            }
        }
        let mut plain = u.clone();
        plain_sweeps(dims, 0.7, &mut plain, &fixed);
        sweep(dims, 0.7, &mut u, &fixed);
        let worst = u
            .iter()
            .zip(&plain)
            .filter(|(a, _)| a.is_finite())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        assert!(worst < 1e-12, "{worst}");
        assert!(
            u.iter()
                .zip(&plain)
                .all(|(a, b)| a.is_finite() == b.is_finite())
        );
    }

    #[test]
    fn no_surface_is_an_error() {
        let spec = GridSpec::cube(5, -1.0, 1.0).expect("spec");
        let mut g = Grid::from_fn(spec, |_| 1.0).expect("grid");
        assert!(matches!(g.reinitialise(), Err(Error::NoSurface)));
    }
}
