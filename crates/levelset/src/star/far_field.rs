//! The interior far field of the band build: the distance to the closest points of the
//! band, propagated on the coarse grid of even nodes ([`Coarse`]), and the assembly of the
//! final values of a slab.

use nalgebra::Vector3;

use super::BAND_CELLS;
use super::band::Band;
use crate::error::{Error, Result};
use crate::grid::GridSpec;

/// Coarse band nodes within this many grid spacings of the surface seed the far field.
const SOURCE_CELLS: f64 = 3.0;

/// Largest disagreement, in grid spacings, between a band value beyond the sources and the
/// far field before the far field is used.
const AGREEMENT: f64 = 0.5;

/// Value of an exterior node outside the band: `min(|g|, BAND_CELLS·h)`, the band width
/// capped by the radial distance. The band width is a lower bound of the distance wherever
/// the band estimate was trusted (and always outside the radial shell, which is wider than
/// the band); `|g|` (an upper bound) keeps nodes next to the surface that the band left out
/// close to the surface.
#[inline]
fn exterior_value(g: f64, band_w: f64) -> f64 {
    g.abs().min(band_w)
}

/// Interior far field on the coarse grid of the even nodes (spacing 2h; one node beyond the
/// grid on an axis with an odd number of cells), padded by one node.
pub(super) struct Coarse {
    m: [usize; 3],
    /// The signed coarse values interpolated along x to every fine column: `nx` values per
    /// coarse row (row `jc + m[1]·kc`).
    ax: Vec<f64>,
}

impl Coarse {
    /// Closest-point propagation (the fast-sweeping orderings with the seven upwind
    /// neighbours of each octant) from the coarse band nodes within SOURCE_CELLS·h, whose
    /// closest surface point is `x − d·∇g/|∇g|`, to every interior coarse node; exterior
    /// coarse nodes outside the band take [`exterior_value`].
    #[inline(never)]
    pub(super) fn interior(spec: &GridSpec, slabs: &[&[f64]], band: &Band) -> Result<Self> {
        let [nx, ny, nz] = spec.dims;
        let h = spec.spacing;
        let (sy, sz) = (nx, nx * ny);
        let m = [
            (nx - 1).div_ceil(2) + 1,
            (ny - 1).div_ceil(2) + 1,
            (nz - 1).div_ceil(2) + 1,
        ];
        let (px, py) = (m[0] + 2, m[1] + 2);
        let pz = px * py;
        let plen = pz * (m[2] + 2);
        let nan = f32::NAN;
        // Closest points (f32: ≈ 1e-7 relative, far below the method's error) and one value
        // per node: the squared distance of the closest point while an active node is
        // propagated, the final signed value for every other node.
        let (mut cx, mut cy, mut cz) = (vec![nan; plen], vec![nan; plen], vec![nan; plen]);
        let mut dist = vec![f64::INFINITY; plen];
        // Interior non-source nodes to update: per coarse row, the index range.
        let mut active = vec![false; plen];
        let mut ranges = vec![(usize::MAX, 0usize); m[1] * m[2]];
        let mut any_source = false;
        let inv2h = 0.5 / h;
        let band_w = BAND_CELLS * h;
        for kc in 0..m[2] {
            for jc in 0..m[1] {
                for ic in 0..m[0] {
                    let p = (ic + 1) + px * (jc + 1) + pz * (kc + 1);
                    // Nodes beyond the grid take the sign of the last grid node.
                    let (i, j, k) = (2 * ic, 2 * jc, 2 * kc);
                    let (ks, cs) = (k.min(nz - 1), i.min(nx - 1) + sy * j.min(ny - 1));
                    let c = cs + sz * ks;
                    let g = slabs[ks];
                    let d = g[cs];
                    let inside = d < 0.0;
                    // A source: a band node within SOURCE_CELLS·h whose six neighbours are band
                    // nodes (band nodes are interior nodes, so they exist), the normal being
                    // the gradient of the band distance.
                    let source = i < nx
                        && j < ny
                        && k < nz
                        && band.has(c)
                        && d.abs() <= SOURCE_CELLS * h
                        && [c - 1, c + 1, c - sy, c + sy, c - sz, c + sz]
                            .iter()
                            .all(|&q| band.has(q));
                    if source {
                        let grad = Vector3::new(
                            (g[cs + 1] - g[cs - 1]) * inv2h,
                            (g[cs + sy] - g[cs - sy]) * inv2h,
                            (slabs[ks + 1][cs] - slabs[ks - 1][cs]) * inv2h,
                        );
                        let x = spec.node(i, j, k).coords - grad * (d / grad.norm());
                        (cx[p], cy[p], cz[p]) = (x.x as f32, x.y as f32, x.z as f32);
                        dist[p] = d;
                        any_source = true;
                    } else if inside {
                        active[p] = true;
                        let r = &mut ranges[jc + m[1] * kc];
                        r.0 = r.0.min(ic);
                        r.1 = r.1.max(ic + 1);
                    } else {
                        dist[p] = exterior_value(d, band_w);
                    }
                }
            }
        }
        if !any_source {
            return Err(Error::NoSurface);
        }
        let hc = 2.0 * h;
        let o = spec.origin.coords;
        // The diagonal neighbours are needed: with the six face neighbours alone, a node
        // whose closest point lies diagonally keeps a point up to 1·h too far (measured).
        for sweep in 0..8 {
            let (fx, fy, fz) = (sweep & 1 == 0, sweep & 2 == 0, sweep & 4 == 0);
            let sx: isize = if fx { -1 } else { 1 };
            let sy2: isize = if fy { -(px as isize) } else { px as isize };
            let sz2: isize = if fz { -(pz as isize) } else { pz as isize };
            let offs = [sx, sy2, sz2, sx + sy2, sx + sz2, sy2 + sz2, sx + sy2 + sz2];
            for kp in 0..m[2] {
                let kc = if fz { kp } else { m[2] - 1 - kp };
                for jp in 0..m[1] {
                    let jc = if fy { jp } else { m[1] - 1 - jp };
                    let (lo, hi) = ranges[jc + m[1] * kc];
                    if lo >= hi {
                        continue;
                    }
                    let row = px * (jc + 1) + pz * (kc + 1);
                    let (y, z) = (o.y + hc * jc as f64, o.z + hc * kc as f64);
                    for ip in 0..hi - lo {
                        let ic = if fx { lo + ip } else { hi - 1 - ip };
                        let p = row + ic + 1;
                        if !active[p] {
                            continue;
                        }
                        let x = o.x + hc * ic as f64;
                        let mut best = dist[p];
                        let mut b = p;
                        for off in offs {
                            let q = p.wrapping_add_signed(off);
                            let (ex, ey, ez) = (
                                x - f64::from(cx[q]),
                                y - f64::from(cy[q]),
                                z - f64::from(cz[q]),
                            );
                            let e = ex * ex + ey * ey + ez * ez;
                            if e < best {
                                best = e;
                                b = q;
                            }
                        }
                        dist[p] = best;
                        (cx[p], cy[p], cz[p]) = (cx[b], cy[b], cz[b]);
                    }
                }
            }
        }
        for p in 0..plen {
            if active[p] {
                dist[p] = -dist[p].sqrt();
            }
        }
        let mut ax = vec![0.0; nx * m[1] * m[2]];
        for kc in 0..m[2] {
            for jc in 0..m[1] {
                let src = 1 + px * (jc + 1) + pz * (kc + 1);
                let dst = nx * (jc + m[1] * kc);
                for i in 0..nx {
                    let ic = i / 2;
                    ax[dst + i] = if i % 2 == 0 {
                        dist[src + ic]
                    } else {
                        0.5 * (dist[src + ic] + dist[src + ic + 1])
                    };
                }
            }
        }
        Ok(Self { m, ax })
    }

    /// Fine values of z-slab `k`, written over its band values: trusted band values;
    /// elsewhere inside, the trilinear interpolation of the coarse values (separably: x,
    /// then y, then z); elsewhere outside, [`exterior_value`].
    pub(super) fn assemble_slab(&self, spec: &GridSpec, k: usize, slab: &mut [f64], band: &Band) {
        let [nx, ny, _] = spec.dims;
        let h = spec.spacing;
        let (sy, sz) = (nx, nx * ny);
        let m = self.m;
        let ax = &self.ax;
        let band_w = BAND_CELLS * h;
        for j in 0..ny {
            let dst = sy * j;
            // The (up to four) coarse rows around the fine row and their weights.
            let (j0, j1) = (j / 2, j.div_ceil(2));
            let (k0, k1) = (k / 2, k.div_ceil(2));
            let r = [
                nx * (j0 + m[1] * k0),
                nx * (j1 + m[1] * k0),
                nx * (j0 + m[1] * k1),
                nx * (j1 + m[1] * k1),
            ];
            for i in 0..nx {
                let c = dst + i;
                let b = slab[c];
                let in_band = band.has(sz * k + c);
                let inside = b < 0.0;
                // Band values within the sources, and outside (where the far field is only a
                // bound), are kept.
                if in_band && (b.abs() <= SOURCE_CELLS * h || !inside) {
                    continue;
                }
                if !inside {
                    slab[c] = exterior_value(b, band_w);
                    continue;
                }
                let interp = 0.25 * (ax[r[0] + i] + ax[r[1] + i] + ax[r[2] + i] + ax[r[3] + i]);
                // Inside beyond the sources a band value must agree with the far field
                // (robust near ridges, where an expansion can underestimate); an interpolated
                // value of the other sign (next to the surface) is small, and only its
                // magnitude is kept.
                if !(in_band && (b - interp).abs() <= AGREEMENT * h) {
                    // Off the band, `b` is still the radial distance |ρ − r(û)|: the surface
                    // point on the node's ray is that far, so it bounds the distance from
                    // above. The far field can exceed it where no source is near (thin tips
                    // of rough grains, whose nodes leave the band): clamp.
                    let v = interp.abs();
                    slab[c] = -(if in_band { v } else { v.min(b.abs()) });
                }
            }
        }
    }
}
