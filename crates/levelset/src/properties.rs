//! Geometric and mass properties, each computed only on request.
//!
//! Design choice: volume, area, centroid and inertia are integrated exactly over the
//! closed piecewise-linear zero surface of [`crate::surface`] (divergence theorem: the
//! solid is the union of signed tetrahedra from a reference point to each triangle), without
//! storing a mesh; only cells crossed by the surface do work. This is sub-cell accurate
//! (sphere R = 1 on 45³ over [−1.2, 1.2]³: see the tests for the measured errors), unlike a
//! smoothed Heaviside whose error is O(h) in the band width. Where the linear reconstruction
//! is not trusted (cells with a corner whose gradient is not a unit vector: sharp edges and
//! kinks), the `sharp` module replaces the cell's volume by the exact volume under the corner
//! tangent planes (box 2 × 1 × 0.5 on 45³: −0.70 % → −0.04 %); [`Grid::volume_linear`]
//! keeps the uncorrected volume. Tetrahedron moments:
//! `∫ x xᵀ dV = V/20 · (Σ vᵢvᵢᵀ + s sᵀ)`, `s = Σ vᵢ` (Tonon 2004, J. Math. Stat. 1, Eq. 9–15).

use nalgebra::{Matrix3, Point3, SymmetricEigen, Vector3};

use crate::error::{Error, Result};
use crate::grid::Grid;
use crate::sharp::{CellCorrection, SharpSink};
use crate::surface::{Sink, Surface, walk, with_closed_values};

/// Volume, centroid and inertia tensor (per unit density, about the centroid).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Enclosed volume.
    pub volume: f64,
    /// Surface area.
    pub area: f64,
    /// Centre of volume.
    pub centroid: Point3<f64>,
    /// Inertia tensor about the centroid for unit density (multiply by density for mass).
    pub inertia: Matrix3<f64>,
}

/// Principal moments (ascending) and the corresponding unit axes (columns).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Principal {
    /// Principal moments of inertia, ascending.
    pub moments: Vector3<f64>,
    /// Columns are the principal axes, matching `moments`; right-handed.
    pub axes: Matrix3<f64>,
}

impl MassProperties {
    /// Principal moments and axes of the inertia tensor.
    pub fn principal(&self) -> Principal {
        let eig = SymmetricEigen::new(self.inertia);
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let moments = Vector3::new(
            eig.eigenvalues[idx[0]],
            eig.eigenvalues[idx[1]],
            eig.eigenvalues[idx[2]],
        );
        let mut axes = Matrix3::zeros();
        for (c, &i) in idx.iter().enumerate() {
            axes.set_column(c, &eig.eigenvectors.column(i));
        }
        if axes.determinant() < 0.0 {
            let c2 = -axes.column(2);
            axes.set_column(2, &c2);
        }
        Principal { moments, axes }
    }

    /// Diameter of the sphere of the same volume, `(6V/π)^(1/3)`.
    pub fn equivalent_diameter(&self) -> f64 {
        (6.0 * self.volume / std::f64::consts::PI).cbrt()
    }
}

#[derive(Default)]
struct Integrals<const AREA: bool, const MOMENTS: bool> {
    o: Vector3<f64>,
    vol6: f64,
    area2: f64,
    first24: Vector3<f64>,
    /// The upper triangle of `120 ∫ x xᵀ dV` (xx, xy, xz, yy, yz, zz): the tensor is
    /// symmetric, so six sums instead of nine (each the same expression, in the same order,
    /// as the full matrix's element).
    second120: [f64; 6],
}

/// `(row, column)` of each entry of [`Integrals::second120`].
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

impl<const AREA: bool, const MOMENTS: bool> Integrals<AREA, MOMENTS> {
    /// The full symmetric matrix of [`Integrals::second120`].
    fn second120(&self) -> Matrix3<f64> {
        let mut m = Matrix3::zeros();
        for (&(i, j), &v) in UPPER.iter().zip(&self.second120) {
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
        m
    }
}

impl<const AREA: bool, const MOMENTS: bool> Sink for Integrals<AREA, MOMENTS> {
    type V = Point3<f64>;
    fn vertex(&mut self, _: usize, _: usize, _: usize, _: u8, p: Point3<f64>) -> Point3<f64> {
        p
    }
    #[inline]
    fn triangle(&mut self, t: [Point3<f64>; 3]) {
        let a = t[0].coords - self.o;
        let b = t[1].coords - self.o;
        let c = t[2].coords - self.o;
        let bc = b.cross(&c);
        let det = a.dot(&bc);
        self.vol6 += det;
        if AREA {
            self.area2 += (b - a).cross(&(c - a)).norm();
        }
        if MOMENTS {
            let s = a + b + c;
            self.first24 += det * s;
            for (acc, &(i, j)) in self.second120.iter_mut().zip(&UPPER) {
                *acc += det * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]);
            }
        }
    }
}

/// A sink that ignores everything (the sharp-feature check of recorded cells).
struct NoSink;

impl Sink for NoSink {
    type V = ();
    fn vertex(&mut self, _: usize, _: usize, _: usize, _: u8, _: Point3<f64>) {}
    fn triangle(&mut self, _: [(); 3]) {}
}

impl Grid {
    /// The reference point of the integrals: the centre of the grid box.
    fn integration_origin(&self) -> Vector3<f64> {
        let spec = self.spec();
        spec.origin.coords
            + 0.5
                * spec.spacing
                * Vector3::new(
                    (spec.dims[0] - 1) as f64,
                    (spec.dims[1] - 1) as f64,
                    (spec.dims[2] - 1) as f64,
                )
    }

    /// The linear integrals and, with `SHARP`, the sharp-feature corrections.
    fn integrate<const AREA: bool, const MOMENTS: bool, const SHARP: bool>(
        &self,
    ) -> (Integrals<AREA, MOMENTS>, Vec<CellCorrection>) {
        let mut s = Integrals::<AREA, MOMENTS> {
            o: self.integration_origin(),
            ..Default::default()
        };
        let corrections = with_closed_values(self, |sp, v| {
            if SHARP {
                let mut w = SharpSink::new(&mut s, sp, v);
                walk(sp, v, &mut w);
                w.corrections
            } else {
                walk(sp, v, &mut s);
                Vec::new()
            }
        });
        (s, corrections)
    }

    /// Volume enclosed by the zero level set (0 if no node is inside): the piecewise-linear
    /// volume with the sharp-feature correction of the `sharp` module (no change for surfaces
    /// the grid resolves; the convex edges of a box are no longer cut).
    pub fn volume(&self) -> f64 {
        let (s, corrections) = self.integrate::<false, false, true>();
        s.vol6 / 6.0 + corrections.iter().map(|c| c.dv).sum::<f64>()
    }

    /// Volume enclosed by the piecewise-linear zero set alone (the method before the
    /// sharp-feature correction, kept for comparison).
    pub fn volume_linear(&self) -> f64 {
        self.integrate::<false, false, false>().0.vol6 / 6.0
    }

    /// Area of the zero level set.
    pub fn area(&self) -> f64 {
        self.integrate::<true, false, false>().0.area2 / 2.0
    }

    /// Volume, area, centroid and inertia tensor in one pass. Volume and moments include the
    /// sharp-feature correction of [`Grid::volume`] (each corrected cell's volume change is
    /// placed at the cell centre, an O(h²) error on a correction that is itself O(h²));
    /// the area is that of the piecewise-linear zero set.
    ///
    /// # Errors
    /// [`Error::NoSurface`] if the enclosed volume is not positive.
    pub fn mass_properties(&self) -> Result<MassProperties> {
        let (s, corrections) = self.integrate::<true, true, true>();
        finish_mass(s, corrections)
    }

    /// Volume, area, centroid and inertia tensor of the piecewise-linear zero set alone,
    /// without the sharp-feature correction of [`Grid::mass_properties`] (as
    /// [`Grid::volume_linear`]). Its integrals are smooth functions of the grid values,
    /// whereas the correction switches on and off per cell with a threshold on the
    /// corners' gradients: what an iteration on the values needs
    /// ([`crate::io::principal_morph`]).
    ///
    /// # Errors
    /// [`Error::NoSurface`] if the enclosed volume is not positive.
    pub fn mass_properties_linear(&self) -> Result<MassProperties> {
        let (s, _) = self.integrate::<true, true, false>();
        finish_mass(s, Vec::new())
    }

    /// [`Grid::mass_properties`] from a [`Surface`] extracted from this grid
    /// ([`Grid::surface`]): the integrals over its mesh and the sharp-feature corrections
    /// of its crossed cells, without walking the grid again (the same values bit for bit;
    /// on a 45³ cloned grain 10.9M instead of 13.4M instructions: the walk is skipped).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `surface` was not extracted from this grid (another
    /// layout or other values at the crossed cells); [`Error::NoSurface`] as
    /// [`Grid::mass_properties`].
    pub fn mass_properties_of(&self, surface: &Surface) -> Result<MassProperties> {
        let (s, corrections) = with_closed_values(self, |sp, v| {
            if !surface.matches(self, sp, v) {
                return Err(Error::InvalidParameter {
                    name: "surface",
                    value: f64::NAN,
                    requirement: "the surface extracted from this grid (Grid::surface)",
                });
            }
            let mut s = Integrals::<true, true> {
                o: self.integration_origin(),
                ..Default::default()
            };
            let verts = surface.mesh().vertices();
            for t in surface.mesh().triangles() {
                s.triangle(t.map(|i| verts[i]));
            }
            let mut sharp = SharpSink::new(NoSink, sp, v);
            for &[i, j, k] in surface.cells() {
                sharp.cell(i as usize, j as usize, k as usize);
            }
            Ok((s, sharp.corrections))
        })?;
        finish_mass(s, corrections)
    }

    /// Axis-aligned bounding box of the zero level set (min, max corners).
    ///
    /// # Errors
    /// [`Error::NoSurface`] if the grid has no surface.
    pub fn bounding_box(&self) -> Result<(Point3<f64>, Point3<f64>)> {
        struct Bb {
            lo: Vector3<f64>,
            hi: Vector3<f64>,
        }
        impl Sink for Bb {
            type V = ();
            fn vertex(&mut self, _: usize, _: usize, _: usize, _: u8, p: Point3<f64>) {
                self.lo = self.lo.inf(&p.coords);
                self.hi = self.hi.sup(&p.coords);
            }
            fn triangle(&mut self, _: [(); 3]) {}
        }
        let mut b = Bb {
            lo: Vector3::repeat(f64::INFINITY),
            hi: Vector3::repeat(f64::NEG_INFINITY),
        };
        with_closed_values(self, |sp, v| walk(sp, v, &mut b));
        if b.lo.x > b.hi.x {
            return Err(Error::NoSurface);
        }
        Ok((Point3::from(b.lo), Point3::from(b.hi)))
    }

    /// Largest inscribed sphere: radius `−min φ` and its centre (the minimum node, refined
    /// per axis by the vertex of the parabola through the node and its two neighbours).
    ///
    /// # Errors
    /// [`Error::NoSurface`] if no node is inside.
    pub fn inscribed_sphere(&self) -> Result<(f64, Point3<f64>)> {
        let (m, [i, j, k]) = self.min_node();
        if m >= 0.0 {
            return Err(Error::NoSurface);
        }
        let idx = [i, j, k];
        let dims = self.dims();
        let mut centre = self.spec().node(i, j, k);
        let mut value = m;
        for a in 0..3 {
            if idx[a] == 0 || idx[a] + 1 == dims[a] {
                continue;
            }
            let mut lo = idx;
            lo[a] -= 1;
            let mut hi = idx;
            hi[a] += 1;
            let (fl, fh) = (self.at(lo[0], lo[1], lo[2]), self.at(hi[0], hi[1], hi[2]));
            let curv = fl - 2.0 * m + fh;
            if curv > 0.0 {
                let t = (0.5 * (fl - fh) / curv).clamp(-0.5, 0.5);
                centre[a] += t * self.spacing();
                value += -0.125 * (fh - fl) * (fh - fl) / curv;
            }
        }
        Ok((-value, centre))
    }

    /// Equivalent diameter `(6V/π)^(1/3)`.
    pub fn equivalent_diameter(&self) -> f64 {
        (6.0 * self.volume() / std::f64::consts::PI).cbrt()
    }
}

/// Volume, area, centroid and inertia from the integrals and the sharp-feature corrections.
fn finish_mass(
    mut s: Integrals<true, true>,
    corrections: Vec<CellCorrection>,
) -> Result<MassProperties> {
    let mut second120 = s.second120();
    for cc in corrections {
        let x = cc.centre.coords - s.o;
        s.vol6 += 6.0 * cc.dv;
        s.first24 += 24.0 * cc.dv * x;
        // A point mass dv at x adds dv·x to ∫ x dV and dv·x xᵀ to ∫ x xᵀ dV.
        second120 += 120.0 * cc.dv * x * x.transpose();
    }
    let volume = s.vol6 / 6.0;
    if volume.is_nan() || volume <= 0.0 {
        return Err(Error::NoSurface);
    }
    let c = s.first24 / 24.0 / volume;
    let second = second120 / 120.0 - volume * c * c.transpose();
    let inertia = Matrix3::identity() * second.trace() - second;
    Ok(MassProperties {
        volume,
        area: s.area2 / 2.0,
        centroid: Point3::from(c + s.o),
        inertia,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::shapes::{Cuboid, Cylinder, Ellipsoid, Sphere};
    use approx::assert_abs_diff_eq;
    use nalgebra::{Isometry3, UnitQuaternion};
    use std::f64::consts::PI;

    #[test]
    fn sphere_volume_area_on_45_cubed() {
        let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
        let g = Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity())
            .expect("grid");
        let v = g.volume();
        let a = g.area();
        let ev = (v / (4.0 * PI / 3.0) - 1.0).abs();
        let ea = (a / (4.0 * PI) - 1.0).abs();
        assert!(ev < 0.003, "volume rel err {ev}");
        assert!(ea < 0.005, "area rel err {ea}");
        let mp = g.mass_properties().expect("mp");
        assert_abs_diff_eq!(mp.volume, v, epsilon = 1e-12);
        assert_abs_diff_eq!(mp.centroid.coords.norm(), 0.0, epsilon = 1e-9);
        let i_exact = 2.0 / 5.0 * (4.0 * PI / 3.0);
        for a in 0..3 {
            assert!((mp.inertia[(a, a)] / i_exact - 1.0).abs() < 0.01);
        }
        let (r, c) = g.inscribed_sphere().expect("inside");
        assert_abs_diff_eq!(r, 1.0, epsilon = 0.01);
        assert_abs_diff_eq!(c.coords.norm(), 0.0, epsilon = 0.03);
        let (lo, hi) = g.bounding_box().expect("bb");
        assert_abs_diff_eq!(lo.x, -1.0, epsilon = 1e-3);
        assert_abs_diff_eq!(hi.z, 1.0, epsilon = 1e-3);
        assert_abs_diff_eq!(g.equivalent_diameter(), 2.0, epsilon = 0.004);
    }

    #[test]
    fn rotated_ellipsoid_moments_and_axes() {
        let axes = Vector3::new(2.0, 1.5, 1.0);
        let e = Ellipsoid::new(axes).expect("e");
        let rot = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7);
        let pose = Isometry3::from_parts(Vector3::new(0.05, -0.1, 0.02).into(), rot);
        let spec = GridSpec::cube(45, -2.4, 2.4).expect("spec");
        let g = Grid::from_shape(spec, &e, &pose).expect("grid");
        let mp = g.mass_properties().expect("mp");
        let v_exact = 4.0 / 3.0 * PI * 3.0;
        assert!(
            (mp.volume / v_exact - 1.0).abs() < 0.005,
            "vol {}",
            mp.volume
        );
        let (a, b, c) = (axes.x, axes.y, axes.z);
        let m = v_exact / 5.0;
        // Ascending moments: about the longest axis is smallest.
        let exact = [
            m * (b * b + c * c),
            m * (a * a + c * c),
            m * (a * a + b * b),
        ];
        let p = mp.principal();
        for (i, ex) in exact.iter().enumerate() {
            assert!((p.moments[i] / ex - 1.0).abs() < 0.01, "moment {i}");
            let ax = rot * Vector3::ith(i, 1.0);
            let cos = p.axes.column(i).dot(&ax).abs().min(1.0);
            assert!(cos.acos().to_degrees() < 1.0, "axis {i}");
        }
        assert_abs_diff_eq!(
            (mp.centroid - Point3::new(0.05, -0.1, 0.02)).norm(),
            0.0,
            epsilon = 2e-3
        );
    }

    #[test]
    fn box_and_cylinder_volumes() {
        let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
        let b = Cuboid::new(Vector3::new(1.0, 0.5, 0.25)).expect("b");
        let g = Grid::from_shape(spec, &b, &Isometry3::identity()).expect("grid");
        // Acceptance: 0.5 %. The piecewise-linear zero set alone chamfers the 12 convex
        // edges (measured −0.70 % at h = 2.4/44); the sharp-feature correction restores
        // them (measured −0.041 %).
        let rel = g.volume() - 1.0;
        assert!(rel.abs() < 0.005, "box vol {}", g.volume());
        let lin = g.volume_linear() - 1.0;
        assert!(
            lin < -0.0065 && lin > -0.0075,
            "box linear vol {}",
            g.volume_linear()
        );
        assert_abs_diff_eq!(
            g.mass_properties().expect("mp").volume,
            g.volume(),
            epsilon = 1e-12
        );
        // A rotated box (edges oblique to the grid): measured −0.68 % linear, −0.13 %.
        let rot = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7);
        let bb = Cuboid::new(Vector3::new(0.8, 0.5, 0.25)).expect("b");
        let pose = Isometry3::from_parts(Vector3::new(0.01, 0.02, 0.0).into(), rot);
        let gr = Grid::from_shape(spec, &bb, &pose).expect("grid");
        let rel = gr.volume() / 0.8 - 1.0;
        assert!(rel.abs() < 0.003, "rotated box vol {}", gr.volume());
        let c = Cylinder::new(0.6, 0.8).expect("c");
        let g = Grid::from_shape(spec, &c, &Isometry3::identity()).expect("grid");
        let ve = PI * 0.36 * 1.6;
        assert!(
            (g.volume() / ve - 1.0).abs() < 0.01,
            "cyl vol {}",
            g.volume()
        );
        let empty = Grid::from_fn(spec, |_| 1.0).expect("g");
        assert_abs_diff_eq!(empty.volume(), 0.0);
        assert!(matches!(empty.mass_properties(), Err(Error::NoSurface)));
        assert!(matches!(empty.inscribed_sphere(), Err(Error::NoSurface)));
    }

    #[test]
    fn mass_from_the_extracted_surface_is_bit_identical() {
        let spec = GridSpec::cube(45, -1.2, 1.2).expect("spec");
        let rot = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7);
        let pose = Isometry3::from_parts(Vector3::new(0.01, 0.02, 0.0).into(), rot);
        let ell = Ellipsoid::new(Vector3::new(1.0, 0.6, 0.4)).expect("e");
        let bx = Cuboid::new(Vector3::new(0.8, 0.5, 0.25)).expect("b");
        // a sphere, an oblique ellipsoid, an oblique box (sharp-corrected cells) and a
        // sphere cut by the grid boundary (padded walk)
        let grids = [
            Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity()),
            Grid::from_shape(spec, &ell, &pose),
            Grid::from_shape(spec, &bx, &pose),
            Grid::from_shape(spec, &Sphere::new(1.3).expect("s"), &Isometry3::identity()),
        ];
        for g in grids {
            let g = g.expect("grid");
            let surface = g.surface();
            assert_eq!(surface.mesh(), &g.marching_cubes());
            let a = g.mass_properties().expect("walk");
            let b = g.mass_properties_of(&surface).expect("mesh");
            assert_eq!(a.volume.to_bits(), b.volume.to_bits());
            assert_eq!(a.area.to_bits(), b.area.to_bits());
            assert_eq!(a, b);
        }
        // a surface of another grid is refused
        let g1 = Grid::from_shape(spec, &ell, &pose).expect("grid");
        let g2 = Grid::from_shape(spec, &bx, &pose).expect("grid");
        let other = GridSpec::cube(41, -1.2, 1.2).expect("spec");
        let g3 = Grid::from_shape(other, &ell, &pose).expect("grid");
        for g in [&g2, &g3] {
            assert!(matches!(
                g.mass_properties_of(&g1.surface()),
                Err(Error::InvalidParameter {
                    name: "surface",
                    ..
                })
            ));
        }
        // an empty grid: an empty surface, and no volume
        let empty = Grid::from_fn(spec, |_| 1.0).expect("g");
        let s = empty.surface();
        assert!(s.mesh().vertices().is_empty());
        assert!(matches!(
            empty.mass_properties_of(&s),
            Err(Error::NoSurface)
        ));
    }
}
