//! Advancing-front dense packing of disks (Pinto 2009).
//!
//! Purpose: fill a 2D domain with non-overlapping disks that follow a
//! prescribed grading, fast, for DEM codes.
//!
//! Key items: [`pack`] / [`pack_sizes`] (the advancing front of Pinto 2009,
//! Ch. 3) with [`PackParams`]; [`Grading`] (sieve curves with semi-log
//! inverse-transform sampling, constant, uniform, mixtures);
//! [`Domain`]; the [`SpatialIndex`] trait with [`CellGrid`] and the seed's
//! [`MxQuadtree`]; metrics ([`porosity`], [`check_packing`]).
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
//! Conventions: lengths in the caller's unit (the seed uses mm); gravity
//! along −y: the front advances upwards, the lowest candidate wins.
//!
//! References: Pinto, R. C. (2009), *Geração de arranjos de partículas para
//! o método dos elementos discretos*, MSc thesis, PUC-Rio,
//! doi:10.17771/PUCRio.acad.14425; Feng, Han & Owen (2003),
//! doi:10.1002/nme.827.

// Seeded randomised tests print their seed (house style).
#![cfg_attr(test, allow(clippy::print_stdout))]

mod domain;
mod error;
mod ga;
mod grading;
mod index;
mod io;
mod metrics;
mod packer;

pub use domain::Domain;
pub use error::{Error, Result};
pub use ga::{GaParams, GaResult, graded_layers, optimise_porosity};
pub use grading::{Grading, MixtureComponent, estimate_count};
pub use index::{CellGrid, MxQuadtree, SpatialIndex};
pub use io::{write_csv, write_lammps_data, write_svg, write_vtu, write_yade};
pub use metrics::{
    OverlapReport, Window, check_packing, disk_window_area, porosity, porosity_in_window,
};
pub use packer::{
    BoundaryMode, Disk, FrontOrder, HaloMode, PackParams, PackStats, Packing, pack, pack_seeded,
    pack_sizes, pack_sizes_with_index, pack_with_index,
};
