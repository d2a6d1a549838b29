//! DEM specimens of cloned grains as a library: the pipeline behind
//! `cargo xtask specimen` — parents → clones → dense packing → independent
//! check → level sets on demand → clumps → DEM files — stage by stage, on
//! typed values, for DEM codes that build specimens without shelling out.
//!
//! Stages (each a function; the caller times them, shows progress and
//! stores the files):
//! 1. **clone**: [`clone_grains`] fits the cloner to the parents (passed in
//!    as data, `cloner::Parents`) and makes the distinct shapes
//!    ([`Clones`]; grain `k` copies shape `k mod shapes`), optionally
//!    graded by a [`SizeRule`];
//! 2. **place**: [`place::place_grains`] packs the shapes' star surfaces
//!    ([`Clones::star_grains`]) densely with `packer_grains::pack_grains`,
//!    in a fixed container or an auto-sized triaxial cylinder;
//!    [`place::place`] packs bounding spheres instead (loose, safe);
//! 3. **check**: [`check_grains`] (the independent LS-DEM node check) or
//!    [`check_bounding_spheres`]; a packing that fails is an `Err`;
//! 4. **level sets on demand**: [`shape_outputs`] rasterises one distinct
//!    shape and makes what the outputs ask ([`ShapeOptions`]: LS-DEM morph
//!    file in its principal frame, multi-sphere clump, DNA, VTU surface);
//! 5. **clumps**: [`clump_templates`] trims the clumps against every
//!    copy's neighbours (and closes their small gaps in a settled packing)
//!    and integrates each union's mass and inertia;
//! 6. **writers** (bytes or `impl Write`, never paths): [`dem`] (LAMMPS,
//!    LIGGGHTS and Yade decks, [`dem::write_lammps_clump_data`]),
//!    [`outputs`] (LS-DEM layout, the VTU of the surfaces, `poses.csv`).
//!
//! ```no_run
//! # fn demo(parents: &cloner::Parents, params: &cloner::Params, clock: &dyn cloner::Clock)
//! #     -> specimen::Result<()> {
//! use specimen::{clone_grains, check_grains, place::{place_grains, Preset}};
//! let hooks = cloner::Hooks { clock, progress: None };
//! let clones = clone_grains(parents, params, 200, 200, None, hooks)?;
//! let grains = clones.grains_of(&clones.star_grains()?);
//! // settled under gravity (None: spread over the container at the fraction asked)
//! let settle = Some(packer_grains::Settle::default());
//! let packed = place_grains(&grains, None, Some((0.5, false)), Preset::Default, 7, settle)?;
//! check_grains(&grains, &packed.poses, &packed.container)?;
//! # Ok(()) }
//! ```
//! The complete path to LAMMPS clump data is `examples/lammps_clumps.rs`.
//!
//! Conventions: lengths of the stages in the parents' unit, the DEM writers
//! in SI (the caller gives metres per unit); determinism: every stream comes
//! from `(seed, index)`, so a specimen is identical for any thread count.

mod error;

pub mod dem;
pub mod outputs;
pub mod place;
mod stages;

pub use error::{Context, Error, Result};
pub use stages::{
    CLUMP_DNA, CLUMP_REACH, Clones, ClumpTemplates, GrainCheck, MORPH_DECIMALS, STAR_FACE_CELLS,
    ShapeOptions, ShapeOut, SizeRule, SphereCheck, UNION_CELLS, check_bounding_spheres,
    check_grains, clone_grains, clump_templates, dem_bodies, grain_d_max, scale_container,
    scale_pose, shape_clumps, shape_outputs,
};
