//! Signed-distance (level-set) grids of grains — the grain representation of
//! LS-DEM (Kawamoto et al. 2016) and of GSC 2.0 (Medina 2018).
//!
//! This crate will hold (issue 3): a uniform grid of signed distances
//! (negative inside, x fastest in memory) with a rigid pose; construction from
//! analytic shapes, star-shaped radius functions, closed triangle meshes and
//! binary voxel images; reinitialisation to a true distance field; trilinear
//! value/gradient queries; LS-DEM node-to-grid contact; volume, area, inertia
//! and principal axes; marching-cubes surfaces; and LS-DEM, LAMMPS-LSDEM, VTK
//! and STL readers/writers over `BufRead`/`Write`.
//!
//! Layer 0: no internal dependencies (see `docs/architecture.md`).
