//! The radial profile of a cylindrical specimen: solid fractions of
//! coaxial annuli.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::volumes::{lens_area, slab, slice_integral};
use super::{kind, validate_spheres};
use crate::error::{Error, Result};
use crate::{Container, Sphere};

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
