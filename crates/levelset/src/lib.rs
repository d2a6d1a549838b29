//! Signed-distance (level-set) grids of grains — the grain representation of LS-DEM
//! (Kawamoto et al. 2016) and of GSC 2.0 (Medina 2018, 45³ level sets).
//!
//! # Key types
//! * [`Grid`] / [`GridSpec`]: uniform grid of signed distances, negative inside, x fastest;
//!   trilinear [`Grid::value`], corrected [`Grid::sample`] (value + gradient),
//!   [`Grid::closest_point`], [`Grid::surface_nodes`].
//! * Construction: analytic [`Shape`]s ([`Sphere`], [`Ellipsoid`], [`Cuboid`], [`Cylinder`])
//!   via [`Grid::from_shape`]; [`Superellipsoid`] and any star-shaped radius function via
//!   [`Grid::from_star`] (cube-map direction table, narrow-band second-order distances and a
//!   closest-point interior, or the seed's full fast sweeping: [`StarParams`], [`Redistance`]);
//!   closed triangle meshes via [`Grid::from_mesh`] ([`MeshDistance`]: BVH + pseudonormals;
//!   exact everywhere) or [`Grid::from_mesh_banded`] (exact within a band of
//!   [`MESH_BAND_CELLS`], fast-swept beyond; same volume, area and mass properties),
//!   users' grain meshes made closed, manifold and outward by [`TriMesh::prepare_closed`]
//!   (policy [`Orientation`], report [`MeshRepair`]) and framed by [`TriMesh::centroid`] and
//!   [`GridSpec::around_points`];
//!   voxel images via [`Grid::from_voxels`] (exact EDT) and [`Grid::from_grayscale`];
//!   [`Grid::reinitialise`] (fast sweeping).
//! * Properties on request: [`Grid::volume`] (sharp-feature corrected; [`Grid::volume_linear`]
//!   without), [`Grid::area`], [`Grid::mass_properties`]
//!   ([`MassProperties::principal`]), [`Grid::bounding_box`], [`Grid::inscribed_sphere`],
//!   [`Grid::equivalent_diameter`].
//! * [`Grid::marching_cubes`] → [`TriMesh`] (closed, oriented, shared vertices);
//!   [`Grid::surface`] → [`Surface`] (the mesh and the cells it crosses), from which
//!   [`Grid::mass_properties_of`] integrates without walking the grid again (bit for bit
//!   [`Grid::mass_properties`]).
//! * LS-DEM contact: [`Body`], [`contact()`] / [`contact_into`] → [`NodeContact`].
//! * Multi-sphere clumps for DEM codes without level sets: [`clump()`] ([`ClumpParams`],
//!   [`VolumeCorrection`]) → [`Clump`] (CLUMP's distance-transform generator on φ, radii
//!   grown to the grain's volume), [`clump_quality`] → [`ClumpQuality`] (volume, principal
//!   moments and surface deviation of the union of the spheres), see [`clump`](mod@clump).
//! * Labelled images (watershed-segmented CT scans): [`LabelImage`] (x fastest, 0 =
//!   background, [`LabelImage::paint`] rasterises grids), [`LabelImage::extract`] →
//!   [`Extraction`] (one level set per grain, [`ExtractParams`]: border exclusion,
//!   `min_voxels`, [`ComponentPolicy`], pad, Gaussian smoothing; [`Skipped`] labels with a
//!   [`SkipReason`]), see [`labels`].
//! * [`io`]: LS-DEM morph files, LAMMPS LSDEM grid files, VTK structured points, STL
//!   (binary and ASCII) and Wavefront OBJ meshes; label images as NumPy `.npy`, multi-page TIFF and raw binary ([`io::Dtype`],
//!   [`io::RawLayout`]).
//!
//! # Example
//! ```
//! use levelset::nalgebra::{Isometry3, Point3, Vector3};
//! use levelset::{Body, Grid, GridSpec, Sphere, StarParams, contact};
//!
//! // A 45³ grid over [−1.2, 1.2]³ holding a lumpy star-shaped grain.
//! let spec = GridSpec::cube(45, -1.2, 1.2)?;
//! let (grain, build) = Grid::from_star(
//!     spec,
//!     &Point3::origin(),
//!     |u| 0.9 + 0.1 * u.x * u.y,
//!     &StarParams::default(),
//! )?;
//! assert_eq!(build.radius_calls, 6 * 33 * 33);
//! let mp = grain.mass_properties()?;
//! assert!(mp.volume > 2.5 && mp.volume < 3.6);
//!
//! // Two unit spheres overlapping by 0.1: LS-DEM node-to-grid contact.
//! let sphere = Grid::from_shape(spec, &Sphere::new(1.0)?, &Isometry3::identity())?;
//! let nodes = sphere.surface_nodes(500)?;
//! let body = Body::new(sphere, nodes)?;
//! let other = Isometry3::translation(1.9, 0.0, 0.0);
//! let hits = contact(&body, &Isometry3::identity(), &body, &other);
//! let deepest = hits.iter().map(|c| c.penetration).fold(0.0, f64::max);
//! assert!(deepest > 0.08 && deepest <= 0.1 + 1e-3);
//! # let _ = Vector3::<f64>::zeros();
//! # Ok::<(), levelset::Error>(())
//! ```
//!
//! # Conventions
//! * φ < 0 inside, |∇φ| = 1 near the surface; node `(i, j, k)` at `origin + h·(i, j, k)`,
//!   stored at `i + nx·(j + ny·k)`.
//! * Body frames: a [`Body`]'s grid and nodes share one frame; poses map body → world.
//! * Properties are per unit density; lengths in the grid's units.
//! * Meshes: triangles counter-clockwise seen from outside (positive
//!   [`TriMesh::signed_volume`]); mesh errors name vertices and edges by index and
//!   position, and the caller adds the file name.
//!
//! # References
//! * Kawamoto, Andò, Viggiani, Andrade 2016, J. Mech. Phys. Solids 91,
//!   doi:10.1016/j.jmps.2016.02.021 (LS-DEM).
//! * Zhao 2005, Math. Comp. 74, doi:10.1090/S0025-5718-04-01678-3 (fast sweeping).
//! * Bærentzen & Aanæs 2005, IEEE TVCG 11, doi:10.1109/TVCG.2005.49 (pseudonormals).
//! * Felzenszwalb & Huttenlocher 2012, Theory Comput. 8, doi:10.4086/toc.2012.v008a019 (EDT).
//! * Lorensen & Cline 1987, doi:10.1145/37402.37422 (marching cubes).
//! * Angelidakis, Nadimi, Otsubo, Utili 2021, SoftwareX 15, 100735,
//!   doi:10.1016/j.softx.2021.100735 (CLUMP multi-sphere generators).
//!
//! Layer 0: no internal dependencies (see `docs/architecture.md`).

pub mod clump;
pub mod contact;
mod crew;
pub mod error;
pub mod grid;
pub mod io;
pub mod labels;
pub mod mesh;
pub mod properties;
pub mod reinit;
pub mod shapes;
mod sharp;
pub mod star;
pub mod surface;
pub mod voxel;

/// Re-export of the vector vocabulary of the API, so callers need no separate pin.
pub use nalgebra;

pub use clump::{
    Clump, ClumpParams, ClumpQuality, VolumeCorrection, clump, clump_quality, union_mass_properties,
};
pub use contact::{Body, NodeContact, contact, contact_into};
pub use error::{Error, Result};
pub use grid::{Grid, GridSpec};
pub use labels::{
    Bending, ComponentPolicy, ExtractParams, ExtractedGrain, Extraction, LabelImage,
    ROUNDNESS_SMOOTHING, SkipCounts, SkipReason, Skipped,
};
pub use mesh::{FAR_ERROR_CELLS, MESH_BAND_CELLS, MeshDistance, MeshRepair, Orientation, TriMesh};
pub use properties::{MassProperties, Principal};
pub use shapes::{Cuboid, Cylinder, Ellipsoid, Shape, Sphere, Superellipsoid};
pub use star::{
    BAND_CELLS, DirectionTable, Redistance, StarBuild, StarParams, StarTable, cube_map_directions,
};
pub use surface::Surface;
