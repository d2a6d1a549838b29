//! Real spherical-harmonic shape models of star-shaped grains
//! (Radvilaitė 2016).
//!
//! This crate will hold (issue 4): a real orthonormal spherical-harmonic basis
//! stable to high degree, shape models r(θ, φ) with derivatives, least-squares
//! and quadrature fits with diagnostics, the sampling strategies and error
//! norms of Radvilaitė 2016 §2.2, area/volume/inertia integrals, curvature,
//! the curvature-corrected Hertz contact, surface segmentation, analytic
//! reference shapes, and the NIST/VCCTL `*-anm-*.dat` reader.
//!
//! Layer 0: no internal dependencies (see `docs/architecture.md`).
