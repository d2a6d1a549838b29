//! `cargo xtask specimen SCENE.ron`: a DEM specimen of cloned grains from a
//! scene file (schema in `scene.rs`): parents → clone → place → check →
//! the outputs the scene asks for, with a stage report.
//!
//! Demand-driven: the cloner keeps no level set (`Outputs::level_set =
//! false`) and measures DNA only for the report; the level set of a placed
//! grain is rasterised only when an output needs it (LS-DEM, clumps, VTU),
//! per grain on the fly in parallel chunks and dropped at once, so a
//! specimen of 10⁴ grains never holds 10⁴ grids. A stage nobody needs is
//! listed as `skipped (reason)` with zero time. Placement is one function
//! (`place.rs`) so that a grain packer can replace the bounding-sphere
//! packing without touching the rest.
//!
//! Every file goes through a staging folder and is moved into `out_dir`
//! only when every stage succeeded: an error leaves nothing half-written.

use std::fmt::Write as _;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;
use cloner::{Calibrated, CloneModel, Hooks};
use nalgebra::{Isometry3, Point3};
use packer_grains::StarGrain;
use packer_spheres::{Container, Sphere};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

pub(crate) mod check;
mod dem;
mod estimate;
#[cfg(test)]
mod golden;
mod outputs;
mod place;
mod report;
mod scene;
#[cfg(test)]
mod tests;

use outputs::{LsdemFrame, Staging, Surfaces, VtuWriter};
use scene::{Clones, ContainerSpec, ParentsSpec, Placement, Scene};

/// Cube-map cells per face of the star tables the grain packer packs (and
/// the level sets of the outputs are rasterised from: 1734 radii).
const STAR_FACE_CELLS: usize = 16;

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
}

struct Clock(Instant);

impl cloner::Clock for Clock {
    fn now_ns(&self) -> u64 {
        self.0.elapsed().as_nanos() as u64
    }
}

/// Stream offset of the graded sizes (never shared with the cloner's).
const SIZE_STREAM: u64 = 0x7369_7a65;

/// Runs a scene: every stage, then moves the files into `out_dir`.
///
/// # Errors
/// Any stage's error, naming the scene key or the file; nothing is left in
/// `out_dir` then.
pub(crate) fn run_scene(scene: &Scene, root: &Path, quiet: bool) -> anyhow::Result<StageReport> {
    let t_all = Instant::now();
    let mut st = Stages(Vec::new());
    let out = &scene.outputs;

    // inputs first: every named file before any heavy work
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
    // memory and disk, estimated before any work
    let need_est = estimate::Estimate::of(scene);
    need_est.check(
        estimate::available_memory(),
        estimate::free_disk(&root.join(&scene.out_dir)),
    )?;
    let staging = Staging::new(&root.join(&scene.out_dir))?;

    // parents
    let t = Instant::now();
    let owned;
    let (parents, note): (&cloner::Parents, String) = match &scene.parents {
        ParentsSpec::Ottawa => (
            ottawa()?,
            "71 embedded Ottawa-sand grains (spherical harmonics → level sets)".to_owned(),
        ),
        ParentsSpec::Files {
            path,
            format,
            spacing,
            raw_dims,
            raw_dtype,
            big_endian,
            keep_border,
            min_voxels,
            smoothing,
            sh_degree,
            resolution,
        } => {
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
            owned = parents;
            (&owned, format!("{summary}, DNA {dna_s:.2} s"))
        }
    };
    st.ran(
        "parents",
        t,
        format!(
            "{note}; estimated need: memory {}, disk {}",
            estimate::human(need_est.memory),
            estimate::human(need_est.disk)
        ),
    );

    // clone
    let t = Instant::now();
    let mut params = cal.params;
    params.outputs = cloner::Outputs {
        level_set: false,
        dna: out.report,
    };
    let seed = scene.seed.unwrap_or(params.seed);
    params.seed = seed;
    let provenance = provenance_lines(scene, &scene.source_text, root, seed);
    let model = CloneModel::fit(parents, &params)?;
    let count = scene.distinct();
    let pb = crate::progress::bar("cloning", count, quiet);
    let cb = crate::progress::clone_callback(&pb);
    let clock = Clock(Instant::now());
    let run = model.run(
        0..count,
        Hooks {
            clock: &clock,
            progress: Some(&cb),
        },
    )?;
    pb.finish_and_clear();
    st.ran(
        "clone",
        t,
        format!(
            "{} clones of `{}`{} ({} candidates, acceptance {:.1} %); level sets kept: no, DNA measured: {}",
            run.clones.len(),
            if scene.distinct_shapes.is_some() {
                format!(
                    " as the distinct shapes of {} grains (grain k a copy of clone k mod {})",
                    scene.clones.count(),
                    run.clones.len()
                )
            } else {
                String::new()
            },
            cal.name,
            run.stats.attempts,
            100.0 * run.stats.acceptance_rate(),
            if out.report { "yes (report)" } else { "no" }
        ),
    );

    // sizes: graded scenes rescale every clone
    let equivalent =
        |c: &cloner::ClonedGrain| (6.0 * c.surface.volume / std::f64::consts::PI).cbrt();
    let scales: Vec<f64> = match &scene.clones {
        Clones::Count(_) => vec![1.0; run.clones.len()],
        Clones::Graded { grading, size, .. } => {
            let g = crate::pack_cmd::parse_grading(grading)?;
            run.clones
                .iter()
                .map(|c| {
                    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ SIZE_STREAM);
                    rng.set_stream(c.index);
                    size.scale(
                        g.diameter_at(rng.random::<f64>()),
                        c.surface.volume,
                        c.surface.dims,
                    )
                })
                .collect()
        }
    };
    // grain k is a copy of clone (template) k mod n
    let n_templates = run.clones.len();
    let n_grains = scene.clones.count() as usize;
    let template_of = |k: usize| k % n_templates;
    let bounding: Vec<f64> = (0..n_grains)
        .map(|k| {
            let t = template_of(k);
            run.clones[t].surface.r_max * scales[t] * place::BOUNDING_MARGIN
        })
        .collect();
    let to_place: Vec<place::ToPlace> = (0..n_grains)
        .map(|k| place::ToPlace {
            index: k as u64,
            bounding_radius: bounding[k],
        })
        .collect();

    // place
    let t = Instant::now();
    let shapes: Option<Vec<StarGrain>> = match scene.placement {
        Placement::Grains => Some(
            run.clones
                .par_iter()
                .zip(&scales)
                .map(|(c, s)| {
                    let radii: Vec<f64> = c.radii.iter().map(|r| r * s).collect();
                    let table = model
                        .star_table(&radii, STAR_FACE_CELLS)
                        .with_context(|| format!("star table of clone {}", c.index))?;
                    StarGrain::from_table(STAR_FACE_CELLS, &table)
                        .with_context(|| format!("star table of clone {}", c.index))
                })
                .collect::<anyhow::Result<_>>()?,
        ),
        Placement::BoundingSpheres => None,
    };
    let grains: Option<Vec<StarGrain>> = shapes
        .as_ref()
        .map(|t| (0..n_grains).map(|k| t[template_of(k)].clone()).collect());
    let mut grain_stats = None;
    let (container, poses) = if let Some(grains) = &grains {
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
        refuse_narrow(scene, &planned, &[], grain_d_max(grains))?;
        let pb = crate::progress::spinner("packing grains", quiet);
        let gp = place::place_grains(grains, fixed, auto, scene.preset, seed)?;
        pb.finish_and_clear();
        let s = gp.stats;
        st.ran(
            "place",
            t,
            format!(
                "{} grains (star tables, {STAR_FACE_CELLS} cells per cube face) packed in {}{} by pack_grains ({:?} skeleton): solid fraction {:.4}; compaction: {} proxy spheres, {} growth steps ({} undone), {} FIRE iterations, {} neighbour builds; first gap sweep: {} overlapping pairs, deepest / d {:.2e}; {} + {} sweeps, worst gap / d {:.2e}",
                grains.len(),
                describe(&gp.container),
                if gp.tries > 1 {
                    format!(
                        ", auto-sized in {} tries: REQUESTED solid fraction {:.4} NOT REACHED, lowered to {:.4} (lower_if_needed)",
                        gp.tries,
                        auto.map_or(0.0, |a| a.0),
                        s.solid_fraction
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
        grain_stats = Some(s);
        (gp.container, gp.poses)
    } else {
        let (container, poses, tries) = place_in(scene, &to_place, seed)?;
        st.ran(
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
        (container, poses)
    };

    // the walls' share of the specimen (issue 28): refuse a narrow container unless asked
    let d_max = match &grains {
        Some(g) => grain_d_max(g),
        None => to_place
            .iter()
            .map(|c| 2.0 * c.bounding_radius)
            .fold(0.0, f64::max),
    };
    let wall = refuse_narrow(scene, &container, &poses, d_max)?;
    st.note(
        "place",
        format!(
            "container {:.2} d_max wide (d_max {:.4}); grains within one d_max of a wall: {:.1} %",
            wall.width / d_max,
            d_max,
            100.0 * wall.near_fraction
        ),
    );

    // check
    let t = Instant::now();
    if let Some(grains) = &grains {
        let pb = crate::progress::spinner("checking overlaps", quiet);
        let r = packer_grains::check_grain_overlaps(
            grains,
            &poses,
            &container,
            &packer_grains::CheckParams::default(),
        )?;
        pb.finish_and_clear();
        if !r.is_clean() {
            bail!(
                "the independent check rejects the grain packing: {} overlapping nodes (worst φ/d {:.2e} between grains {:?}), {} nodes outside the container, {} overlap voxels",
                r.overlapping_nodes,
                r.worst_phi_over_d,
                r.worst_pair,
                r.nodes_outside,
                r.raster_overlap_voxels
            );
        }
        let fabric = packer_grains::orientation_fabric(&poses, &nalgebra::Vector3::x())?;
        let fraction = grain_stats.map_or(f64::NAN, |s| s.solid_fraction);
        st.ran(
            "check",
            t,
            format!(
                "independent LS-DEM check: {} nodes of 1000 per grain sampled in the neighbours' 32³ level sets, worst φ/d {:.2e} (≥ −1e-6), walls {:.2e}, {} overlap voxels in {} pairs rasterised 4× finer; solid fraction {fraction:.4}; fabric of the major axes ‖N − I/3‖ = {:.4}",
                r.nodes_checked,
                r.worst_phi_over_d,
                r.worst_wall_over_d,
                r.raster_overlap_voxels,
                r.raster_pairs,
                fabric.deviatoric_norm
            ),
        );
    } else {
        let spheres: Vec<Sphere> = poses
            .iter()
            .zip(&bounding)
            .map(|(p, r)| Sphere {
                center: Point3::from(p.translation.vector),
                radius: *r,
            })
            .collect();
        let check = packer_spheres::check_spheres(&container, &spheres, 1e-9)?;
        if !check.is_clean(1e-9) {
            bail!(
                "the independent checker rejects the placement (worst pair gap / d {:.2e}, wall {:.2e})",
                check.worst_normalised_gap,
                check.worst_normalised_wall_gap
            );
        }
        let sphere_fraction = packer_spheres::solid_fraction(&container, &spheres)?;
        let grain_volume: f64 = (0..n_grains)
            .map(|k| {
                let t = template_of(k);
                run.clones[t].surface.volume * scales[t].powi(3)
            })
            .sum();
        st.ran(
            "check",
            t,
            format!(
                "independent checker: bounding spheres do not overlap (worst gap / d {:.2e}, walls {:.2e}); solid fraction {:.3} of bounding spheres, {:.3} of grains",
                check.worst_normalised_gap,
                check.worst_normalised_wall_gap,
                sphere_fraction,
                grain_volume / container.volume()
            ),
        );
    }

    // level sets on demand, per distinct shape (template), with its outputs
    let need = |on: bool, what: &str| {
        if on {
            None
        } else {
            Some(format!("no {what} asked"))
        }
    };
    let metres = scene.metres();
    let mut frames: Vec<Option<LsdemFrame>> = vec![None; n_templates];
    let mut template_spheres: Vec<Vec<(Point3<f64>, f64)>> = vec![Vec::new(); n_templates];
    let mut template_volume: Vec<f64> = vec![f64::NAN; n_templates];
    let mut template_dna: Vec<Option<(levelset::GridSpec, Vec<f64>)>> = Vec::new();
    let mut clump_section: Option<String> = None;
    let mut meshes: Vec<Option<levelset::TriMesh>> = Vec::new();
    let ns = [
        AtomicU64::new(0), // rasterise
        AtomicU64::new(0), // lsdem
        AtomicU64::new(0), // clumps
        AtomicU64::new(0), // vtu
    ];
    let mut shrunk = 0usize;
    let mut triangles = 0usize;
    let reuse = n_templates < n_grains;
    if out.level_sets() {
        let t = Instant::now();
        let res = scene.level_set_resolution;
        let clump_params = out.clump.params();
        let lsdem_h = lsdem_spacing(scene, &run, &scales, params.grid_margin);
        let mut vtu = if out.vtu {
            let p = staging.path("specimen.vtu")?;
            let f =
                std::fs::File::create(&p).with_context(|| format!("creating {}", p.display()))?;
            Some(VtuWriter::new(BufWriter::new(f))?)
        } else {
            None
        };
        let pb = crate::progress::bar("level sets", n_templates as u64, quiet);
        let items: Vec<usize> = (0..n_templates).collect();
        for chunk in items.chunks(CHUNK) {
            let results: Vec<GrainOut> = chunk
                .par_iter()
                .map(|&k| {
                    let c = &run.clones[k];
                    let t0 = Instant::now();
                    let radii: Vec<f64> = c.radii.iter().map(|r| r * scales[k]).collect();
                    // Grains: the packed star surface itself (the level set the
                    // check passed); bounding spheres: the model's own table.
                    let grid = match &shapes {
                        Some(g) => star_grid(&g[k], &radii, params.grid_margin, res),
                        None => model.rasterise_at(&radii, res).map_err(Into::into),
                    }
                    .with_context(|| format!("level set of clone {}", c.index))?;
                    let t1 = Instant::now();
                    ns[0].fetch_add((t1 - t0).as_nanos() as u64, Ordering::Relaxed);
                    let mut g = GrainOut::default();
                    if out.lsdem {
                        let pm =
                            levelset::io::principal_morph(&grid, lsdem_h, 1.0, out.lsdem_nodes)
                                .with_context(|| format!("LS-DEM morph of clone {}", c.index))?;
                        let path = staging
                            .path(&format!("lsdem/{}", levelset::io::lsdem::morph_path(k + 1)))?;
                        let f = std::fs::File::create(&path)
                            .with_context(|| format!("creating {}", path.display()))?;
                        let mut w = BufWriter::new(f);
                        levelset::io::write_morph_decimals(&mut w, &pm.morph, MORPH_DECIMALS)
                            .with_context(|| format!("writing {}", path.display()))?;
                        std::io::Write::flush(&mut w)
                            .with_context(|| format!("writing {}", path.display()))?;
                        g.lsdem = Some(LsdemFrame {
                            frame: pm.frame,
                            spacing: pm.spacing,
                            off_diagonal: pm.off_diagonal,
                        });
                    }
                    let t2 = Instant::now();
                    ns[1].fetch_add((t2 - t1).as_nanos() as u64, Ordering::Relaxed);
                    if out.clumps() {
                        let cl = levelset::clump(&grid, &clump_params)
                            .with_context(|| format!("clump of clone {}", c.index))?;
                        g.shrunk = cl.shrunk;
                        g.volume = grid.volume();
                        g.clump = Some(cl.spheres);
                        if out.report {
                            let dna = morph_dna::measure(
                                &grid,
                                &CLUMP_DNA,
                                &morph_dna::MeasureParams::default(),
                            )
                            .with_context(|| format!("DNA of clone {}", c.index))?;
                            g.dna = Some((*grid.spec(), dna));
                        }
                    }
                    let t3 = Instant::now();
                    ns[2].fetch_add((t3 - t2).as_nanos() as u64, Ordering::Relaxed);
                    if out.vtu {
                        let coarse = coarsen(&grid, out.vtu_resolution)
                            .with_context(|| format!("VTU grid of clone {}", c.index))?;
                        g.mesh = Some(coarse.as_ref().unwrap_or(&grid).marching_cubes());
                    }
                    ns[3].fetch_add(t3.elapsed().as_nanos() as u64, Ordering::Relaxed);
                    Ok(g)
                })
                .collect::<anyhow::Result<_>>()?;
            let t4 = Instant::now();
            let mut piece = Surfaces::default();
            for (&k, g) in chunk.iter().zip(results) {
                frames[k] = g.lsdem;
                if let Some(c) = g.clump {
                    template_spheres[k] = c;
                    template_volume[k] = g.volume;
                }
                if let Some(d) = g.dna {
                    template_dna.resize(n_templates, None);
                    template_dna[k] = Some(d);
                }
                shrunk += g.shrunk;
                if let Some(m) = g.mesh {
                    if reuse {
                        meshes.resize_with(n_templates, || None);
                        meshes[k] = Some(m);
                    } else {
                        piece.push(k as u64, &m, &poses[k], metres);
                    }
                }
            }
            if let Some(w) = vtu.as_mut()
                && !reuse
            {
                triangles += piece.triangles.len();
                w.piece(&piece).context("writing specimen.vtu")?;
            }
            ns[3].fetch_add(t4.elapsed().as_nanos() as u64, Ordering::Relaxed);
            pb.inc(chunk.len() as u64);
        }
        pb.finish_and_clear();
        if let Some(mut w) = vtu {
            let t4 = Instant::now();
            if reuse {
                // every grain a copy of its template's surface, CHUNK grains per piece
                for grains_chunk in (0..n_grains).collect::<Vec<_>>().chunks(CHUNK) {
                    let mut piece = Surfaces::default();
                    for &k in grains_chunk {
                        if let Some(m) = &meshes[template_of(k)] {
                            piece.push(k as u64, m, &poses[k], metres);
                        }
                    }
                    triangles += piece.triangles.len();
                    w.piece(&piece).context("writing specimen.vtu")?;
                }
            }
            let mut w = w.finish().context("writing specimen.vtu")?;
            std::io::Write::flush(&mut w).context("writing specimen.vtu")?;
            ns[3].fetch_add(t4.elapsed().as_nanos() as u64, Ordering::Relaxed);
        }
        let wall = t.elapsed().as_secs_f64();
        let cpu = |k: usize| ns[k].load(Ordering::Relaxed) as f64 * 1e-9;
        st.ran_s(
            "level sets",
            wall,
            format!(
                "{n_templates} grids at {res}³ rasterised on the fly and dropped, one per distinct shape (for: {}); {:.3} s wall, {:.3} s CPU rasterising; per-output CPU below",
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
                cpu(0)
            ),
        );
    } else {
        st.skip("level sets", "no output needs a level set");
    }
    let cpu = |k: usize| ns[k].load(Ordering::Relaxed) as f64 * 1e-9;

    // LS-DEM
    match need(out.lsdem, "LS-DEM") {
        Some(r) => st.skip("lsdem", &r),
        None => {
            let t = Instant::now();
            let files = outputs::lsdem_files(
                &frames,
                &poses,
                &template_of,
                metres,
                &out.lsdem_name,
                &provenance,
            )?;
            for (name, bytes) in &files.text {
                staging.write(&format!("lsdem/{name}"), bytes)?;
            }
            for (link, target) in &files.links {
                staging.link(&format!("lsdem/{link}"), target)?;
            }
            st.ran_s(
                "lsdem",
                cpu(1) + t.elapsed().as_secs_f64(),
                format!(
                    "{n_templates} morph files in their principal frames (worst |I_ij|/I_max {:.1e}; {} surface nodes, one grid unit = {:.4e} m){}, InitState/positions_{name}.dat, rotations_{name}.dat, poses.txt, PROVENANCE.txt (CPU)",
                    files.worst_off_diagonal,
                    out.lsdem_nodes,
                    files.spacing_m,
                    if reuse {
                        format!(
                            ", {} more Morphologies/morph_<k>.dat as links to them",
                            n_grains - n_templates
                        )
                    } else {
                        String::new()
                    },
                    name = out.lsdem_name
                ),
            );
        }
    }
    // clumps (shared by the three clump outputs): one clump per distinct shape, trimmed
    // against every copy's neighbours, then the union's mass properties per shape
    let mut dem_templates: Vec<dem::Template> = Vec::new();
    match need(out.clumps(), "clump output") {
        Some(r) => st.skip("clumps", &r),
        None => {
            let n: usize = template_spheres.iter().map(Vec::len).sum();
            let t = Instant::now();
            let tr = packer_grains::separate_clumps(
                &mut template_spheres,
                &poses,
                template_of,
                &container,
            )?;
            let unions: Vec<levelset::MassProperties> = template_spheres
                .par_iter()
                .zip(&template_volume)
                .enumerate()
                .map(|(k, (s, v))| {
                    let d = (6.0 * v / std::f64::consts::PI).cbrt();
                    levelset::union_mass_properties(s, d / UNION_CELLS)
                        .with_context(|| format!("union of the clump of clone {k}"))
                })
                .collect::<anyhow::Result<_>>()?;
            let k = n_templates.max(1) as f64;
            let union_err = unions
                .iter()
                .zip(&template_volume)
                .map(|(u, v)| (u.volume / v - 1.0).abs())
                .sum::<f64>()
                / k;
            let sum_err = template_spheres
                .iter()
                .zip(&template_volume)
                .map(|(s, v)| {
                    s.iter()
                        .map(|(_, r)| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
                        .sum::<f64>()
                        / v
                        - 1.0
                })
                .sum::<f64>()
                / k;
            if out.report {
                clump_section = Some(clump_dna_section(
                    &template_spheres,
                    &template_dna,
                    &unions,
                    &template_volume,
                    out.clump.spheres_per_clump,
                )?);
            }
            dem_templates = template_spheres
                .iter()
                .zip(&unions)
                .map(|(s, u)| dem::Template {
                    spheres: s.iter().map(|(c, r)| (c * metres, r * metres)).collect(),
                    volume: u.volume * metres.powi(3),
                    centroid: u.centroid * metres,
                    inertia: u.inertia * metres.powi(5),
                })
                .collect();

            st.ran_s(
                "clumps",
                cpu(2) + t.elapsed().as_secs_f64(),
                format!(
                    "{n_templates} clumps for {n_grains} grains, {n} spheres ({:.1} per clump, at most {}){}; {} sphere pairs of different grains overlapped (worst {:.2e} of the smaller diameter) and {} spheres crossed a wall: {} radii trimmed (at most {:.1} %), summed sphere volume {:+.2} %; union volume vs level set: mean |error| {:.2} % (summed spheres: {:+.1} %, what a code that adds the spheres' masses would get) (CPU)",
                    n as f64 / k,
                    out.clump.spheres_per_clump,
                    if shrunk > 0 {
                        format!(", {shrunk} candidate spheres shrunk")
                    } else {
                        String::new()
                    },
                    tr.pairs,
                    tr.worst,
                    tr.walls,
                    tr.trimmed,
                    100.0 * tr.max_cut,
                    100.0 * tr.volume_change,
                    100.0 * union_err,
                    100.0 * sum_err,
                ),
            );
        }
    }
    let container_m = scale_container(&container, metres);
    let dem_bodies: Vec<dem::Body> = (0..n_grains)
        .map(|k| dem::Body {
            id: k as u64,
            template: template_of(k),
            pose: scale_pose(&poses[k], metres),
        })
        .collect();
    // GLUE: the scene's density overrides the material's (one key, `outputs.density`)
    let material = dem::Material {
        density: out.density,
        ..out.material.clone()
    };
    let dem_specimen = dem::DemSpecimen {
        templates: &dem_templates,
        bodies: &dem_bodies,
        container: &container_m,
        material: &material,
        provenance: &provenance,
    };
    type Writer = fn(&dem::DemSpecimen) -> anyhow::Result<Vec<(String, Vec<u8>)>>;
    let decks: [(&'static str, bool, &str, Writer); 3] = [
        (
            "lammps",
            out.lammps_clumps,
            "LAMMPS clumps",
            dem::lammps_files,
        ),
        (
            "liggghts",
            out.liggghts_templates,
            "LIGGGHTS templates",
            dem::liggghts_files,
        ),
        ("yade", out.yade_clumps, "Yade clumps", dem::yade_files),
    ];
    for (name, on, what, write) in decks {
        match need(on, what) {
            Some(r) => st.skip(name, &r),
            None => {
                let t = Instant::now();
                let files = write(&dem_specimen).with_context(|| format!("the {name} deck"))?;
                for (path, bytes) in &files {
                    staging.write(path, bytes)?;
                }
                let plan = dem_specimen.plan()?;
                staging.write(
                    &format!("{name}/settle.txt"),
                    check::settle_text(plan.n, plan.atoms, plan.d50, &container_m).as_bytes(),
                )?;
                st.ran(
                    name,
                    t,
                    format!(
                        "{} files: {name}/ settle deck (Hertz-Mindlin E/{}, union mass and inertia, dt {:.3e} s = Hertz time of the smallest clump / {}, at most {} steps, self-checks: bodies, KE <= {:.3e} J, overlap <= 0.01 d50, bed fraction within 0.01 of {:.4}) + settle.txt",
                        files.len() + 1,
                        material.stiffness_scale,
                        plan.dt,
                        dem::STEPS_PER_CONTACT,
                        plan.max_steps,
                        plan.ke_limit,
                        plan.packed_fraction
                    ),
                );
            }
        }
    }
    match need(out.vtu, "VTU") {
        Some(r) => st.skip("vtu", &r),
        None => st.ran_s(
            "vtu",
            cpu(3),
            format!(
                "specimen.vtu: {triangles} marching-cubes triangles of {n_grains} grains at {} cells across, binary, grain_id per cell, metres (CPU)",
                out.vtu_resolution.min(scene.level_set_resolution - 1)
            ),
        ),
    }
    // report
    match need(out.report, "report") {
        Some(r) => st.skip("report", &r),
        None => {
            let t = Instant::now();
            let diameters: Vec<f64> = run
                .clones
                .iter()
                .zip(&scales)
                .map(|(c, s)| equivalent(c) * s)
                .collect();
            let mut files = report::write(parents, &run, &diameters, &scene.clones, &cal.name)?;
            if let (Some(sec), Some(md)) = (&clump_section, files.first_mut()) {
                md.1.push_str(sec);
            }
            for (name, bytes) in &files {
                staging.write(name, bytes.as_bytes())?;
            }
            st.ran(
                "report",
                t,
                format!("report.md + {} SVG plots", files.len() - 1),
            );
        }
    }
    // always: poses and the stage report
    let t = Instant::now();
    let rows: Vec<outputs::PoseRow> = (0..n_grains)
        .map(|k| outputs::PoseRow {
            grain: k as u64,
            clone: run.clones[template_of(k)].index,
            pose: scale_pose(&poses[k], metres),
            bounding_radius: bounding[k] * metres,
            scale: scales[template_of(k)],
        })
        .collect();
    staging.write(
        "poses.csv",
        outputs::poses_csv(&rows, &provenance).as_bytes(),
    )?;
    staging.write(
        "PROVENANCE.txt",
        provenance_text(&provenance, scene).as_bytes(),
    )?;
    let out_dir = root.join(&scene.out_dir);
    st.ran(
        "write",
        t,
        "poses.csv (metres), PROVENANCE.txt, report.txt; staged files moved into out_dir".into(),
    );
    let mut report = StageReport {
        stages: st.0,
        files: Vec::new(),
        out_dir: out_dir.clone(),
        total_s: t_all.elapsed().as_secs_f64(),
    };
    staging.write("report.txt", report.text().as_bytes())?;
    report.files = staging.commit(&out_dir)?;
    Ok(report)
}

/// Decimals of the level-set values and nodes of the LS-DEM morph files (grid units):
/// within 5e-10 of the exact values, and the products of inertia of the file's own level
/// set stay below 1e-11 of its moments (`specimen/lsdem-files` parses the files).
const MORPH_DECIMALS: u32 = 9;

/// Lattice cells per equivalent diameter of the union integration of a clump
/// (`levelset::union_mass_properties`; validated by `specimen/clump-mass` at the same
/// value): 60 gives a 20-sphere clump's largest spheres (≈ d/4) 15 cells per radius
/// (volume −0.3 % for a lone sphere) and costs ≈ 5 ms; 100 cost 24 ms per clump (121 s
/// for 10⁴ clumps on 2 cores).
const UNION_CELLS: f64 = 60.0;

/// `pose` with its translation in metres (`metres` per scene unit).
fn scale_pose(pose: &Isometry3<f64>, metres: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        nalgebra::Translation3::from(pose.translation.vector * metres),
        pose.rotation,
    )
}

/// `container` with its lengths in metres.
fn scale_container(container: &Container, metres: f64) -> Container {
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

/// The provenance lines of every output: grainforge version and commit, seed, the scene,
/// and for clones of the embedded NIST/VCCTL grains their licence and citation.
fn provenance_lines(scene: &Scene, scene_text: &str, root: &Path, seed: u64) -> Vec<String> {
    let commit = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_else(|| "unknown".into());
    let dirty = std::process::Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .current_dir(root)
        .output()
        .ok()
        .is_some_and(|o| o.status.success() && !o.stdout.is_empty());
    let mut lines = vec![
        format!(
            "grainforge {} (commit {commit}{}), cargo xtask specimen",
            env!("CARGO_PKG_VERSION"),
            if dirty {
                ", with uncommitted changes"
            } else {
                ""
            }
        ),
        format!(
            "seed {seed}; units: SI (lengths m, masses kg, density {} kg/m^3); 1 parents' length unit = {:e} m",
            scene.outputs.density,
            scene.metres()
        ),
    ];
    match &scene.parents {
        ParentsSpec::Ottawa => lines.extend(
            [
                "parents: 71 Ottawa-sand grains of the NIST/VCCTL aggregate shape database (X-ray CT, spherical harmonics),",
                "  Garboczi (2002), Cem. Concr. Res. 32:1621; VCCTL (Bentz, Garboczi, Bullard; github.com/jwbullard/VCCTL),",
                "  Copyright (c) 2020-present Jeffrey W. Bullard, MIT licence (notice in full in PROVENANCE.txt).",
                "  The clones are new grains statistically like these parents (grainforge GSC 2.0), not copies.",
            ]
            .iter()
            .map(|s| (*s).to_owned()),
        ),
        ParentsSpec::Files { path, .. } => lines.push(format!("parents: {}", path.display())),
    }
    lines.push("scene:".into());
    lines.extend(scene_text.lines().map(|l| format!("  {l}")));
    lines
}

/// The licence notice of the embedded NIST/VCCTL grains.
const VCCTL_NOTICE: &str = include_str!("../../../fixtures/grains/vcctl/NOTICE.txt");

/// `PROVENANCE.txt`: the provenance lines, and the VCCTL licence notice in full when the
/// parents are the embedded grains.
fn provenance_text(lines: &[String], scene: &Scene) -> String {
    let mut s = String::new();
    for l in lines {
        s.push_str(l);
        s.push('\n');
    }
    if matches!(scene.parents, ParentsSpec::Ottawa) {
        s.push('\n');
        s.push_str(VCCTL_NOTICE);
    }
    s
}

/// The embedded Ottawa parents, built once per process (the tests run
/// several scenes).
fn ottawa() -> anyhow::Result<&'static cloner::Parents> {
    static OTTAWA: std::sync::OnceLock<cloner::Parents> = std::sync::OnceLock::new();
    if let Some(p) = OTTAWA.get() {
        return Ok(p);
    }
    let p = validate::grains::ottawa_parents()?;
    Ok(OTTAWA.get_or_init(|| p))
}

/// The one grid spacing of the LS-DEM morph files: the scene's, or the
/// median of the grains' own spacings (`2 · margin · r_max / (res − 1)`).
fn lsdem_spacing(scene: &Scene, run: &cloner::Run, scales: &[f64], margin: f64) -> f64 {
    if let Some(h) = scene.outputs.lsdem_spacing {
        return h;
    }
    let res = scene.level_set_resolution as f64;
    let mut own: Vec<f64> = run
        .clones
        .iter()
        .zip(scales)
        .map(|(c, s)| 2.0 * margin * c.surface.r_max * s / (res - 1.0))
        .collect();
    own.sort_by(f64::total_cmp);
    own.get(own.len() / 2).copied().unwrap_or(1.0)
}

/// `grid` resampled (trilinear) over the same box at `cells` cells across
/// its largest side, for the VTU surface only; `None` when the grid is
/// already that coarse (no upsampling).
fn coarsen(grid: &levelset::Grid, cells: usize) -> anyhow::Result<Option<levelset::Grid>> {
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

/// The DNA compared between a grain's level set and its delivered clump.
const CLUMP_DNA: [morph_dna::Descriptor; 4] = [
    morph_dna::Descriptor::Volume,
    morph_dna::Descriptor::VolumeSurfaceRatio,
    morph_dna::Descriptor::AspectRatio,
    morph_dna::Descriptor::Roundness,
];

/// The report's section on the clumps as delivered (after trimming): their DNA, each
/// union rasterised on its grain's own grid, and their union mass against the level sets.
fn clump_dna_section(
    spheres: &[Vec<(Point3<f64>, f64)>],
    dna: &[Option<(levelset::GridSpec, Vec<f64>)>],
    unions: &[levelset::MassProperties],
    volumes: &[f64],
    per_clump: usize,
) -> anyhow::Result<String> {
    let errors: Vec<Vec<f64>> = spheres
        .par_iter()
        .zip(dna)
        .filter_map(|(s, d)| d.as_ref().map(|d| (s, d)))
        .map(|(s, (spec, ours))| {
            let union = levelset::Grid::from_fn(*spec, |p| {
                s.iter()
                    .fold(f64::INFINITY, |m, (c, r)| m.min((p - c).norm() - r))
            })?;
            let theirs =
                morph_dna::measure(&union, &CLUMP_DNA, &morph_dna::MeasureParams::default())?;
            Ok(theirs
                .iter()
                .zip(ours)
                .map(|(c, l)| 100.0 * (c / l - 1.0))
                .collect())
        })
        .collect::<anyhow::Result<_>>()?;
    let k = errors.len().max(1) as f64;
    let mut md = format!(
        "\n## Clumps as delivered ({per_clump} spheres per clump, after trimming)\n\n\
         The body a clump DEM code moves, against the grain's level set: DNA of the sphere union \
         rasterised on the grain's own grid (mean and mean |error| over {} clumps), and the \
         union's mass properties (`levelset::union_mass_properties`).\n\n\
         | parameter | mean error % | mean \\|error\\| % |\n| --- | --- | --- |\n",
        errors.len()
    );
    for (i, d) in CLUMP_DNA.iter().enumerate() {
        let mean = errors.iter().map(|e| e[i]).sum::<f64>() / k;
        let abs = errors.iter().map(|e| e[i].abs()).sum::<f64>() / k;
        md.push_str(&format!("| {} | {mean:+.2} | {abs:.2} |\n", d.name()));
    }
    let vol = unions
        .iter()
        .zip(volumes)
        .map(|(u, v)| 100.0 * (u.volume / v - 1.0).abs())
        .sum::<f64>()
        / unions.len().max(1) as f64;
    md.push_str(&format!(
        "\nUnion volume (mass) against the level set: mean |error| {vol:.2} %. \
         The masses and inertias given to LAMMPS, LIGGGHTS and Yade are the union's.\n"
    ));
    Ok(md)
}

/// The products of the level-set stage for one distinct shape.
#[derive(Default)]
struct GrainOut {
    /// The level set's spec and DNA ([`CLUMP_DNA`]) when a report of the clumps is asked.
    dna: Option<(levelset::GridSpec, Vec<f64>)>,
    lsdem: Option<LsdemFrame>,
    clump: Option<Vec<(Point3<f64>, f64)>>,
    /// The level set's volume (scene units) when a clump was made.
    volume: f64,
    shrunk: usize,
    mesh: Option<levelset::TriMesh>,
}

/// The container of the scene and the poses; an auto-sized cylinder grows
/// by 5 % until every clone fits (at most 30 tries).
fn place_in(
    scene: &Scene,
    clones: &[place::ToPlace],
    seed: u64,
) -> anyhow::Result<(Container, Vec<Isometry3<f64>>, usize)> {
    let fixed = |c: Container| -> anyhow::Result<(Container, Vec<Isometry3<f64>>, usize)> {
        let poses = place::place(clones, &c, scene.preset, seed)?;
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
                match place::place(clones, &c, scene.preset, seed) {
                    Ok(p) => return Ok((c, p, tries)),
                    Err(e) if e.downcast_ref::<place::ContainerFull>().is_some() => d *= 1.05,
                    Err(e) => return Err(e),
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

/// The level set of a packed grain: its star table rasterised on the grid
/// `CloneModel::rasterise_at` would use (`±margin · max node radius`).
fn star_grid(
    grain: &StarGrain,
    radii: &[f64],
    margin: f64,
    resolution: usize,
) -> anyhow::Result<levelset::Grid> {
    let half = margin * radii.iter().fold(grain.r_max(), |a, b| a.max(*b));
    Ok(grain.level_set(resolution, half)?)
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

/// The largest volume-equivalent diameter of the grains.
fn grain_d_max(grains: &[StarGrain]) -> f64 {
    grains
        .iter()
        .map(|g| (6.0 * g.volume() / std::f64::consts::PI).cbrt())
        .fold(0.0, f64::max)
}

/// The walls' share of the specimen (issue 28): refuses a container
/// narrower than 8 d_max unless the scene allows it (periodic sides are not
/// walls: an x–y periodic box is never narrow).
fn refuse_narrow(
    scene: &Scene,
    container: &Container,
    poses: &[nalgebra::Isometry3<f64>],
    d_max: f64,
) -> anyhow::Result<place::WallShare> {
    let wall = place::wall_share(container, poses, d_max);
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
