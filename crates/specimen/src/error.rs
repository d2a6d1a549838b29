//! The one error type of the crate: every stage validates its input and
//! reports the offending values, or the lower crate's error, here.

/// Everything that can go wrong when building a specimen or writing it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter or an input that cannot be used, with the reason.
    #[error("{what}: {message}")]
    Invalid {
        /// The offending parameter or input.
        what: String,
        /// Why it cannot be used.
        message: String,
    },
    /// A scene parameter that cannot be satisfied; the message names the
    /// parameter (e.g. "`container` is too small for the largest clone …").
    #[error("{0}")]
    Scene(String),
    /// The container cannot take every clone (an auto-sized one grows on it).
    #[error(
        "`container` cannot take all {clones} clones: their bounding spheres fill it after {placed}"
    )]
    ContainerFull {
        /// Clones to place.
        clones: usize,
        /// Bounding spheres that fitted.
        placed: usize,
    },
    /// The independent check (or a writer's own check) rejects the specimen.
    #[error("{0}")]
    Rejected(String),
    /// A stage failed on one item (a clone, a file): the item and the cause.
    #[error("{context}: {source}")]
    Context {
        /// The item or stage.
        context: String,
        /// The cause.
        #[source]
        source: Box<Error>,
    },
    /// The cloner refused or failed.
    #[error(transparent)]
    Cloner(#[from] cloner::Error),
    /// The grain packer or its check refused or failed.
    #[error(transparent)]
    Grains(#[from] packer_grains::Error),
    /// The sphere packer, a container or the sphere check refused or failed.
    #[error(transparent)]
    Spheres(#[from] packer_spheres::Error),
    /// A grading refused by `packer-quadtree`.
    #[error(transparent)]
    Grading(#[from] packer_quadtree::Error),
    /// A level set, a clump or a mesh refused by `levelset`.
    #[error(transparent)]
    LevelSet(#[from] levelset::Error),
    /// A descriptor measurement refused by `morph-dna`.
    #[error(transparent)]
    Dna(#[from] morph_dna::Error),
    /// Writing to the caller's writer failed.
    #[error("writing failed: {0}")]
    Io(#[from] std::io::Error),
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Adds the item or stage to an error (`anyhow`'s `with_context`, structured).
pub trait Context<T> {
    /// Wraps the error with `context()`.
    ///
    /// # Errors
    /// The wrapped error.
    fn context_with(self, context: impl FnOnce() -> String) -> Result<T>;
}

impl<T, E: Into<Error>> Context<T> for std::result::Result<T, E> {
    fn context_with(self, context: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| Error::Context {
            context: context(),
            source: Box::new(e.into()),
        })
    }
}

/// `Err(Error::Invalid { … })` with a formatted message.
macro_rules! invalid {
    ($what:expr, $($arg:tt)*) => {
        return Err($crate::error::Error::Invalid { what: ($what).to_string(), message: format!($($arg)*) })
    };
}
pub(crate) use invalid;
