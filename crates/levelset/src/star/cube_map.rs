//! The cube-map table of a star-shaped surface: radii at the nodes of six gnomonic faces,
//! validated in table order and interpolated bilinearly ([`CubeMap`]), and its public
//! face, [`StarTable`].

use nalgebra::{Unit, Vector3};
use rayon::prelude::*;
use std::sync::OnceLock;

use super::{DirectionTable, StarParams, checked_radius};
use crate::error::{Error, Result};

/// A star-shaped surface `r(u)` tabulated on a cube map, with the bilinear lookup of
/// [`Grid::from_star_table`](crate::Grid::from_star_table): the same radius function the grid builder interpolates, for
/// callers that need the surface itself (packers, node generators) without a grid.
/// Stored as f32 (`6·(face_cells+1)²` values: 6.9 KB for 16 cells per face, 26 KB for 32).
#[derive(Debug, Clone, PartialEq)]
pub struct StarTable {
    map: CubeMap,
}

impl StarTable {
    /// The table from the radii at `cube_map_directions(face_cells)`, in that order.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for `face_cells` outside 2..=4096 or a wrong number of
    /// radii; [`Error::InvalidRadius`] for a radius that is not finite and positive.
    pub fn new(face_cells: usize, radii: &[f64]) -> Result<Self> {
        StarParams {
            table: DirectionTable::CubeMap { face_cells },
            ..StarParams::default()
        }
        .validate()?;
        let m = face_cells + 1;
        if radii.len() != 6 * m * m {
            return Err(Error::InvalidParameter {
                name: "radii",
                value: radii.len() as f64,
                requirement: "6·(face_cells + 1)² values, one per cube-map direction",
            });
        }
        Ok(Self {
            map: CubeMap::from_values(face_cells, radii.iter().copied())?,
        })
    }

    /// Cells per face edge.
    pub fn face_cells(&self) -> usize {
        self.map.n
    }

    /// The tabulated radii (as stored, f32 widened), in `cube_map_directions` order.
    pub fn radii(&self) -> Vec<f64> {
        self.map.radii.iter().map(|&r| f64::from(r)).collect()
    }

    /// Bilinearly interpolated radius in direction `d` (need not be unit; the zero vector
    /// or a non-finite one reads as +x).
    #[inline]
    pub fn radius(&self, d: &Vector3<f64>) -> f64 {
        let m = d.x.abs().max(d.y.abs()).max(d.z.abs());
        if m > 0.0 && m.is_finite() {
            self.map.radius(d)
        } else {
            self.map.radius(&Vector3::x())
        }
    }

    /// Largest and smallest tabulated radius (the extremes of the interpolated surface).
    pub fn extremes(&self) -> (f64, f64) {
        self.map
            .radii
            .iter()
            .fold((0.0_f64, f64::INFINITY), |(hi, lo), &r| {
                (hi.max(f64::from(r)), lo.min(f64::from(r)))
            })
    }
}

/// Cube-map table of radii: face f = 2·axis + (negative ? 1 : 0); node (p, q) of a face is
/// the direction `s·e_axis + u·e_b + v·e_c` with u, v = −1 + 2p/n, −1 + 2q/n.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct CubeMap {
    /// Cells per face edge.
    pub(super) n: usize,
    /// f32: the 6·33² table of the default fits in L1 (52 KB as f64 does not); relative
    /// error 6e-8, far below the bilinear interpolation error.
    pub(super) radii: Vec<f32>,
}

const OTHER: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];

impl CubeMap {
    /// Direction of node (p, q) of face f (not normalised).
    #[inline]
    pub(super) fn direction(n: usize, f: usize, p: usize, q: usize) -> Unit<Vector3<f64>> {
        let axis = f / 2;
        let [b, c] = OTHER[axis];
        let mut d = Vector3::zeros();
        d[axis] = if f.is_multiple_of(2) { 1.0 } else { -1.0 };
        d[b] = -1.0 + 2.0 * p as f64 / n as f64;
        d[c] = -1.0 + 2.0 * q as f64 / n as f64;
        Unit::new_normalize(d)
    }

    pub(super) fn build(n: usize, r: &mut impl FnMut(Unit<Vector3<f64>>) -> f64) -> Result<Self> {
        let m = n + 1;
        let mut radii = Vec::with_capacity(6 * m * m);
        for f in 0..6 {
            for q in 0..m {
                for p in 0..m {
                    let u = Self::direction(n, f, p, q);
                    radii.push(checked_radius(u, r(u))? as f32);
                }
            }
        }
        Ok(Self { n, radii })
    }

    /// [`CubeMap::build`] with the calls spread over the rayon pool by face rows; the first
    /// invalid radius in table order is reported, as by the sequential build.
    pub(super) fn build_parallel(
        n: usize,
        r: &(dyn Fn(Unit<Vector3<f64>>) -> f64 + Sync),
    ) -> Result<Self> {
        let m = n + 1;
        let rows: Vec<OnceLock<Vec<f64>>> = (0..6 * m).map(|_| OnceLock::new()).collect();
        rows.par_iter().enumerate().for_each(|(row, slot)| {
            let (f, q) = (row / m, row % m);
            let _ = slot.set((0..m).map(|p| r(Self::direction(n, f, p, q))).collect());
        });
        Self::from_rows(n, &rows)
    }

    /// The table from its face rows (row `f·m + q` holds the nodes p = 0..m of face f, row
    /// q), validated in table order; a missing row (only after a panic elsewhere) reads as
    /// invalid radii.
    pub(super) fn from_rows(n: usize, rows: &[OnceLock<Vec<f64>>]) -> Result<Self> {
        let m = n + 1;
        Self::from_values(
            n,
            rows.iter().flat_map(|slot| {
                let vals = slot.get().map_or(&[][..], Vec::as_slice);
                (0..m).map(move |p| vals.get(p).copied().unwrap_or(f64::NAN))
            }),
        )
    }

    /// The table from its values in table order, validated in that order (a direction is
    /// computed only to report an invalid radius); missing values read as invalid.
    pub(super) fn from_values(n: usize, values: impl Iterator<Item = f64>) -> Result<Self> {
        let m = n + 1;
        let len = 6 * m * m;
        let mut radii = Vec::with_capacity(len);
        for (t, v) in values
            .chain(std::iter::repeat(f64::NAN))
            .take(len)
            .enumerate()
        {
            if !(v.is_finite() && v > 0.0) {
                let (f, q, p) = (t / (m * m), t / m % m, t % m);
                checked_radius(Self::direction(n, f, p, q), v)?;
            }
            radii.push(v as f32);
        }
        Ok(Self { n, radii })
    }

    /// Interpolated radius for a non-zero (not necessarily unit) direction.
    #[inline(always)]
    pub(super) fn radius(&self, d: &Vector3<f64>) -> f64 {
        // Only the reciprocal of the major component is read: one division.
        let m = d.x.abs().max(d.y.abs()).max(d.z.abs());
        self.radius_inv(d.x, d.y, d.z, [1.0 / m; 3])
    }

    /// [`CubeMap::radius`] with the reciprocals of `|x|, |y|, |z|` given (the builder
    /// tabulates them per grid column and row: no division per node). Only the reciprocal
    /// of the major component is used, so the others may be infinite.
    #[inline(always)]
    pub(super) fn radius_inv(&self, x: f64, y: f64, z: f64, inv: [f64; 3]) -> f64 {
        let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
        // Major axis `a` and the face coordinates (u, v) along OTHER[axis].
        let (axis, a, u, v) = if ax >= ay && ax >= az {
            (0, x, y, z)
        } else if ay >= az {
            (1, y, z, x)
        } else {
            (2, z, x, y)
        };
        let n = self.n as f64;
        let s = 0.5 * n * inv[axis];
        let fu = (u * s + 0.5 * n).clamp(0.0, n);
        let fv = (v * s + 0.5 * n).clamp(0.0, n);
        // fu, fv ∈ [0, n] with n ≤ 4096: the 32-bit conversion is exact and cheaper than
        // the saturating one to usize.
        let p = (fu as u32 as usize).min(self.n - 1);
        let q = (fv as u32 as usize).min(self.n - 1);
        let tu = fu - p as f64;
        let tv = fv - q as f64;
        let m = self.n + 1;
        let f = 2 * axis + usize::from(a < 0.0);
        let base = f * m * m + q * m + p;
        // One bounds check for the four corners.
        let c = &self.radii[base..base + m + 2];
        let (a0, a1) = (f64::from(c[0]), f64::from(c[1]));
        let (b0, b1) = (f64::from(c[m]), f64::from(c[m + 1]));
        let r0 = a0 + tu * (a1 - a0);
        let r1 = b0 + tu * (b1 - b0);
        r0 + tv * (r1 - r0)
    }
}
