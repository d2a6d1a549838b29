//! Geometric Stochastic Cloning 2.0 (Medina 2018): new grains statistically
//! indistinguishable from real parents.
//!
//! This crate will hold (issue 6): the GSC 2.0 pipeline (population model,
//! embryo ellipsoid, correlated radii on a spherical mesh, Laplacian
//! roundness polishing, volume-surface quality control, level-set
//! rasterisation) with validated parameters, per-clone `(seed, index)` random
//! streams and parallel generation.
//!
//! Layer 2: may depend on `morph-dna`, `levelset` and `sph-harmonics`.
