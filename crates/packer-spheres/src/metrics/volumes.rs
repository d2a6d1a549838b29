//! Exact sphere ∩ region volumes: slices of a sphere integrated over `z`
//! by adaptive Gauss–Legendre on the closed-form area of a circle ∩
//! rectangle or of a circle ∩ disk lens.

use std::f64::consts::PI;
use std::sync::OnceLock;

use crate::Sphere;

/// Gauss–Legendre nodes and weights on `[0, 1]` (Newton on `P_n`).
pub(super) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
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

pub(super) fn gl16() -> &'static [(f64, f64)] {
    static NODES: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    NODES.get_or_init(|| gauss_legendre(16))
}

pub(super) fn gl32() -> &'static [(f64, f64)] {
    static NODES: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    NODES.get_or_init(|| gauss_legendre(32))
}

/// `∫_a^b f` by smoothstep-mapped 32-point Gauss–Legendre, accepted when
/// the 16-point rule agrees to `tol`, else bisected (`depth` levels).
pub(super) fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32) -> f64 {
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
pub(super) fn slab(r: f64, ta: f64, tb: f64) -> f64 {
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
pub(super) fn slice_integral(
    r: f64,
    ta: f64,
    tb: f64,
    kinks: &[f64],
    area: &dyn Fn(f64) -> f64,
) -> f64 {
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
pub(super) fn quadrant_area(rho: f64, a: f64, b: f64) -> f64 {
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
pub(super) fn rect_area(rho: f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let q = |a: f64, b: f64| quadrant_area(rho, a, b);
    (q(x1, y1) - q(x0, y1) - q(x1, y0) + q(x0, y0)).clamp(0.0, PI * rho * rho)
}

/// Area of the intersection of a disk of radius `rho` and a disk of radius
/// `big` whose centres are `s` apart (the lens; atan2 form).
pub(super) fn lens_area(rho: f64, s: f64, big: f64) -> f64 {
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
pub(super) fn sphere_box_volume(s: &Sphere, lo: [f64; 3], hi: [f64; 3]) -> f64 {
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
pub(super) fn sphere_cylinder_volume(
    s: &Sphere,
    cx: f64,
    cy: f64,
    big: f64,
    z0: f64,
    z1: f64,
) -> f64 {
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
