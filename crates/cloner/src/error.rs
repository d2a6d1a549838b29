//! The crate's error type: one structured variant per kind of bad input.

/// Errors of the cloner.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// No parent grain was given.
    #[error("no parent grains: cloning needs a population of at least {required}")]
    NoParents {
        /// Minimum number of parents.
        required: usize,
    },
    /// Too few parents for a population model (statistics need two or more).
    #[error("{found} parent grain(s): a population model needs at least {required}")]
    TooFewParents {
        /// Number of parents given.
        found: usize,
        /// Minimum number of parents.
        required: usize,
    },
    /// A parent grain cannot be measured or described on the spherical mesh.
    #[error("parent {index} is degenerate: {reason}")]
    DegenerateParent {
        /// Index of the parent in the input.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Every parent has the same value of a descriptor the model needs, so
    /// its distribution (histogram, correlation) is undefined.
    #[error("every parent has the same {what} ({value}): the population model needs spread")]
    ConstantParents {
        /// The descriptor.
        what: &'static str,
        /// The common value.
        value: f64,
    },
    /// A parameter is out of its domain.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name (field path of [`crate::Params`]).
        name: &'static str,
        /// The offending value.
        value: f64,
        /// The requirement it violates.
        reason: &'static str,
    },
    /// The spherical mesh cannot carry the Laplacian and neighbour stencil.
    #[error(
        "spherical mesh {n_az} x ({n_pol} + 2) is too coarse: the neighbour stencil and the Laplacian need n_az >= 4 and n_pol >= 2"
    )]
    MeshTooCoarse {
        /// Azimuthal divisions.
        n_az: usize,
        /// Polar rings (poles excluded).
        n_pol: usize,
    },
    /// More histogram bins than parents: most bins would be empty and the
    /// histograms would describe sampling noise, not the population.
    #[error("{bins} histogram bins for {parents} parents: use at most one bin per parent")]
    TooManyBins {
        /// Requested bins.
        bins: usize,
        /// Number of parents.
        parents: usize,
    },
    /// A clone index could not be accepted within the attempt limit.
    #[error(
        "clone {index}: no candidate accepted in {attempts} attempts (rejected: {} too round, {} roundness not reached, {} V/S quality control, {} measured roundness, {} predicted roundness, {} degenerate, {} target unavailable)",
        rejections.too_round,
        rejections.roundness_unreached,
        rejections.quality_control,
        rejections.measured_roundness,
        rejections.predicted_roundness,
        rejections.degenerate,
        rejections.target_unavailable
    )]
    TooManyRejections {
        /// The clone index.
        index: u64,
        /// Attempts made.
        attempts: usize,
        /// Why they were rejected.
        rejections: crate::rejections::Rejections,
    },
    /// An empty or reversed index range, or a shard that does not exist.
    #[error("invalid clone range {start}..{end}")]
    InvalidRange {
        /// First index.
        start: u64,
        /// One past the last index.
        end: u64,
    },
    /// A shard `k of n` with `k = 0`, `n = 0` or `k > n`.
    #[error("invalid shard {k} of {n} (1-based, k <= n)")]
    InvalidShard {
        /// 1-based shard number.
        k: u64,
        /// Number of shards.
        n: u64,
    },
    /// Error from `levelset`.
    #[error("level set: {message}")]
    LevelSet {
        /// The level-set error message.
        message: String,
    },
    /// Error from `morph-dna`.
    #[error("morphological DNA: {message}")]
    MorphDna {
        /// The morph-dna error message.
        message: String,
    },
    /// Writing an output failed.
    #[error("writing {what}: {message}")]
    Write {
        /// What was being written.
        what: &'static str,
        /// The underlying message.
        message: String,
    },
    /// Reading or writing the RON form of [`crate::Params`] failed.
    #[error("parameters (RON): {message}")]
    Ron {
        /// The parser's message, with its position.
        message: String,
    },
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, Error>;

impl From<levelset::Error> for Error {
    fn from(e: levelset::Error) -> Self {
        Self::LevelSet {
            message: e.to_string(),
        }
    }
}

impl From<morph_dna::Error> for Error {
    fn from(e: morph_dna::Error) -> Self {
        Self::MorphDna {
            message: e.to_string(),
        }
    }
}
