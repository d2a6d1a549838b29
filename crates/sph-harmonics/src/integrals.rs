//! Volume, surface area, centroid and inertia tensor of star-shaped surfaces.
//!
//! Two methods, both available for comparison:
//!
//! * [`cell_integration`] — the thesis' scheme (Radvilaitė 2016, Eqs. 2.27–2.38): every cell
//!   of a polar grid gets a centre point whose radius is the mean of its four corner radii
//!   (Eq. 2.28), is split into four triangles (area Eq. 2.30) and four pyramids from the
//!   origin (volume Eqs. 2.35–2.37, computed as the signed triple product, which equals
//!   `h·S/3`). It works on any radius function, also non-smooth analytic shapes.
//! * [`gauss_integrals`] — Gauss–Legendre × equiangular quadrature of the exact integrands of
//!   a model: `V = ⅓∫ r³ dΩ` (Eq. 2.34), `S = ∫ r √(r² + r_θ² + r_φ²/sin²θ) dΩ` (Eq. 2.27),
//!   centroid `∫ r⁴/4 u dΩ / V` and inertia `∫ r⁵/5 (I − u uᵀ) dΩ` (Eqs. 2.39–2.41 and the
//!   off-diagonal terms), spectrally accurate for smooth surfaces.

use crate::error::Error;
use crate::grid::RingGrid;
use crate::model::{ShModel, direction};
use nalgebra::{Matrix3, Point3, Vector3};
use std::f64::consts::PI;

/// Integral properties of a solid bounded by a star-shaped surface, unit density.
#[derive(Debug, Clone, PartialEq)]
pub struct Integrals {
    /// Volume.
    pub volume: f64,
    /// Surface area.
    pub area: f64,
    /// Centroid (centre of mass at uniform density).
    pub centroid: Point3<f64>,
    /// Inertia tensor about the origin of the model frame, unit density.
    pub inertia_origin: Matrix3<f64>,
    /// Inertia tensor about the centroid, unit density (multiply by the density for mass units).
    pub inertia_centroid: Matrix3<f64>,
}

impl Integrals {
    /// Normalised area: area / area of the sphere of equal volume (1/Wadell sphericity).
    #[must_use]
    pub fn normalised_area(&self) -> f64 {
        let r = (3.0 * self.volume / (4.0 * PI)).cbrt();
        self.area / (4.0 * PI * r * r)
    }
}

/// Default number of Gauss nodes in θ for a model of degree L: `max(4L + 16, 24)`.
#[must_use]
pub fn default_gauss_nodes(degree: usize) -> usize {
    (4 * degree + 16).max(24)
}

/// Integrals of a model by Gauss quadrature of the exact integrands, with `n_theta` Gauss nodes
/// in cos θ and `2·n_theta` azimuths (see the module docs). Use [`default_gauss_nodes`].
///
/// # Errors
/// [`Error::InvalidGrid`] for `n_theta == 0`; [`Error::ModelNotStarShaped`] when the radius is
/// not positive at a node.
pub fn gauss_integrals(model: &ShModel, n_theta: usize) -> Result<Integrals, Error> {
    let grid = RingGrid::gauss_legendre_sized(n_theta, 2 * n_theta)?;
    let values = model.derivatives_grid(&grid)?;
    let mut volume = 0.0;
    let mut area = 0.0;
    let mut first = Vector3::zeros();
    let mut second = Matrix3::zeros();
    let mut k = 0;
    for ring in grid.rings() {
        let s = ring.theta.sin();
        for j in 0..ring.n_phi {
            let d = values[k];
            k += 1;
            let phi = ring.phi(j);
            if !(d.r.is_finite() && d.r > 0.0) {
                return Err(Error::ModelNotStarShaped {
                    theta: ring.theta,
                    phi,
                    value: d.r,
                });
            }
            let w = ring.weight;
            let u = direction(ring.theta, phi);
            let r2 = d.r * d.r;
            volume += w * r2 * d.r / 3.0;
            area += w * d.r * (r2 + d.r_theta * d.r_theta + (d.r_phi / s).powi(2)).sqrt();
            first += u * (w * r2 * r2 / 4.0);
            second += u * u.transpose() * (w * r2 * r2 * d.r / 5.0);
        }
    }
    Ok(assemble(volume, area, first, second))
}

/// From ∫x dV and ∫x xᵀ dV to centroid and inertia tensors.
fn assemble(volume: f64, area: f64, first: Vector3<f64>, second: Matrix3<f64>) -> Integrals {
    let inertia_origin = Matrix3::identity() * second.trace() - second;
    let c = first / volume;
    let shift = Matrix3::identity() * c.norm_squared() - c * c.transpose();
    Integrals {
        volume,
        area,
        centroid: Point3::from(c),
        inertia_origin,
        inertia_centroid: inertia_origin - shift * volume,
    }
}

/// Angular domain of the cell integration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellDomain {
    /// The whole sphere θ ∈ [0, π], φ ∈ [0, 2π).
    Sphere,
    /// One octant θ ∈ [0, π/2], φ ∈ [0, π/2]; results are multiplied by 8 (shapes with three
    /// symmetry planes, as sampled in Radvilaitė 2016 §2.2). The centroid is then the origin.
    SymmetricOctant,
}

/// Area and volume by the thesis' four-triangle cell integration (Radvilaitė 2016,
/// Eqs. 2.28–2.38) of a radius function on an `n_theta × n_phi` cell grid over `domain`.
///
/// # Errors
/// [`Error::InvalidGrid`] for zero sizes; [`Error::NonPositiveRadius`] / [`Error::NonFinite`]
/// when the radius function returns a bad value.
pub fn cell_integration(
    radius: impl Fn(f64, f64) -> f64,
    n_theta: usize,
    n_phi: usize,
    domain: CellDomain,
) -> Result<(f64, f64), Error> {
    if n_theta == 0 || n_phi == 0 {
        return Err(Error::InvalidGrid {
            what: "cell grid size",
            value: 0.0,
        });
    }
    let (theta_max, phi_max, factor) = match domain {
        CellDomain::Sphere => (PI, 2.0 * PI, 1.0),
        CellDomain::SymmetricOctant => (PI / 2.0, PI / 2.0, 8.0),
    };
    let thetas: Vec<f64> = (0..=n_theta)
        .map(|i| theta_max * i as f64 / n_theta as f64)
        .collect();
    let phis: Vec<f64> = (0..=n_phi)
        .map(|j| phi_max * j as f64 / n_phi as f64)
        .collect();
    let mut nodes = vec![Vector3::zeros(); (n_theta + 1) * (n_phi + 1)];
    let mut radii = vec![0.0; nodes.len()];
    for (i, &t) in thetas.iter().enumerate() {
        for (j, &p) in phis.iter().enumerate() {
            let r = radius(t, p);
            let idx = i * (n_phi + 1) + j;
            if !r.is_finite() {
                return Err(Error::NonFinite {
                    what: "radius",
                    index: idx,
                    value: r,
                });
            }
            if r <= 0.0 {
                return Err(Error::NonPositiveRadius {
                    index: idx,
                    value: r,
                });
            }
            radii[idx] = r;
            nodes[idx] = direction(t, p) * r;
        }
    }
    let mut area = 0.0;
    let mut volume = 0.0;
    for i in 0..n_theta {
        for j in 0..n_phi {
            let id = |a: usize, b: usize| a * (n_phi + 1) + b;
            let corners = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            // Eq. 2.28: centre radius = mean of the four corner radii.
            let ra = corners.iter().map(|&c| radii[c]).sum::<f64>() / 4.0;
            let centre = direction(
                0.5 * (thetas[i] + thetas[i + 1]),
                0.5 * (phis[j] + phis[j + 1]),
            ) * ra;
            for k in 0..4 {
                let x1 = nodes[corners[k]];
                let x2 = nodes[corners[(k + 1) % 4]];
                // Eqs. 2.30–2.31.
                area += 0.5 * (x2 - x1).cross(&(centre - x1)).norm();
                // Eqs. 2.35–2.37: pyramid from the origin, h·S/3 = |det(x1, x2, x_A)|/6.
                volume += x1.dot(&x2.cross(&centre)).abs() / 6.0;
            }
        }
    }
    Ok((area * factor, volume * factor))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::quadrature_transform;
    use crate::shapes::Shape;
    use approx::assert_relative_eq;

    fn fit_shape(shape: &Shape, degree: usize) -> ShModel {
        let grid = RingGrid::gauss_legendre(degree).expect("grid");
        let values: Vec<f64> = grid
            .points()
            .iter()
            .map(|&(t, p)| shape.radius(t, p))
            .collect();
        quadrature_transform(&grid, &values, degree).expect("transform")
    }

    #[test]
    fn sphere_integrals_are_exact() {
        let s = ShModel::sphere(1.5).expect("sphere");
        let i = gauss_integrals(&s, 16).expect("integrals");
        assert_relative_eq!(i.volume, 4.0 / 3.0 * PI * 1.5_f64.powi(3), epsilon = 1e-13);
        assert_relative_eq!(i.area, 4.0 * PI * 1.5 * 1.5, epsilon = 1e-13);
        let i_sphere = 0.4 * i.volume * 1.5 * 1.5;
        assert_relative_eq!(i.inertia_centroid[(0, 0)], i_sphere, epsilon = 1e-12);
        assert!(i.centroid.coords.norm() < 1e-14);
        assert_relative_eq!(i.normalised_area(), 1.0, epsilon = 1e-13);
    }

    #[test]
    fn oblate_ellipsoid_degree_20_volume_and_area() {
        let shape = Shape::Ellipsoid {
            a: 2.0,
            b: 2.0,
            c: 1.0,
        };
        let model = fit_shape(&shape, 20);
        let i = gauss_integrals(&model, default_gauss_nodes(20)).expect("integrals");
        let (v, s) = (shape.volume(), shape.area());
        assert_relative_eq!(v, 16.755_160_819_145_562, epsilon = 1e-12);
        assert_relative_eq!(s, 34.6875, epsilon = 1e-4);
        assert!((i.volume - v).abs() < 1e-4, "V {} vs {v}", i.volume);
        assert!((i.area - s).abs() < 5e-4, "S {} vs {s}", i.area);
        // Inertia of the exact spheroid: I_xx = V (b² + c²)/5, I_zz = V (a² + b²)/5.
        let ixx = v * (4.0 + 1.0) / 5.0;
        let izz = v * (4.0 + 4.0) / 5.0;
        assert_relative_eq!(i.inertia_centroid[(0, 0)], ixx, max_relative = 1e-4);
        assert_relative_eq!(i.inertia_centroid[(2, 2)], izz, max_relative = 1e-4);
        assert!(i.inertia_centroid[(0, 1)].abs() < 1e-8);
    }

    #[test]
    fn off_centre_sphere_has_shifted_centroid_and_parallel_axis_inertia() {
        // Sphere of radius 2 centred at (0, 0, 0.3): r(θ) = 0.3 cos θ + √(4 − 0.09 sin²θ).
        let shape = |t: f64, _p: f64| 0.3 * t.cos() + (4.0 - 0.09 * t.sin().powi(2)).sqrt();
        let degree = 40;
        let grid = RingGrid::gauss_legendre(degree).expect("grid");
        let values: Vec<f64> = grid.points().iter().map(|&(t, p)| shape(t, p)).collect();
        let model = quadrature_transform(&grid, &values, degree).expect("transform");
        let i = gauss_integrals(&model, 80).expect("integrals");
        let v = 4.0 / 3.0 * PI * 8.0;
        assert_relative_eq!(i.volume, v, max_relative = 1e-10);
        assert_relative_eq!(i.centroid.z, 0.3, epsilon = 1e-9);
        assert_relative_eq!(
            i.inertia_centroid[(0, 0)],
            0.4 * v * 4.0,
            max_relative = 1e-9
        );
        assert_relative_eq!(
            i.inertia_origin[(0, 0)],
            0.4 * v * 4.0 + v * 0.09,
            max_relative = 1e-9
        );
    }

    #[test]
    fn cell_integration_converges_for_sphere_and_box() {
        let (s, v) = cell_integration(|_, _| 1.0, 64, 128, CellDomain::Sphere).expect("cells");
        assert_relative_eq!(s, 4.0 * PI, max_relative = 1e-3);
        assert_relative_eq!(v, 4.0 / 3.0 * PI, max_relative = 1e-3);
        let (s8, v8) =
            cell_integration(|_, _| 1.0, 32, 32, CellDomain::SymmetricOctant).expect("cells");
        assert_relative_eq!(s8, s, max_relative = 1e-12);
        assert_relative_eq!(v8, v, max_relative = 1e-12);
        let cube = Shape::Box {
            a: 2.0,
            b: 2.0,
            c: 1.0,
        };
        let (s, v) = cell_integration(|t, p| cube.radius(t, p), 256, 512, CellDomain::Sphere)
            .expect("cells");
        assert_relative_eq!(v, 32.0, max_relative = 5e-3);
        assert_relative_eq!(s, 64.0, max_relative = 5e-3);
    }

    #[test]
    fn bad_input() {
        assert!(cell_integration(|_, _| -1.0, 4, 4, CellDomain::Sphere).is_err());
        assert!(cell_integration(|_, _| f64::NAN, 4, 4, CellDomain::Sphere).is_err());
        assert!(cell_integration(|_, _| 1.0, 0, 4, CellDomain::Sphere).is_err());
        let bad = ShModel::new(0, vec![-1.0]).expect("model");
        assert!(matches!(
            gauss_integrals(&bad, 8),
            Err(Error::ModelNotStarShaped { .. })
        ));
    }
}
