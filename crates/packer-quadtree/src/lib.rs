//! Seed 004: the advancing-front dense packing of disks (Pinto 2009) with
//! its MX quadtree / cell grid, gradings, genetic porosity control and 2D
//! outputs.
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
//! * [`optimise_porosity`]: genetic porosity control (§4.1–4.2);
//!   [`graded_layers`]: functionally graded property layers (§4.3);
//! * writers: [`write_csv`], [`write_vtu`], [`write_lammps_data`],
//!   [`write_yade`], [`write_svg`];
//! * shared with the 3D packers (`packer-spheres`): [`MassCurve`] (mass
//!   passing of a number grading), [`write_vtu_glyphs`] and the normal
//!   distribution helpers [`erfc`], [`norm_cdf`], [`norm_ppf`].
//!
//! The other packers live in their own crates: `packer-spheres` (the 3D
//! sphere front and its densification), `packer-contact` (the
//! particle-in-contact solvers of Pérez Morales et al. 2016) and
//! `packer-grains` (packings of star-shaped grains).
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
pub use grading::{Grading, MassCurve, MixtureComponent, erfc, estimate_count, norm_cdf, norm_ppf};
pub use index::{CellGrid, MxQuadtree, SpatialIndex};
pub use io::{write_csv, write_lammps_data, write_svg, write_vtu, write_vtu_glyphs, write_yade};
pub use metrics::{
    OverlapReport, Window, check_packing, disk_window_area, porosity, porosity_in_window,
};
pub use packer::{
    BoundaryMode, Disk, FrontOrder, HaloMode, PackParams, PackStats, Packing, pack, pack_seeded,
    pack_sizes, pack_sizes_with_index, pack_with_index,
};
