//! Morphological DNA of grains (Medina 2018, §2.1–2.3) and its multivariate
//! distributions.
//!
//! This crate will hold (issue 5): per-grain descriptors measured on level-set
//! grids and spherical-harmonic models (volume, area, volume/surface ratio,
//! equivalent diameter, principal dimensions, aspect ratio, elongation,
//! flatness, sphericity, convexity, 3D roundness), radial profiles on a
//! principal-axis-aligned spherical mesh, population models (correlations,
//! histograms, interpolated PDFs, samplers, copulas), grading curves and
//! population comparison statistics.
//!
//! Layer 1: may depend on `levelset` and `sph-harmonics`.
