//! Seed 001: packing general grains by particle in contact (Pérez Morales,
//! Roselló Valera, Recarey Morfa & Muniz de Farias 2016) — closed-form
//! contact positions, gap functions with Newton and Nelder–Mead, grain
//! shapes, advancing-front packings in a square or a cube and an
//! independent checker built on parry's exact distances.
//!
//! Key items:
//! * closed-form wrappers [`contact2d`] and [`contact3d`] (a disk or sphere
//!   tangent to two / three disks, spheres, lines, planes, segments,
//!   polygons and clusters; [`contact3d::intersect`] is also the kernel of
//!   the 3D sphere front in `packer-spheres`);
//! * gap functions with Newton and Nelder–Mead minimisation: [`gap`];
//! * grain shapes ([`Grain`], [`GrainShape`]: disks/spheres,
//!   spherocylinders, clusters, convex polygons/polyhedra);
//! * packings [`pack_pic`] in a square or cube ([`PicParams`],
//!   [`ContactMethod`], preset [`PicParams::perezmorales2016`]), the
//!   independent parry checker [`check_pic`] and [`write_pic_vtu`].
//!
//! ```
//! use packer_contact::{check_pic, pack_pic, PicParams};
//! let params = PicParams { max_grains: 40, ..PicParams::default() };
//! let packing = pack_pic::<2>(&params, 7)?;
//! assert!(check_pic(&packing, 1e-6)?.min_relative_gap > -1e-9);
//! # Ok::<(), packer_contact::Error>(())
//! ```
//!
//! Conventions: lengths in the caller's unit; gravity along −y in 2D and
//! −z in 3D; per-grain ChaCha8 streams from `(seed, index)`.
//!
//! References: Pérez Morales, Roselló Valera, Recarey Morfa & Muniz de
//! Farias (2016), Dense packing of general-shaped particles using
//! analytical and minimization techniques, Rev. Cubana Cienc. Informát. 10
//! (supl. 1); Nelder & Mead (1965), doi:10.1093/comjnl/7.4.308.

// Seeded randomised tests print their seed (house style).
#![cfg_attr(test, allow(clippy::print_stdout))]

pub mod contact2d;
pub mod contact3d;
mod error;
pub mod gap;
mod pic;
mod shapes;

pub use error::{Error, Result};
pub use pic::{
    ContactMethod, PicPacking, PicParams, PicReport, Placed, check_pic, pack_pic, write_pic_vtu,
};
pub use shapes::{Geometry, Grain, GrainShape, ParryConvex, Swept};
