//! Morphological DNA of grains (Medina 2018, §2.1–2.3) and its multivariate
//! distributions: the population statistics that GSC-style cloning samples
//! from and that judge the clones.
//!
//! # Key types
//!
//! * [`DnaTable`]: validated plain-data table, one column per [`Descriptor`],
//!   one row per grain; serialises to RON ([`DnaTable::write_ron`]) and CSV
//!   ([`DnaTable::write_csv`]).
//! * [`correlation_matrix`] (Pearson / Spearman, Medina 2018 Table 1) and
//!   [`neighbour_correlation`] of radii on a [`SphericalMesh`] (Table 2).
//! * [`Histogram1d`], [`Histogram2d`]; densities [`BicubicPdf`] (the seed's
//!   choice), [`GaussianKde2d`] (smoother alternative), [`TabulatedPdf2d`].
//! * Samplers: [`AcceptanceRejection2d`] (the seed's Monte Carlo),
//!   [`EnvelopeRejection2d`] (the same target with a per-bin envelope),
//!   [`InverseCdfSampler1d`] / [`InverseCdfSampler2d`] (exact tabulated
//!   inverse CDF with conditional draws), [`GaussianCopula`] (joint model of
//!   all descriptors, with draws conditional on any given descriptors).
//!   Conditional draws `y | x` (the cloner's quality control, Medina 2018
//!   §2.4) exist for the rejection, inverse-CDF and copula samplers.
//! * [`GradingCurve`] with D10/D30/D60, Cu and Cc.
//! * [`compare_populations`]: Medina 2018 Tables 4–5 errors, KS, W1 and
//!   correlation-matrix differences.
//!
//! * [`measure()`]: the per-grain descriptors of a `levelset::Grid` (only
//!   those asked for are computed), [`measure_star`] for any star-shaped
//!   radius function (e.g. a spherical-harmonic model), [`measure_table`] for
//!   a population, [`measure_with_frame`] for the descriptors and the
//!   principal frame from one pass; [`principal_frame`] (deterministic axis
//!   signs) and
//!   [`radial_profile`] on a [`SphericalMesh`]; [`convex_hull_volume`]
//!   (Quickhull) for the convexity. Definitions and the roundness corner rule
//!   are in the [`mod@measure`] module docs.
//!
//! # Example
//!
//! ```
//! use morph_dna::{
//!     correlation_matrix, BicubicPdf, CorrelationMethod, Descriptor, DnaTable, Histogram2d,
//!     InverseCdfSampler2d,
//! };
//! use rand::SeedableRng;
//!
//! let table = DnaTable::from_rows(
//!     vec![Descriptor::AspectRatio, Descriptor::MinPrincipalDimension],
//!     &[vec![0.5, 1.0e-3], vec![0.7, 1.4e-3], vec![0.6, 1.1e-3], vec![0.9, 1.9e-3]],
//! )?;
//! let r = correlation_matrix(&table, CorrelationMethod::Spearman)?;
//! let rho = r.get(Descriptor::AspectRatio, Descriptor::MinPrincipalDimension);
//! assert!(rho.is_some_and(|v| (v - 1.0).abs() < 1e-12));
//!
//! let (x, y) = (table.column(Descriptor::AspectRatio)?, table.column(Descriptor::MinPrincipalDimension)?);
//! let hist = Histogram2d::new(x, y, (4, 4), None, None)?;
//! let pdf = BicubicPdf::from_histogram(&hist, 8)?;
//! let sampler = InverseCdfSampler2d::new(&pdf.tabulate(8)?)?;
//! let mut rng = rand::rngs::StdRng::seed_from_u64(42);
//! let (ar, s) = sampler.sample(&mut rng);
//! assert!((0.5..=0.9).contains(&ar) && (1.0e-3..=1.9e-3).contains(&s));
//! # Ok::<(), morph_dna::Error>(())
//! ```
//!
//! # Conventions
//!
//! * Lengths in the caller's unit (SI metres for measured grains), angles in
//!   radians, θ polar from +z, φ azimuth from +x.
//! * Standard deviations use divisor `n − 1` (MATLAB's, which the seed used).
//! * Every stochastic function takes `rng: &mut impl rand::Rng`.
//! * Population statistics need ≥ 2 grains ([`Error::TooFewSamples`]); a
//!   constant descriptor makes correlations an [`Error::ConstantDescriptor`]
//!   (never NaN); empty histogram bins have density zero.
//!
//! # References
//!
//! * Medina, D. (2018). A geometry-based algorithm for cloning real grains 2.0
//!   (GSC 2.0). USFQ thesis.
//! * Jerves, A. X., Kawamoto, R. Y., Andrade, J. E. (2017). A geometry-based
//!   algorithm for cloning real grains. Granular Matter 19(2),
//!   doi:10.1007/s10035-017-0716-7.
//! * Keys, R. (1981). Cubic convolution interpolation for digital image
//!   processing. doi:10.1109/TASSP.1981.1163711.
//! * Genest, C., Ghoudi, K., Rivest, L.-P. (1995). A semiparametric estimation
//!   procedure of dependence parameters in multivariate families of
//!   distributions. doi:10.1093/biomet/82.3.543.
//! * Chen, H.-C., Asau, Y. (1974). On generating random variates from an
//!   empirical distribution. doi:10.1080/05695557408974946.

pub mod compare;
pub mod copula;
pub mod correlation;
pub mod csv;
mod descriptor;
pub mod error;
pub mod grading;
pub mod histogram;
pub mod hull;
pub mod measure;
pub mod pdf;
pub mod radial;
pub mod sampling;
pub mod stats;
pub mod table;

pub use compare::{
    DistributionDistance, ErrorTable, MomentErrors, PopulationComparison, compare_populations,
    ks_distance, ks_distance_to_cdf, moment_errors, wasserstein1,
};
pub use copula::GaussianCopula;
pub use correlation::{CorrelationMatrix, CorrelationMethod, correlation_matrix};
pub use error::{CsvErrorKind, Error, Moment, Result};
pub use grading::{GradingCoefficients, GradingCurve, GradingInterpolation, GradingWeight};
pub use histogram::{BinAxis, Histogram1d, Histogram2d};
pub use hull::{convex_hull, convex_hull_volume};
pub use measure::{
    BENDING_CORNER_OFFSET, CANONICAL_MARGIN, CANONICAL_RESOLUTION, CornerAveraging,
    MAX_CORNER_RADIUS_OFFSET, MeasureParams, Measurement, PrincipalFrame, RoundnessGrid,
    max_principal_curvature, measure, measure_star, measure_table, measure_with_frame,
    principal_frame, radial_profile,
};
pub use pdf::{Bandwidth, BicubicPdf, GaussianKde2d, TabulatedPdf2d};
pub use radial::{
    NeighbourCorrelation, NeighbourCorrelationSummary, RadialProfiles, SphericalMesh,
    all_neighbour_correlations, neighbour_correlation,
};
pub use sampling::{
    AcceptanceRejection2d, Density2d, EnvelopeRejection2d, InverseCdfSampler1d, InverseCdfSampler2d,
};
pub use table::{Descriptor, DnaTable};
