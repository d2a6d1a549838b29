//! The crate's error type: one structured variant per kind of bad input.

use crate::descriptor::Descriptor;

/// Which moment a [`Error::ZeroReference`] refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Moment {
    /// The arithmetic mean.
    Mean,
    /// The sample standard deviation.
    StandardDeviation,
}

impl std::fmt::Display for Moment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Mean => "mean",
            Self::StandardDeviation => "standard deviation",
        })
    }
}

/// What went wrong on one line of a CSV DNA table (see [`Error::Csv`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CsvErrorKind {
    /// The input holds no header line.
    #[error("missing header line")]
    MissingHeader,
    /// A header field is not the snake-case name of a [`Descriptor`].
    #[error("unknown descriptor name {name:?}")]
    UnknownDescriptor {
        /// The offending field, as read.
        name: String,
    },
    /// A descriptor appears twice in the header.
    #[error("descriptor {descriptor} appears twice in the header")]
    DuplicateDescriptor {
        /// The repeated descriptor.
        descriptor: Descriptor,
    },
    /// A data line has the wrong number of fields.
    #[error("expected {expected} fields, found {found}")]
    FieldCount {
        /// Number of descriptors in the header.
        expected: usize,
        /// Number of fields on the line.
        found: usize,
    },
    /// A field is not a finite decimal number.
    #[error("field {column} ({text:?}) is not a finite number")]
    InvalidNumber {
        /// 1-based field index on the line.
        column: usize,
        /// The offending text.
        text: String,
    },
    /// The line is not valid UTF-8 or could not be read.
    #[error("unreadable line: {message}")]
    Read {
        /// The reader's message.
        message: String,
    },
}

/// Errors of the `morph-dna` crate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A DNA table was given no descriptor column.
    #[error("a dna table needs at least one descriptor")]
    NoDescriptors,
    /// A descriptor appears twice in a table.
    #[error("descriptor {descriptor} appears twice")]
    DuplicateDescriptor {
        /// The repeated descriptor.
        descriptor: Descriptor,
    },
    /// Columns or rows of a table have inconsistent lengths.
    #[error("{what} {index} has {found} values, expected {expected}")]
    RaggedTable {
        /// `"row"` or `"column"`.
        what: &'static str,
        /// Index of the offending row or column.
        index: usize,
        /// Expected number of values.
        expected: usize,
        /// Number of values found.
        found: usize,
    },
    /// A table entry is NaN or infinite.
    #[error("descriptor {descriptor} of grain {grain} is not finite ({value})")]
    NonFiniteValue {
        /// Column of the value.
        descriptor: Descriptor,
        /// Row (grain index) of the value.
        grain: usize,
        /// The value.
        value: f64,
    },
    /// A descriptor is not a column of the table.
    #[error("descriptor {descriptor} is not in the table")]
    MissingDescriptor {
        /// The requested descriptor.
        descriptor: Descriptor,
    },
    /// A population statistic was asked of too few samples (for example a
    /// correlation of a single grain).
    #[error("need at least {needed} samples, got {found}")]
    TooFewSamples {
        /// Minimum number of samples.
        needed: usize,
        /// Number of samples given.
        found: usize,
    },
    /// A descriptor takes one value across the whole population, so its
    /// correlations (and any spread-based statistic) are undefined.
    #[error("descriptor {descriptor} is constant ({value}) across the population")]
    ConstantDescriptor {
        /// The constant descriptor.
        descriptor: Descriptor,
        /// Its single value.
        value: f64,
    },
    /// A raw sample has no spread.
    #[error("sample is constant ({value})")]
    ConstantSample {
        /// Its single value.
        value: f64,
    },
    /// A raw sample value is NaN or infinite.
    #[error("sample value {index} is not finite ({value})")]
    NonFiniteSample {
        /// Index of the value.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Two paired samples have different lengths.
    #[error("paired samples have different lengths ({left} and {right})")]
    LengthMismatch {
        /// Length of the first sample.
        left: usize,
        /// Length of the second sample.
        right: usize,
    },
    /// A value that must be strictly positive is not.
    #[error("{what} {index} must be positive, got {value}")]
    NonPositive {
        /// What the value is (for example `"diameter"`).
        what: &'static str,
        /// Index of the value.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A histogram or table was asked for zero bins or cells.
    #[error("{what} must be at least {min}, got {value}")]
    CountTooSmall {
        /// Which count (for example `"bins"`).
        what: &'static str,
        /// Minimum accepted value.
        min: usize,
        /// The value.
        value: usize,
    },
    /// A bin, cell or refinement count exceeds the crate's limit
    /// ([`crate::histogram::MAX_CELLS`]) or overflows.
    #[error("{what} = {value} exceeds the limit {max}")]
    CountTooLarge {
        /// Which count.
        what: &'static str,
        /// The limit.
        max: usize,
        /// The requested count (saturated on overflow).
        value: usize,
    },
    /// A range is empty, reversed or not finite.
    #[error("invalid range [{min}, {max}]")]
    InvalidRange {
        /// Lower end.
        min: f64,
        /// Upper end.
        max: f64,
    },
    /// No sample falls inside a histogram's range.
    #[error("no sample falls inside the histogram range")]
    EmptyHistogram,
    /// A density is zero everywhere (or on the slice a conditional sampler was
    /// asked about).
    #[error("density has no mass {context}")]
    ZeroMass {
        /// Where the mass is missing.
        context: String,
    },
    /// A rejection sampler hit its proposal limit (the conditional slice has
    /// little or no mass).
    #[error("no proposal accepted in {trials} trials")]
    TooManyRejections {
        /// The limit that was reached.
        trials: usize,
    },
    /// A query point is outside the support of a distribution.
    #[error("{value} is outside the support [{min}, {max}]")]
    OutsideSupport {
        /// The query.
        value: f64,
        /// Lower end of the support.
        min: f64,
        /// Upper end of the support.
        max: f64,
    },
    /// A parameter is out of its documented domain.
    #[error("parameter {name} = {value} is invalid: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Accepted domain.
        reason: &'static str,
    },
    /// A spherical mesh has too few azimuthal or polar divisions.
    #[error("invalid spherical mesh {n_az} x ({n_pol} + 2): needs n_az >= 3 and n_pol >= 1")]
    InvalidMesh {
        /// Azimuthal divisions.
        n_az: usize,
        /// Polar rings (poles excluded).
        n_pol: usize,
    },
    /// A node index is outside the mesh or is a pole where a ring node is needed.
    #[error("node (i = {i}, j = {j}) is not a ring node of the {n_az} x ({n_pol} + 2) mesh")]
    NotARingNode {
        /// Azimuthal index.
        i: usize,
        /// Polar index (0 = north pole).
        j: usize,
        /// Azimuthal divisions.
        n_az: usize,
        /// Polar rings.
        n_pol: usize,
    },
    /// A correlation matrix could not be factorised.
    #[error("correlation matrix is not positive semidefinite (pivot {pivot} at index {index})")]
    NotPositiveSemidefinite {
        /// Index of the failing pivot.
        index: usize,
        /// Its value.
        pivot: f64,
    },
    /// A sample covariance matrix is singular (constant or perfectly
    /// correlated variables), so a Gaussian kernel cannot be built on it.
    #[error("sample covariance is singular (determinant {determinant})")]
    SingularCovariance {
        /// Its determinant.
        determinant: f64,
    },
    /// A reference statistic is zero, so a relative error is undefined.
    #[error("reference {moment} of {descriptor} is zero: relative error undefined")]
    ZeroReference {
        /// The descriptor.
        descriptor: Descriptor,
        /// The statistic.
        moment: Moment,
    },
    /// Two correlation matrices or tables do not describe the same descriptors.
    #[error("descriptor sets differ")]
    DescriptorMismatch,
    /// A line of a CSV table is malformed.
    #[error("csv line {line}: {kind}")]
    Csv {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        kind: CsvErrorKind,
    },
    /// A RON document could not be parsed or written.
    #[error("ron: {message}")]
    Ron {
        /// The parser's message, with its position.
        message: String,
    },
    /// The level-set library rejected a grid or a construction.
    #[error("level set: {message}")]
    LevelSet {
        /// The level-set error, rendered.
        message: String,
    },
    /// Writing to or reading from the caller's stream failed.
    #[error("i/o: {message}")]
    Io {
        /// The error's message.
        message: String,
    },
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Self::Io {
            message: e.to_string(),
        }
    }
}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
