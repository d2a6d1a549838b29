//! Advancing-front dense packing of disks (Pinto 2009) and of general
//! grains by particle-in-contact solvers (Pérez Morales et al. 2016).
//!
//! Purpose: fill a 2D domain with non-overlapping disks that follow a
//! prescribed grading, fast, and write them for DEM codes.
//!
//! Key items:
//! * [`pack`] / [`pack_seeded`] / [`pack_sizes`]: the advancing front of
//!   Pinto 2009, Ch. 3 (front list, search area, halos, candidate centres
//!   from halo intersections, feasibility, lowest-ordinate rule, front
//!   removal, Eq. 3-1 size list), configured by [`PackParams`]
//!   ([`BoundaryMode`], [`HaloMode`], [`FrontOrder`]); every choice the
//!   seed leaves open is listed in the `packer` module docs. Presets:
//!   [`PackParams::default`] (reproduces the seed's porosities),
//!   [`PackParams::dense`] (densest, about twice the cost; narrow channels
//!   and slots much denser) and [`PackParams::seed`] (the text's literal
//!   configuration);
//! * [`Grading`]: sieve curves with semi-log inverse-transform sampling
//!   (§4.2.1), constant, uniform, mixtures (Table 4.1), truncated
//!   log-normal; [`estimate_count`] (Eq. 3-1);
//! * [`Domain`]: rectangle, trapezoid (both orientations), circle, simple
//!   polygon (self-intersections rejected), fracture slot;
//! * [`SpatialIndex`] with [`CellGrid`] (default, fastest) and the seed's
//!   [`MxQuadtree`] (§3.1);
//! * metrics: [`porosity`] (Eq. 4-2), [`porosity_in_window`],
//!   [`check_packing`] (independent brute-force overlap/containment check,
//!   contacts, coordination number, minimum gap);
//! * 3D sphere packings ([`Sphere`] in a [`Container`]: box, periodic
//!   box, cylinder, closed mesh) and their metrics: [`check_spheres`]
//!   (independent cell-grid overlap and containment check, contacts,
//!   coordination), [`solid_fraction`], [`core_solid_fraction`] (exact for
//!   boxes and cylinders), [`radial_profile`] of a cylindrical specimen and
//!   [`grading_report`] (mass-based D10/D30/D60, Cu, Cc);
//! * [`optimise_porosity`]: genetic porosity control (§4.1–4.2);
//!   [`graded_layers`]: functionally graded property layers (§4.3);
//! * writers: [`write_csv`], [`write_vtu`], [`write_lammps_data`],
//!   [`write_yade`], [`write_svg`];
//! * 3D sphere packings ([`Sphere`] in a [`Container`]): writers and
//!   bit-exact round-trip readers [`write_lammps_data3`] /
//!   [`read_lammps_data3`] (LAMMPS/LIGGGHTS `atom_style sphere`),
//!   [`write_yade3`] / [`read_yade3`], [`write_csv3`] / [`read_csv3`],
//!   [`write_vtu3`] / [`read_vtu3`];
//! * particle in contact (Pérez Morales et al. 2016): closed-form wrappers
//!   [`contact2d`] and [`contact3d`], gap functions with Newton and
//!   Nelder–Mead [`gap`], grain shapes ([`Grain`], [`GrainShape`]:
//!   disks/spheres, spherocylinders, clusters, convex polygons/polyhedra),
//!   packings [`pack_pic`] in a square or cube ([`PicParams`],
//!   [`ContactMethod`], presets [`PicParams::perezmorales2016`]), the
//!   independent parry checker [`check_pic`] and [`write_pic_vtu`].
//!
//! ```
//! use packer_quadtree::{pack, check_packing, porosity, Domain, Grading, PackParams};
//! use rand::SeedableRng;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let domain = Domain::Rectangle { width: 20.0, height: 20.0 };
//! let p = pack(&domain, &Grading::Constant { diameter: 1.2 }, &PackParams::default(), &mut rng)?;
//! assert!(check_packing(&domain, &p.disks, 1e-9, 1e-9)?.is_clean());
//! assert!(porosity(&domain, &p.disks)? < 0.3);
//! # Ok::<(), packer_quadtree::Error>(())
//! ```
//!
//! Conventions: lengths in the caller's unit (the seed and the tests use
//! mm); gravity along −y: the front advances upwards and the lowest
//! candidate wins, ties to the left; 2D disks are exported as spheres at
//! `z = 0`. Determinism: sizes come from the caller's seeded RNG; the
//! packer itself is deterministic and independent of the spatial index;
//! the genetic algorithm derives per-individual ChaCha8 streams from
//! `(seed, index)` and gives identical results for any thread count.
//!
//! References: Pinto, R. C. (2009), *Geração de arranjos de partículas para
//! o método dos elementos discretos*, MSc thesis, PUC-Rio
//! (Certificação Digital 0721419/CA); Feng, Han & Owen (2003), Filling
//! domains with disks: an advancing front approach, IJNME 56,
//! doi:10.1002/nme.583; Samet (1990), The Design and Analysis of Spatial
//! Data Structures (MX quadtree); Pérez Morales, Roselló Valera, Recarey
//! Morfa & Muniz de Farias (2016), Dense packing of general-shaped particles
//! using analytical and minimization techniques, Rev. Cubana Cienc.
//! Informát. 10 (supl. 1); Nelder & Mead (1965), doi:10.1093/comjnl/7.4.308.

// Seeded randomised tests print their seed (house style).
#![cfg_attr(test, allow(clippy::print_stdout))]

mod clump_trim;
pub mod contact2d;
pub mod contact3d;
mod domain;
mod error;
mod ga;
pub mod gap;
mod grading;
pub mod grains3d;
mod index;
mod io;
mod metrics;
mod pack3d;
mod packer;
mod pic;
mod shapes;

pub use clump_trim::{ClumpTrim, separate_clumps};
pub use domain::Domain;
pub use error::{Error, Result};
pub use ga::{GaParams, GaResult, graded_layers, optimise_porosity};
pub use grading::{Grading, MixtureComponent, estimate_count};
pub use grains3d::{
    CheckParams, Fabric, GrainOverlapReport, GrainPackParams, GrainPackStats, GrainPacking,
    StarGrain, boundary_for, check_grain_overlaps, check_grain_overlaps_in, container_for,
    occupied, occupied_in, orientation_fabric, pack_grains, pack_grains_in, random_rotation,
};
pub use index::{CellGrid, MxQuadtree, SpatialIndex};
pub use io::{write_csv, write_lammps_data, write_svg, write_vtu, write_yade};
pub use metrics::{
    OverlapReport, Window, check_packing, disk_window_area, porosity, porosity_in_window,
};
pub use pack3d::{
    Boundary, Container, CoreFraction, DensePacking3, Densified, DensifyParams, DensifyStats,
    GradingReport, GradingStats, LammpsData3, MeshContainer, Pack3Params, Pack3Stats, Packing3,
    RadialBin, Sphere, SphereReport, Target, check_spheres, core_solid_fraction, densify,
    grading_report, max_overlap, pack3d, pack3d_dense, pack3d_seeded, pack3d_sizes, radial_profile,
    read_csv3, read_lammps_data3, read_vtu3, read_yade3, solid_fraction, write_csv3,
    write_lammps_data3, write_vtu3, write_yade3,
};
pub use packer::{
    BoundaryMode, Disk, FrontOrder, HaloMode, PackParams, PackStats, Packing, pack, pack_seeded,
    pack_sizes, pack_sizes_with_index, pack_with_index,
};
pub use pic::{
    ContactMethod, PicPacking, PicParams, PicReport, Placed, check_pic, pack_pic, write_pic_vtu,
};
pub use shapes::{Geometry, Grain, GrainShape, ParryConvex, Swept};
