//! Signed-distance (level-set) grids of grains — the grain representation of
//! LS-DEM (Kawamoto et al. 2016) and of GSC 2.0 (Medina 2018).
//!
//! Layer 0: no internal dependencies (see `docs/architecture.md`).

pub mod contact;
pub mod error;
pub mod grid;
pub mod io;
pub mod mesh;
pub mod properties;
pub mod reinit;
pub mod shapes;
pub mod star;
pub mod surface;
pub mod voxel;

pub use contact::{Body, NodeContact, contact, contact_into};
pub use error::{Error, Result};
pub use grid::{Grid, GridSpec};
pub use mesh::{MeshDistance, TriMesh};
pub use properties::{MassProperties, Principal};
pub use shapes::{Cuboid, Cylinder, Ellipsoid, Shape, Sphere, Superellipsoid};
pub use star::{DirectionTable, StarBuild, StarParams};
