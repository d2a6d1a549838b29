//! Integration tests of morph-dna: the sampler acceptance point of issue 5
//! (10⁵ draws from each sampler reproduce a known bivariate distribution with
//! a Kolmogorov–Smirnov distance ≤ 0.02 per marginal) and population-level
//! oracles, and a Quickhull regression.

mod hull_regression;
mod population;
mod samplers;
