//! The one error type of the crate: every public entry validates its input
//! and reports the offending values here.

/// Everything that can go wrong when packing or densifying spheres,
/// measuring a sphere packing, writing it or reading one back.
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
    /// A container mesh that cannot be used (open, non-manifold,
    /// inconsistently oriented, degenerate), as levelset reports it.
    #[error("container mesh: {0}")]
    Mesh(#[from] levelset::Error),
    /// A text format that cannot be read: the format, the 1-based line
    /// number (one past the last line for problems found at the end of the
    /// input) and what is wrong there.
    #[error("{format} line {line}: {message}")]
    Parse {
        /// Format name (`"lammps data"`, `"yade text"`, `"csv"`, `"vtu"`).
        format: &'static str,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A margin that leaves no core region inside the container.
    #[error("margin {margin} leaves an empty core region")]
    EmptyCore {
        /// The offending margin.
        margin: f64,
    },
    /// A metric that only applies to one kind of container.
    #[error("{what} needs a {expected} container, got a {got}")]
    WrongContainer {
        /// The metric.
        what: &'static str,
        /// The container kind it needs.
        expected: &'static str,
        /// The container kind given.
        got: &'static str,
    },
    /// The independent checker could not build its own (parry) copy of a
    /// container mesh.
    #[error("checker mesh: {reason}")]
    CheckerMesh {
        /// What parry reported.
        reason: String,
    },
    /// Overlap removal did not finish within the allowed sweeps.
    #[error(
        "overlaps remain after {sweeps} sweeps ({overlapping_pairs} pairs at grain scale {scale})"
    )]
    NotConverged {
        /// Sweeps run.
        sweeps: usize,
        /// Pairs still closer than the margin.
        overlapping_pairs: usize,
        /// Grain scale reached by the growth (1 = full size).
        scale: f64,
    },
    /// A requested solid fraction lies beyond what the densification can
    /// free of overlaps (beyond jamming).
    #[error(
        "solid fraction {requested} cannot be reached: the packing jams at {reached:.4} (the densest overlap-free state found)"
    )]
    FractionNotReached {
        /// The requested fraction.
        requested: f64,
        /// The highest overlap-free fraction reached.
        reached: f64,
    },
    /// An I/O error from a reader or a writer.
    #[error("reading or writing failed: {0}")]
    Io(#[from] std::io::Error),
    /// A grading (sieve curve, distribution) refused by `packer-quadtree`.
    #[error(transparent)]
    Grading(#[from] packer_quadtree::Error),
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
