//! Advancing-front packings of general grains in a square (2D) or cube (3D)
//! with the particle-in-contact solvers (Pérez Morales et al. 2016,
//! Pseudocode 1 and §3), and an independent overlap checker built on
//! parry's exact distances.
//!
//! Algorithm (choices the seed leaves open are ours):
//! 1. the first grain sits in the corner touching the `D` lower walls;
//! 2. the front holds placed grains ordered by height (last axis; gravity
//!    along −y in 2D, −z in 3D); the new grain (circumscribed radius
//!    `U[r_min, r_max]`, random orientation, both from the ChaCha8 stream
//!    `(seed, index)`) is tried around the lowest front grain `P`: every set
//!    of `P` plus `D − 1` reachable grains or walls gives up to two contact
//!    positions ([`ContactMethod`]); the lowest position that overlaps
//!    nothing and stays in the domain wins;
//! 3. if nothing fits around `P`, a grain of the smallest size with the
//!    same orientation is tried there: if it does not fit either, `P`
//!    leaves the front, else the next front grain is tried (up to 32);
//!    a grain that fits nowhere is discarded (counted in
//!    [`PicPacking::rejected`]);
//! 4. the packing ends when the front is empty, after 400 discards in a
//!    row, or at [`PicParams::max_grains`].
//!
//! [`ContactMethod::ApproxWrappers`] (disk/sphere clusters only) replaces
//! step 2's grain-level sets by element-level ones on a cell grid of every
//! placed element and drops a front grain at its first failure once the
//! front holds 32 grains (no smallest-grain probe); see its docs.
//!
//! Overlap tolerance: a candidate is accepted with every gap
//! `≥ −1e-10·R_mob`; contacts are solved to `1e-13·R_mob` (closed forms
//! and Newton) or `1e-10·R_mob` (Nelder–Mead).

mod approx;
mod check;
mod front;
mod grid;
mod params;
mod vtu;
mod wrap;

pub use check::{PicReport, check_pic};
pub use front::{PicPacking, Placed, pack_pic};
pub use params::{ContactMethod, PicParams};
pub use vtu::write_pic_vtu;

#[cfg(test)]
mod tests;
