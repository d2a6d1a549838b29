//! `cargo xtask specimen SCENE.ron`: a DEM specimen of cloned grains from a
//! scene file (schema in `scene.rs`): parents → clone → place → check →
//! the outputs the scene asks for, with a stage report.
//!
//! A thin command over the `specimen` library: this module reads the scene
//! and the parents, calls the library's stages (`specimen::clone_grains`,
//! `specimen::place`, `specimen::check_grains`, `specimen::shape_outputs`,
//! `specimen::clump_templates`, the writers of `specimen::dem` and
//! `specimen::outputs`), times them, shows progress and stages the files.
//!
//! Demand-driven: the cloner keeps no level set (`Outputs::level_set =
//! false`) and measures DNA only for the report; the level set of a distinct
//! shape is rasterised only when an output needs it (LS-DEM, clumps, VTU),
//! in parallel chunks and dropped at once, so a specimen of 10⁴ grains never
//! holds 10⁴ grids. A stage nobody needs is listed as `skipped (reason)`
//! with zero time.
//!
//! Every file goes through a staging folder and is moved into `out_dir`
//! only when every stage succeeded: an error leaves nothing half-written.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use ::specimen as lib;
use anyhow::{Context, bail};
use clap::Args;
use cloner::{Calibrated, Hooks};
use nalgebra::{Isometry3, Point3};
use packer_grains::StarGrain;
use packer_spheres::Container;
use rayon::prelude::*;

pub(crate) mod check;
mod estimate;
#[cfg(test)]
mod golden;
mod provenance;
mod report;
mod scene;
mod staging;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod vtu_read;

use lib::outputs::{LsdemFrame, Surfaces, VtuWriter};
use provenance::{ottawa, provenance_lines, provenance_text};
use scene::{Clones, ContainerSpec, ParentsSpec, Placement, Scene};
use staging::Staging;

/// Flags of `cargo xtask specimen`.
#[derive(Debug, Args)]
pub(crate) struct Specimen {
    /// The scene file (RON; schema in the README and `xtask/src/specimen/scene.rs`).
    scene: PathBuf,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

impl Specimen {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        // a path relative to the current folder, else to the workspace root
        let path = if self.scene.exists() {
            self.scene.clone()
        } else {
            root.join(&self.scene)
        };
        let scene = Scene::read(&path)?;
        let report = run_scene(&scene, root, self.quiet)?;
        print!("{}", report.text());
        println!("written to {}", report.out_dir.display());
        Ok(())
    }
}

/// Grains per parallel chunk of the level-set stage: bounds the memory
/// (a 45³ grid is 0.73 MB) while keeping both cores busy.
const CHUNK: usize = 64;

/// One stage of the pipeline.
#[derive(Debug, Clone)]
pub(crate) struct Stage {
    pub(crate) name: &'static str,
    pub(crate) seconds: f64,
    /// `None` when it ran; `Some(reason)` when skipped.
    pub(crate) skipped: Option<String>,
    pub(crate) note: String,
}

/// The result of a scene: its stages and the files written.
#[derive(Debug, Clone)]
pub(crate) struct StageReport {
    pub(crate) stages: Vec<Stage>,
    pub(crate) files: Vec<PathBuf>,
    pub(crate) out_dir: PathBuf,
    pub(crate) total_s: f64,
}

impl StageReport {
    /// The stage named `name`.
    #[cfg(test)]
    pub(crate) fn stage(&self, name: &str) -> Option<&Stage> {
        self.stages.iter().find(|s| s.name == name)
    }

    /// The stage table (report.txt and stdout).
    pub(crate) fn text(&self) -> String {
        let mut s = String::from("stage          time (s)  status\n");
        for st in &self.stages {
            let status = match &st.skipped {
                Some(r) => format!("skipped ({r})"),
                None => st.note.clone(),
            };
            let _ = writeln!(s, "{:<14} {:>8.3}  {status}", st.name, st.seconds);
        }
        let _ = writeln!(
            s,
            "total          {:>8.3}  {} files",
            self.total_s,
            self.files.len()
        );
        s
    }
}

struct Stages(Vec<Stage>);

impl Stages {
    fn ran(&mut self, name: &'static str, t: Instant, note: String) {
        self.ran_s(name, t.elapsed().as_secs_f64(), note);
    }
    fn ran_s(&mut self, name: &'static str, seconds: f64, note: String) {
        self.0.push(Stage {
            name,
            seconds,
            skipped: None,
            note,
        });
    }
    /// Appends `text` to the note of the last stage called `name`.
    fn note(&mut self, name: &'static str, text: String) {
        if let Some(st) = self.0.iter_mut().rev().find(|s| s.name == name) {
            st.note.push_str("; ");
            st.note.push_str(&text);
        }
    }
    fn skip(&mut self, name: &'static str, reason: &str) {
        self.0.push(Stage {
            name,
            seconds: 0.0,
            skipped: Some(reason.into()),
            note: String::new(),
        });
    }
    /// Whether output `name` is on; when it is off, lists it as skipped ("no `what` asked").
    fn skip_unless(&mut self, on: bool, name: &'static str, what: &str) -> bool {
        if !on {
            self.skip(name, &format!("no {what} asked"));
        }
        on
    }
}

struct Clock(Instant);

impl cloner::Clock for Clock {
    fn now_ns(&self) -> u64 {
        self.0.elapsed().as_nanos() as u64
    }
}

/// What a scene run carries from stage to stage.
struct Run<'a> {
    scene: &'a Scene,
    root: &'a Path,
    quiet: bool,
    staging: Staging,
    st: Stages,
    cal: Calibrated,
    seed: u64,
    provenance: Vec<String>,
}

/// Runs a scene: every stage, then moves the files into `out_dir`.
///
/// # Errors
/// Any stage's error, naming the scene key or the file; nothing is left in
/// `out_dir` then.
pub(crate) fn run_scene(scene: &Scene, root: &Path, quiet: bool) -> anyhow::Result<StageReport> {
    let t_all = Instant::now();
    let (cal, need_est) = read_inputs(scene, root)?;
    let staging = Staging::new(&root.join(&scene.out_dir))?;
    let seed = scene.seed.unwrap_or(cal.params.seed);
    let mut run = Run {
        scene,
        root,
        quiet,
        staging,
        st: Stages(Vec::new()),
        provenance: provenance_lines(scene, &scene.source_text, root, seed),
        cal,
        seed,
    };
    let t = Instant::now();
    let (owned, note) = load_parents(scene, root)?;
    let parents = match &owned {
        Some(p) => p,
        None => ottawa()?,
    };
    run.st.ran(
        "parents",
        t,
        format!(
            "{note}; estimated need: memory {}, disk {}",
            estimate::human(need_est.memory),
            estimate::human(need_est.disk)
        ),
    );
    let clones = clone_stage(&mut run, parents)?;
    let placed = place_stage(&mut run, &clones)?;
    check_stage(&mut run, &clones, &placed)?;
    let mut sets = level_set_stage(&mut run, &clones, &placed)?;
    lsdem_stage(&mut run, &clones, &placed, &sets)?;
    let (templates, clump_section) = clump_stage(&mut run, &clones, &placed, &mut sets)?;
    deck_stages(&mut run, &clones, &placed, &templates)?;
    if run.st.skip_unless(scene.outputs.vtu, "vtu", "VTU") {
        run.st.ran_s(
            "vtu",
            sets.cpu(3),
            format!(
                "specimen.vtu: {} marching-cubes triangles of {} grains at {} cells across, binary, grain_id per cell, metres (CPU)",
                sets.triangles,
                clones.grains,
                scene.outputs.vtu_resolution.min(scene.level_set_resolution - 1)
            ),
        );
    }
    report_stage(&mut run, parents, &clones, clump_section.as_deref())?;
    write_stage(run, &clones, &placed, t_all)
}

/// The calibration and the parents' path read, and the memory and disk a
/// scene needs estimated, before any heavy work.
fn read_inputs(scene: &Scene, root: &Path) -> anyhow::Result<(Calibrated, estimate::Estimate)> {
    let cal_path = scene.calibrated.as_ref().map_or_else(
        || root.join("fixtures/calibrated/gsc2-ottawa.ron"),
        |p| root.join(p),
    );
    let text = std::fs::read_to_string(&cal_path)
        .with_context(|| format!("`calibrated`: cannot read {}", cal_path.display()))?;
    let cal = Calibrated::from_ron(&text)
        .with_context(|| format!("`calibrated`: parsing {}", cal_path.display()))?;
    if let ParentsSpec::Files { path, .. } = &scene.parents {
        let p = root.join(path);
        if !p.exists() {
            bail!("`parents.path`: {} does not exist", p.display());
        }
    }
    let need_est = estimate::Estimate::of(scene);
    need_est.check(
        estimate::available_memory(),
        estimate::free_disk(&root.join(&scene.out_dir)),
    )?;
    Ok((cal, need_est))
}

/// The scene's parents from files (`None`: the embedded Ottawa grains) and
/// their description.
fn load_parents(scene: &Scene, root: &Path) -> anyhow::Result<(Option<cloner::Parents>, String)> {
    let ParentsSpec::Files {
        path,
        format,
        spacing,
        raw_dims,
        raw_dtype,
        big_endian,
        keep_border,
        min_voxels,
        smoothing,
        minimal_bending,
        sh_degree,
        resolution,
    } = &scene.parents
    else {
        return Ok((
            None,
            "71 embedded Ottawa-sand grains (spherical harmonics → level sets)".to_owned(),
        ));
    };
    let p = root.join(path);
    let args = crate::parents::ParentArgs {
        parents: Some(p.clone()),
        format: *format,
        spacing: *spacing,
        raw_dims: raw_dims.map(|(x, y, z)| format!("{x},{y},{z}")),
        raw_dtype: raw_dtype.clone(),
        big_endian: *big_endian,
        keep_border: *keep_border,
        min_voxels: *min_voxels,
        reject_split: false,
        smoothing: *smoothing,
        native_roundness: false,
        minimal_bending: *minimal_bending,
        sh_degree: *sh_degree,
        resolution: *resolution,
    };
    let loaded = crate::parents::load(&args, &p).with_context(|| "`parents`".to_owned())?;
    let summary = format!(
        "{}{}",
        loaded.summary(&p),
        if loaded.format == crate::parents::InputFormat::Anm {
            ", spherical harmonics → level sets"
        } else {
            ", level sets (no spherical harmonics)"
        }
    );
    let (parents, _, dna_s) = crate::parents::measure(loaded)?;
    Ok((Some(parents), format!("{summary}, DNA {dna_s:.2} s")))
}

/// Clones the distinct shapes (graded scenes rescale every clone).
fn clone_stage(run: &mut Run, parents: &cloner::Parents) -> anyhow::Result<lib::Clones> {
    let scene = run.scene;
    let t = Instant::now();
    let mut params = run.cal.params;
    params.outputs = cloner::Outputs {
        level_set: false,
        dna: scene.outputs.report,
    };
    params.seed = run.seed;
    let grading = match &scene.clones {
        Clones::Count(_) => None,
        Clones::Graded { grading, size, .. } => {
            Some((crate::pack_cmd::parse_grading(grading)?, *size))
        }
    };
    let rule = grading.as_ref().map(|(g, size)| {
        move |c: &cloner::ClonedGrain, u: f64| {
            size.scale(g.diameter_at(u), c.surface.volume, c.surface.dims)
        }
    });
    let count = scene.distinct();
    let pb = crate::progress::bar("cloning", count, run.quiet);
    let cb = crate::progress::clone_callback(&pb);
    let clock = Clock(Instant::now());
    let hooks = Hooks {
        clock: &clock,
        progress: Some(&cb),
    };
    let clones = lib::clone_grains(
        parents,
        &params,
        scene.clones.count(),
        count,
        rule.as_ref().map(|r| r as lib::SizeRule<'_>),
        hooks,
    )?;
    pb.finish_and_clear();
    let c = &clones.run;
    run.st.ran(
        "clone",
        t,
        format!(
            "{} clones of `{}`{} ({} candidates, acceptance {:.1} %); level sets kept: no, DNA measured: {}",
            c.clones.len(),
            run.cal.name,
            if scene.distinct_shapes.is_some() {
                format!(
                    " as the distinct shapes of {} grains (grain k a copy of clone k mod {})",
                    scene.clones.count(),
                    c.clones.len()
                )
            } else {
                String::new()
            },
            c.stats.attempts,
            100.0 * c.stats.acceptance_rate(),
            if scene.outputs.report { "yes (report)" } else { "no" }
        ),
    );
    Ok(clones)
}

/// A placed specimen: the container, every grain's pose, and for grain
/// placement the packed shapes.
struct Placed {
    container: Container,
    poses: Vec<Isometry3<f64>>,
    /// The distinct shapes' star surfaces (grain placement).
    shapes: Option<Vec<StarGrain>>,
    /// Every grain's star surface (grain placement).
    grains: Option<Vec<StarGrain>>,
    /// The grain packer's solid fraction (grain placement).
    fraction: f64,
}

/// Places the grains (grain packing or bounding spheres) and measures the
/// walls' share of the specimen.
fn place_stage(run: &mut Run, clones: &lib::Clones) -> anyhow::Result<Placed> {
    let scene = run.scene;
    let t = Instant::now();
    let shapes = match scene.placement {
        Placement::Grains => Some(clones.star_grains()?),
        Placement::BoundingSpheres => None,
    };
    let grains = shapes.as_ref().map(|s| clones.grains_of(s));
    let mut placed = match &grains {
        Some(g) => place_grains_stage(run, g, t)?,
        None => {
            let (container, poses, tries) = place_in(scene, &clones.to_place(), run.seed)?;
            run.st.ran(
                "place",
                t,
                format!(
                    "{} bounding spheres packed in {}{} (pack3d_sizes, {:?} preset) + isotropic rotations",
                    poses.len(),
                    describe(&container),
                    if tries > 1 {
                        format!(", auto-sized in {tries} tries")
                    } else {
                        String::new()
                    },
                    scene.preset
                ),
            );
            Placed {
                container,
                poses,
                shapes: None,
                grains: None,
                fraction: f64::NAN,
            }
        }
    };
    placed.shapes = shapes;
    // the walls' share of the specimen (issue 28): refuse a narrow container unless asked
    let d_max = match &grains {
        Some(g) => lib::grain_d_max(g),
        None => clones
            .bounding_radii()
            .iter()
            .map(|r| 2.0 * r)
            .fold(0.0, f64::max),
    };
    let wall = refuse_narrow(scene, &placed.container, &placed.poses, d_max)?;
    run.st.note(
        "place",
        format!(
            "container {:.2} d_max wide (d_max {:.4}); grains within one d_max of a wall: {:.1} %",
            wall.width / d_max,
            d_max,
            100.0 * wall.near_fraction
        ),
    );
    placed.grains = grains;
    Ok(placed)
}

/// Packs the grains themselves (`specimen::place::place_grains`).
fn place_grains_stage(run: &mut Run, grains: &[StarGrain], t: Instant) -> anyhow::Result<Placed> {
    let scene = run.scene;
    let (fixed, auto) = match &scene.container {
        ContainerSpec::AutoCylinder {
            solid_fraction,
            lower_if_needed,
        } => (None, Some((*solid_fraction, *lower_if_needed))),
        other => (Some(fixed_container(other)), None),
    };
    // refuse a narrow container before spending the packing on it
    let planned = match &fixed {
        Some(c) => c.clone(),
        None => packer_grains::container_for(
            &Container::triaxial(1.0),
            grains,
            auto.map_or(0.5, |a| a.0),
        )?,
    };
    refuse_narrow(scene, &planned, &[], lib::grain_d_max(grains))?;
    let pb = crate::progress::spinner("packing grains", run.quiet);
    let settle = scene.settle.then(packer_grains::Settle::default);
    let gp = lib::place::place_grains(grains, fixed, auto, scene.preset, run.seed, settle)?;
    pb.finish_and_clear();
    let s = gp.stats;
    let requested = auto.map_or(0.0, |a| a.0);
    if gp.tries > 1 {
        let mut fraction = requested;
        for _ in 1..gp.tries {
            fraction *= lib::place::FRACTION_STEP;
        }
        eprintln!(
            "specimen: WARNING: AutoCylinder could not separate the clones at the requested solid fraction {requested:.4}; lowered to {fraction:.4} in {} tries (lower_if_needed)",
            gp.tries
        );
    }
    run.st.ran(
        "place",
        t,
        format!(
            "{} grains (star tables, {} cells per cube face) packed in {}{} by pack_grains ({:?} skeleton): solid fraction {:.4}; compaction: {} proxy spheres, {} growth steps ({} undone), {} FIRE iterations, {} neighbour builds; first gap sweep: {} overlapping pairs, deepest / d {:.2e}; {} + {} sweeps, worst gap / d {:.2e}",
            grains.len(),
            lib::STAR_FACE_CELLS,
            describe(&gp.container),
            if gp.tries > 1 {
                format!(
                    ", auto-sized in {} tries: REQUESTED solid fraction {requested:.4} NOT REACHED, lowered to {:.4} (lower_if_needed)",
                    gp.tries, s.solid_fraction
                )
            } else {
                String::new()
            },
            scene.preset,
            s.solid_fraction,
            s.compaction.spheres,
            s.compaction.steps_accepted,
            s.compaction.steps_rejected,
            s.compaction.iterations,
            s.compaction.neighbour_builds,
            s.initial_overlaps,
            s.initial_depth_over_d,
            s.coarse_sweeps,
            s.fine_sweeps,
            s.worst_gap_over_d,
        ),
    );
    if scene.settle {
        let st = &s.settle;
        run.st.note(
            "place",
            format!(
                "settled under gravity (frictionless FIRE): {} iterations to rest (mean net force {:.4} of the mean weight, largest {:.3} of a grain's own; loaded overlaps ≤ {:.2e} d_min) + {} to separate; grain centres fell {:.3} d_med on average (at most {:.3}); lid lowered onto the bed: {}, solid fraction {:.4}",
                st.iterations,
                st.residual,
                st.max_residual,
                st.loaded_overlap_over_d,
                st.separation_iterations,
                st.mean_drop_over_d,
                st.max_drop_over_d,
                describe(&gp.container),
                s.solid_fraction
            ),
        );
    }
    Ok(Placed {
        container: gp.container,
        poses: gp.poses,
        shapes: None,
        grains: None,
        fraction: s.solid_fraction,
    })
}

/// The independent check of the placement.
fn check_stage(run: &mut Run, clones: &lib::Clones, placed: &Placed) -> anyhow::Result<()> {
    let t = Instant::now();
    if let Some(grains) = &placed.grains {
        let pb = crate::progress::spinner("checking overlaps", run.quiet);
        let c = lib::check_grains(grains, &placed.poses, &placed.container)?;
        pb.finish_and_clear();
        let r = &c.report;
        run.st.ran(
            "check",
            t,
            format!(
                "independent LS-DEM check: {} nodes of 1000 per grain sampled in the neighbours' 32³ level sets, worst φ/d {:.2e} (≥ −1e-6), walls {:.2e}, {} overlap voxels in {} pairs rasterised 4× finer; solid fraction {:.4}; fabric of the major axes ‖N − I/3‖ = {:.4}",
                r.nodes_checked,
                r.worst_phi_over_d,
                r.worst_wall_over_d,
                r.raster_overlap_voxels,
                r.raster_pairs,
                placed.fraction,
                c.fabric.deviatoric_norm
            ),
        );
    } else {
        let c = lib::check_bounding_spheres(clones, &placed.poses, &placed.container)?;
        run.st.ran(
            "check",
            t,
            format!(
                "independent checker: bounding spheres do not overlap (worst gap / d {:.2e}, walls {:.2e}); solid fraction {:.3} of bounding spheres, {:.3} of grains",
                c.report.worst_normalised_gap,
                c.report.worst_normalised_wall_gap,
                c.sphere_fraction,
                c.grain_fraction
            ),
        );
    }
    Ok(())
}

/// The products of the level-set stage, per distinct shape.
struct LevelSets {
    frames: Vec<Option<LsdemFrame>>,
    spheres: Vec<Vec<(Point3<f64>, f64)>>,
    volumes: Vec<f64>,
    dna: Vec<Option<(levelset::GridSpec, Vec<f64>)>>,
    shrunk: usize,
    triangles: usize,
    /// CPU of rasterising, LS-DEM, clumps, VTU (ns).
    ns: [u64; 4],
}

impl LevelSets {
    fn cpu(&self, k: usize) -> f64 {
        self.ns[k] as f64 * 1e-9
    }
}

/// What the scene's outputs ask of each distinct shape's level set.
fn shape_options(scene: &Scene, clones: &lib::Clones, margin: f64) -> lib::ShapeOptions {
    let out = &scene.outputs;
    let res = scene.level_set_resolution;
    lib::ShapeOptions {
        resolution: res,
        margin,
        lsdem: out.lsdem.then(|| {
            let h = out
                .lsdem_spacing
                .unwrap_or_else(|| clones.lsdem_spacing(res, margin));
            (h, out.lsdem_nodes)
        }),
        clump: out.clumps().then(|| out.clump.params()),
        dna: out.report,
        surface_cells: out.vtu.then_some(out.vtu_resolution),
    }
}

/// Level sets on demand, per distinct shape, with what the outputs make of
/// them (morph files and the VTU are staged as they come).
fn level_set_stage(
    run: &mut Run,
    clones: &lib::Clones,
    placed: &Placed,
) -> anyhow::Result<LevelSets> {
    let scene = run.scene;
    let out = &scene.outputs;
    let n = clones.templates();
    let mut sets = LevelSets {
        frames: vec![None; n],
        spheres: vec![Vec::new(); n],
        volumes: vec![f64::NAN; n],
        dna: Vec::new(),
        shrunk: 0,
        triangles: 0,
        ns: [0; 4],
    };
    if !out.level_sets() {
        run.st.skip("level sets", "no output needs a level set");
        return Ok(sets);
    }
    let t = Instant::now();
    let opts = shape_options(scene, clones, run.cal.params.grid_margin);
    let metres = scene.metres();
    let reuse = n < clones.grains;
    let mut meshes: Vec<Option<levelset::TriMesh>> = Vec::new();
    let mut vtu = if out.vtu {
        let p = run.staging.path("specimen.vtu")?;
        let f = std::fs::File::create(&p).with_context(|| format!("creating {}", p.display()))?;
        Some(VtuWriter::new(std::io::BufWriter::new(f))?)
    } else {
        None
    };
    let clock = Clock(Instant::now());
    let pb = crate::progress::bar("level sets", n as u64, run.quiet);
    let items: Vec<usize> = (0..n).collect();
    for chunk in items.chunks(CHUNK) {
        let results: Vec<lib::ShapeOut> = chunk
            .par_iter()
            .map(|&k| lib::shape_outputs(clones, placed.shapes.as_deref(), k, &opts, &clock))
            .collect::<lib::Result<_>>()?;
        let t4 = Instant::now();
        let mut piece = Surfaces::default();
        for (&k, g) in chunk.iter().zip(results) {
            for (total, part) in sets.ns.iter_mut().zip(g.cpu_ns) {
                *total += part;
            }
            if let Some((frame, bytes)) = g.lsdem {
                let rel = format!("lsdem/{}", levelset::io::lsdem::morph_path(k + 1));
                run.staging.write(&rel, &bytes)?;
                sets.frames[k] = Some(frame);
            }
            if let Some(c) = g.clump {
                sets.spheres[k] = c;
                sets.volumes[k] = g.volume;
            }
            if let Some(d) = g.dna {
                sets.dna.resize(n, None);
                sets.dna[k] = Some(d);
            }
            sets.shrunk += g.shrunk;
            if let Some(m) = g.mesh {
                if reuse {
                    meshes.resize_with(n, || None);
                    meshes[k] = Some(m);
                } else {
                    piece.push(k as u64, &m, &placed.poses[k], metres);
                }
            }
        }
        if let Some(w) = vtu.as_mut()
            && !reuse
        {
            sets.triangles += piece.triangles.len();
            w.piece(&piece).context("writing specimen.vtu")?;
        }
        sets.ns[3] += t4.elapsed().as_nanos() as u64;
        pb.inc(chunk.len() as u64);
    }
    pb.finish_and_clear();
    if let Some(w) = vtu {
        let t4 = Instant::now();
        sets.triangles += finish_vtu(w, reuse, &meshes, clones, placed, metres)?;
        sets.ns[3] += t4.elapsed().as_nanos() as u64;
    }
    let wall = t.elapsed().as_secs_f64();
    run.st.ran_s(
        "level sets",
        wall,
        format!(
            "{n} grids at {}³ rasterised on the fly and dropped, one per distinct shape (for: {}); {:.3} s wall, {:.3} s CPU rasterising; per-output CPU below",
            scene.level_set_resolution,
            [
                (out.lsdem, "LS-DEM"),
                (out.clumps(), "clumps"),
                (out.vtu, "VTU"),
            ]
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, s)| *s)
            .collect::<Vec<_>>()
            .join(", "),
            wall,
            sets.cpu(0)
        ),
    );
    Ok(sets)
}

/// Ends the specimen VTU: with shared shapes, every grain a copy of its
/// shape's surface, [`CHUNK`] grains per piece. Returns the triangles written.
fn finish_vtu<W: std::io::Write>(
    mut w: VtuWriter<W>,
    reuse: bool,
    meshes: &[Option<levelset::TriMesh>],
    clones: &lib::Clones,
    placed: &Placed,
    metres: f64,
) -> anyhow::Result<usize> {
    let mut triangles = 0;
    if reuse {
        for grains_chunk in (0..clones.grains).collect::<Vec<_>>().chunks(CHUNK) {
            let mut piece = Surfaces::default();
            for &k in grains_chunk {
                if let Some(m) = &meshes[clones.template_of(k)] {
                    piece.push(k as u64, m, &placed.poses[k], metres);
                }
            }
            triangles += piece.triangles.len();
            w.piece(&piece).context("writing specimen.vtu")?;
        }
    }
    let mut w = w.finish().context("writing specimen.vtu")?;
    std::io::Write::flush(&mut w).context("writing specimen.vtu")?;
    Ok(triangles)
}

/// The LS-DEM layout beside the morph files.
fn lsdem_stage(
    run: &mut Run,
    clones: &lib::Clones,
    placed: &Placed,
    sets: &LevelSets,
) -> anyhow::Result<()> {
    let out = &run.scene.outputs;
    if !run.st.skip_unless(out.lsdem, "lsdem", "LS-DEM") {
        return Ok(());
    }
    let t = Instant::now();
    let files = lib::outputs::lsdem_files(
        &sets.frames,
        &placed.poses,
        &|k| clones.template_of(k),
        run.scene.metres(),
        &out.lsdem_name,
        &run.provenance,
    )?;
    for (name, bytes) in &files.text {
        run.staging.write(&format!("lsdem/{name}"), bytes)?;
    }
    for (link, target) in &files.links {
        run.staging.link(&format!("lsdem/{link}"), target)?;
    }
    let n = clones.templates();
    run.st.ran_s(
        "lsdem",
        sets.cpu(1) + t.elapsed().as_secs_f64(),
        format!(
            "{n} morph files in their principal frames (worst |I_ij|/I_max {:.1e}; {} surface nodes, one grid unit = {:.4e} m){}, InitState/positions_{name}.dat, rotations_{name}.dat, poses.txt, PROVENANCE.txt (CPU)",
            files.worst_off_diagonal,
            out.lsdem_nodes,
            files.spacing_m,
            if n < clones.grains {
                format!(
                    ", {} more Morphologies/morph_<k>.dat as links to them",
                    clones.grains - n
                )
            } else {
                String::new()
            },
            name = out.lsdem_name
        ),
    );
    Ok(())
}

/// The clumps shared by the three clump outputs: one clump per distinct
/// shape, trimmed against every copy's neighbours, with the union's mass
/// properties; the report's clump section when a report is asked.
fn clump_stage(
    run: &mut Run,
    clones: &lib::Clones,
    placed: &Placed,
    sets: &mut LevelSets,
) -> anyhow::Result<(Vec<lib::dem::Template>, Option<String>)> {
    let out = &run.scene.outputs;
    if !run.st.skip_unless(out.clumps(), "clumps", "clump output") {
        return Ok((Vec::new(), None));
    }
    let t = Instant::now();
    let c = lib::clump_templates(
        &mut sets.spheres,
        &sets.volumes,
        &placed.poses,
        |k| clones.template_of(k),
        &placed.container,
        run.scene.metres(),
        run.scene.settle,
    )?;
    let section = if out.report {
        Some(report::clump_dna_section(
            &sets.spheres,
            &sets.dna,
            &c.unions,
            &sets.volumes,
            out.clump.spheres_per_clump,
        )?)
    } else {
        None
    };
    let n = clones.templates();
    let tr = &c.trim;
    run.st.ran_s(
        "clumps",
        sets.cpu(2) + t.elapsed().as_secs_f64(),
        format!(
            "{n} clumps for {} grains, {} spheres ({:.1} per clump, at most {}){}; {} sphere pairs of different grains overlapped (worst {:.2e} of the smaller diameter) and {} spheres crossed a wall: {} radii trimmed (at most {:.1} %), summed sphere volume {:+.2} %; union volume vs level set: mean |error| {:.2} % (summed spheres: {:+.1} %, what a code that adds the spheres' masses would get) (CPU)",
            clones.grains,
            c.spheres,
            c.spheres as f64 / n.max(1) as f64,
            out.clump.spheres_per_clump,
            if sets.shrunk > 0 {
                format!(", {} candidate spheres shrunk", sets.shrunk)
            } else {
                String::new()
            },
            tr.pairs,
            tr.worst,
            tr.walls,
            tr.trimmed,
            100.0 * tr.max_cut,
            100.0 * tr.volume_change,
            100.0 * c.union_error,
            100.0 * c.summed_error,
        ),
    );
    if let Some(r) = &c.reach {
        run.st.note(
            "clumps",
            format!(
                "settled packing: gaps between clumps below {} d50 closed: {} of {} near pairs of grains now touching; {} radii grown (at most {:.2} of the reach), summed sphere volume {:+.2} %",
                lib::CLUMP_REACH,
                r.closed_pairs,
                r.near_pairs,
                r.grown,
                r.max_growth,
                100.0 * r.volume_change
            ),
        );
    }
    Ok((c.templates, section))
}

/// The DEM decks the scene asks for (LAMMPS, LIGGGHTS, Yade), each with its
/// `settle.txt`.
fn deck_stages(
    run: &mut Run,
    clones: &lib::Clones,
    placed: &Placed,
    templates: &[lib::dem::Template],
) -> anyhow::Result<()> {
    let out = &run.scene.outputs;
    let metres = run.scene.metres();
    let container_m = lib::scale_container(&placed.container, metres);
    let bodies = lib::dem_bodies(&placed.poses, |k| clones.template_of(k), metres);
    // GLUE: the scene's density overrides the material's (one key, `outputs.density`)
    let material = lib::dem::Material {
        density: out.density,
        ..out.material.clone()
    };
    let s = lib::dem::DemSpecimen {
        templates,
        bodies: &bodies,
        container: &container_m,
        material: &material,
        provenance: &run.provenance,
    };
    type Writer = fn(&lib::dem::DemSpecimen) -> lib::Result<Vec<(String, Vec<u8>)>>;
    let decks: [(&'static str, bool, &str, Writer); 3] = [
        (
            "lammps",
            out.lammps_clumps,
            "LAMMPS clumps",
            lib::dem::lammps_files,
        ),
        (
            "liggghts",
            out.liggghts_templates,
            "LIGGGHTS templates",
            lib::dem::liggghts_files,
        ),
        ("yade", out.yade_clumps, "Yade clumps", lib::dem::yade_files),
    ];
    for (name, on, what, write) in decks {
        if !run.st.skip_unless(on, name, what) {
            continue;
        }
        let t = Instant::now();
        let files = write(&s).with_context(|| format!("the {name} deck"))?;
        for (path, bytes) in &files {
            run.staging.write(path, bytes)?;
        }
        let plan = s.plan()?;
        run.staging.write(
            &format!("{name}/settle.txt"),
            check::settle_text(plan.n, plan.atoms, plan.d50, &container_m).as_bytes(),
        )?;
        run.st.ran(
            name,
            t,
            format!(
                "{} files: {name}/ settle deck (Hertz-Mindlin E/{}, union mass and inertia, dt {:.3e} s = Hertz time of the smallest clump / {}, at most {} steps, self-checks: bodies, KE <= {:.3e} J, overlap <= 0.01 d50, bed fraction within 0.01 of {:.4}) + settle.txt",
                files.len() + 1,
                material.stiffness_scale,
                plan.dt,
                lib::dem::STEPS_PER_CONTACT,
                plan.max_steps,
                plan.ke_limit,
                plan.packed_fraction
            ) + &if name == "liggghts" && lib::dem::liggghts_batches(&s) > 1 {
                format!(
                    "; {} templates defined and inserted in {} batches of at most {} (LIGGGHTS 3.8's template set-up grows with the cube of the templates defined at once)",
                    s.templates.len(),
                    lib::dem::liggghts_batches(&s),
                    lib::dem::LIGGGHTS_BATCH
                )
            } else {
                String::new()
            },
        );
    }
    Ok(())
}

/// The DNA and grading report with its plots.
fn report_stage(
    run: &mut Run,
    parents: &cloner::Parents,
    clones: &lib::Clones,
    clump_section: Option<&str>,
) -> anyhow::Result<()> {
    if !run
        .st
        .skip_unless(run.scene.outputs.report, "report", "report")
    {
        return Ok(());
    }
    let t = Instant::now();
    let diameters = clones.equivalent_diameters();
    let mut files = report::write(
        parents,
        &clones.run,
        &diameters,
        &run.scene.clones,
        &run.cal.name,
    )?;
    if let (Some(sec), Some(md)) = (clump_section, files.first_mut()) {
        md.1.push_str(sec);
    }
    for (name, bytes) in &files {
        run.staging.write(name, bytes.as_bytes())?;
    }
    run.st.ran(
        "report",
        t,
        format!("report.md + {} SVG plots", files.len() - 1),
    );
    Ok(())
}

/// Always: poses and the stage report; then the staged files move into
/// `out_dir`.
fn write_stage(
    mut run: Run,
    clones: &lib::Clones,
    placed: &Placed,
    t_all: Instant,
) -> anyhow::Result<StageReport> {
    let scene = run.scene;
    let metres = scene.metres();
    let t = Instant::now();
    let bounding = clones.bounding_radii();
    let rows: Vec<lib::outputs::PoseRow> = (0..clones.grains)
        .map(|k| lib::outputs::PoseRow {
            grain: k as u64,
            clone: clones.run.clones[clones.template_of(k)].index,
            pose: lib::scale_pose(&placed.poses[k], metres),
            bounding_radius: bounding[k] * metres,
            scale: clones.scales[clones.template_of(k)],
        })
        .collect();
    run.staging.write(
        "poses.csv",
        lib::outputs::poses_csv(&rows, &run.provenance).as_bytes(),
    )?;
    run.staging.write(
        "PROVENANCE.txt",
        provenance_text(&run.provenance, scene).as_bytes(),
    )?;
    let out_dir = run.root.join(&scene.out_dir);
    run.st.ran(
        "write",
        t,
        "poses.csv (metres), PROVENANCE.txt, report.txt; staged files moved into out_dir".into(),
    );
    let mut report = StageReport {
        stages: run.st.0,
        files: Vec::new(),
        out_dir: out_dir.clone(),
        total_s: t_all.elapsed().as_secs_f64(),
    };
    run.staging.write("report.txt", report.text().as_bytes())?;
    report.files = run.staging.commit(&out_dir)?;
    Ok(report)
}

/// The container of the scene and the poses; an auto-sized cylinder grows
/// by 5 % until every clone fits (at most 30 tries).
fn place_in(
    scene: &Scene,
    clones: &[lib::place::ToPlace],
    seed: u64,
) -> anyhow::Result<(Container, Vec<Isometry3<f64>>, usize)> {
    let fixed = |c: Container| -> anyhow::Result<(Container, Vec<Isometry3<f64>>, usize)> {
        let poses = lib::place::place(clones, &c, scene.preset, seed)?;
        Ok((c, poses, 1))
    };
    match &scene.container {
        spec @ (ContainerSpec::Cylinder { .. } | ContainerSpec::Box { .. }) => {
            fixed(fixed_container(spec))
        }
        ContainerSpec::AutoCylinder { solid_fraction, .. } => {
            let v: f64 = clones
                .iter()
                .map(|c| 4.0 / 3.0 * std::f64::consts::PI * c.bounding_radius.powi(3))
                .sum();
            let d_max = clones
                .iter()
                .map(|c| 2.0 * c.bounding_radius)
                .fold(0.0, f64::max);
            // V_cyl = π D² / 4 · 2 D = π D³ / 2
            let mut d = (2.0 * v / (std::f64::consts::PI * solid_fraction))
                .cbrt()
                .max(1.5 * d_max);
            for tries in 1..=30 {
                let c = Container::triaxial(d);
                match lib::place::place(clones, &c, scene.preset, seed) {
                    Ok(p) => return Ok((c, p, tries)),
                    Err(lib::Error::ContainerFull { .. }) => d *= 1.05,
                    Err(e) => return Err(e.into()),
                }
            }
            bail!("`container`: AutoCylinder found no cylinder taking every clone in 30 tries")
        }
    }
}

fn describe(c: &Container) -> String {
    match c {
        Container::Cylinder { radius, height, .. } => {
            format!("a cylinder D = {:.4}, H = {height:.4}", 2.0 * radius)
        }
        Container::Box { min, max, .. } => {
            let s = max - min;
            format!("a box {:.4} × {:.4} × {:.4}", s.x, s.y, s.z)
        }
        _ => "a mesh".into(),
    }
}

/// The container of a fixed-size scene container.
fn fixed_container(spec: &ContainerSpec) -> Container {
    match spec {
        ContainerSpec::Cylinder { diameter, height } => Container::Cylinder {
            base: Point3::origin(),
            radius: 0.5 * diameter,
            height: height.unwrap_or(2.0 * diameter),
        },
        ContainerSpec::Box { x, y, z } => Container::Box {
            min: Point3::origin(),
            max: Point3::new(*x, *y, *z),
            periodic: [false, false],
        },
        // sized by the caller
        ContainerSpec::AutoCylinder { .. } => Container::triaxial(1.0),
    }
}

/// The walls' share of the specimen (issue 28): refuses a container
/// narrower than 8 d_max unless the scene allows it (periodic sides are not
/// walls: an x–y periodic box is never narrow).
fn refuse_narrow(
    scene: &Scene,
    container: &Container,
    poses: &[nalgebra::Isometry3<f64>],
    d_max: f64,
) -> anyhow::Result<lib::place::WallShare> {
    let wall = lib::place::wall_share(container, poses, d_max);
    if wall.width < 8.0 * d_max && !scene.allow_narrow_container {
        bail!(
            "the container is {:.2} d_max wide (width {:.4}, d_max {:.4}), narrower than 8 d_max: \
             the walls dominate such a packing{}; use a wider container, or set \
             `allow_narrow_container: true` to accept it",
            wall.width / d_max,
            wall.width,
            d_max,
            if poses.is_empty() {
                String::new()
            } else {
                format!(
                    " ({:.1} % of the grains lie within one d_max of a wall)",
                    100.0 * wall.near_fraction
                )
            }
        );
    }
    Ok(wall)
}
