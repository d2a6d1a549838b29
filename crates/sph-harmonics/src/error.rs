//! The crate's error type.

use thiserror::Error;

/// Every failure of a public entry point of this crate.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// The coefficient vector does not have `(degree + 1)²` entries.
    #[error("coefficient count {got} does not match degree {degree} (expected {expected})")]
    CoefficientCount {
        /// Requested degree.
        degree: usize,
        /// `(degree + 1)²`.
        expected: usize,
        /// Length supplied.
        got: usize,
    },
    /// A coefficient or input value is NaN or infinite.
    #[error("non-finite {what} at index {index}: {value}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Position in the input.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A sampled radius is zero or negative.
    #[error("radius at sample {index} is not positive: {value}")]
    NonPositiveRadius {
        /// Position of the sample.
        index: usize,
        /// The offending radius.
        value: f64,
    },
    /// A weight is negative or not finite.
    #[error("weight at sample {index} is invalid: {value}")]
    InvalidWeight {
        /// Position of the sample.
        index: usize,
        /// The offending weight.
        value: f64,
    },
    /// Input slices have different lengths.
    #[error("length mismatch: {what} has {got} entries, expected {expected}")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Supplied length.
        got: usize,
    },
    /// Fewer samples than unknown coefficients.
    #[error("degree {degree} needs at least {needed} samples, grid has {available}")]
    DegreeTooHighForGrid {
        /// Requested degree.
        degree: usize,
        /// `(degree + 1)²`.
        needed: usize,
        /// Samples available.
        available: usize,
    },
    /// A degree above the supported maximum, or a truncation above the model's degree.
    #[error("degree {degree} is out of range (maximum {max})")]
    DegreeOutOfRange {
        /// Requested degree.
        degree: usize,
        /// Largest allowed.
        max: usize,
    },
    /// A grid or quadrature size parameter is invalid.
    #[error("invalid grid parameter {what}: {value}")]
    InvalidGrid {
        /// Which parameter.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// An angle outside its domain (θ ∈ [0, π]) or non-finite.
    #[error("angle {what} out of range: {value}")]
    AngleOutOfRange {
        /// Which angle.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A shape parameter (semi-axis, radius of curvature, modulus) is invalid.
    #[error("invalid shape parameter {what}: {value}")]
    InvalidParameter {
        /// Which parameter.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The model's radius is not positive somewhere, so it is not a star-shaped surface.
    #[error("model radius is not positive at theta {theta}, phi {phi}: {value}")]
    ModelNotStarShaped {
        /// Polar angle.
        theta: f64,
        /// Azimuth.
        phi: f64,
        /// Radius found.
        value: f64,
    },
    /// The surface is degenerate at a point (zero metric determinant).
    #[error("degenerate surface metric at theta {theta}, phi {phi}")]
    DegenerateMetric {
        /// Polar angle.
        theta: f64,
        /// Azimuth.
        phi: f64,
    },
    /// The dense linear-algebra backend failed.
    #[error("linear algebra failure: {what}")]
    LinearAlgebra {
        /// Which step failed.
        what: &'static str,
    },
    /// A malformed line in a VCCTL `*-anm-*.dat` file.
    #[error("line {line}: {reason}")]
    Parse {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// Reading the input failed.
    #[error("i/o error at line {line}: {message}")]
    Io {
        /// 1-based line number being read.
        line: usize,
        /// The I/O error message.
        message: String,
    },
}

/// Checks that every value of `values` is finite.
pub(crate) fn check_finite(what: &'static str, values: &[f64]) -> Result<(), Error> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(Error::NonFinite {
            what,
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Checks a polar angle θ ∈ [0, π] and an azimuth φ that is finite.
pub(crate) fn check_angles(theta: f64, phi: f64) -> Result<(), Error> {
    if !(theta.is_finite() && (0.0..=std::f64::consts::PI).contains(&theta)) {
        return Err(Error::AngleOutOfRange {
            what: "theta",
            value: theta,
        });
    }
    if !phi.is_finite() {
        return Err(Error::AngleOutOfRange {
            what: "phi",
            value: phi,
        });
    }
    Ok(())
}
