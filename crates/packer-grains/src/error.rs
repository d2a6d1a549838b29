//! The one error type of the crate: every public entry validates its input
//! and reports the offending values here.

/// Everything that can go wrong when packing star-shaped grains, checking
/// a grain packing or trimming clumps.
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
    /// A particle list given to a writer or metric is empty where it must not be.
    #[error("{what} is empty")]
    Empty {
        /// What is empty.
        what: &'static str,
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
    /// A grain's star table or its rasterisation was refused by levelset.
    #[error("star grain: {0}")]
    StarTable(levelset::Error),
    /// The grains fill too much of the container to be packed (or the
    /// sphere skeleton could not place them all).
    #[error("grains fill {fraction} of the container, more than can be packed (limit {limit})")]
    TooDense {
        /// Grain volume over container volume.
        fraction: f64,
        /// The largest fraction attempted.
        limit: f64,
    },
    /// Trimming the clumps of a packing would take most of a sphere away (the packing is
    /// tighter than a clump of so few spheres can follow).
    #[error(
        "clump of shape {shape}: a sphere of radius {radius} would lose {percent:.0} % of it to its neighbours; use more spheres per clump"
    )]
    ClumpTrimTooDeep {
        /// The shape (template) index.
        shape: usize,
        /// The sphere's radius.
        radius: f64,
        /// The radius it would lose, in percent.
        percent: f64,
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
    /// A gravity settling ([`crate::Settle`]) did not bring the grains to
    /// rest within its iteration budget.
    #[error(
        "the grains did not come to rest under gravity in {iterations} FIRE iterations: the grains' mean net force left is {residual:.3e} of their mean weight (asked: {asked:.3e}); raise `Settle::max_iterations`"
    )]
    NotSettled {
        /// FIRE iterations run.
        iterations: usize,
        /// Mean net force of the grains over their mean weight.
        residual: f64,
        /// The asked bound, same unit.
        asked: f64,
    },
    /// The sphere skeleton or a container refused by `packer-spheres`.
    #[error(transparent)]
    Spheres(#[from] packer_spheres::Error),
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
