//! Grids from voxel images (CT scans).
//!
//! * Binary images: exact Euclidean distance transform by the separable lower-envelope
//!   algorithm (Felzenszwalb & Huttenlocher 2012, Theory of Computing 8,
//!   doi:10.4086/toc.2012.v008a019, Alg. 1), run once to the nearest inside voxel and once
//!   to the nearest outside voxel. A binary image carries no sub-voxel information; the
//!   surface is placed half-way between the centres of unlike neighbours, i.e. φ = d − h/2
//!   outside and −(d − h/2) inside (`d` = distance to the nearest voxel of the other class).
//! * Grey-level images (e.g. CT intensities): the interface is located with sub-voxel
//!   accuracy by linear interpolation of `threshold − value` between voxel centres, then the
//!   field is reinitialised by fast sweeping ([`crate::reinit`]).
//!
//! Voxel `(i, j, k)` of the image becomes node `(i, j, k)` of the grid (x fastest).

use crate::error::{Error, Result};
use crate::grid::{Grid, GridSpec};
use crate::reinit::redistance;

/// Squared 1-D distance transform of `f` (values 0 or ∞) into `d`, scratch `v`, `z`.
fn dt1d(f: &[f64], d: &mut [f64], v: &mut [usize], z: &mut [f64]) {
    let n = f.len();
    let Some(first) = f.iter().position(|x| x.is_finite()) else {
        d.fill(f64::INFINITY);
        return;
    };
    let mut k = 0usize;
    v[0] = first;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    for q in first + 1..n {
        if !f[q].is_finite() {
            continue;
        }
        let qf = q as f64;
        loop {
            let vk = v[k] as f64;
            let s = ((f[q] + qf * qf) - (f[v[k]] + vk * vk)) / (2.0 * (qf - vk));
            // z[0] = −∞, so this never pops the first parabola.
            if s <= z[k] {
                k -= 1;
                continue;
            }
            k += 1;
            v[k] = q;
            z[k] = s;
            z[k + 1] = f64::INFINITY;
            break;
        }
    }
    let mut k = 0usize;
    for (q, dq) in d.iter_mut().enumerate() {
        let qf = q as f64;
        while z[k + 1] < qf {
            k += 1;
        }
        let vk = v[k] as f64;
        *dq = (qf - vk) * (qf - vk) + f[v[k]];
    }
}

/// Squared Euclidean distance (in voxel units) to the nearest voxel with `seed == true`.
fn edt(dims: [usize; 3], seed: impl Fn(usize) -> bool) -> Vec<f64> {
    let [nx, ny, nz] = dims;
    let n = nx * ny * nz;
    // First axis directly: the squared distance to the nearest seed of the row, by a
    // forward and a backward scan (the same values as the parabola transform of 0/∞).
    let mut g = vec![f64::INFINITY; n];
    for (r, row) in g.chunks_exact_mut(nx).enumerate() {
        let base = r * nx;
        let mut last: Option<usize> = None;
        for (i, x) in row.iter_mut().enumerate() {
            if seed(base + i) {
                last = Some(i);
            }
            if let Some(q) = last {
                *x = ((i - q) * (i - q)) as f64;
            }
        }
        let mut next: Option<usize> = None;
        for (i, x) in row.iter_mut().enumerate().rev() {
            if *x == 0.0 {
                next = Some(i);
            } else if let Some(q) = next {
                *x = x.min(((q - i) * (q - i)) as f64);
            }
        }
    }
    let m = nx.max(ny).max(nz);
    let (mut f, mut d, mut v, mut z) = (
        vec![0.0; m],
        vec![0.0; m],
        vec![0usize; m],
        vec![0.0; m + 1],
    );
    let stride = [1, nx, nx * ny];
    for axis in 1..3 {
        let len = dims[axis];
        let s = stride[axis];
        // Visit each line once from its node with coordinate 0 along `axis` (enumerated
        // directly: an integer division per node costs as much as the transform).
        let starts: Box<dyn Iterator<Item = usize>> = if axis == 1 {
            Box::new((0..nz).flat_map(move |k| (0..nx).map(move |i| i + nx * ny * k)))
        } else {
            Box::new(0..nx * ny)
        };
        for start in starts {
            for t in 0..len {
                f[t] = g[start + t * s];
            }
            dt1d(&f[..len], &mut d[..len], &mut v[..len], &mut z[..len + 1]);
            for t in 0..len {
                g[start + t * s] = d[t];
            }
        }
    }
    g
}

impl Grid {
    /// Signed distance of a binary image (`true` = grain), exact EDT, surface half-way
    /// between unlike voxel centres.
    ///
    /// # Errors
    /// Invalid spec; [`Error::ImageSizeMismatch`]; [`Error::NoSurface`] if the image is all
    /// grain or all background.
    pub fn from_voxels(spec: GridSpec, inside: &[bool]) -> Result<Self> {
        spec.validate()?;
        if inside.len() != spec.len() {
            return Err(Error::ImageSizeMismatch {
                dims: spec.dims,
                expected: spec.len(),
                found: inside.len(),
            });
        }
        if inside.iter().all(|&b| b) || inside.iter().all(|&b| !b) {
            return Err(Error::NoSurface);
        }
        let to_in = edt(spec.dims, |i| inside[i]);
        let to_out = edt(spec.dims, |i| !inside[i]);
        let h = spec.spacing;
        let values = (0..spec.len())
            .map(|i| {
                if inside[i] {
                    -(to_out[i].sqrt() - 0.5) * h
                } else {
                    (to_in[i].sqrt() - 0.5) * h
                }
            })
            .collect();
        Grid::new(spec, values)
    }

    /// Signed distance of a grey-level image: grain where `value > threshold`, interface by
    /// linear interpolation between voxel centres (sub-voxel), then fast-sweeping
    /// reinitialisation.
    ///
    /// # Errors
    /// Invalid spec; [`Error::ImageSizeMismatch`]; [`Error::NonFiniteValue`] for NaN/∞
    /// intensities or threshold; [`Error::NoSurface`] if nothing crosses the threshold.
    pub fn from_grayscale(spec: GridSpec, image: &[f64], threshold: f64) -> Result<Self> {
        spec.validate()?;
        if image.len() != spec.len() {
            return Err(Error::ImageSizeMismatch {
                dims: spec.dims,
                expected: spec.len(),
                found: image.len(),
            });
        }
        if !threshold.is_finite() {
            return Err(Error::InvalidParameter {
                name: "threshold",
                value: threshold,
                requirement: "finite",
            });
        }
        if let Some((index, &value)) = image.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFiniteValue { index, value });
        }
        let mut values: Vec<f64> = image.iter().map(|v| threshold - v).collect();
        redistance(&spec, &mut values, false)?;
        Grid::new(spec, values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn one_dimensional_transform_is_exact() {
        let f = [
            f64::INFINITY,
            0.0,
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            0.0,
            f64::INFINITY,
        ];
        let mut d = [0.0; 7];
        let (mut v, mut z) = ([0usize; 7], [0.0; 8]);
        dt1d(&f, &mut d, &mut v, &mut z);
        let expect = [1.0, 0.0, 1.0, 4.0, 1.0, 0.0, 1.0];
        for (a, b) in d.iter().zip(expect) {
            approx::assert_abs_diff_eq!(*a, b, epsilon = 0.0);
        }
    }

    #[test]
    fn edt_matches_brute_force() {
        let dims = [9, 7, 8];
        let n = 9 * 7 * 8;
        // Deterministic scattered seeds.
        let seed = |i: usize| (i * 7919).is_multiple_of(23);
        let g = edt(dims, seed);
        let pos = |i: usize| [(i % 9) as f64, ((i / 9) % 7) as f64, (i / 63) as f64];
        for (i, gi) in g.iter().enumerate() {
            let p = pos(i);
            let mut best = f64::INFINITY;
            for j in (0..n).filter(|&j| seed(j)) {
                let q = pos(j);
                best =
                    best.min((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2));
            }
            approx::assert_abs_diff_eq!(*gi, best, epsilon = 1e-9);
        }
    }

    #[test]
    fn voxel_sphere_within_voxel_accuracy_and_grayscale_sub_voxel() {
        let spec = GridSpec::cube(41, -1.2, 1.2).expect("spec");
        let h = spec.spacing;
        let mut inside = Vec::new();
        let mut grey = Vec::new();
        for k in 0..41 {
            for j in 0..41 {
                for i in 0..41 {
                    let r = spec.node(i, j, k).coords.norm();
                    inside.push(r < 0.8);
                    grey.push((-(r * r)).exp());
                }
            }
        }
        let b = Grid::from_voxels(spec, &inside).expect("binary");
        let g = Grid::from_grayscale(spec, &grey, (-0.64f64).exp()).expect("grey");
        let (mut eb, mut eg) = (0.0f64, 0.0f64);
        for k in 0..41 {
            for j in 0..41 {
                for i in 0..41 {
                    let exact = spec.node(i, j, k).coords.norm() - 0.8;
                    if exact.abs() < 2.0 * h {
                        eb = eb.max((b.at(i, j, k) - exact).abs());
                        eg = eg.max((g.at(i, j, k) - exact).abs());
                    }
                }
            }
        }
        assert!(eb < 0.9 * h, "binary error {eb} vs h {h}");
        assert!(eg < 0.1 * h, "grey error {eg} vs h {h}");
        let _ = Point3::<f64>::origin();
        assert!(matches!(
            Grid::from_voxels(spec, &inside[1..]),
            Err(Error::ImageSizeMismatch { .. })
        ));
        assert!(matches!(
            Grid::from_voxels(spec, &vec![true; spec.len()]),
            Err(Error::NoSurface)
        ));
        let mut bad = grey.clone();
        bad[5] = f64::NAN;
        assert!(matches!(
            Grid::from_grayscale(spec, &bad, 0.5),
            Err(Error::NonFiniteValue { index: 5, .. })
        ));
    }
}
