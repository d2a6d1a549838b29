//! The overlap and containment checker: every pair in neighbouring cells
//! (minimum image across periodic faces) and every sphere against the
//! walls, in parallel with deterministic reductions.

use rayon::prelude::*;

use super::grid::{Axes, Buckets};
use super::walls::Walls;
use super::{Worst, validate_spheres};
use crate::error::{Error, Result};
use crate::{Container, Sphere};

/// Result of [`check_spheres`]. Gaps are `|c_i − c_j| − r_i − r_j` for
/// pairs (nearest periodic image) and `clearance − r` for walls; the
/// normalised gaps divide by the smaller diameter of the pair, or by the
/// sphere's diameter for walls. Negative means overlap / protrusion.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereReport {
    /// Number of spheres checked.
    pub n_spheres: usize,
    /// Pairs are examined when their gap is below this reach:
    /// `max(contact_tol, 1/4) · d_max`. Every such pair is found.
    pub pair_reach: f64,
    /// Smallest pair gap (exact minimum over all pairs when below
    /// [`SphereReport::pair_reach`], else `+∞`).
    pub worst_pair_gap: f64,
    /// The pair `(i, j)`, `i < j`, of the smallest gap (smallest indices
    /// on ties); `None` when no pair is within reach.
    pub worst_pair: Option<(usize, usize)>,
    /// Smallest normalised pair gap `gap / min(d_i, d_j)` (`+∞` if none).
    pub worst_normalised_gap: f64,
    /// The pair of the smallest normalised gap.
    pub worst_normalised_pair: Option<(usize, usize)>,
    /// Smallest wall gap `clearance − r` (`+∞` without spheres).
    pub worst_wall_gap: f64,
    /// The sphere of the smallest wall gap.
    pub worst_wall_sphere: Option<usize>,
    /// Smallest normalised wall gap `(clearance − r) / d`.
    pub worst_normalised_wall_gap: f64,
    /// Particle–particle contacts: pairs with `|gap| ≤ contact_tol · d`,
    /// `d` the smaller diameter of the pair.
    pub pair_contacts: usize,
    /// Spheres touching a wall: `|clearance − r| ≤ contact_tol · d` (a
    /// sphere in a corner counts once).
    pub wall_contacts: usize,
    /// Mean particle–particle coordination number `2 · pair_contacts / n`
    /// (0 without spheres).
    pub coordination_number: f64,
}

impl SphereReport {
    /// No pair overlaps and no sphere protrudes by more than `tol` times
    /// the relevant diameter (`worst gap ≥ −tol · d` for pairs and walls).
    pub fn is_clean(&self, tol: f64) -> bool {
        self.worst_normalised_gap >= -tol && self.worst_normalised_wall_gap >= -tol
    }
}

#[derive(Debug, Clone, Copy)]
struct PairAcc {
    worst: Worst,
    worst_norm: Worst,
    contacts: usize,
}

impl PairAcc {
    const EMPTY: Self = Self {
        worst: Worst::NONE,
        worst_norm: Worst::NONE,
        contacts: 0,
    };

    fn merge(self, o: Self) -> Self {
        Self {
            worst: self.worst.merge(o.worst),
            worst_norm: self.worst_norm.merge(o.worst_norm),
            contacts: self.contacts + o.contacts,
        }
    }
}

/// Minimum-image component of a displacement (the rounding only when
/// `|d|` exceeds half the period; at exactly half either sign has the
/// same length).
#[inline]
pub(super) fn min_image(d: f64, len: f64, periodic: bool) -> f64 {
    if periodic && d.abs() > 0.5 * len {
        d - len * (d / len).round()
    } else {
        d
    }
}

/// Independent overlap and containment check of a 3D packing.
///
/// Every pair whose gap is below the reach `max(contact_tol, 1/4) · d_max`
/// is compared (centres bucketed by a counting sort into a uniform grid of
/// cell `d_max + reach`, the 27 neighbouring cells scanned; across a
/// periodic x/y face the nearest image is taken, with the box lengths), and
/// every sphere is tested against the walls (box faces, cylinder radius and
/// ends, mesh via parry3d; see the module docs). Runs in parallel over the
/// spheres in cell order; the report does not depend on the thread count.
///
/// # Errors
/// Container validation errors; [`Error::NonFinite`] / [`Error::NonPositive`]
/// for a bad sphere; [`Error::Parameter`] for `contact_tol` outside
/// `[0, 1]` or a periodic length shorter than the largest diameter (a
/// sphere would overlap its own image); [`Error::CheckerMesh`] if parry
/// rejects the container mesh.
pub fn check_spheres(
    container: &Container,
    spheres: &[Sphere],
    contact_tol: f64,
) -> Result<SphereReport> {
    let walls = Walls::new(container)?;
    if !(contact_tol.is_finite() && (0.0..=1.0).contains(&contact_tol)) {
        return Err(Error::Parameter {
            what: "contact_tol",
            value: contact_tol,
            range: "[0, 1]",
        });
    }
    validate_spheres(spheres)?;
    let n = spheres.len();
    let rmax = spheres.iter().map(|s| s.radius).fold(0.0, f64::max);
    let reach = 2.0 * rmax * contact_tol.max(0.25);
    let periodic = container.periodic();
    let (bmin, bmax) = container.bbox();
    for k in 0..2 {
        if periodic[k] && n > 0 {
            let ratio = (bmax[k] - bmin[k]) / (2.0 * rmax);
            if ratio < 1.0 {
                return Err(Error::Parameter {
                    what: "periodic box length / largest diameter",
                    value: ratio,
                    range: "[1, inf)",
                });
            }
        }
    }

    let pairs = if n >= 2 {
        scan_pairs(
            spheres,
            [periodic[0], periodic[1], false],
            [bmin.x, bmin.y, bmin.z],
            [bmax.x, bmax.y, bmax.z],
            rmax,
            reach,
            contact_tol,
        )
    } else {
        PairAcc::EMPTY
    };

    let (wall, wall_norm, wall_contacts) = spheres
        .par_iter()
        .enumerate()
        .with_min_len(1024)
        .fold(
            || (Worst::NONE, Worst::NONE, 0usize),
            |(mut w, mut wn, mut k), (i, s)| {
                let p = [s.center.x, s.center.y, s.center.z];
                let gap = walls.clearance(p) - s.radius;
                let d = 2.0 * s.radius;
                w.offer(gap, (i, 0));
                wn.offer(gap / d, (i, 0));
                if gap.abs() <= contact_tol * d {
                    k += 1;
                }
                (w, wn, k)
            },
        )
        .reduce(
            || (Worst::NONE, Worst::NONE, 0usize),
            |a, b| (a.0.merge(b.0), a.1.merge(b.1), a.2 + b.2),
        );

    Ok(SphereReport {
        n_spheres: n,
        pair_reach: reach,
        worst_pair_gap: pairs.worst.value,
        worst_pair: pairs.worst.pair(),
        worst_normalised_gap: pairs.worst_norm.value,
        worst_normalised_pair: pairs.worst_norm.pair(),
        worst_wall_gap: wall.value,
        worst_wall_sphere: wall.pair().map(|p| p.0),
        worst_normalised_wall_gap: wall_norm.value,
        pair_contacts: pairs.contacts,
        wall_contacts,
        coordination_number: if n == 0 {
            0.0
        } else {
            2.0 * pairs.contacts as f64 / n as f64
        },
    })
}

/// The pair scan of [`check_spheres`] (at least two spheres).
fn scan_pairs(
    spheres: &[Sphere],
    periodic: [bool; 3],
    bmin: [f64; 3],
    bmax: [f64; 3],
    rmax: f64,
    reach: f64,
    contact_tol: f64,
) -> PairAcc {
    let n = spheres.len();
    // Every pair with gap ≤ reach has centre distance ≤ 2 r_max + reach;
    // pairs in non-neighbouring cells are at least one cell apart.
    let cutoff = (2.0 * rmax + reach) * (1.0 + 1e-9);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for s in spheres {
        for k in 0..3 {
            lo[k] = lo[k].min(s.center[k]);
            hi[k] = hi[k].max(s.center[k]);
        }
    }
    for k in 0..2 {
        if periodic[k] {
            lo[k] = bmin[k];
            hi[k] = bmax[k];
        }
    }
    let axes = Axes::new(lo, hi, periodic, cutoff, (2 * n).max(64));
    let keys: Vec<usize> = spheres
        .par_iter()
        .with_min_len(4096)
        .map(|s| axes.flat(axes.coord([s.center.x, s.center.y, s.center.z])))
        .collect();
    let buckets = Buckets::from_keys(axes.total(), &keys);
    // Cell-ordered copies for locality.
    let pos: Vec<[f64; 4]> = buckets
        .items
        .iter()
        .map(|&i| {
            let s = &spheres[i];
            [s.center.x, s.center.y, s.center.z, s.radius]
        })
        .collect();
    let len = axes.len;
    let (nx, ny) = (axes.n[0], axes.n[1]);
    (0..n)
        .into_par_iter()
        .with_min_len(2048)
        .fold(
            || PairAcc::EMPTY,
            |mut acc, a| {
                let i = buckets.items[a];
                let [xi, yi, zi, ri] = pos[a];
                let key = keys[i];
                let c = [key % nx, (key / nx) % ny, key / (nx * ny)];
                let (bx, mx) = axes.neighbours(0, c[0]);
                let (by, my) = axes.neighbours(1, c[1]);
                let (bz, mz) = axes.neighbours(2, c[2]);
                for &z in &bz[..mz] {
                    for &y in &by[..my] {
                        for &x in &bx[..mx] {
                            for b in buckets.cell(axes.flat([x, y, z])) {
                                let j = buckets.items[b];
                                if j <= i {
                                    continue;
                                }
                                let [xj, yj, zj, rj] = pos[b];
                                let dx = min_image(xj - xi, len[0], periodic[0]);
                                let dy = min_image(yj - yi, len[1], periodic[1]);
                                let dz = zj - zi;
                                let gap = (dx * dx + dy * dy + dz * dz).sqrt() - ri - rj;
                                let d = 2.0 * ri.min(rj);
                                if gap < reach {
                                    acc.worst.offer(gap, (i, j));
                                    acc.worst_norm.offer(gap / d, (i, j));
                                }
                                if gap.abs() <= contact_tol * d {
                                    acc.contacts += 1;
                                }
                            }
                        }
                    }
                }
                acc
            },
        )
        .reduce(|| PairAcc::EMPTY, PairAcc::merge)
}
