//! The closed-form wrapper solves: centres of a sphere tangent to the
//! generating sphere and to two more obstacles (spheres, planes, the
//! cylinder side), relative to the generating sphere.

use nalgebra::Vector3;

use super::Plane;

/// One neighbour of the generating sphere, relative to its centre.
#[derive(Clone, Copy, Default)]
pub(super) struct Nb {
    /// `c_j − c_f` (periodic image applied).
    pub(super) d: [f64; 3],
    /// `|d|²`.
    pub(super) dd: f64,
    /// Halo radius `r_j + r`.
    pub(super) rho: f64,
    /// `(|d|² + ρ_f² − ρ_j²)/2`: right-hand side of `d · y = b`.
    pub(super) b: f64,
    /// Sphere id.
    pub(super) id: u32,
}

/// Up to eight solution points, without allocation.
#[derive(Default)]
pub(super) struct Pts {
    p: [[f64; 3]; 8],
    n: usize,
}

impl Pts {
    #[inline]
    pub(super) fn push(&mut self, q: [f64; 3]) {
        if self.n < 8 {
            self.p[self.n] = q;
            self.n += 1;
        }
    }
    #[inline]
    pub(super) fn clear(&mut self) {
        self.n = 0;
    }
    #[inline]
    pub(super) fn as_slice(&self) -> &[[f64; 3]] {
        &self.p[..self.n]
    }
}

/// Centres (relative to the front) of a sphere tangent to the front and to
/// obstacles `a`, `b`: `|y|² = ρ_f²`, `d_a·y = b_a`, `d_b·y = b_b`. The
/// solution line `y_0 + t (d_a × d_b)` with `y_0` in the plane of `d_a`,
/// `d_b` (the closed form of [`packer_contact::contact3d::intersect`], inlined).
#[inline]
pub(super) fn three_spheres(a: &Nb, b: &Nb, rho_f2: f64, out: &mut Pts) {
    let (da, db) = (a.d, b.d);
    let u = [
        da[1] * db[2] - da[2] * db[1],
        da[2] * db[0] - da[0] * db[2],
        da[0] * db[1] - da[1] * db[0],
    ];
    let uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    if !uu.gt(&(1e-20 * a.dd * b.dd)) {
        return;
    }
    // y0 = ((d_b × u) b_a + (u × d_a) b_b) / |u|²
    let dbu = [
        db[1] * u[2] - db[2] * u[1],
        db[2] * u[0] - db[0] * u[2],
        db[0] * u[1] - db[1] * u[0],
    ];
    let uda = [
        u[1] * da[2] - u[2] * da[1],
        u[2] * da[0] - u[0] * da[2],
        u[0] * da[1] - u[1] * da[0],
    ];
    let inv = 1.0 / uu;
    let y0 = [
        (dbu[0] * a.b + uda[0] * b.b) * inv,
        (dbu[1] * a.b + uda[1] * b.b) * inv,
        (dbu[2] * a.b + uda[2] * b.b) * inv,
    ];
    let y0n = y0[0] * y0[0] + y0[1] * y0[1] + y0[2] * y0[2];
    let disc = rho_f2 - y0n;
    if disc < 0.0 {
        return;
    }
    let t = (disc * inv).sqrt();
    out.push([y0[0] + u[0] * t, y0[1] + u[1] * t, y0[2] + u[2] * t]);
    if t > 0.0 {
        out.push([y0[0] - u[0] * t, y0[1] - u[1] * t, y0[2] - u[2] * t]);
    }
}

/// Front, obstacle `a` and a plane `n·y = o` (relative to the front).
#[inline]
pub(super) fn sphere_sphere_plane(a: &Nb, w: &Plane, rho_f2: f64, out: &mut Pts) {
    let da = Vector3::from(a.d);
    let u = da.cross(&w.n);
    let uu = u.norm_squared();
    if !uu.gt(&(1e-20 * a.dd)) {
        return;
    }
    let y0 = (w.n.cross(&u) * a.b + u.cross(&da) * w.o) / uu;
    let disc = rho_f2 - y0.norm_squared();
    if disc < 0.0 {
        return;
    }
    let t = (disc / uu).sqrt();
    let p = y0 + u * t;
    out.push([p.x, p.y, p.z]);
    if t > 0.0 {
        let p = y0 - u * t;
        out.push([p.x, p.y, p.z]);
    }
}

/// Front and two planes `n_i·y = o_i`.
#[inline]
pub(super) fn sphere_two_planes(
    n1: &Vector3<f64>,
    o1: f64,
    n2: &Vector3<f64>,
    o2: f64,
    rho_f2: f64,
    out: &mut Pts,
) {
    let u = n1.cross(n2);
    let uu = u.norm_squared();
    if !uu.gt(&1e-20) {
        return;
    }
    let y0 = (n2.cross(&u) * o1 + u.cross(n1) * o2) / uu;
    let disc = rho_f2 - y0.norm_squared();
    if disc < 0.0 {
        return;
    }
    let t = (disc / uu).sqrt();
    let p = y0 + u * t;
    out.push([p.x, p.y, p.z]);
    if t > 0.0 {
        let p = y0 - u * t;
        out.push([p.x, p.y, p.z]);
    }
}

/// Front circle at height `zc` (relative) meets the offset cylinder of
/// radius `rr` around `ax` (relative, horizontal).
pub(super) fn circle_cylinder_horizontal(
    zc: f64,
    rho_f2: f64,
    ax: [f64; 2],
    rr: f64,
    out: &mut Pts,
) {
    let s2 = rho_f2 - zc * zc;
    if s2 < 0.0 {
        return;
    }
    let s = s2.sqrt();
    // Circles (0, s) and (ax, rr) in the plane.
    let d2 = ax[0] * ax[0] + ax[1] * ax[1];
    if d2 == 0.0 {
        return;
    }
    let d = d2.sqrt();
    if d > s + rr || d < (s - rr).abs() {
        return;
    }
    let a = (d2 + s2 - rr * rr) / (2.0 * d);
    let h = (s2 - a * a).max(0.0).sqrt();
    let (ux, uy) = (ax[0] / d, ax[1] / d);
    let (mx, my) = (a * ux, a * uy);
    out.push([mx - h * uy, my + h * ux, zc]);
    if h > 0.0 {
        out.push([mx + h * uy, my - h * ux, zc]);
    }
}

/// The circle common to the front's halo and obstacle `a`'s halo meets the
/// offset cylinder (radius `rr` around `ax`, relative): the roots of
/// `g(θ) = |x_xy(θ) − ax|² − rr²` on the circle, bracketed on 32 samples
/// and refined by the Illinois method to round-off.
pub(super) fn circle_cylinder(a: &Nb, rho_f2: f64, ax: [f64; 2], rr: f64, out: &mut Pts) {
    let dd = a.dd;
    if dd == 0.0 {
        return;
    }
    let dl = dd.sqrt();
    let u = Vector3::from(a.d) / dl;
    let t = a.b / dl;
    let s2 = rho_f2 - t * t;
    if s2 <= 0.0 {
        return;
    }
    let s = s2.sqrt();
    let m = u * t;
    let helper = if u.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = u.cross(&helper).normalize();
    let e2 = u.cross(&e1);
    let at = |th: f64| -> Vector3<f64> { m + (e1 * th.cos() + e2 * th.sin()) * s };
    let g = |th: f64| -> f64 {
        let x = at(th);
        let (dx, dy) = (x.x - ax[0], x.y - ax[1]);
        dx * dx + dy * dy - rr * rr
    };
    const N: usize = 32;
    let step = std::f64::consts::TAU / N as f64;
    let mut t0 = 0.0;
    let mut g0 = g(t0);
    for i in 1..=N {
        let t1 = i as f64 * step;
        let g1 = g(t1);
        if g0 == 0.0 {
            let p = at(t0);
            out.push([p.x, p.y, p.z]);
        } else if g0 * g1 < 0.0 {
            // Illinois (modified regula falsi).
            let (mut a0, mut fa, mut b0, mut fb) = (t0, g0, t1, g1);
            for _ in 0..80 {
                let c = b0 - fb * (b0 - a0) / (fb - fa);
                let fc = g(c);
                if fc == 0.0 {
                    b0 = c;
                    break;
                }
                if fc * fb < 0.0 {
                    a0 = b0;
                    fa = fb;
                } else {
                    fa *= 0.5;
                }
                b0 = c;
                fb = fc;
                if (b0 - a0).abs() <= 1e-15 {
                    break;
                }
            }
            let p = at(b0);
            out.push([p.x, p.y, p.z]);
        }
        t0 = t1;
        g0 = g1;
    }
}
