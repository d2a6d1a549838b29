//! Packing metrics: porosity (Pinto 2009, Eq. 4-2) over the domain or an
//! interior window, contacts, coordination number, minimum gap, and an
//! independent brute-force overlap checker.
//!
//! The checker deliberately shares no code with the packer or with
//! [`crate::SpatialIndex`]: it bins disks into a plain `Vec<Vec<usize>>`
//! grid of cell size `d_max` and compares every pair in neighbouring bins,
//! and it tests containment against every wall of the domain.

use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::packer::Disk;
use std::f64::consts::PI;

/// Porosity of Pinto 2009, Eq. 4-2: `φ = (A_T − Σ A_p) / A_T`, with `A_T`
/// the domain area and the disks assumed inside the domain.
///
/// # Errors
/// Validation errors of the domain.
pub fn porosity(domain: &Domain, disks: &[Disk]) -> Result<f64> {
    let a = domain.area()?;
    let solid: f64 = disks.iter().map(|d| PI * d.radius * d.radius).sum();
    Ok((a - solid) / a)
}

/// An axis-aligned window `[x0, x1] × [y0, y1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Left edge.
    pub x0: f64,
    /// Bottom edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Top edge.
    pub y1: f64,
}

/// `∫_0^t sqrt(r² − u²) du` for `|t| ≤ r`.
fn g(r: f64, t: f64) -> f64 {
    let t = t.clamp(-r, r);
    0.5 * (t * (r * r - t * t).max(0.0).sqrt() + r * r * (t / r).clamp(-1.0, 1.0).asin())
}

/// Area of the disk of radius `r` centred at the origin intersected with
/// the quadrant `{X ≤ a, Y ≤ b}` (exact).
fn quadrant_area(r: f64, a: f64, b: f64) -> f64 {
    if a <= -r || b <= -r {
        return 0.0;
    }
    let a = a.min(r);
    if b >= r {
        return 2.0 * (g(r, a) - g(r, -r));
    }
    // On |X| ≤ w the chord below b has length b + s; outside it is 2s
    // (b ≥ 0) or 0 (b < 0), with s = sqrt(r² − X²).
    let w = (r * r - b * b).max(0.0).sqrt();
    let mut total = 0.0;
    let seg = |lo: f64, hi: f64| -> (f64, f64) { (lo, hi.min(a)) };
    // Outer-left part [-r, -w].
    let (lo, hi) = seg(-r, -w);
    if hi > lo && b >= 0.0 {
        total += 2.0 * (g(r, hi) - g(r, lo));
    }
    // Middle part [-w, w].
    let (lo, hi) = seg(-w, w);
    if hi > lo {
        total += b * (hi - lo) + g(r, hi) - g(r, lo);
    }
    // Outer-right part [w, r].
    let (lo, hi) = seg(w, r);
    if hi > lo && b >= 0.0 {
        total += 2.0 * (g(r, hi) - g(r, lo));
    }
    total
}

/// Exact area of a disk inside a window.
pub fn disk_window_area(d: &Disk, w: &Window) -> f64 {
    let (cx, cy, r) = (d.center.x, d.center.y, d.radius);
    let f = |x: f64, y: f64| quadrant_area(r, x - cx, y - cy);
    (f(w.x1, w.y1) - f(w.x0, w.y1) - f(w.x1, w.y0) + f(w.x0, w.y0)).max(0.0)
}

/// Porosity inside an interior window (solid area cut exactly at the
/// window edges).
///
/// # Errors
/// [`Error::Parameter`] for an empty or non-finite window.
pub fn porosity_in_window(disks: &[Disk], w: &Window) -> Result<f64> {
    let a = (w.x1 - w.x0) * (w.y1 - w.y0);
    if !(a.is_finite() && a > 0.0) {
        return Err(Error::Parameter {
            what: "window area",
            value: a,
            range: "(0, inf)",
        });
    }
    let solid: f64 = disks
        .iter()
        .filter(|d| {
            d.center.x + d.radius > w.x0
                && d.center.x - d.radius < w.x1
                && d.center.y + d.radius > w.y0
                && d.center.y - d.radius < w.y1
        })
        .map(|d| disk_window_area(d, w))
        .sum();
    Ok((a - solid) / a)
}

/// Result of the independent overlap check.
#[derive(Debug, Clone, PartialEq)]
pub struct OverlapReport {
    /// Smallest `(|c_i − c_j| − r_i − r_j) / min(d_i, d_j)` over neighbour
    /// pairs (`+inf` with fewer than two disks or no neighbours).
    pub min_relative_gap: f64,
    /// Pairs with `gap < −rel_tol · min(d_i, d_j)`.
    pub overlapping_pairs: Vec<(usize, usize)>,
    /// Disks not inside the domain (beyond `rel_tol · d`).
    pub outside: Vec<usize>,
    /// Pairs with `|gap| ≤ contact_tol · min(d_i, d_j)`.
    pub contacts: Vec<(usize, usize)>,
}

impl OverlapReport {
    /// No overlap and nothing outside.
    pub fn is_clean(&self) -> bool {
        self.overlapping_pairs.is_empty() && self.outside.is_empty()
    }

    /// Mean particle–particle coordination number `2 · contacts / n`.
    pub fn coordination_number(&self, n: usize) -> f64 {
        if n == 0 {
            0.0
        } else {
            2.0 * self.contacts.len() as f64 / n as f64
        }
    }
}

/// Independent brute-force-over-a-grid check of a packing: every pair of
/// disks in neighbouring bins is compared, every disk is tested against the
/// exact domain. `rel_tol` is the admitted overlap relative to the smaller
/// diameter (the acceptance criterion uses `1e-9`); `contact_tol` the gap
/// (relative) under which a pair counts as a contact.
///
/// # Errors
/// Domain validation errors; [`Error::NonFinite`] for a non-finite disk.
pub fn check_packing(
    domain: &Domain,
    disks: &[Disk],
    rel_tol: f64,
    contact_tol: f64,
) -> Result<OverlapReport> {
    let shape = domain.shape()?;
    let walls = shape.walls();
    let mut rmax = 0.0_f64;
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for d in disks {
        crate::error::finite("disk x", d.center.x)?;
        crate::error::finite("disk y", d.center.y)?;
        crate::error::finite("disk radius", d.radius)?;
        rmax = rmax.max(d.radius);
        x0 = x0.min(d.center.x);
        y0 = y0.min(d.center.y);
        x1 = x1.max(d.center.x);
        y1 = y1.max(d.center.y);
    }
    let mut report = OverlapReport {
        min_relative_gap: f64::INFINITY,
        overlapping_pairs: Vec::new(),
        outside: Vec::new(),
        contacts: Vec::new(),
    };
    if disks.is_empty() {
        return Ok(report);
    }
    let h = (2.0 * rmax).max(1e-300);
    let nx = (((x1 - x0) / h) as usize + 1).min(1 << 14);
    let ny = (((y1 - y0) / h) as usize + 1).min(1 << 14);
    let hx = ((x1 - x0) / nx as f64).max(h);
    let hy = ((y1 - y0) / ny as f64).max(h);
    let mut bins: Vec<Vec<usize>> = vec![Vec::new(); nx * ny];
    let bin = |x: f64, y: f64| -> (usize, usize) {
        (
            (((x - x0) / hx) as usize).min(nx - 1),
            (((y - y0) / hy) as usize).min(ny - 1),
        )
    };
    for (i, d) in disks.iter().enumerate() {
        let (bx, by) = bin(d.center.x, d.center.y);
        bins[by * nx + bx].push(i);
    }
    for (i, d) in disks.iter().enumerate() {
        let (bx, by) = bin(d.center.x, d.center.y);
        for yy in by.saturating_sub(1)..=(by + 1).min(ny - 1) {
            for xx in bx.saturating_sub(1)..=(bx + 1).min(nx - 1) {
                for &j in &bins[yy * nx + xx] {
                    if j <= i {
                        continue;
                    }
                    let e = &disks[j];
                    let dist = ((d.center.x - e.center.x).powi(2)
                        + (d.center.y - e.center.y).powi(2))
                    .sqrt();
                    let scale = 2.0 * d.radius.min(e.radius);
                    let gap = (dist - d.radius - e.radius) / scale;
                    report.min_relative_gap = report.min_relative_gap.min(gap);
                    if gap < -rel_tol {
                        report.overlapping_pairs.push((i, j));
                    }
                    if gap.abs() <= contact_tol {
                        report.contacts.push((i, j));
                    }
                }
            }
        }
        let c = [d.center.x, d.center.y];
        if !crate::domain::shape_contains_disk(
            &shape,
            &walls,
            c,
            d.radius,
            rel_tol * 2.0 * d.radius,
        ) {
            report.outside.push(i);
        }
    }
    report.contacts.sort_unstable();
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Point2;

    fn disk(x: f64, y: f64, r: f64) -> Disk {
        Disk {
            center: Point2::new(x, y),
            radius: r,
        }
    }

    #[test]
    fn window_area_oracles() {
        let d = disk(0.0, 0.0, 1.0);
        let full = Window {
            x0: -2.0,
            y0: -2.0,
            x1: 2.0,
            y1: 2.0,
        };
        assert_relative_eq!(disk_window_area(&d, &full), PI, epsilon = 1e-12);
        let half = Window {
            x0: 0.0,
            y0: -2.0,
            x1: 2.0,
            y1: 2.0,
        };
        assert_relative_eq!(disk_window_area(&d, &half), PI / 2.0, epsilon = 1e-12);
        let quarter = Window {
            x0: 0.0,
            y0: 0.0,
            x1: 2.0,
            y1: 2.0,
        };
        assert_relative_eq!(disk_window_area(&d, &quarter), PI / 4.0, epsilon = 1e-12);
        // Circular segment above y = 0.5: r²acos(h/r) − h sqrt(r² − h²).
        let cap = Window {
            x0: -2.0,
            y0: 0.5,
            x1: 2.0,
            y1: 2.0,
        };
        let expect = (0.5f64).acos() - 0.5 * (0.75f64).sqrt();
        assert_relative_eq!(disk_window_area(&d, &cap), expect, epsilon = 1e-12);
        // Square inscribed in the disk is fully covered.
        let s = 0.5f64.sqrt();
        let inner = Window {
            x0: -s,
            y0: -s,
            x1: s,
            y1: s,
        };
        assert_relative_eq!(disk_window_area(&d, &inner), 2.0, epsilon = 1e-12);
    }

    #[test]
    fn checker_finds_overlaps_and_escapes() {
        let dom = Domain::Rectangle {
            width: 10.0,
            height: 10.0,
        };
        let disks = [
            disk(1.0, 1.0, 1.0),
            disk(2.99, 1.0, 1.0),
            disk(9.5, 5.0, 1.0),
            disk(5.0, 5.0, 1.0),
            disk(7.0, 5.0, 1.0),
        ];
        let rep = check_packing(&dom, &disks, 1e-9, 1e-9).expect("valid");
        assert_eq!(rep.overlapping_pairs, vec![(0, 1)]);
        assert_eq!(rep.outside, vec![2]);
        assert_eq!(rep.contacts, vec![(3, 4)]);
        assert_relative_eq!(rep.min_relative_gap, -0.005, epsilon = 1e-12);
    }

    #[test]
    fn porosity_of_one_disk() {
        let dom = Domain::Rectangle {
            width: 2.0,
            height: 2.0,
        };
        let p = porosity(&dom, &[disk(1.0, 1.0, 1.0)]).expect("valid");
        assert_relative_eq!(p, 1.0 - PI / 4.0, epsilon = 1e-12);
    }
}
