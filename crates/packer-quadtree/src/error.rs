//! The one error type of the crate: every public entry validates its input
//! and reports the offending values here.

/// Everything that can go wrong when building a grading, a domain, a 2D
/// packing, running the genetic algorithm or writing an output.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A value that must be finite is NaN or infinite.
    #[error("{what} must be finite, got {value}")]
    NonFinite {
        /// Name of the offending quantity.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A size, length or radius that must be positive is not.
    #[error("{what} must be positive, got {value}")]
    NonPositive {
        /// Name of the offending quantity.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A grading curve without enough points.
    #[error("grading needs at least {needed} points, got {got}")]
    GradingTooShort {
        /// Minimum number of points.
        needed: usize,
        /// Number of points given.
        got: usize,
    },
    /// Sieve sizes and passing percentages of different length.
    #[error("grading has {sizes} sieve sizes but {passing} passing values")]
    GradingLengthMismatch {
        /// Number of sieve sizes.
        sizes: usize,
        /// Number of passing values.
        passing: usize,
    },
    /// Sieve sizes not strictly increasing or passing percentages decreasing.
    #[error("grading is not monotone at point {index}: size {size}, passing {passing}")]
    GradingNotMonotone {
        /// Index of the first offending point.
        index: usize,
        /// Sieve size at that point.
        size: f64,
        /// Passing percentage at that point.
        passing: f64,
    },
    /// The passing percentages do not run from 0 to 100.
    #[error("grading passing must run from 0 to 100 %, got {first} to {last}")]
    GradingRange {
        /// First passing percentage.
        first: f64,
        /// Last passing percentage.
        last: f64,
    },
    /// A uniform distribution with `min > max`.
    #[error("uniform distribution needs min <= max, got {min} > {max}")]
    InvertedRange {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Mixture components that do not tile 0–100 % passing.
    #[error("mixture components must tile 0 to 100 % passing; gap or overlap at {at} %")]
    MixtureNotTiling {
        /// Passing percentage where the tiling breaks.
        at: f64,
    },
    /// A polygon with fewer than three vertices.
    #[error("polygon needs at least 3 vertices, got {got}")]
    PolygonTooFewVertices {
        /// Number of vertices given.
        got: usize,
    },
    /// Two non-adjacent edges of a polygon intersect (or adjacent ones overlap).
    #[error("polygon is self-intersecting: edges {first} and {second} intersect")]
    SelfIntersecting {
        /// Index of the first edge (from vertex `first` to `first + 1`).
        first: usize,
        /// Index of the second edge.
        second: usize,
    },
    /// A polygon with zero area.
    #[error("polygon has zero area")]
    DegeneratePolygon,
    /// The domain cannot hold a single largest particle.
    #[error("domain (inscribed size {domain}) is smaller than the largest particle ({particle})")]
    DomainTooSmall {
        /// Diameter of the largest inscribed circle (or a bound of it).
        domain: f64,
        /// Largest particle diameter.
        particle: f64,
    },
    /// A parameter outside its admissible range.
    #[error("parameter {what} = {value} is outside {range}")]
    Parameter {
        /// Parameter name.
        what: &'static str,
        /// The offending value.
        value: f64,
        /// The admissible range, as text.
        range: &'static str,
    },
    /// The estimated particle count exceeds the configured limit.
    #[error("estimated particle count {estimate} exceeds the limit {limit}")]
    TooManyParticles {
        /// Estimate of Pinto 2009, Eq. 3-1.
        estimate: f64,
        /// The configured limit.
        limit: usize,
    },
    /// A particle list given to a writer or metric is empty where it must not be.
    #[error("{what} is empty")]
    Empty {
        /// What is empty.
        what: &'static str,
    },
    /// An I/O error from a reader or a writer.
    #[error("reading or writing failed: {0}")]
    Io(#[from] std::io::Error),
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// `Ok(value)` if finite, else [`Error::NonFinite`].
pub(crate) fn finite(what: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::NonFinite { what, value })
    }
}

/// `Ok(value)` if finite and positive.
pub(crate) fn positive(what: &'static str, value: f64) -> Result<f64> {
    finite(what, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(Error::NonPositive { what, value })
    }
}
