//! Real spherical-harmonic shape models of star-shaped grains, after Radvilaitė 2016
//! (doctoral dissertation, VGTU, "Spherical harmonics models and their application to
//! non-spherical shape particles") and Garboczi 2002 (doi:10.1016/S0008-8846(02)00836-0).
//!
//! Key types: [`ShModel`] (coefficients, evaluation of r(θ, φ) and its derivatives, grids,
//! rotation, truncation, conversion from complex NIST/VCCTL coefficients), [`grid::RingGrid`]
//! (Gauss–Legendre and threshold grids), [`fit`] (least squares with faer QR and SVD
//! diagnostics, block least squares on ring grids, quadrature transform),
//! [`integrals`] (volume, area, centroid, inertia; thesis cell integration and Gauss
//! quadrature), [`curvature`] (mean/Gaussian curvature, principal radii, Gauss–Bonnet),
//! [`contact`] (Hertz with curvature correction), [`shapes`] (analytic reference shapes),
//! [`sampling`] (the sampling strategies q = 1..8 and error norms of §2.2/§3.3)
//! [`segmentation`] (piecewise models, Eqs. 4.1–4.2) and [`vcctl`] (the `*-anm-*.dat` reader).
//!
//! # Conventions
//!
//! θ is the polar angle from +z, φ the azimuth from +x, radians. The basis is the real
//! orthonormal one, `Y_{l,m} = √2 p̄_l^m(θ) cos mφ`, `Y_{l,−m} = √2 p̄_l^m(θ) sin mφ`,
//! `Y_{l,0} = p̄_l^0`, with `p̄` fully normalised and **without** the Condon–Shortley phase
//! (see [`basis`]). Coefficients are stored at index `l² + l + m`.
//!
//! # Example
//!
//! ```
//! use sph_harmonics::{ShModel, fit, grid::RingGrid, integrals, shapes::Shape};
//!
//! # fn main() -> Result<(), sph_harmonics::Error> {
//! // Fit an oblate ellipsoid at degree 20 by quadrature and integrate it.
//! let shape = Shape::Ellipsoid { a: 2.0, b: 2.0, c: 1.0 };
//! let grid = RingGrid::gauss_legendre(20)?;
//! let radii: Vec<f64> = grid.points().iter().map(|&(t, p)| shape.radius(t, p)).collect();
//! let model: ShModel = fit::quadrature_transform(&grid, &radii, 20)?;
//! let props = integrals::gauss_integrals(&model, integrals::default_gauss_nodes(20))?;
//! assert!((props.volume - shape.volume()).abs() < 1e-4);
//! assert!((props.area - shape.area()).abs() < 5e-4);
//! # Ok(())
//! # }
//! ```
//!
//! Layer 0: no internal dependencies.

pub mod basis;
pub mod contact;
pub mod curvature;
pub mod error;
pub mod fit;
pub mod grid;
pub mod integrals;
pub mod model;
pub mod sampling;
pub mod segmentation;
pub mod shapes;
pub mod vcctl;

pub use error::Error;
pub use model::{RadiusDerivatives, ShModel};
