//! The scene file of `cargo xtask specimen SCENE.ron`: its schema, parsing
//! (RON, every struct and enum refuses unknown keys) and validation.
//!
//! Schema (every key but `clones` and `container` may be left out; relative
//! paths are relative to the workspace root, as every xtask path):
//!
//! ```ron
//! Scene(
//!     // the embedded 71 Ottawa-sand grains (default), or any input of `--parents`:
//!     // Files(path: "fixtures/grains/vcctl/MA107-6-fine", format: Some(Anm), spacing: None,
//!     //       raw_dims: None, raw_dtype: None, big_endian: false, keep_border: false,
//!     //       min_voxels: None, smoothing: None, minimal_bending: false, sh_degree: None,
//!     //       resolution: 45)
//!     parents: Ottawa,
//!     calibrated: None,            // Some("my-sand.ron"); default fixtures/calibrated/gsc2-ottawa.ron
//!     clones: Count(200),          // or Graded(count: 200, grading: "uniform:200,400"):
//!                                  // each clone rescaled to a volume-equivalent diameter
//!                                  // drawn from the grading (by number; `cargo xtask pack` syntax)
//!     distinct_shapes: None,       // Some(1000): 1000 clones, grain k a copy of clone k mod 1000
//!     seed: None,                  // default: the calibrated seed
//!     length_unit: None,           // metres per parents' unit (Ottawa: 1e-6; required for Files)
//!     container: AutoCylinder(solid_fraction: 0.5),
//!                                  // or Cylinder(diameter: 3000.0, height: None) (H = 2 D),
//!                                  // or Box(x: 2500.0, y: 2500.0, z: 2500.0); lengths in the parents' unit
//!     placement: Grains,           // dense packing of the grains themselves (pack_grains),
//!                                  // or BoundingSpheres (loose: one sphere per grain)
//!     settle: false,               // true: settle the packing under gravity (frictionless)
//!                                  // and lower the lid onto the bed: what a DEM code
//!                                  // loads under gravity then stays put
//!     preset: Default,             // or Dense (the sphere packer's presets: the bounding
//!                                  // spheres, or the grain packer's skeleton)
//!     level_set_resolution: 45,    // nodes per axis of each output level set
//!     outputs: (
//!         lsdem: false,            // LS-DEM morph files + poses
//!         lsdem_nodes: 1000,       // surface nodes per morph file
//!         lsdem_spacing: None,     // one grid spacing for all morph files (default: the median grain's)
//!         lammps_clumps: true,     // LAMMPS data of all clump spheres + body ids
//!         liggghts_templates: false, // LIGGGHTS particletemplate/multisphere files
//!         yade_clumps: false,      // Yade clump list + loader script
//!         clump: (spheres_per_clump: 20, overlap: 0.6),
//!         density: 2650.0,         // particle density, kg/m³ (quartz)
//!         lsdem_name: "specimen",  // InitState/positions_<NAME>.dat, rotations_<NAME>.dat
//!         vtu: false,              // marching-cubes surfaces of every placed grain (ParaView)
//!         vtu_resolution: 16,      // cells across each grain's level-set box for its VTU surface (≈ 44 KB per grain)
//!         report: false,           // DNA and grading report with SVG plots
//!     ),
//!     out_dir: "target/specimen",
//! )
//! ```

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Deserialize;

use crate::parents::InputFormat;

/// A specimen scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Scene {
    /// Where the parents come from.
    #[serde(default)]
    pub(crate) parents: ParentsSpec,
    /// The calibrated cloner configuration (default: the committed Ottawa one).
    #[serde(default)]
    pub(crate) calibrated: Option<PathBuf>,
    /// How many clones, and their sizes.
    pub(crate) clones: Clones,
    /// Distinct clone shapes (default: one per grain): with `Some(n)` only `n` clones are
    /// made and grain `k` is a copy of clone `k mod n` (own pose, same size): LS-DEM's own
    /// morph reuse, so that `n` morph files (the others are links) and `n` LIGGGHTS
    /// templates serve any number of grains.
    #[serde(default)]
    pub(crate) distinct_shapes: Option<u64>,
    /// Master seed (default: the calibrated configuration's).
    #[serde(default)]
    pub(crate) seed: Option<u64>,
    /// Metres per length unit of the parents (and of every length in this scene: the
    /// container, the grading, `lsdem_spacing`). Default for the embedded Ottawa grains:
    /// [`OTTAWA_LENGTH_UNIT`]; required for `Files` parents. Every output is written in
    /// metres.
    #[serde(default)]
    pub(crate) length_unit: Option<f64>,
    /// The container.
    pub(crate) container: ContainerSpec,
    /// Accept a container narrower than 8 d_max (d_max: the largest clone's
    /// volume-equivalent diameter, or bounding diameter with `BoundingSpheres`),
    /// where the walls dominate the packing; refused otherwise.
    #[serde(default)]
    pub(crate) allow_narrow_container: bool,
    /// How the clones are placed.
    #[serde(default)]
    pub(crate) placement: Placement,
    /// Settle the grain packing under gravity (−z) before anything is written
    /// (`packer_grains::Settle`: frictionless, until every grain is at rest on its
    /// contacts), then lower the container's lid onto the bed; the specimen's solid
    /// fraction is then the settled bed's. For specimens a DEM code will load under
    /// gravity: they do not compact further there. `placement: Grains` and a walled
    /// container only.
    #[serde(default)]
    pub(crate) settle: bool,
    /// The sphere packer's preset (bounding spheres, or the grain packer's
    /// skeleton).
    #[serde(default)]
    pub(crate) preset: Preset,
    /// Nodes per axis of every output level set.
    #[serde(default = "default_resolution")]
    pub(crate) level_set_resolution: usize,
    /// What to write.
    #[serde(default)]
    pub(crate) outputs: Outputs,
    /// Output folder.
    #[serde(default = "default_out_dir")]
    pub(crate) out_dir: PathBuf,
    /// The scene file's text (for the provenance of every output).
    #[serde(skip)]
    pub(crate) source_text: String,
}

/// Metres per scan unit of the embedded NIST/VCCTL Ottawa-sand grains (see
/// `fixtures/grains/vcctl/README.md`, "Units").
pub(crate) const OTTAWA_LENGTH_UNIT: f64 = 1e-6;

/// The default particle density, kg/m³ (quartz).
pub(crate) const QUARTZ_DENSITY: f64 = 2650.0;

fn default_resolution() -> usize {
    45
}

fn default_out_dir() -> PathBuf {
    PathBuf::from("target/specimen")
}

/// Where the parents come from.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) enum ParentsSpec {
    /// The embedded 71 Ottawa-sand grains (spherical harmonics → level sets).
    #[default]
    Ottawa,
    /// Any input of `--parents` (see `parents.rs`).
    Files {
        /// A labelled image file or a directory of per-grain files.
        path: PathBuf,
        /// Input format (default: from the extension and contents).
        #[serde(default)]
        format: Option<InputFormat>,
        /// Voxel spacing of a labelled image.
        #[serde(default)]
        spacing: Option<f64>,
        /// Raw image dimensions (x fastest).
        #[serde(default)]
        raw_dims: Option<(usize, usize, usize)>,
        /// Raw voxel type (u8, u16, u32, i32, i64).
        #[serde(default)]
        raw_dtype: Option<String>,
        /// Raw image is big-endian.
        #[serde(default)]
        big_endian: bool,
        /// Keep grains touching the image border.
        #[serde(default)]
        keep_border: bool,
        /// Skip labels with fewer voxels.
        #[serde(default)]
        min_voxels: Option<usize>,
        /// Gaussian smoothing σ in voxels.
        #[serde(default)]
        smoothing: Option<f64>,
        /// Minimal-bending surfaces and corner correction for labelled images
        /// (`--minimal-bending`).
        #[serde(default)]
        minimal_bending: bool,
        /// Spherical-harmonic degree of `anm` files.
        #[serde(default)]
        sh_degree: Option<usize>,
        /// Level-set nodes per axis for mesh and SH grains.
        #[serde(default = "default_resolution")]
        resolution: usize,
    },
}

/// Number (and sizes) of the clones.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) enum Clones {
    /// `count` clones at the sizes the cloner draws (the parents' sizes).
    Count(u64),
    /// `count` clones, each rescaled so that its `size` measure is a size
    /// drawn (by number) from `grading` (`cargo xtask pack --grading`
    /// syntax; `sieve-mass:SIZE:PASSING,…` is a lab's curve by mass).
    Graded {
        /// Number of clones.
        count: u64,
        /// The grading, e.g. `"uniform:20,40"`.
        grading: String,
        /// What a drawn size is (default the volume-equivalent diameter).
        #[serde(default)]
        size: SizeMeasure,
    },
}

/// The grain dimension a grading's sizes stand for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
pub(crate) enum SizeMeasure {
    /// The volume-equivalent diameter `(6 V / π)^(1/3)`.
    #[default]
    Equivalent,
    /// The intermediate principal dimension `I` (of the volume-scaled
    /// inertia-equivalent ellipsoid): a grain passes a square sieve opening
    /// `s` when `I ≤ s`, the usual reading of a sieve analysis.
    Intermediate,
}

impl SizeMeasure {
    /// Scale that gives a grain of volume `volume` and principal dimensions
    /// `dims = [L, I, S]` the size `drawn` in this measure.
    pub(crate) fn scale(self, drawn: f64, volume: f64, dims: [f64; 3]) -> f64 {
        match self {
            Self::Equivalent => drawn / (6.0 * volume / std::f64::consts::PI).cbrt(),
            Self::Intermediate => drawn / dims[1],
        }
    }
}

impl Clones {
    pub(crate) fn count(&self) -> u64 {
        match self {
            Self::Count(n) | Self::Graded { count: n, .. } => *n,
        }
    }
}

/// The container; lengths in the parents' unit.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) enum ContainerSpec {
    /// A walled cylinder with its axis along z and its base at the origin
    /// (H = 2 D, the triaxial specimen, unless `height` is given).
    Cylinder {
        /// Inner diameter.
        diameter: f64,
        /// Inner height (default 2 × diameter).
        #[serde(default)]
        height: Option<f64>,
    },
    /// A cylinder with H/D = 2 sized so that the clones fill
    /// `solid_fraction` of it (`Grains`: the grains' volume; when the grain
    /// packer cannot separate them there, the scene fails naming the
    /// fraction it reached, unless `lower_if_needed` lets it lower the
    /// fraction by 5 % per try, at most 6 tries, reported in the stage line
    /// and on standard error; `BoundingSpheres`: the spheres' volume, the
    /// cylinder grown by 5 % until every sphere fits).
    AutoCylinder {
        /// Target solid fraction, in (0, 0.7].
        solid_fraction: f64,
        /// Accept a lower fraction than asked (5 % less per try).
        #[serde(default)]
        lower_if_needed: bool,
    },
    /// A walled box `[0, x] × [0, y] × [0, z]`.
    Box {
        /// Side along x.
        x: f64,
        /// Side along y.
        y: f64,
        /// Side along z.
        z: f64,
    },
}

/// How the clones are placed in the container.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
pub(crate) enum Placement {
    /// `packer_grains::pack_grains`: the star surfaces of the clones
    /// packed densely without overlap (sphere skeleton, then gap
    /// minimisation with rotations), checked by `check_grain_overlaps`.
    #[default]
    Grains,
    /// One bounding sphere per clone packed by `pack3d_sizes`, isotropic
    /// random rotations: non-overlapping by construction, and loose.
    BoundingSpheres,
}

pub(crate) use ::specimen::place::Preset;

/// What to write.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct Outputs {
    /// LS-DEM morph files and the poses file.
    pub(crate) lsdem: bool,
    /// Surface nodes per morph file.
    pub(crate) lsdem_nodes: usize,
    /// One grid spacing for every morph file, in the scene's length unit
    /// (LS-DEM works in one grid unit): default the median of the grains'
    /// own spacings at `level_set_resolution`.
    pub(crate) lsdem_spacing: Option<f64>,
    /// LAMMPS data file of every clump sphere + the body-id file.
    pub(crate) lammps_clumps: bool,
    /// LIGGGHTS `particletemplate/multisphere` templates.
    pub(crate) liggghts_templates: bool,
    /// Yade clump list and loader script.
    pub(crate) yade_clumps: bool,
    /// Clump parameters shared by the three clump outputs.
    pub(crate) clump: ClumpSpec,
    /// Particle density in kg/m³ (default 2650, quartz): every output's masses.
    pub(crate) density: f64,
    /// LS-DEM test name: `InitState/positions_<NAME>.dat`, `rotations_<NAME>.dat`.
    pub(crate) lsdem_name: String,
    /// Contact constants of the DEM decks (Hertz–Mindlin, quartz; `dem.rs`).
    pub(crate) material: ::specimen::dem::Material,
    /// VTU of the marching-cubes surfaces of every placed grain.
    pub(crate) vtu: bool,
    /// Cells across the widest side of each grain's level-set box for its
    /// VTU surface only: the grid is resampled (trilinear) to this
    /// resolution before marching cubes (never above
    /// `level_set_resolution − 1`), so that the VTU of 10⁴ grains stays a
    /// few hundred MB. The other outputs keep `level_set_resolution`.
    pub(crate) vtu_resolution: usize,
    /// DNA (clones vs parents) and grading report with SVG plots.
    pub(crate) report: bool,
}

impl Default for Outputs {
    fn default() -> Self {
        Self {
            lsdem: false,
            lsdem_nodes: 1000,
            lsdem_spacing: None,
            lammps_clumps: false,
            liggghts_templates: false,
            yade_clumps: false,
            clump: ClumpSpec::default(),
            density: QUARTZ_DENSITY,
            lsdem_name: "specimen".into(),
            material: ::specimen::dem::Material::default(),
            vtu: false,
            vtu_resolution: 16,
            report: false,
        }
    }
}

impl Outputs {
    /// Any of the three clump outputs.
    pub(crate) fn clumps(&self) -> bool {
        self.lammps_clumps || self.liggghts_templates || self.yade_clumps
    }

    /// Any output that needs a level set per grain.
    pub(crate) fn level_sets(&self) -> bool {
        self.lsdem || self.clumps() || self.vtu
    }
}

/// Multi-sphere clump parameters (`levelset::ClumpParams`).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct ClumpSpec {
    /// Spheres per clump (at most; CLUMP's `N`).
    pub(crate) spheres_per_clump: usize,
    /// Overlap in [0, 1) (CLUMP's `overlap`).
    pub(crate) overlap: f64,
}

impl Default for ClumpSpec {
    fn default() -> Self {
        Self {
            spheres_per_clump: 20,
            overlap: 0.6,
        }
    }
}

impl ClumpSpec {
    pub(crate) fn params(&self) -> levelset::ClumpParams {
        levelset::ClumpParams {
            n_spheres: self.spheres_per_clump,
            overlap: self.overlap,
            ..levelset::ClumpParams::default()
        }
    }
}

impl Scene {
    /// Metres per scene length unit (validated: `Files` parents state it).
    pub(crate) fn metres(&self) -> f64 {
        self.length_unit.unwrap_or(OTTAWA_LENGTH_UNIT)
    }

    /// Distinct clone shapes to make.
    pub(crate) fn distinct(&self) -> u64 {
        self.distinct_shapes.unwrap_or(self.clones.count())
    }

    /// Parses a scene; errors carry `line:column` and the offending key.
    pub(crate) fn parse(text: &str, source: &Path) -> anyhow::Result<Self> {
        let mut scene: Self =
            ron::from_str(text).map_err(|e| anyhow::anyhow!("{}:{e}", source.display()))?;
        scene.source_text = text.to_owned();
        scene.validate(source)?;
        Ok(scene)
    }

    /// Reads and parses a scene file.
    pub(crate) fn read(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading the scene {}", path.display()))?;
        Self::parse(&text, path)
    }

    /// Checks values that the schema cannot (files are checked where they
    /// are read, with the key in the message).
    fn validate(&self, source: &Path) -> anyhow::Result<()> {
        let at = source.display();
        if self.clones.count() == 0 {
            bail!("{at}: `clones`: the count must be at least 1, got 0");
        }
        if let Clones::Graded { grading, .. } = &self.clones {
            let g = crate::pack_cmd::parse_grading(grading)
                .with_context(|| format!("{at}: `clones.grading`"))?;
            g.validate()
                .with_context(|| format!("{at}: `clones.grading` `{grading}`"))?;
        }
        let positive = |key: &str, v: f64| -> anyhow::Result<()> {
            if !(v.is_finite() && v > 0.0) {
                bail!("{at}: `{key}` must be positive and finite, got {v}");
            }
            Ok(())
        };
        match &self.container {
            ContainerSpec::Cylinder { diameter, height } => {
                positive("container.diameter", *diameter)?;
                if let Some(h) = height {
                    positive("container.height", *h)?;
                }
            }
            ContainerSpec::AutoCylinder { solid_fraction, .. } => {
                if !(*solid_fraction > 0.0 && *solid_fraction <= 0.7) {
                    bail!(
                        "{at}: `container.solid_fraction` must be in (0, 0.7], got {solid_fraction}"
                    );
                }
            }
            ContainerSpec::Box { x, y, z } => {
                positive("container.x", *x)?;
                positive("container.y", *y)?;
                positive("container.z", *z)?;
            }
        }
        if self.settle && self.placement != Placement::Grains {
            bail!(
                "{at}: `settle: true` settles the grain packing: it needs `placement: Grains` (bounding spheres are not settled)"
            );
        }
        if !(5..=400).contains(&self.level_set_resolution) {
            bail!(
                "{at}: `level_set_resolution` must be in 5..=400, got {}",
                self.level_set_resolution
            );
        }
        if self.outputs.lsdem && self.outputs.lsdem_nodes == 0 {
            bail!("{at}: `outputs.lsdem_nodes` must be at least 1");
        }
        positive("outputs.density", self.outputs.density)?;
        if let Some(l) = self.length_unit {
            positive("length_unit", l)?;
        }
        if matches!(self.parents, ParentsSpec::Files { .. }) && self.length_unit.is_none() {
            bail!(
                "{at}: `length_unit` (metres per length unit of the parents, e.g. 1e-6 for micrometres) is required for `Files` parents: every output is written in metres"
            );
        }
        if let Some(n) = self.distinct_shapes
            && (n == 0 || n > self.clones.count())
        {
            bail!(
                "{at}: `distinct_shapes` must be in 1..={} (the clone count), got {n}",
                self.clones.count()
            );
        }
        self.outputs
            .material
            .validate()
            .with_context(|| format!("{at}: `outputs.material`"))?;
        let name = &self.outputs.lsdem_name;
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            bail!(
                "{at}: `outputs.lsdem_name` must be a non-empty file-name part of letters, digits, `_` and `-`, got {name:?}"
            );
        }
        if self.outputs.clumps() && self.outputs.clump.spheres_per_clump < 2 {
            bail!(
                "{at}: `outputs.clump.spheres_per_clump` must be at least 2 for the clump outputs (LIGGGHTS refuses a one-sphere multisphere template; a one-sphere clump is a sphere: use `cargo xtask pack`), got {}",
                self.outputs.clump.spheres_per_clump
            );
        }
        if !(4..=400).contains(&self.outputs.vtu_resolution) {
            bail!(
                "{at}: `outputs.vtu_resolution` must be in 4..=400, got {}",
                self.outputs.vtu_resolution
            );
        }
        if let Some(h) = self.outputs.lsdem_spacing {
            positive("outputs.lsdem_spacing", h)?;
        }
        if self.outputs.clumps() {
            self.outputs
                .clump
                .params()
                .validate()
                .with_context(|| format!("{at}: `outputs.clump`"))?;
        }
        if let ParentsSpec::Files { resolution, .. } = &self.parents
            && !(5..=400).contains(resolution)
        {
            bail!("{at}: `parents.resolution` must be in 5..=400, got {resolution}");
        }
        Ok(())
    }
}
