//! The one error type of the crate.

/// Everything that can go wrong in `levelset`; every variant carries the offending values.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Grid spacing must be finite and strictly positive.
    #[error("grid spacing must be finite and positive, got {spacing}")]
    NonPositiveSpacing {
        /// The spacing given.
        spacing: f64,
    },
    /// Every axis needs at least two cells (three nodes).
    #[error("axis {axis} has {nodes} nodes; at least 3 (2 cells) are required")]
    TooFewNodes {
        /// Axis index (0 = x, 1 = y, 2 = z).
        axis: usize,
        /// Number of nodes given on that axis.
        nodes: usize,
    },
    /// The grid would exceed the addressable size.
    #[error("grid of {dims:?} nodes is too large")]
    GridTooLarge {
        /// Requested dimensions.
        dims: [usize; 3],
    },
    /// The number of values does not match the dimensions.
    #[error("expected {expected} values for the grid, got {found}")]
    ValueCountMismatch {
        /// nx·ny·nz.
        expected: usize,
        /// Number given.
        found: usize,
    },
    /// A grid value (or produced value) is NaN or infinite.
    #[error("value {value} at index {index} is not finite")]
    NonFiniteValue {
        /// Linear index (x fastest).
        index: usize,
        /// The value.
        value: f64,
    },
    /// A geometric parameter is out of its domain.
    #[error("parameter {name} = {value} is invalid: {requirement}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// What is required.
        requirement: &'static str,
    },
    /// A radius function returned a non-finite or non-positive radius.
    #[error(
        "radius function returned {value} in direction ({x}, {y}, {z}); radii must be finite and positive"
    )]
    InvalidRadius {
        /// Returned value.
        value: f64,
        /// Direction x component.
        x: f64,
        /// Direction y component.
        y: f64,
        /// Direction z component.
        z: f64,
    },
    /// The grid has no zero crossing, so there is no surface to work on.
    #[error("the grid has no zero level set (no sign change between neighbouring nodes)")]
    NoSurface,
    /// A mesh is empty.
    #[error("mesh has no triangles")]
    EmptyMesh,
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index} but the mesh has {vertices} vertices")]
    VertexIndexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// Offending vertex index.
        index: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// A triangle has zero area or repeats a vertex.
    #[error("triangle {triangle} is degenerate (repeated vertex or zero area)")]
    DegenerateTriangle {
        /// Triangle index.
        triangle: usize,
    },
    /// The mesh is not closed and consistently oriented.
    #[error(
        "mesh is not closed: edge ({a}, {b}) is used {count} times in this direction and {reverse} times reversed"
    )]
    NonClosedMesh {
        /// First vertex of the edge.
        a: usize,
        /// Second vertex of the edge.
        b: usize,
        /// Number of triangles using a→b.
        count: usize,
        /// Number of triangles using b→a.
        reverse: usize,
    },
    /// An edge of a closed-mesh candidate is shared by more than two triangles.
    #[error(
        "mesh is not manifold: edge ({a}, {b}) from {pa:?} to {pb:?} is shared by {count} triangles ({edges} such edges)"
    )]
    NonManifoldEdge {
        /// First vertex of the edge (the smaller index, numbering of the input mesh).
        a: usize,
        /// Second vertex of the edge.
        b: usize,
        /// Position of `a`.
        pa: [f64; 3],
        /// Position of `b`.
        pb: [f64; 3],
        /// Number of triangles sharing the edge (≥ 3).
        count: usize,
        /// Number of edges shared by more than two triangles.
        edges: usize,
    },
    /// A closed-mesh candidate has boundary edges (edges of only one triangle): it has holes.
    #[error(
        "mesh is not closed: edge ({a}, {b}) from {pa:?} to {pb:?} belongs to one triangle only ({boundary_edges} boundary edges)"
    )]
    OpenMesh {
        /// First vertex of the edge (the smaller index, numbering of the input mesh).
        a: usize,
        /// Second vertex of the edge.
        b: usize,
        /// Position of `a`.
        pa: [f64; 3],
        /// Position of `b`.
        pb: [f64; 3],
        /// Number of boundary edges.
        boundary_edges: usize,
    },
    /// The triangles around a vertex form several fans instead of one disk (e.g. two
    /// solids touching at a corner).
    #[error(
        "mesh is not manifold at vertex {vertex} at {position:?}: its triangles form {fans} separate fans"
    )]
    NonManifoldVertex {
        /// Vertex index (numbering of the input mesh).
        vertex: usize,
        /// Its position.
        position: [f64; 3],
        /// Number of fans (≥ 2).
        fans: usize,
    },
    /// A mesh that should hold one grain holds several disconnected surfaces.
    #[error("mesh has {count} connected components; one grain per mesh is expected")]
    SeveralComponents {
        /// Number of edge-connected components.
        count: usize,
    },
    /// No consistent orientation exists (a one-sided surface such as a Klein bottle).
    #[error("mesh is not orientable: triangle {triangle} cannot be oriented consistently")]
    NonOrientable {
        /// Index of the triangle (input numbering) where the conflict was found.
        triangle: usize,
    },
    /// Triangles disagree in orientation and repair was refused.
    #[error(
        "mesh orientation is inconsistent: {flipped} of {triangles} triangles would have to be flipped"
    )]
    InconsistentOrientation {
        /// Number of triangles in the minority orientation.
        flipped: usize,
        /// Number of (non-degenerate) triangles.
        triangles: usize,
    },
    /// A consistently oriented mesh faces inward (negative volume) and repair was refused.
    #[error("mesh faces inward (signed volume {volume}); refusing to invert it")]
    InwardOrientation {
        /// Signed volume (negative).
        volume: f64,
    },
    /// A closed mesh encloses no volume (flat, or negligible against its area).
    #[error("mesh encloses zero volume (signed volume {volume}, area {area})")]
    ZeroVolume {
        /// Signed volume.
        volume: f64,
        /// Total area.
        area: f64,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Vertex index.
        index: usize,
    },
    /// More surface nodes were requested than the surface can provide.
    #[error(
        "requested {requested} surface nodes but only {available} candidates exist at this resolution"
    )]
    TooManyNodes {
        /// Requested count.
        requested: usize,
        /// Candidate count.
        available: usize,
    },
    /// A voxel image does not match its stated dimensions.
    #[error("image has {found} voxels but dimensions {dims:?} need {expected}")]
    ImageSizeMismatch {
        /// Stated dimensions.
        dims: [usize; 3],
        /// Required number of voxels.
        expected: usize,
        /// Number given.
        found: usize,
    },
    /// A file could not be parsed.
    #[error("{format} parse error at line {line}: {reason}")]
    Parse {
        /// Format name (`"morph"`, `"lammps"`, `"vtk"`, `"stl"`, `"obj"`).
        format: &'static str,
        /// 1-based line number (0 for binary data: see `reason`).
        line: usize,
        /// What was wrong.
        reason: String,
    },
    /// A label image axis has no voxel.
    #[error("label image axis {axis} has size 0; every axis needs at least one voxel")]
    EmptyAxis {
        /// Axis index (0 = x, 1 = y, 2 = z).
        axis: usize,
    },
    /// A label image (or a file header) claims more voxels than the crate accepts.
    #[error("label image of {dims:?} voxels is too large (at most {max_voxels} voxels)")]
    ImageTooLarge {
        /// Claimed dimensions (x, y, z); for a header, the shape as declared.
        dims: [usize; 3],
        /// The cap ([`crate::labels::MAX_VOXELS`]).
        max_voxels: u64,
    },
    /// A stored label is negative or does not fit a `u32`.
    #[error("{format} label {value} at byte offset {offset} is out of range (0 ..= 4294967295)")]
    LabelOutOfRange {
        /// Format name (`"npy"`, `"raw"`).
        format: &'static str,
        /// Byte offset of the element from the start of the stream.
        offset: u64,
        /// The stored value.
        value: i64,
    },
    /// A label does not fit the data type asked for by a writer.
    #[error("label {label} at voxel {index} does not fit the data type {dtype}")]
    LabelDoesNotFit {
        /// The label.
        label: u32,
        /// Linear voxel index (x fastest).
        index: usize,
        /// The requested data type.
        dtype: crate::io::dtype::Dtype,
    },
    /// A data type name or NumPy `descr` that is not supported.
    #[error(
        "unsupported data type {name:?}; supported: u8, u16, u32, i32, i64 (npy: |u1 <u2 >u2 <u4 >u4 <i4 >i4 <i8 >i8)"
    )]
    UnsupportedDtype {
        /// The name or `descr` found.
        name: String,
    },
    /// The data section of a binary stream is shorter or longer than the header or layout says.
    #[error("{format} data size mismatch: expected {expected} bytes of voxel data, found {found}")]
    DataSizeMismatch {
        /// Format name (`"npy"`, `"raw"`).
        format: &'static str,
        /// Bytes required by the shape and data type.
        expected: u64,
        /// Bytes present (counted to the end of the stream).
        found: u64,
    },
    /// A TIFF page cannot be read as a label slice.
    #[error("tiff page {page}: {reason}")]
    Tiff {
        /// 0-based page (= z slice) index.
        page: usize,
        /// What was wrong, naming the layout found (colour type, bits, sample format, size).
        reason: String,
    },
    /// A label image holds no grain (every voxel is 0).
    #[error("the label image has no non-zero label (all {voxels} voxels are background)")]
    EmptyLabelImage {
        /// Number of voxels.
        voxels: usize,
    },
    /// Extraction found labels but kept none of them.
    #[error(
        "no usable grain among {labels} labels: {border} touch the image border, {too_small} have fewer than {min_voxels} voxels, {several_components} have several components, {no_surface} lost their surface to smoothing"
    )]
    NoUsableGrain {
        /// Distinct non-zero labels found.
        labels: usize,
        /// Skipped because they touch the border.
        border: usize,
        /// Skipped because they are too small.
        too_small: usize,
        /// The `min_voxels` threshold in force.
        min_voxels: usize,
        /// Rejected for having several connected components.
        several_components: usize,
        /// Skipped because the smoothed image did not cross the threshold.
        no_surface: usize,
    },
    /// Reading or writing failed.
    #[error("i/o error: {0}")]
    Io(#[from] std::io::Error),
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, Error>;
