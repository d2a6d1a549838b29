//! The radial signed distances `ρ − r(û)` of a cube-map star build, looked up only in the
//! shell of nodes that can be near the surface ([`Shell`]).

use nalgebra::{Point3, Vector3};

use super::cube_map::CubeMap;
use super::{BAND_CELLS, FAR, Redistance};
use crate::grid::GridSpec;

/// The radial signed distances of the cube-map build in the shell of nodes that can be within
/// the band (or the interface stencil) of the surface; ∓∞ (far marker, sign only) inside
/// and outside the shell.
pub(super) struct Shell {
    map: CubeMap,
    nx: usize,
    h: f64,
    /// Grid origin relative to the centre.
    o: Vector3<f64>,
    /// Per column: x and 1/|x| (the per-node division of the face coordinates becomes a
    /// table lookup).
    xs: Vec<f64>,
    inv_x: Vec<f64>,
    inner2: f64,
    outer2: f64,
}

impl Shell {
    pub(super) fn new(
        spec: &GridSpec,
        centre: &Point3<f64>,
        map: CubeMap,
        redist: Redistance,
    ) -> Self {
        let h = spec.spacing;
        // Narrow shell: interpolated radii lie in [r_min, r_max], so nodes with
        // ρ < r_min − w are inside and nodes with ρ > r_max + w outside, and neither touches
        // the interface (or the band); they start at ∓∞ (far marker) and get their value
        // from the sweeps. Only the shell is looked up.
        let (rmin, rmax) = map
            .radii
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &r| {
                (a.min(f64::from(r)), b.max(f64::from(r)))
            });
        // The band build needs radii wherever a node or its stencil can be within
        // BAND_CELLS·h of the surface.
        let w = match redist {
            Redistance::FullSweep => 2.0 * h,
            Redistance::Band => (BAND_CELLS + 1.5) * h,
        };
        let inner = (rmin - w).max(0.0);
        let o = spec.origin - centre;
        let xs: Vec<f64> = (0..spec.dims[0]).map(|i| o.x + h * i as f64).collect();
        let inv_x = xs.iter().map(|x| 1.0 / x.abs()).collect();
        Self {
            map,
            nx: spec.dims[0],
            h,
            o,
            xs,
            inv_x,
            inner2: inner * inner,
            outer2: (rmax + w) * (rmax + w),
        }
    }

    /// Writes the radial values of z-slab `k` over `slab` (which holds `FAR`).
    #[inline]
    pub(super) fn fill(&self, k: usize, slab: &mut [f64]) {
        let (h, o, map) = (self.h, self.o, &self.map);
        let (inner2, outer2) = (self.inner2, self.outer2);
        let z = o.z + h * k as f64;
        let inv_z = 1.0 / z.abs();
        for (j, row) in slab.chunks_exact_mut(self.nx).enumerate() {
            let y = o.y + h * j as f64;
            let yz2 = y * y + z * z;
            if yz2 > outer2 {
                // The whole row is outside the shell (already FAR).
                continue;
            }
            let inv_y = 1.0 / y.abs();
            for ((v, &x), &ix) in row.iter_mut().zip(&self.xs).zip(&self.inv_x) {
                let rho2 = x * x + yz2;
                *v = if rho2 < inner2 {
                    -FAR
                } else if rho2 > outer2 {
                    FAR
                } else if rho2 > 1e-24 * h * h {
                    rho2.sqrt() - map.radius_inv(x, y, z, [ix, inv_y, inv_z])
                } else {
                    -map.radius(&Vector3::z())
                };
            }
        }
    }
}
