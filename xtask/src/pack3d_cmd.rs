//! `cargo xtask pack --dim 3 --container …`: dense 3D sphere packing (the
//! advancing front of open sites, `packer-quadtree::pack3d`) in a box,
//! cylinder or closed STL/OBJ mesh, checked by the independent overlap
//! checker, written for DEM tools (LAMMPS/LIGGGHTS `read_data`, Yade text,
//! CSV, VTU for ParaView) with a report (`report.txt`: counts, solid
//! fractions, grading, stage times, memory).
//!
//! Every file goes through a temporary file and a rename: a failed run
//! writes nothing half-way.

use std::fmt::Write as _;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use levelset::Orientation;
use nalgebra::Point3;
use packer_quadtree::Grading;
use packer_spheres::{Boundary, Container, DensifyParams, Pack3Params, Sphere, Target};

use crate::pack_cmd::{Output, Preset};
use crate::progress::write_atomic;

/// Parses `--container`: `box:LX,LY,LZ[,periodic|periodic-x]`,
/// `cylinder:D[,H]` (H = 2 D by default, the triaxial specimen) or
/// `mesh:FILE` (STL or OBJ, closed; welded and oriented on reading).
pub(crate) fn parse_container(s: &str, root: &Path) -> anyhow::Result<Container> {
    let (kind, rest) = s.split_once(':').unwrap_or((s, ""));
    Ok(match kind {
        "box" => {
            let mut parts: Vec<&str> = rest.split(',').collect();
            let periodic = match parts.last().copied() {
                Some("periodic-xyz") => bail!(
                    "box:…,periodic-xyz (fully periodic) needs --target-fraction: the front packs \
                     with walls in z, the densification closes them"
                ),
                Some("periodic") => {
                    parts.pop();
                    [true, true]
                }
                Some("periodic-x") => {
                    parts.pop();
                    [true, false]
                }
                _ => [false, false],
            };
            let v: Vec<f64> = parts
                .iter()
                .map(|t| {
                    t.trim()
                        .parse::<f64>()
                        .with_context(|| format!("box: `{t}` is not a number"))
                })
                .collect::<anyhow::Result<_>>()?;
            let [lx, ly, lz]: [f64; 3] = v
                .try_into()
                .map_err(|_| anyhow::anyhow!("box takes LX,LY,LZ[,periodic|periodic-x]"))?;
            Container::Box {
                min: Point3::origin(),
                max: Point3::new(lx, ly, lz),
                periodic,
            }
        }
        "cylinder" => {
            let v: Vec<f64> = rest
                .split(',')
                .map(|t| {
                    t.trim()
                        .parse::<f64>()
                        .with_context(|| format!("cylinder: `{t}` is not a number"))
                })
                .collect::<anyhow::Result<_>>()?;
            let (d, h) = match v.as_slice() {
                [d] => (*d, 2.0 * d),
                [d, h] => (*d, *h),
                _ => bail!("cylinder takes D[,H]"),
            };
            Container::Cylinder {
                base: Point3::origin(),
                radius: 0.5 * d,
                height: h,
            }
        }
        "mesh" => {
            let path = root.join(rest);
            let file = std::fs::File::open(&path)
                .with_context(|| format!("opening the container mesh {}", path.display()))?;
            let r = BufReader::new(file);
            let mesh = if rest.to_ascii_lowercase().ends_with(".obj") {
                levelset::io::read_obj(r)
            } else {
                levelset::io::read_stl(r)
            }
            .with_context(|| format!("reading {}", path.display()))?;
            let (mesh, _) = mesh.prepare_closed(Orientation::Repair).with_context(|| {
                format!(
                    "the container mesh {} is not a closed surface",
                    path.display()
                )
            })?;
            Container::mesh(mesh).with_context(|| format!("container mesh {}", path.display()))?
        }
        _ => bail!("unknown container `{kind}` (box, cylinder, mesh)"),
    })
}

/// Parses `--container` into a densification domain: as [`parse_container`],
/// plus `box:LX,LY,LZ,periodic-xyz` (periodic in x, y and z); meshes are refused.
pub(crate) fn parse_boundary(s: &str, root: &Path) -> anyhow::Result<Boundary> {
    if let Some(rest) = s.strip_prefix("box:")
        && let Some(dims) = rest.strip_suffix(",periodic-xyz")
    {
        let c = parse_container(&format!("box:{dims}"), root)?;
        let (min, max) = c.bbox();
        return Ok(Boundary::Periodic { min, max });
    }
    let c = parse_container(s, root)?;
    if matches!(c, Container::Mesh(_)) {
        bail!("--target-fraction needs a box or cylinder container, not a mesh");
    }
    Ok(Boundary::Walls(c))
}

/// Parses `--target-fraction`: a solid fraction in (0, 0.74] or `jammed`.
pub(crate) fn parse_target(s: &str) -> anyhow::Result<Target> {
    if s.trim() == "jammed" {
        return Ok(Target::Jammed);
    }
    let f: f64 = s
        .trim()
        .parse()
        .with_context(|| format!("--target-fraction: `{s}` is neither a number nor `jammed`"))?;
    if !(f.is_finite() && f > 0.0 && f <= 0.74) {
        bail!("--target-fraction must be in (0, 0.74] or `jammed`, got {s}");
    }
    Ok(Target::Fraction(f))
}

/// A 3D packing run of `cargo xtask pack`.
pub(crate) struct Run3<'a> {
    pub(crate) container: &'a str,
    pub(crate) grading: Grading,
    pub(crate) preset: Preset,
    pub(crate) seed: u64,
    pub(crate) formats: &'a [Output],
    pub(crate) density: f64,
    pub(crate) out: PathBuf,
    /// Densify to this target after the front.
    pub(crate) target: Option<&'a str>,
}

impl Run3<'_> {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        let t0 = Instant::now();
        if let Some(t) = self.target {
            return self.run_dense(root, parse_target(t)?, t0);
        }
        let container = parse_container(self.container, root)?;
        let params = self.params();
        if !(self.density.is_finite() && self.density > 0.0) {
            bail!(
                "--density must be positive and finite, got {}",
                self.density
            );
        }
        let t_setup = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let p = packer_spheres::pack3d_seeded(&container, &self.grading, &params, self.seed)?;
        let t_pack = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        let report = metrics_report(&container, &self.grading, &p.spheres)?;
        let t_check = t2.elapsed().as_secs_f64();
        let t_write = self.write(root, &p.spheres, &container, false)?;
        let mut text = report;
        let n = p.spheres.len() as f64;
        let _ = writeln!(
            text,
            "stage times: setup {t_setup:.3} s, pack {t_pack:.3} s ({:.0} spheres/s, {:.2} µs per \
             sphere), check and metrics {t_check:.3} s, write {t_write:.3} s",
            n / t_pack.max(1e-9),
            1e6 * t_pack / n.max(1.0)
        );
        let _ = writeln!(
            text,
            "packer: front order {:?}, {} slab(s), {} site generations, {} site tests, {} sites \
             dropped, {} sizes drawn, {} skipped, packer structures {:.1} MB",
            p.front_order,
            p.stats.slabs.max(1),
            p.stats.evaluations,
            p.stats.site_tests,
            p.stats.fronts_removed,
            p.stats.sizes_drawn,
            p.stats.sizes_skipped,
            p.stats.peak_bytes as f64 / 1e6
        );
        self.publish(root, &text)
    }

    fn params(&self) -> Pack3Params {
        match self.preset {
            Preset::Default => Pack3Params::default(),
            Preset::Dense => Pack3Params::dense(),
            Preset::Seed => Pack3Params {
                lookahead: 1,
                slabs: 0,
                ..Pack3Params::default()
            },
        }
    }

    /// The front, then the densification to `target` (`--target-fraction`).
    fn run_dense(&self, root: &Path, target: Target, t0: Instant) -> anyhow::Result<()> {
        let boundary = parse_boundary(self.container, root)?;
        if !(self.density.is_finite() && self.density > 0.0) {
            bail!(
                "--density must be positive and finite, got {}",
                self.density
            );
        }
        let t_setup = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let dense = DensifyParams {
            target,
            ..DensifyParams::default()
        };
        let p = packer_spheres::pack3d_dense(
            &boundary,
            &self.grading,
            &self.params(),
            &dense,
            self.seed,
        )?;
        let t_pack = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        let (report, container, fully) = match &p.boundary {
            Boundary::Walls(c) => (
                metrics_report(c, &self.grading, &p.spheres)?,
                c.clone(),
                false,
            ),
            Boundary::Periodic { min, max } => {
                let worst = packer_spheres::max_overlap(&p.spheres, &p.boundary)?;
                if worst > 1e-9 {
                    bail!(
                        "the independent check rejects this packing (worst overlap / d {worst:.2e}): \
                         nothing written; please report it with the command line"
                    );
                }
                let g = packer_spheres::grading_report(&self.grading, &p.spheres)?;
                let mut t = String::new();
                let _ = writeln!(
                    t,
                    "{} spheres, solid fraction {:.4} (periodic in x, y and z; box {:.4} × {:.4} × \
                     {:.4}); worst overlap / d {worst:.2e}",
                    p.spheres.len(),
                    p.fraction,
                    max.x - min.x,
                    max.y - min.y,
                    max.z - min.z
                );
                let _ = writeln!(
                    t,
                    "grading by mass: Cu {:.3} (requested {:.3}), Cc {:.3} (requested {:.3}), max \
                     deviation of the passing curve {:.4}",
                    g.packed.cu, g.requested.cu, g.packed.cc, g.requested.cc, g.max_deviation
                );
                let c = Container::Box {
                    min: *min,
                    max: *max,
                    periodic: [true, true],
                };
                (t, c, true)
            }
        };
        let t_check = t2.elapsed().as_secs_f64();
        let t_write = self.write(root, &p.spheres, &container, fully)?;
        let mut text = report;
        let n = p.spheres.len() as f64;
        let _ = writeln!(
            text,
            "densified to {} (target {}): front placed {} spheres, {} removed at random for the \
             target, then {} compression steps ({} undone), {} FIRE iterations, {} neighbour \
             builds, largest overlap before the final expansion ≤ {:.0e} × the pair's centre distance",
            format_args!("{:.4}", p.fraction),
            match target {
                Target::Fraction(f) => format!("{f}"),
                _ => "jammed".into(),
            },
            p.placed,
            p.removed,
            p.densify.steps_accepted,
            p.densify.steps_rejected,
            p.densify.iterations,
            p.densify.neighbour_builds,
            dense.tolerance
        );
        let _ = writeln!(
            text,
            "stage times: setup {t_setup:.3} s, front + densify {t_pack:.3} s ({:.0} spheres/s), \
             check and metrics {t_check:.3} s, write {t_write:.3} s",
            n / t_pack.max(1e-9)
        );
        self.publish(root, &text)
    }

    /// Writes the output files atomically; returns the seconds it took.
    fn write(
        &self,
        root: &Path,
        spheres: &[Sphere],
        container: &Container,
        fully: bool,
    ) -> anyhow::Result<f64> {
        let t = Instant::now();
        for (path, bytes) in &self.files(spheres, container, fully)? {
            write_atomic(&root.join(path), bytes)?;
        }
        Ok(t.elapsed().as_secs_f64())
    }

    /// Writes `report.txt` and prints it.
    fn publish(&self, root: &Path, text: &str) -> anyhow::Result<()> {
        let dir = root.join(&self.out);
        write_atomic(&dir.join("report.txt"), text.as_bytes())?;
        print!("{text}");
        println!("written to {}", dir.display());
        Ok(())
    }

    /// The output files of `spheres` (`fully`: periodic in z too, named on the LAMMPS title).
    fn files(
        &self,
        spheres: &[Sphere],
        container: &Container,
        fully: bool,
    ) -> anyhow::Result<Vec<(PathBuf, Vec<u8>)>> {
        let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
        for f in self.formats {
            let (name, bytes) = match f {
                Output::Csv => {
                    let mut b = Vec::new();
                    packer_spheres::write_csv3(spheres, &mut b)?;
                    ("packing.csv", b)
                }
                Output::Vtu => {
                    let mut b = Vec::new();
                    packer_spheres::write_vtu3(spheres, &mut b)?;
                    ("packing.vtu", b)
                }
                Output::Lammps => {
                    let mut b = Vec::new();
                    packer_spheres::write_lammps_data3(spheres, container, self.density, &mut b)?;
                    if fully {
                        // the box is periodic in z too: the title line names the boundary
                        let text = String::from_utf8(b)?;
                        let (title, rest) = text.split_once('\n').unwrap_or((&text, ""));
                        b = format!(
                            "{}\n{rest}",
                            title.replace("boundary p p f", "boundary p p p")
                        )
                        .into_bytes();
                    }
                    ("packing.data", b)
                }
                Output::Yade => {
                    let mut b = Vec::new();
                    packer_spheres::write_yade3(spheres, &mut b)?;
                    ("packing.txt", b)
                }
                Output::Svg => continue,
            };
            files.push((self.out.join(name), bytes));
        }
        Ok(files)
    }
}

/// The checked metrics of a packing, as report text; an error when the
/// independent checker finds an overlap.
fn metrics_report(
    container: &Container,
    grading: &Grading,
    spheres: &[Sphere],
) -> anyhow::Result<String> {
    let mut text = String::new();
    let d_max = grading.d_max();
    let check = packer_spheres::check_spheres(container, spheres, 1e-9)?;
    if !check.is_clean(1e-9) {
        bail!(
            "the independent checker rejects this packing (worst pair gap / d {:.2e}, worst wall \
             gap / d {:.2e}): nothing written; please report it with the command line",
            check.worst_normalised_gap,
            check.worst_normalised_wall_gap
        );
    }
    let overall = packer_spheres::solid_fraction(container, spheres)?;
    let _ = writeln!(
        text,
        "{} spheres, solid fraction {overall:.4} overall; mean coordination number {:.2}; worst \
         gap / d {:.2e} (pairs), {:.2e} (walls)",
        spheres.len(),
        check.coordination_number,
        check.worst_normalised_gap,
        check.worst_normalised_wall_gap
    );
    match packer_spheres::core_solid_fraction(container, spheres, 2.0 * d_max) {
        Ok(core) => {
            let _ = writeln!(
                text,
                "core (2 d_max = {:.3} from the walls): solid fraction {:.4}",
                2.0 * d_max,
                core.fraction
            );
        }
        Err(e) => {
            let _ = writeln!(text, "core: not available ({e})");
        }
    }
    if let Container::Cylinder { radius, .. } = container {
        let bins = ((radius / (0.5 * d_max)).round() as usize).clamp(4, 200);
        let prof = packer_spheres::radial_profile(container, spheres, bins)?;
        let _ = writeln!(text, "radial solid fraction profile (annulus: fraction):");
        for b in prof {
            let _ = writeln!(
                text,
                "  {:>8.3} – {:>8.3}: {:.4}",
                b.r_inner, b.r_outer, b.solid_fraction
            );
        }
    }
    let g = packer_spheres::grading_report(grading, spheres)?;
    let _ = writeln!(
        text,
        "grading by mass: Cu {:.3} (requested {:.3}), Cc {:.3} (requested {:.3}), max deviation of \
         the passing curve {:.4}",
        g.packed.cu, g.requested.cu, g.packed.cc, g.requested.cc, g.max_deviation
    );
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::{parse_boundary, parse_container, parse_target};
    use packer_spheres::{Boundary, Container, Target};
    use std::path::Path;

    #[test]
    fn targets_and_periodic_boxes_parse() {
        assert_eq!(parse_target("0.64").expect("0.64"), Target::Fraction(0.64));
        assert_eq!(parse_target(" jammed").expect("jammed"), Target::Jammed);
        for bad in ["0.75", "0", "-0.2", "NaN", "inf", "dense", ""] {
            let e = parse_target(bad).expect_err(bad).to_string();
            assert!(e.contains("--target-fraction"), "{bad}: {e}");
        }
        let root = Path::new(".");
        assert!(matches!(
            parse_boundary("box:30,30,30,periodic-xyz", root),
            Ok(Boundary::Periodic { .. })
        ));
        assert!(matches!(
            parse_boundary("cylinder:20", root),
            Ok(Boundary::Walls(Container::Cylinder { .. }))
        ));
        // fully periodic needs the densification
        let e = parse_container("box:30,30,30,periodic-xyz", root).expect_err("front only");
        assert!(e.to_string().contains("--target-fraction"), "{e}");
    }

    #[test]
    fn containers_parse() {
        let root = Path::new(".");
        assert!(matches!(
            parse_container("box:40,40,40", root),
            Ok(Container::Box {
                periodic: [false, false],
                ..
            })
        ));
        assert!(matches!(
            parse_container("box:40,40,40,periodic", root),
            Ok(Container::Box {
                periodic: [true, true],
                ..
            })
        ));
        match parse_container("cylinder:20", root) {
            Ok(Container::Cylinder { radius, height, .. }) => {
                assert_eq!((radius, height), (10.0, 40.0));
            }
            other => panic!("{other:?}"),
        }
        for bad in [
            "box:1,2",
            "cylinder:",
            "cylinder:1,2,3",
            "sphere:3",
            "mesh:/nonexistent.stl",
        ] {
            assert!(parse_container(bad, root).is_err(), "{bad}");
        }
    }
}
