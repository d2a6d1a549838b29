//! Metrics of 3D sphere packings: an independent overlap and containment
//! checker ([`check_spheres`]), solid fractions over the container
//! ([`solid_fraction`]) and over a core region away from the walls
//! ([`core_solid_fraction`]), the radial profile of a cylindrical specimen
//! ([`radial_profile`]) and the geotechnical grading report
//! ([`grading_report`]).
//!
//! **Independence.** The checker shares no code with the packer: it bins
//! the centres into its own uniform cell grid (a counting sort into a flat
//! cell-major list), compares every pair in neighbouring cells (minimum
//! image across periodic faces) and measures containment itself: box
//! faces one by one, cylinder radially and axially, and closed meshes with
//! parry3d's `TriMesh` and its angle-weighted pseudo-normals, not with
//! levelset's `MeshDistance`, which the packer uses.
//!
//! **Exact volumes.** For boxes and cylinders the volume of a sphere inside
//! the core region is computed exactly: spheres wholly inside count whole,
//! spheres crossing the boundary are integrated over `z` of the exact area
//! of the slice circle inside the region's cross-section (closed form of a
//! circle ∩ rectangle, or of a circle ∩ disk lens). The `z` range is split
//! wherever the slice circle becomes tangent to an edge or passes a corner
//! (the only kinks of the integrand), every piece is mapped by the
//! smoothstep `t = a + (b − a)(3u² − 2u³)`, which removes the `(t − a)^½`
//! and `^{3/2}` endpoint behaviour, and integrated by 32-point
//! Gauss–Legendre, checked against 16 points and bisected if they differ
//! by more than `1e-12 r³` (so the relative accuracy is far better than
//! `1e-10`).
//!
//! **Determinism.** Parallel loops (rayon) reduce with associative and
//! commutative operations only: integer sums, and minima with ties broken
//! by the sphere indices; floating-point sums are taken over fixed chunks
//! and added in order. Results are identical for any thread count.

use std::f64::consts::PI;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{TriMesh as ParryMesh, TriMeshFlags};
use rayon::prelude::*;

use super::{Container, Sphere};
use crate::error::{Error, Result, finite, positive};
use packer_quadtree::{Grading, MassCurve};

// ---------------------------------------------------------------------------
// Input checks and small helpers
// ---------------------------------------------------------------------------

fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * PI * r * r * r
}

fn validate_spheres(spheres: &[Sphere]) -> Result<()> {
    for s in spheres {
        finite("sphere centre x", s.center.x)?;
        finite("sphere centre y", s.center.y)?;
        finite("sphere centre z", s.center.z)?;
        positive("sphere radius", s.radius)?;
    }
    Ok(())
}

fn kind(container: &Container) -> &'static str {
    match container {
        Container::Box { .. } => "box",
        Container::Cylinder { .. } => "cylinder",
        Container::Mesh(_) => "mesh",
    }
}

/// Fixed-chunk parallel sum of `f` over `items`, with the number of
/// positive terms; chunk sums are added in order (thread-count independent).
fn chunked_sum<T: Sync>(items: &[T], f: impl Fn(&T) -> f64 + Sync) -> (f64, usize) {
    let parts: Vec<(f64, usize)> = items
        .par_chunks(512)
        .map(|chunk| {
            let mut s = 0.0;
            let mut k = 0;
            for x in chunk {
                let v = f(x);
                if v > 0.0 {
                    s += v;
                    k += 1;
                }
            }
            (s, k)
        })
        .collect();
    parts
        .into_iter()
        .fold((0.0, 0), |(s, k), (a, b)| (s + a, k + b))
}

/// A minimum with its key; ties go to the smaller key, so merging is
/// associative and commutative (deterministic under any reduction tree).
#[derive(Debug, Clone, Copy)]
struct Worst {
    value: f64,
    key: (usize, usize),
}

impl Worst {
    const NONE: Self = Self {
        value: f64::INFINITY,
        key: (usize::MAX, usize::MAX),
    };

    fn offer(&mut self, value: f64, key: (usize, usize)) {
        if value
            .total_cmp(&self.value)
            .then(key.cmp(&self.key))
            .is_lt()
        {
            *self = Self { value, key };
        }
    }

    fn merge(mut self, other: Self) -> Self {
        self.offer(other.value, other.key);
        self
    }

    fn pair(&self) -> Option<(usize, usize)> {
        (self.key.0 != usize::MAX).then_some(self.key)
    }
}

// ---------------------------------------------------------------------------
// Walls, measured independently of `Container::clearance`
// ---------------------------------------------------------------------------

/// The checker's own description of the container walls.
enum Walls {
    Box {
        min: [f64; 3],
        max: [f64; 3],
        walled: [bool; 3],
    },
    Cylinder {
        cx: f64,
        cy: f64,
        z0: f64,
        radius: f64,
        height: f64,
    },
    Mesh(Box<ParryMesh>),
}

impl Walls {
    fn new(container: &Container) -> Result<Self> {
        container.validate()?;
        Ok(match container {
            Container::Box { min, max, periodic } => Self::Box {
                min: [min.x, min.y, min.z],
                max: [max.x, max.y, max.z],
                walled: [!periodic[0], !periodic[1], true],
            },
            Container::Cylinder {
                base,
                radius,
                height,
            } => Self::Cylinder {
                cx: base.x,
                cy: base.y,
                z0: base.z,
                radius: *radius,
                height: *height,
            },
            Container::Mesh(m) => {
                let mesh = m.mesh();
                let vertices = mesh
                    .vertices()
                    .iter()
                    .map(|v| parry3d_f64::math::Vector::new(v.x, v.y, v.z))
                    .collect();
                let index = |k: usize| {
                    u32::try_from(k).map_err(|_| Error::CheckerMesh {
                        reason: format!("vertex index {k} does not fit in u32"),
                    })
                };
                let mut triangles = Vec::with_capacity(mesh.triangles().len());
                for t in mesh.triangles() {
                    triangles.push([index(t[0])?, index(t[1])?, index(t[2])?]);
                }
                let pm = ParryMesh::with_flags(vertices, triangles, TriMeshFlags::ORIENTED)
                    .map_err(|e| Error::CheckerMesh {
                        reason: e.to_string(),
                    })?;
                Self::Mesh(Box::new(pm))
            }
        })
    }

    /// Containment distance of a point: a sphere of radius `r` at `p` is
    /// inside exactly when `clearance(p) ≥ r`. Box: the smallest signed
    /// distance to a walled face plane; cylinder: the smaller of the radial
    /// (`R − ρ`) and axial distances; mesh: parry's exact signed distance
    /// (positive inside, sign from the pseudo-normals).
    fn clearance(&self, p: [f64; 3]) -> f64 {
        match self {
            Self::Box { min, max, walled } => {
                let mut c = f64::INFINITY;
                for k in 0..3 {
                    if walled[k] {
                        c = c.min(p[k] - min[k]).min(max[k] - p[k]);
                    }
                }
                c
            }
            Self::Cylinder {
                cx,
                cy,
                z0,
                radius,
                height,
            } => {
                let rho = (p[0] - cx).hypot(p[1] - cy);
                (radius - rho).min(p[2] - z0).min(z0 + height - p[2])
            }
            Self::Mesh(mesh) => {
                let q = parry3d_f64::math::Vector::new(p[0], p[1], p[2]);
                let proj = mesh.project_local_point(q, true);
                let d = (proj.point - q).length();
                if proj.is_inside { d } else { -d }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The checker's own uniform cell grid
// ---------------------------------------------------------------------------

/// Axes of a uniform cell grid: `n[k]` cells of size `cell[k]` from
/// `origin[k]`; periodic axes wrap with period `len[k] = n[k] · cell[k]`.
struct Axes {
    origin: [f64; 3],
    cell: [f64; 3],
    len: [f64; 3],
    n: [usize; 3],
    periodic: [bool; 3],
}

impl Axes {
    /// Cells of size at least `h` over `[lo, hi]`; the size grows until
    /// there are at most `max_cells` cells. Periodic axes get a whole
    /// number of cells per period `hi − lo`.
    fn new(lo: [f64; 3], hi: [f64; 3], periodic: [bool; 3], h: f64, max_cells: usize) -> Self {
        let mut h = h;
        loop {
            let mut n = [1usize; 3];
            let mut cell = [h; 3];
            let mut len = [0.0; 3];
            for k in 0..3 {
                let ext = (hi[k] - lo[k]).max(0.0);
                if periodic[k] {
                    n[k] = ((ext / h).floor() as usize).max(1);
                    cell[k] = ext / n[k] as f64;
                    len[k] = ext;
                } else {
                    n[k] = (ext / h).floor() as usize + 1;
                }
            }
            let total = n[0].saturating_mul(n[1]).saturating_mul(n[2]);
            if total <= max_cells {
                return Self {
                    origin: lo,
                    cell,
                    len,
                    n,
                    periodic,
                };
            }
            h *= 1.5;
        }
    }

    fn total(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    fn coord_axis(&self, k: usize, x: f64) -> usize {
        let mut t = x - self.origin[k];
        if self.periodic[k] {
            t = t.rem_euclid(self.len[k]);
        }
        let c = (t / self.cell[k]).floor();
        if c <= 0.0 {
            0
        } else {
            (c as usize).min(self.n[k] - 1)
        }
    }

    fn coord(&self, p: [f64; 3]) -> [usize; 3] {
        [
            self.coord_axis(0, p[0]),
            self.coord_axis(1, p[1]),
            self.coord_axis(2, p[2]),
        ]
    }

    fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    /// Distinct neighbour cells of `c` along axis `k` (itself included).
    fn neighbours(&self, k: usize, c: usize) -> ([usize; 3], usize) {
        let n = self.n[k];
        if self.periodic[k] {
            match n {
                1 => ([0, 0, 0], 1),
                2 => ([0, 1, 0], 2),
                _ => ([(c + n - 1) % n, c, (c + 1) % n], 3),
            }
        } else {
            let lo = c.saturating_sub(1);
            let hi = (c + 1).min(n - 1);
            let mut out = [0; 3];
            let mut m = 0;
            for v in lo..=hi {
                out[m] = v;
                m += 1;
            }
            (out, m)
        }
    }
}

/// Items bucketed by cell: the items of cell `c` are
/// `items[start[c]..start[c + 1]]`, in ascending order.
struct Buckets {
    start: Vec<usize>,
    items: Vec<usize>,
}

impl Buckets {
    /// Counting sort of item `i` into cell `keys[i]` (stable).
    fn from_keys(ncells: usize, keys: &[usize]) -> Self {
        let mut start = vec![0usize; ncells + 1];
        for &k in keys {
            start[k + 1] += 1;
        }
        for c in 0..ncells {
            start[c + 1] += start[c];
        }
        let mut next = start.clone();
        let mut items = vec![0usize; keys.len()];
        for (i, &k) in keys.iter().enumerate() {
            items[next[k]] = i;
            next[k] += 1;
        }
        Self { start, items }
    }

    /// Item `i` in every cell of the box `ranges[i] = (lo, hi)` (inclusive
    /// cell coordinates).
    fn from_ranges(axes: &Axes, ranges: &[([usize; 3], [usize; 3])]) -> Self {
        let ncells = axes.total();
        let mut start = vec![0usize; ncells + 1];
        let each = |r: &([usize; 3], [usize; 3]), f: &mut dyn FnMut(usize)| {
            for z in r.0[2]..=r.1[2] {
                for y in r.0[1]..=r.1[1] {
                    for x in r.0[0]..=r.1[0] {
                        f(axes.flat([x, y, z]));
                    }
                }
            }
        };
        for r in ranges {
            each(r, &mut |c| start[c + 1] += 1);
        }
        for c in 0..ncells {
            start[c + 1] += start[c];
        }
        let mut next = start.clone();
        let mut items = vec![0usize; start[ncells]];
        for (i, r) in ranges.iter().enumerate() {
            each(r, &mut |c| {
                items[next[c]] = i;
                next[c] += 1;
            });
        }
        Self { start, items }
    }

    fn cell(&self, c: usize) -> std::ops::Range<usize> {
        self.start[c]..self.start[c + 1]
    }
}

// ---------------------------------------------------------------------------
// Overlap checker
// ---------------------------------------------------------------------------

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
fn min_image(d: f64, len: f64, periodic: bool) -> f64 {
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

// ---------------------------------------------------------------------------
// Exact sphere ∩ region volumes
// ---------------------------------------------------------------------------

/// Gauss–Legendre nodes and weights on `[0, 1]` (Newton on `P_n`).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    let nf = n as f64;
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            dp = nf * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((0.5 * (1.0 + x), 0.5 * w));
    }
    out
}

fn gl16() -> &'static [(f64, f64)] {
    static NODES: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    NODES.get_or_init(|| gauss_legendre(16))
}

fn gl32() -> &'static [(f64, f64)] {
    static NODES: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    NODES.get_or_init(|| gauss_legendre(32))
}

/// `∫_a^b f` by smoothstep-mapped 32-point Gauss–Legendre, accepted when
/// the 16-point rule agrees to `tol`, else bisected (`depth` levels).
fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32) -> f64 {
    if b <= a {
        return 0.0;
    }
    let w = b - a;
    let rule = |nodes: &[(f64, f64)]| {
        nodes
            .iter()
            .map(|&(u, wt)| {
                let s = u * u * (3.0 - 2.0 * u);
                wt * 6.0 * u * (1.0 - u) * f(a + w * s)
            })
            .sum::<f64>()
            * w
    };
    let fine = rule(gl32());
    let coarse = rule(gl16());
    if (fine - coarse).abs() <= tol || depth == 0 {
        return fine;
    }
    let m = 0.5 * (a + b);
    integrate(f, a, m, 0.5 * tol, depth - 1) + integrate(f, m, b, 0.5 * tol, depth - 1)
}

/// `π ∫_{ta}^{tb} (r² − t²) dt`: the sphere between two planes, as a
/// difference of caps on the side of the nearer pole (no cancellation for
/// thin slices near a pole).
fn slab(r: f64, ta: f64, tb: f64) -> f64 {
    if tb <= ta {
        return 0.0;
    }
    if ta + tb > 0.0 {
        // Volume above t: a cap of height r − t.
        let above = |t: f64| PI * (r - t) * (r - t) * (2.0 * r + t) / 3.0;
        above(ta) - above(tb)
    } else {
        let below = |t: f64| PI * (r + t) * (r + t) * (2.0 * r - t) / 3.0;
        below(tb) - below(ta)
    }
}

/// `∫_{ta}^{tb} area(ρ(t)) dt` with `ρ(t) = √(r² − t²)`, split where `ρ`
/// equals one of the `kinks` (slice circle tangent to an edge, through a
/// corner).
fn slice_integral(r: f64, ta: f64, tb: f64, kinks: &[f64], area: &dyn Fn(f64) -> f64) -> f64 {
    if tb <= ta {
        return 0.0;
    }
    let mut ts = Vec::with_capacity(2 * kinks.len() + 2);
    ts.push(ta);
    ts.push(tb);
    for &k in kinks {
        if k.is_finite() && k >= 0.0 && k < r {
            let t = ((r - k) * (r + k)).sqrt();
            for t in [-t, t] {
                if t > ta && t < tb {
                    ts.push(t);
                }
            }
        }
    }
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    let f = |t: f64| area(((r - t) * (r + t)).max(0.0).sqrt());
    let tol = 1e-12 * r * r * r;
    ts.windows(2)
        .map(|w| integrate(&f, w[0], w[1], tol, 16))
        .sum()
}

/// Area of the disk of radius `rho` about the origin inside the quadrant
/// `{x ≤ a, y ≤ b}` (exact; `a`, `b` may be infinite).
fn quadrant_area(rho: f64, a: f64, b: f64) -> f64 {
    if rho <= 0.0 || a <= -rho || b <= -rho {
        return 0.0;
    }
    // G(x) = ∫_0^x √(ρ² − u²) du, in the well-conditioned atan2 form.
    let g = |x: f64| {
        let x = x.clamp(-rho, rho);
        let s = ((rho - x) * (rho + x)).max(0.0).sqrt();
        0.5 * (x * s + rho * rho * x.atan2(s))
    };
    let amax = a.min(rho);
    if b >= rho {
        return 2.0 * (g(amax) - g(-rho));
    }
    // |x| < w: the chord below y = b is [−s, b]; |x| > w: [−s, s] if b ≥ 0
    // (b above the circle there), empty if b < 0.
    let w = ((rho - b) * (rho + b)).max(0.0).sqrt();
    let mut total = 0.0;
    if b >= 0.0 {
        let hi = amax.min(-w);
        if hi > -rho {
            total += 2.0 * (g(hi) - g(-rho));
        }
        if amax > w {
            total += 2.0 * (g(amax) - g(w));
        }
    }
    let hi = amax.min(w);
    if hi > -w {
        total += b * (hi + w) + g(hi) - g(-w);
    }
    total
}

/// Area of the disk of radius `rho` about the origin inside the rectangle
/// `[x0, x1] × [y0, y1]` (bounds may be infinite).
fn rect_area(rho: f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let q = |a: f64, b: f64| quadrant_area(rho, a, b);
    (q(x1, y1) - q(x0, y1) - q(x1, y0) + q(x0, y0)).clamp(0.0, PI * rho * rho)
}

/// Area of the intersection of a disk of radius `rho` and a disk of radius
/// `big` whose centres are `s` apart (the lens; atan2 form).
fn lens_area(rho: f64, s: f64, big: f64) -> f64 {
    if rho <= 0.0 || big <= 0.0 || s >= rho + big {
        return 0.0;
    }
    if s <= (big - rho).abs() {
        let m = rho.min(big);
        return PI * m * m;
    }
    let delta = ((-s + rho + big) * (s + rho - big) * (s - rho + big) * (s + rho + big))
        .max(0.0)
        .sqrt();
    let alpha = delta.atan2(s * s + rho * rho - big * big);
    let beta = delta.atan2(s * s + big * big - rho * rho);
    rho * rho * alpha + big * big * beta - 0.5 * delta
}

/// Exact volume of a sphere inside the box `[lo, hi]` (bounds may be ±∞).
fn sphere_box_volume(s: &Sphere, lo: [f64; 3], hi: [f64; 3]) -> f64 {
    let c = [s.center.x, s.center.y, s.center.z];
    let r = s.radius;
    for k in 0..3 {
        if c[k] + r <= lo[k] || c[k] - r >= hi[k] {
            return 0.0;
        }
    }
    let ta = (lo[2] - c[2]).max(-r);
    let tb = (hi[2] - c[2]).min(r);
    if (0..2).all(|k| c[k] - r >= lo[k] && c[k] + r <= hi[k]) {
        return slab(r, ta, tb);
    }
    let (x0, x1, y0, y1) = (lo[0] - c[0], hi[0] - c[0], lo[1] - c[1], hi[1] - c[1]);
    let mut kinks = Vec::with_capacity(8);
    for e in [x0, x1, y0, y1] {
        if e.is_finite() {
            kinks.push(e.abs());
        }
    }
    for x in [x0, x1] {
        for y in [y0, y1] {
            if x.is_finite() && y.is_finite() {
                kinks.push(x.hypot(y));
            }
        }
    }
    slice_integral(r, ta, tb, &kinks, &|rho| rect_area(rho, x0, x1, y0, y1))
}

/// Exact volume of a sphere inside the vertical cylinder of radius `big`
/// about `(cx, cy)` between `z0` and `z1`.
fn sphere_cylinder_volume(s: &Sphere, cx: f64, cy: f64, big: f64, z0: f64, z1: f64) -> f64 {
    let r = s.radius;
    let d = (s.center.x - cx).hypot(s.center.y - cy);
    if d - r >= big || s.center.z + r <= z0 || s.center.z - r >= z1 {
        return 0.0;
    }
    let ta = (z0 - s.center.z).max(-r);
    let tb = (z1 - s.center.z).min(r);
    if d + r <= big {
        return slab(r, ta, tb);
    }
    let kinks = [(big - d).abs(), big + d];
    slice_integral(r, ta, tb, &kinks, &|rho| lens_area(rho, d, big))
}

// ---------------------------------------------------------------------------
// Solid fractions
// ---------------------------------------------------------------------------

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

// ---------------------------------------------------------------------------
// Radial profile
// ---------------------------------------------------------------------------

/// One annulus of a [`radial_profile`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadialBin {
    /// Inner radius (distance from the axis).
    pub r_inner: f64,
    /// Outer radius.
    pub r_outer: f64,
    /// Solid volume in the annular shell over the shell volume.
    pub solid_fraction: f64,
}

/// Radial solid-fraction profile of a cylindrical specimen: `n_bins`
/// equal-width annuli from the axis to the wall, over the full height. The
/// solid volume of each sphere in each shell is exact: the difference of
/// its volumes inside the two bounding cylinders, each integrated over `z`
/// of the circle ∩ disk lens area (module docs). Porosity is
/// `1 − solid_fraction`.
///
/// # Errors
/// [`Error::WrongContainer`] for a non-cylinder; [`Error::Parameter`] for
/// `n_bins = 0`; container validation errors; [`Error::NonFinite`] /
/// [`Error::NonPositive`] for a bad sphere.
pub fn radial_profile(
    container: &Container,
    spheres: &[Sphere],
    n_bins: usize,
) -> Result<Vec<RadialBin>> {
    container.validate()?;
    let Container::Cylinder {
        base,
        radius,
        height,
    } = container
    else {
        return Err(Error::WrongContainer {
            what: "radial profile",
            expected: "cylinder",
            got: kind(container),
        });
    };
    if n_bins == 0 {
        return Err(Error::Parameter {
            what: "n_bins",
            value: 0.0,
            range: "[1, inf)",
        });
    }
    validate_spheres(spheres)?;
    let (radius, height) = (*radius, *height);
    let edge = |k: usize| {
        if k == n_bins {
            radius
        } else {
            radius * k as f64 / n_bins as f64
        }
    };
    let (z0, z1) = (base.z, base.z + height);
    let parts: Vec<Vec<f64>> = spheres
        .par_chunks(256)
        .map(|chunk| {
            let mut acc = vec![0.0; n_bins];
            for s in chunk {
                let r = s.radius;
                let d = (s.center.x - base.x).hypot(s.center.y - base.y);
                let ta = (z0 - s.center.z).max(-r);
                let tb = (z1 - s.center.z).min(r);
                if tb <= ta || d - r >= radius {
                    continue;
                }
                let full = slab(r, ta, tb);
                // Volume inside the cylinder of radius edge(k).
                let inside = |k: usize| {
                    let big = edge(k);
                    if k == 0 || d - r >= big {
                        0.0
                    } else if d + r <= big {
                        full
                    } else {
                        let kinks = [(big - d).abs(), big + d];
                        slice_integral(r, ta, tb, &kinks, &|rho| lens_area(rho, d, big))
                    }
                };
                // The last edge surely below the sphere (one more for rounding).
                let first = (((d - r).max(0.0) / radius * n_bins as f64).floor() as usize)
                    .min(n_bins - 1)
                    .saturating_sub(1);
                let mut below = inside(first);
                for (k, slot) in acc.iter_mut().enumerate().skip(first) {
                    let above = inside(k + 1);
                    *slot += above - below;
                    if above >= full {
                        break;
                    }
                    below = above;
                }
            }
            acc
        })
        .collect();
    let mut solid = vec![0.0; n_bins];
    for p in parts {
        for (s, v) in solid.iter_mut().zip(p) {
            *s += v;
        }
    }
    Ok((0..n_bins)
        .map(|k| {
            let (ri, ro) = (edge(k), edge(k + 1));
            RadialBin {
                r_inner: ri,
                r_outer: ro,
                solid_fraction: solid[k] / (PI * (ro * ro - ri * ri) * height),
            }
        })
        .collect())
}

// ---------------------------------------------------------------------------
// Grading report
// ---------------------------------------------------------------------------

/// Characteristic sizes and coefficients of one grading curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradingStats {
    /// Size at which 10 % of the mass passes.
    pub d10: f64,
    /// Size at which 30 % of the mass passes.
    pub d30: f64,
    /// Size at which 50 % of the mass passes.
    pub d50: f64,
    /// Size at which 60 % of the mass passes.
    pub d60: f64,
    /// Uniformity coefficient `Cu = D60 / D10` (by mass).
    pub cu: f64,
    /// Curvature coefficient `Cc = D30² / (D10 · D60)` (by mass).
    pub cc: f64,
    /// Size at which 10 % of the particles (by number) pass.
    pub d10_number: f64,
    /// Size at which 30 % of the particles pass.
    pub d30_number: f64,
    /// Size at which 50 % of the particles pass.
    pub d50_number: f64,
    /// Size at which 60 % of the particles pass.
    pub d60_number: f64,
}

impl GradingStats {
    fn new(mass: impl Fn(f64) -> f64, number: impl Fn(f64) -> f64) -> Self {
        let (d10, d30, d50, d60) = (mass(0.1), mass(0.3), mass(0.5), mass(0.6));
        Self {
            d10,
            d30,
            d50,
            d60,
            cu: d60 / d10,
            cc: d30 * d30 / (d10 * d60),
            d10_number: number(0.1),
            d30_number: number(0.3),
            d50_number: number(0.5),
            d60_number: number(0.6),
        }
    }
}

/// Requested against packed grading, by mass (geotechnical convention).
#[derive(Debug, Clone, PartialEq)]
pub struct GradingReport {
    /// Number of spheres.
    pub n_spheres: usize,
    /// Statistics of the requested distribution.
    pub requested: GradingStats,
    /// Statistics of the packed sample.
    pub packed: GradingStats,
    /// 201 log-spaced sizes (diameters) spanning both curves.
    pub sizes: Vec<f64>,
    /// Requested mass fraction passing each of [`GradingReport::sizes`].
    pub requested_passing: Vec<f64>,
    /// Packed mass fraction passing each size.
    pub packed_passing: Vec<f64>,
    /// Largest absolute difference of the packed and requested mass
    /// passing fractions (0–1) over a fine set of sizes: both sides of
    /// every packed diameter and 1024 log-spaced sizes.
    pub max_deviation: f64,
    /// Size at which [`GradingReport::max_deviation`] occurs.
    pub max_deviation_at: f64,
}

/// Grading report of a packing: the cumulative passing curves **by mass**
/// (volume ∝ `d³`) of the requested distribution and of the packed sample,
/// their `D10/D30/D50/D60`, `Cu = D60/D10` and `Cc = D30²/(D10·D60)` (by
/// mass; number-based `D`s too) and the largest deviation of the packed
/// mass curve from the requested one.
///
/// [`Grading`] curves are **number** distributions, as the packer samples
/// them (one diameter per particle). The requested mass curve is
/// `M(F(d))`, `M(u) = ∫₀ᵘ D(v)³ dv / ∫₀¹ D(v)³ dv` with `D` the inverse
/// number CDF — the integral of `d³ × number density` after the
/// substitution `d = D(v)`, which also covers constant sizes (atoms);
/// it is tabulated by Gauss–Legendre on `2¹⁴` cells of `u`. The packed
/// curve is the step function `Σ_{d_i ≤ d} d_i³ / Σ d_i³`; its `D_x` is the
/// smallest packed diameter at which at least the fraction `x` passes.
///
/// # Errors
/// Grading validation errors; [`Error::Empty`] without spheres;
/// [`Error::NonFinite`] / [`Error::NonPositive`] for a bad sphere.
pub fn grading_report(requested: &Grading, spheres: &[Sphere]) -> Result<GradingReport> {
    requested.validate()?;
    if spheres.is_empty() {
        return Err(Error::Empty { what: "spheres" });
    }
    validate_spheres(spheres)?;
    let n = spheres.len();
    let mut d: Vec<f64> = spheres.iter().map(|s| 2.0 * s.radius).collect();
    d.sort_by(f64::total_cmp);
    let mut cum = Vec::with_capacity(n);
    let mut acc = 0.0;
    for &x in &d {
        acc += x * x * x;
        cum.push(acc);
    }
    for c in &mut cum {
        *c /= acc;
    }
    // Packed passing (mass) at size `s`: spheres with d ≤ s.
    let packed_at = |s: f64| {
        let k = d.partition_point(|&x| x <= s);
        if k == 0 { 0.0 } else { cum[k - 1] }
    };
    let curve = MassCurve::new(requested);
    let requested_stats = GradingStats::new(|x| curve.quantile(x), |x| requested.diameter_at(x));
    let packed_stats = GradingStats::new(
        |x| {
            let k = cum.partition_point(|&c| c < x).min(n - 1);
            d[k]
        },
        |x| {
            let k = ((x * n as f64).ceil() as usize).clamp(1, n) - 1;
            d[k]
        },
    );

    let lo = requested.d_min().min(d[0]) * 0.999;
    let hi = requested.d_max().max(d[n - 1]) * 1.001;
    let log_size = |k: usize, m: usize| lo * (hi / lo).powf(k as f64 / m as f64);

    // Deviation at both sides of every distinct packed diameter (the jumps
    // of the step function) and on a fine log grid.
    let best = |a: (f64, f64), b: (f64, f64)| {
        if b.0.total_cmp(&a.0).then(a.1.total_cmp(&b.1)).is_gt() {
            b
        } else {
            a
        }
    };
    let at_jumps = (0..n)
        .into_par_iter()
        .with_min_len(1024)
        .filter(|&k| k + 1 == n || d[k + 1] > d[k])
        .map(|k| {
            let first = d.partition_point(|&x| x < d[k]);
            let left = if first == 0 { 0.0 } else { cum[first - 1] };
            let dl = (left - curve.passing(d[k] * (1.0 - 1e-12))).abs();
            let dr = (cum[k] - curve.passing(d[k])).abs();
            (dl.max(dr), d[k])
        })
        .reduce(|| (0.0, f64::INFINITY), best);
    let on_grid = (0..=1024)
        .map(|k| {
            let s = log_size(k, 1024);
            ((packed_at(s) - curve.passing(s)).abs(), s)
        })
        .fold((0.0, f64::INFINITY), best);
    let (max_deviation, max_deviation_at) = best(at_jumps, on_grid);

    let sizes: Vec<f64> = (0..=200).map(|k| log_size(k, 200)).collect();
    Ok(GradingReport {
        n_spheres: n,
        requested: requested_stats,
        packed: packed_stats,
        requested_passing: sizes.iter().map(|&s| curve.passing(s)).collect(),
        packed_passing: sizes.iter().map(|&s| packed_at(s)).collect(),
        sizes,
        max_deviation,
        max_deviation_at,
    })
}

#[cfg(test)]
mod tests;
