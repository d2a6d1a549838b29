//! The stages of a specimen on typed values: clone ([`clone_grains`]), the
//! packed shapes ([`Clones::star_grains`]), the independent checks
//! ([`check_grains`], [`check_bounding_spheres`]), the level set of each
//! distinct shape and what the outputs make of it ([`shape_outputs`]), and
//! the clumps with their union mass properties ([`clump_templates`]).
//! Placement is [`crate::place`]; the writers are [`crate::outputs`] and
//! [`crate::dem`].
//!
//! Demand-driven: the cloner keeps no level set; the level set of a distinct
//! shape is rasterised only when an output needs it, by [`shape_outputs`],
//! one shape at a time, and dropped by the caller, so that a specimen of 10⁴
//! grains never holds 10⁴ grids. Grain `k` of a specimen is a copy of shape
//! `k mod templates` ([`Clones::template_of`]).

use cloner::{CloneModel, Hooks, Parents};
use nalgebra::{Isometry3, Point3};
use packer_grains::{CheckParams, Fabric, GrainOverlapReport, StarGrain};
use packer_spheres::{Container, Sphere, SphereReport};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

use crate::error::{Context as _, Error, Result};
use crate::outputs::LsdemFrame;
use crate::place::{BOUNDING_MARGIN, ToPlace};

/// Cube-map cells per face of the star tables the grain packer packs (and
/// the level sets of the outputs are rasterised from: 1734 radii).
pub const STAR_FACE_CELLS: usize = 16;

/// Decimals of the level-set values and nodes of the LS-DEM morph files (grid units):
/// within 5e-10 of the exact values, and the products of inertia of the file's own level
/// set stay below 1e-11 of its moments (`specimen/lsdem-files` parses the files).
pub const MORPH_DECIMALS: u32 = 9;

/// Lattice cells per equivalent diameter of the union integration of a clump
/// (`levelset::union_mass_properties`; validated by `specimen/clump-mass` at the same
/// value): 60 gives a 20-sphere clump's largest spheres (≈ d/4) 15 cells per radius
/// (volume −0.3 % for a lone sphere) and costs ≈ 5 ms; 100 cost 24 ms per clump (121 s
/// for 10⁴ clumps on 2 cores).
pub const UNION_CELLS: f64 = 60.0;

/// The DNA compared between a grain's level set and its delivered clump.
pub const CLUMP_DNA: [morph_dna::Descriptor; 4] = [
    morph_dna::Descriptor::Volume,
    morph_dna::Descriptor::VolumeSurfaceRatio,
    morph_dna::Descriptor::AspectRatio,
    morph_dna::Descriptor::Roundness,
];

/// Stream offset of the graded sizes (never shared with the cloner's).
const SIZE_STREAM: u64 = 0x7369_7a65;

/// The clones of a specimen: its distinct shapes (templates), their size
/// factors and the number of grains that copy them.
pub struct Clones {
    /// The fitted clone model (star tables and rasterisation of its clones).
    pub model: CloneModel,
    /// The accepted clones, in index order: the distinct shapes.
    pub run: cloner::Run,
    /// Size factor of each shape's radii (1 unless the sizes are graded).
    pub scales: Vec<f64>,
    /// Grains of the specimen (≥ shapes; grain `k` copies shape `k mod shapes`).
    pub grains: usize,
}

/// How graded clones are sized: the scale of a clone's radii from the clone
/// and a uniform `u ∈ [0, 1)` drawn from its own `(seed, index)` stream
/// (e.g. a grading's `diameter_at(u)` over the clone's equivalent diameter).
pub type SizeRule<'a> = &'a (dyn Fn(&cloner::ClonedGrain, f64) -> f64 + Sync);

/// Clones `shapes` distinct grains of `parents` with `params` (its seed is
/// the specimen's), for a specimen of `grains` grains, sized by `sizes`
/// (`None`: as cloned). `hooks` carry the caller's clock and progress.
///
/// # Errors
/// `grains` or `shapes` zero or `shapes > grains`; the cloner's errors.
pub fn clone_grains(
    parents: &Parents,
    params: &cloner::Params,
    grains: u64,
    shapes: u64,
    sizes: Option<SizeRule<'_>>,
    hooks: Hooks<'_>,
) -> Result<Clones> {
    if grains == 0 || shapes == 0 || shapes > grains {
        crate::error::invalid!(
            "clones",
            "{shapes} distinct shapes for {grains} grains (need 1 ≤ shapes ≤ grains)"
        );
    }
    let model = CloneModel::fit(parents, params)?;
    let run = model.run(0..shapes, hooks)?;
    let seed = params.seed;
    let scales = match sizes {
        None => vec![1.0; run.clones.len()],
        Some(rule) => run
            .clones
            .iter()
            .map(|c| {
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ SIZE_STREAM);
                rng.set_stream(c.index);
                rule(c, rng.random::<f64>())
            })
            .collect(),
    };
    Ok(Clones {
        model,
        run,
        scales,
        grains: grains as usize,
    })
}

impl Clones {
    /// Distinct shapes.
    pub fn templates(&self) -> usize {
        self.run.clones.len()
    }

    /// The shape grain `k` copies.
    pub fn template_of(&self, k: usize) -> usize {
        k % self.run.clones.len()
    }

    /// Radius of a sphere about each grain's clone-frame origin that holds it
    /// (largest node radius × [`BOUNDING_MARGIN`]).
    pub fn bounding_radii(&self) -> Vec<f64> {
        (0..self.grains)
            .map(|k| {
                let t = self.template_of(k);
                self.run.clones[t].surface.r_max * self.scales[t] * BOUNDING_MARGIN
            })
            .collect()
    }

    /// What bounding-sphere placement needs of every grain.
    pub fn to_place(&self) -> Vec<ToPlace> {
        self.bounding_radii()
            .into_iter()
            .enumerate()
            .map(|(k, r)| ToPlace {
                index: k as u64,
                bounding_radius: r,
            })
            .collect()
    }

    /// Each shape's scaled radii.
    pub fn radii(&self, template: usize) -> Vec<f64> {
        let s = self.scales[template];
        self.run.clones[template]
            .radii
            .iter()
            .map(|r| r * s)
            .collect()
    }

    /// The star surface of every distinct shape ([`STAR_FACE_CELLS`] cells per
    /// cube face), what the grain packer packs.
    ///
    /// # Errors
    /// A star table the cloner or the packer refuses, naming the clone.
    pub fn star_grains(&self) -> Result<Vec<StarGrain>> {
        self.run
            .clones
            .par_iter()
            .enumerate()
            .map(|(t, c)| {
                let table = self
                    .model
                    .star_table(&self.radii(t), STAR_FACE_CELLS)
                    .context_with(|| format!("star table of clone {}", c.index))?;
                StarGrain::from_table(STAR_FACE_CELLS, &table)
                    .context_with(|| format!("star table of clone {}", c.index))
            })
            .collect()
    }

    /// Every grain's shape: `shapes` repeated as grain `k` copies shape `k mod n`.
    pub fn grains_of(&self, shapes: &[StarGrain]) -> Vec<StarGrain> {
        (0..self.grains)
            .map(|k| shapes[self.template_of(k)].clone())
            .collect()
    }

    /// Summed volume of the grains (scaled clone surfaces).
    pub fn grain_volume(&self) -> f64 {
        (0..self.grains)
            .map(|k| {
                let t = self.template_of(k);
                self.run.clones[t].surface.volume * self.scales[t].powi(3)
            })
            .sum()
    }

    /// Volume-equivalent diameter of each distinct shape, scaled.
    pub fn equivalent_diameters(&self) -> Vec<f64> {
        self.run
            .clones
            .iter()
            .zip(&self.scales)
            .map(|(c, s)| (6.0 * c.surface.volume / std::f64::consts::PI).cbrt() * s)
            .collect()
    }

    /// The one grid spacing of LS-DEM morph files at `resolution` nodes: the
    /// median of the shapes' own spacings (`2 · margin · r_max / (res − 1)`).
    pub fn lsdem_spacing(&self, resolution: usize, margin: f64) -> f64 {
        let res = resolution as f64;
        let mut own: Vec<f64> = self
            .run
            .clones
            .iter()
            .zip(&self.scales)
            .map(|(c, s)| 2.0 * margin * c.surface.r_max * s / (res - 1.0))
            .collect();
        own.sort_by(f64::total_cmp);
        own.get(own.len() / 2).copied().unwrap_or(1.0)
    }
}

/// The largest volume-equivalent diameter of the grains.
pub fn grain_d_max(grains: &[StarGrain]) -> f64 {
    grains
        .iter()
        .map(|g| (6.0 * g.volume() / std::f64::consts::PI).cbrt())
        .fold(0.0, f64::max)
}

/// The independent check of a grain packing and its fabric.
pub struct GrainCheck {
    /// The LS-DEM node check (clean).
    pub report: GrainOverlapReport,
    /// Fabric of the grains' major (x) axes.
    pub fabric: Fabric,
}

/// Checks a grain packing with the independent LS-DEM check
/// (`packer_grains::check_grain_overlaps`, default parameters).
///
/// # Errors
/// [`Error::Rejected`] naming the overlap when the packing is not clean;
/// the check's errors.
pub fn check_grains(
    grains: &[StarGrain],
    poses: &[Isometry3<f64>],
    container: &Container,
) -> Result<GrainCheck> {
    let r = packer_grains::check_grain_overlaps(grains, poses, container, &CheckParams::default())?;
    if !r.is_clean() {
        return Err(Error::Rejected(format!(
            "the independent check rejects the grain packing: {} overlapping nodes (worst φ/d {:.2e} between grains {:?}), {} nodes outside the container, {} overlap voxels",
            r.overlapping_nodes,
            r.worst_phi_over_d,
            r.worst_pair,
            r.nodes_outside,
            r.raster_overlap_voxels
        )));
    }
    let fabric = packer_grains::orientation_fabric(poses, &nalgebra::Vector3::x())?;
    Ok(GrainCheck { report: r, fabric })
}

/// The independent check of a bounding-sphere placement.
pub struct SphereCheck {
    /// The sphere check (clean).
    pub report: SphereReport,
    /// Solid fraction of the bounding spheres.
    pub sphere_fraction: f64,
    /// Solid fraction of the grains.
    pub grain_fraction: f64,
}

/// Checks that the grains' bounding spheres do not overlap
/// (`packer_spheres::check_spheres`).
///
/// # Errors
/// [`Error::Rejected`] when they do; the check's errors.
pub fn check_bounding_spheres(
    clones: &Clones,
    poses: &[Isometry3<f64>],
    container: &Container,
) -> Result<SphereCheck> {
    let spheres: Vec<Sphere> = poses
        .iter()
        .zip(clones.bounding_radii())
        .map(|(p, r)| Sphere {
            center: Point3::from(p.translation.vector),
            radius: r,
        })
        .collect();
    let check = packer_spheres::check_spheres(container, &spheres, 1e-9)?;
    if !check.is_clean(1e-9) {
        return Err(Error::Rejected(format!(
            "the independent checker rejects the placement (worst pair gap / d {:.2e}, wall {:.2e})",
            check.worst_normalised_gap, check.worst_normalised_wall_gap
        )));
    }
    let sphere_fraction = packer_spheres::solid_fraction(container, &spheres)?;
    Ok(SphereCheck {
        report: check,
        sphere_fraction,
        grain_fraction: clones.grain_volume() / container.volume(),
    })
}

/// What [`shape_outputs`] makes of a distinct shape's level set.
#[derive(Debug, Clone, Copy)]
pub struct ShapeOptions {
    /// Nodes per axis of the level set.
    pub resolution: usize,
    /// Half-width of the level-set box over the largest radius (the cloner's
    /// `grid_margin`).
    pub margin: f64,
    /// LS-DEM morph file: `Some((grid spacing, surface nodes))`.
    pub lsdem: Option<(f64, usize)>,
    /// Multi-sphere clump.
    pub clump: Option<levelset::ClumpParams>,
    /// Measure [`CLUMP_DNA`] of the level set (with a clump, for the report).
    pub dna: bool,
    /// Marching-cubes surface at this many cells across (VTU).
    pub surface_cells: Option<usize>,
}

/// The products of the level-set stage for one distinct shape.
#[derive(Default)]
pub struct ShapeOut {
    /// The level set's spec and DNA ([`CLUMP_DNA`]) when asked with a clump.
    pub dna: Option<(levelset::GridSpec, Vec<f64>)>,
    /// The LS-DEM morph file (bytes) and where its principal frame sits.
    pub lsdem: Option<(LsdemFrame, Vec<u8>)>,
    /// The clump's spheres (clone frame, scene units).
    pub clump: Option<Vec<(Point3<f64>, f64)>>,
    /// The level set's volume (scene units) when a clump was made.
    pub volume: f64,
    /// Candidate spheres of the clump that were shrunk.
    pub shrunk: usize,
    /// The surface for the VTU.
    pub mesh: Option<levelset::TriMesh>,
    /// CPU time of rasterising, LS-DEM, clump and surface, by the caller's clock (ns).
    pub cpu_ns: [u64; 4],
}

/// The level set of distinct shape `t` and what `opts` asks of it. With the
/// packed star surfaces (`shapes`, grain placement) the level set is the
/// packed surface itself (the one the check passed); otherwise the clone
/// model's own rasterisation.
///
/// # Errors
/// A level set, morph file, clump, DNA or surface that cannot be made,
/// naming the clone.
pub fn shape_outputs(
    clones: &Clones,
    shapes: Option<&[StarGrain]>,
    t: usize,
    opts: &ShapeOptions,
    clock: &dyn cloner::Clock,
) -> Result<ShapeOut> {
    let index = clones.run.clones[t].index;
    let t0 = clock.now_ns();
    let radii = clones.radii(t);
    let grid = match shapes {
        Some(g) => star_grid(&g[t], &radii, opts.margin, opts.resolution),
        None => clones
            .model
            .rasterise_at(&radii, opts.resolution)
            .map_err(Into::into),
    }
    .context_with(|| format!("level set of clone {index}"))?;
    let t1 = clock.now_ns();
    let mut g = ShapeOut::default();
    if let Some((h, nodes)) = opts.lsdem {
        let pm = levelset::io::principal_morph(&grid, h, 1.0, nodes)
            .context_with(|| format!("LS-DEM morph of clone {index}"))?;
        let mut bytes = Vec::new();
        levelset::io::write_morph_decimals(&mut bytes, &pm.morph, MORPH_DECIMALS)
            .context_with(|| format!("LS-DEM morph of clone {index}"))?;
        let frame = LsdemFrame {
            frame: pm.frame,
            spacing: pm.spacing,
            off_diagonal: pm.off_diagonal,
        };
        g.lsdem = Some((frame, bytes));
    }
    let t2 = clock.now_ns();
    if let Some(params) = &opts.clump {
        let cl =
            levelset::clump(&grid, params).context_with(|| format!("clump of clone {index}"))?;
        g.shrunk = cl.shrunk;
        g.volume = grid.volume();
        g.clump = Some(cl.spheres);
        if opts.dna {
            let dna = morph_dna::measure(&grid, &CLUMP_DNA, &morph_dna::MeasureParams::default())
                .context_with(|| format!("DNA of clone {index}"))?;
            g.dna = Some((*grid.spec(), dna));
        }
    }
    let t3 = clock.now_ns();
    if let Some(cells) = opts.surface_cells {
        let coarse = coarsen(&grid, cells).context_with(|| format!("VTU grid of clone {index}"))?;
        g.mesh = Some(coarse.as_ref().unwrap_or(&grid).marching_cubes());
    }
    let t4 = clock.now_ns();
    g.cpu_ns = [t1 - t0, t2 - t1, t3 - t2, t4 - t3];
    Ok(g)
}

/// The multi-sphere clump of every distinct shape (in parallel) and its
/// level set's volume: the inputs of [`clump_templates`].
///
/// # Errors
/// As [`shape_outputs`].
#[allow(clippy::type_complexity)]
pub fn shape_clumps(
    clones: &Clones,
    shapes: Option<&[StarGrain]>,
    resolution: usize,
    margin: f64,
    params: &levelset::ClumpParams,
) -> Result<(Vec<Vec<(Point3<f64>, f64)>>, Vec<f64>)> {
    let opts = ShapeOptions {
        resolution,
        margin,
        lsdem: None,
        clump: Some(*params),
        dna: false,
        surface_cells: None,
    };
    let outs = (0..clones.templates())
        .into_par_iter()
        .map(|t| shape_outputs(clones, shapes, t, &opts, &cloner::NoClock))
        .collect::<Result<Vec<_>>>()?;
    Ok(outs
        .into_iter()
        .map(|o| (o.clump.unwrap_or_default(), o.volume))
        .unzip())
}

/// The level set of a packed grain: its star table rasterised on the grid
/// `CloneModel::rasterise_at` would use (`±margin · max node radius`).
fn star_grid(
    grain: &StarGrain,
    radii: &[f64],
    margin: f64,
    resolution: usize,
) -> Result<levelset::Grid> {
    let half = margin * radii.iter().fold(grain.r_max(), |a, b| a.max(*b));
    Ok(grain.level_set(resolution, half)?)
}

/// `grid` resampled (trilinear) over the same box at `cells` cells across
/// its largest side, for the VTU surface only; `None` when the grid is
/// already that coarse (no upsampling).
fn coarsen(grid: &levelset::Grid, cells: usize) -> Result<Option<levelset::Grid>> {
    let d = grid.dims();
    let widest = d[0].max(d[1]).max(d[2]) - 1;
    if cells >= widest {
        return Ok(None);
    }
    let h = widest as f64 * grid.spacing() / cells as f64;
    let n = |k: usize| ((((d[k] - 1) as f64 * grid.spacing()) / h).round() as usize + 1).max(2);
    let spec = levelset::GridSpec {
        dims: [n(0), n(1), n(2)],
        origin: grid.origin(),
        spacing: h,
    };
    Ok(Some(levelset::Grid::from_fn(spec, |p| grid.value(p))?))
}

/// The clumps as delivered: trimmed against every copy's neighbours, with
/// their union mass properties and the DEM templates in metres.
pub struct ClumpTemplates {
    /// One DEM template per distinct shape (SI).
    pub templates: Vec<crate::dem::Template>,
    /// Each clump's union mass properties (scene units).
    pub unions: Vec<levelset::MassProperties>,
    /// What the trimming did.
    pub trim: packer_grains::ClumpTrim,
    /// What the gap closing did (settled packings, see [`clump_templates`]).
    pub reach: Option<packer_grains::ClumpReach>,
    /// Spheres over all clumps.
    pub spheres: usize,
    /// Mean |union volume / level-set volume − 1|.
    pub union_error: f64,
    /// Mean (summed sphere volume / level-set volume − 1).
    pub summed_error: f64,
}

/// Gaps between clumps closed by [`clump_templates`] for a settled packing,
/// over the median equivalent diameter.
pub const CLUMP_REACH: f64 = 0.05;

/// Trims the clumps of the distinct shapes (`spheres[t]`, clone frame)
/// against every grain's neighbours and the walls
/// (`packer_grains::separate_clumps`), integrates each union
/// ([`UNION_CELLS`] cells per equivalent diameter of its level set's
/// `volumes[t]`) and makes the DEM templates at `metres` per scene unit.
/// With `close_gaps` (a packing settled under gravity), the gaps between
/// clumps narrower than [`CLUMP_REACH`] of the median equivalent diameter are
/// closed after the trimming (`packer_grains::close_clump_gaps`), so that
/// the bodies a DEM code moves rest on each other where the grains do.
///
/// # Errors
/// The trimming's or the union integration's errors, naming the clone.
pub fn clump_templates(
    spheres: &mut [Vec<(Point3<f64>, f64)>],
    volumes: &[f64],
    poses: &[Isometry3<f64>],
    template_of: impl Fn(usize) -> usize,
    container: &Container,
    metres: f64,
    close_gaps: bool,
) -> Result<ClumpTemplates> {
    let n: usize = spheres.iter().map(Vec::len).sum();
    let trim = packer_grains::separate_clumps(spheres, poses, &template_of, container)?;
    let reach = if close_gaps {
        let mut d: Vec<f64> = volumes
            .iter()
            .map(|v| (6.0 * v / std::f64::consts::PI).cbrt())
            .collect();
        d.sort_by(f64::total_cmp);
        let d_med = d.get(d.len() / 2).copied().unwrap_or(0.0);
        Some(packer_grains::close_clump_gaps(
            spheres,
            poses,
            &template_of,
            container,
            CLUMP_REACH * d_med,
        )?)
    } else {
        None
    };
    let unions: Vec<levelset::MassProperties> = spheres
        .par_iter()
        .zip(volumes)
        .enumerate()
        .map(|(k, (s, v))| {
            let d = (6.0 * v / std::f64::consts::PI).cbrt();
            levelset::union_mass_properties(s, d / UNION_CELLS)
                .context_with(|| format!("union of the clump of clone {k}"))
        })
        .collect::<Result<_>>()?;
    let k = spheres.len().max(1) as f64;
    let union_error = unions
        .iter()
        .zip(volumes)
        .map(|(u, v)| (u.volume / v - 1.0).abs())
        .sum::<f64>()
        / k;
    let summed_error = spheres
        .iter()
        .zip(volumes)
        .map(|(s, v)| {
            s.iter()
                .map(|(_, r)| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
                .sum::<f64>()
                / v
                - 1.0
        })
        .sum::<f64>()
        / k;
    let templates = spheres
        .iter()
        .zip(&unions)
        .map(|(s, u)| crate::dem::Template {
            spheres: s.iter().map(|(c, r)| (c * metres, r * metres)).collect(),
            volume: u.volume * metres.powi(3),
            centroid: u.centroid * metres,
            inertia: u.inertia * metres.powi(5),
        })
        .collect();
    Ok(ClumpTemplates {
        templates,
        unions,
        trim,
        reach,
        spheres: n,
        union_error,
        summed_error,
    })
}

/// `pose` with its translation in metres (`metres` per scene unit).
pub fn scale_pose(pose: &Isometry3<f64>, metres: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        nalgebra::Translation3::from(pose.translation.vector * metres),
        pose.rotation,
    )
}

/// `container` with its lengths in metres.
pub fn scale_container(container: &Container, metres: f64) -> Container {
    match container {
        Container::Box { min, max, periodic } => Container::Box {
            min: min * metres,
            max: max * metres,
            periodic: *periodic,
        },
        Container::Cylinder {
            base,
            radius,
            height,
        } => Container::Cylinder {
            base: base * metres,
            radius: radius * metres,
            height: height * metres,
        },
        other => other.clone(),
    }
}

/// The DEM bodies of a specimen: grain `k` with its shape and its pose in metres.
pub fn dem_bodies(
    poses: &[Isometry3<f64>],
    template_of: impl Fn(usize) -> usize,
    metres: f64,
) -> Vec<crate::dem::Body> {
    poses
        .iter()
        .enumerate()
        .map(|(k, p)| crate::dem::Body {
            id: k as u64,
            template: template_of(k),
            pose: scale_pose(p, metres),
        })
        .collect()
}
