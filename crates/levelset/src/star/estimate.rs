//! The band estimates of a star build from the radial distance `g`: the second-order
//! closest-distance estimate, and the seed's first-order interface estimate where the
//! expansion is not trusted next to the surface ([`BandSlab`]).

use nalgebra::{Point3, Vector3};

use super::BAND_CELLS;
use crate::grid::GridSpec;

/// The nine grid rows around a row of nodes: `rows[z][y]` for the z-slabs k − 1, k, k + 1
/// and the rows j − 1, j, j + 1, each exactly `nx` long, so that a stencil at column
/// `1 ≤ i < nx − 1` needs no bounds checks beyond the rows'.
type Rows<'a> = [[&'a [f64]; 3]; 3];

/// The nine rows of [`Rows`] around row `j` (in-slab offset `row = nx·j`) of the slabs
/// `lo`, `mid`, `up`.
#[inline]
fn rows<'a>([lo, mid, up]: [&'a [f64]; 3], row: usize, nx: usize) -> Rows<'a> {
    let three = |s: &'a [f64]| {
        [
            &s[row - nx..row],
            &s[row..row + nx],
            &s[row + nx..row + 2 * nx],
        ]
    };
    [three(lo), three(mid), three(up)]
}

/// Second-order distance estimate from the radial distance `g` at the interior node in
/// column `i` of the middle row of `r` (see [`Rows`]), or NaN if the stencil holds a far
/// marker, the first-order estimate is not below `√cut2`, or a guard fails.
///
/// Along the surface normal through the node, `g(t) = a·t + b·t²/2 + O(t³)` with
/// `b = nᵀ(∇²g)n`; matching `g` and `|∇g|` at the node gives
/// `d = 2g / (|∇g| + √(|∇g|² − 2bg))`, exact for planes and spheres about the centre and
/// third-order otherwise (the first-order `g/|∇g|` of the seed errs by `b·d²/2`).
/// Derivatives are central differences.
#[inline]
fn second_order_distance(r: &Rows<'_>, i: usize, h: f64, cut2: f64) -> f64 {
    let [lo, mid, up] = r;
    let v = mid[1][i];
    let (xl, xr) = (mid[1][i - 1], mid[1][i + 1]);
    let (yl, yr) = (mid[0][i], mid[2][i]);
    let (zl, zr) = (lo[1][i], up[1][i]);
    let inv2h = 0.5 / h;
    let gx = (xr - xl) * inv2h;
    let gy = (yr - yl) * inv2h;
    let gz = (zr - zl) * inv2h;
    let gp2 = gx * gx + gy * gy + gz * gz;
    // First-order screen: far nodes (and far markers, which give NaN or ∞) are skipped, and
    // so are nodes where the radial field is steeper than 2 (the surface more than 60° from
    // the radial direction, or a node near the centre), where the expansion is not trusted.
    if !(gp2.is_finite() && gp2 <= 4.0 && v * v < cut2 * gp2) {
        return f64::NAN;
    }
    let ih2 = 1.0 / (h * h);
    let hxx = (xl - 2.0 * v + xr) * ih2;
    let hyy = (yl - 2.0 * v + yr) * ih2;
    let hzz = (zl - 2.0 * v + zr) * ih2;
    let q = 0.25 * ih2;
    let hxy = (mid[2][i + 1] - mid[0][i + 1] - mid[2][i - 1] + mid[0][i - 1]) * q;
    let hxz = (up[1][i + 1] - lo[1][i + 1] - up[1][i - 1] + lo[1][i - 1]) * q;
    let hyz = (up[2][i] - lo[2][i] - up[0][i] + lo[0][i]) * q;
    let b = (gx * gx * hxx
        + gy * gy * hyy
        + gz * gz * hzz
        + 2.0 * (gx * gy * hxy + gx * gz * hxz + gy * gz * hyz))
        / gp2;
    // The expansion is trusted only while the quadratic term is a correction
    // (|b·g| ≤ |∇g|²/2, i.e. it changes the first-order estimate by less than ≈ 30 %); where
    // the radial field bends faster (far from the surface, near the centre) the node is left
    // to the far field.
    let bv = b * v;
    if bv.is_nan() || bv.abs() > 0.5 * gp2 {
        return f64::NAN;
    }
    2.0 * v / (gp2.sqrt() + (gp2 - 2.0 * bv).sqrt())
}

/// The seed's interface estimate at the node in column `i` of the middle row of `r` if it has
/// a neighbour of the other sign (`None` otherwise): `|g|/|∇g|` (central differences), capped
/// by the distance to the nearest linear zero crossing along a grid edge, with the sign of
/// `g` (see [`crate::reinit`]).
#[inline]
fn interface_estimate(r: &Rows<'_>, i: usize, h: f64) -> Option<f64> {
    let [lo, mid, up] = r;
    let v = mid[1][i];
    let inside = v < 0.0;
    let nb = [
        mid[1][i - 1],
        mid[1][i + 1],
        mid[0][i],
        mid[2][i],
        lo[1][i],
        up[1][i],
    ];
    // Most callers have no neighbour of the other sign: a branch-free count first.
    let negative: u32 = nb.iter().map(|&w| u32::from(w < 0.0)).sum();
    if negative == if inside { 6 } else { 0 } {
        return None;
    }
    let mut cap = f64::INFINITY;
    for w in nb {
        if (w < 0.0) != inside {
            // v and w differ in sign, so v − w ≠ 0 unless both are 0.
            cap = cap.min(h * (v / (v - w)).abs());
        }
    }
    if !cap.is_finite() {
        return None;
    }
    let inv2h = 0.5 / h;
    let (gx, gy, gz) = (
        (nb[1] - nb[0]) * inv2h,
        (nb[3] - nb[2]) * inv2h,
        (nb[5] - nb[4]) * inv2h,
    );
    let gp = (gx * gx + gy * gy + gz * gz).sqrt();
    // Far markers (±∞) in the stencil give a non-finite gradient: the cap alone.
    let est = if gp.is_finite() && gp > 0.0 {
        (v.abs() / gp).min(cap)
    } else {
        cap
    };
    Some(if inside { -est } else { est })
}

/// The band estimates of one z-slab (see [`Redistance::Band`](super::Redistance::Band)).
pub(super) struct BandSlab {
    dims: [usize; 3],
    h: f64,
    band_w: f64,
    /// Grid origin relative to the centre.
    o: Vector3<f64>,
    cut2: f64,
}

impl BandSlab {
    pub(super) fn new(spec: &GridSpec, centre: &Point3<f64>) -> Self {
        let band_w = BAND_CELLS * spec.spacing;
        Self {
            dims: spec.dims,
            h: spec.spacing,
            band_w,
            o: spec.origin.coords - centre.coords,
            cut2: (1.15 * band_w).powi(2),
        }
    }

    /// Appends the band estimates of the interior slab k (`mid`, between `lo` and `up`, all
    /// radial values) to `found`: (in-slab node index, value).
    pub(super) fn estimates(
        &self,
        k: usize,
        [lo, mid, up]: [&[f64]; 3],
        found: &mut Vec<(usize, f64)>,
    ) {
        let [nx, ny, _] = self.dims;
        let (h, o, cut2, band_w) = (self.h, self.o, self.cut2, self.band_w);
        let z = o.z + h * k as f64;
        for j in 1..ny - 1 {
            let row = nx * j;
            let y = o.y + h * j as f64;
            let yz2 = y * y + z * z;
            let r = rows([lo, mid, up], row, nx);
            let centre_row = r[1][1];
            // An index loop: the stencil reads nine rows at i − 1, i, i + 1.
            #[allow(clippy::needless_range_loop)]
            for i in 1..nx - 1 {
                let c = row + i;
                let v = centre_row[i];
                // Cheap screen first: the first-order estimate |g|/|∇g| with |∇g| ≤ 2
                // must be below 1.15 band widths (a node needing a larger second-order
                // correction takes the far field). The radial field is singular at the
                // centre: the expansion is trusted only where the node is farther from
                // the centre than from the surface along its ray (|g| ≤ ρ; this excludes
                // band nodes deeper than r/2 in grains thinner than 2·BAND_CELLS cells,
                // which then take far-field values).
                let x = o.x + h * i as f64;
                let d = if v * v >= 4.0 * cut2 || v * v > x * x + yz2 {
                    f64::NAN
                } else {
                    second_order_distance(&r, i, h, cut2)
                };
                if d.abs() < band_w {
                    found.push((c, d));
                } else if let Some(e) = v
                    .is_finite()
                    .then(|| interface_estimate(&r, i, h))
                    .flatten()
                {
                    // A node next to the surface where the expansion is not trusted:
                    // the seed's first-order interface estimate.
                    found.push((c, e));
                }
            }
        }
    }
}
