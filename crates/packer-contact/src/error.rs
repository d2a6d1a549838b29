//! The one error type of the crate: every public entry validates its input
//! and reports the offending values here.

/// Everything that can go wrong when building a grain shape, computing a
/// contact or a gap, packing grains in contact or writing the packing.
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
    /// A uniform distribution with `min > max`.
    #[error("uniform distribution needs min <= max, got {min} > {max}")]
    InvertedRange {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// A polygon with fewer than three vertices.
    #[error("polygon needs at least 3 vertices, got {got}")]
    PolygonTooFewVertices {
        /// Number of vertices given.
        got: usize,
    },
    /// Two vertices of a polygon or polyhedron coincide.
    #[error("vertices {first} and {second} coincide")]
    RepeatedVertex {
        /// Index of the first vertex.
        first: usize,
        /// Index of the second vertex.
        second: usize,
    },
    /// A polygon or polyhedron that must be convex is not.
    #[error("shape is not convex at vertex {vertex}")]
    NotConvex {
        /// Index of the first offending vertex.
        vertex: usize,
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
