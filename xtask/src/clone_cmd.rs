//! `cargo xtask clone`: generate clones of the embedded Ottawa-sand parents
//! with the calibrated configuration (`fixtures/calibrated/gsc2-ottawa.ron`),
//! or of the user's grains (`--parents PATH`, see `parents.rs`) with the
//! configuration `--config FILE` that `cargo xtask calibrate --parents PATH
//! --out FILE` chose for them, and write them: one LS-DEM morph file per clone (and, on request, VTK
//! structured points for ParaView and binary STL surfaces), plus the clones'
//! DNA table (CSV and RON). Only the requested outputs are computed.

use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;
use cloner::{Calibrated, CloneModel, Format, Hooks, Outputs, shard_range, write_grid};

/// Flags of `cargo xtask clone`.
#[derive(Debug, Args)]
pub(crate) struct Clone {
    /// Number of clones (indices `0..count`, or the shard's part of them).
    #[arg(long, default_value_t = 100)]
    count: u64,
    /// Output directory.
    #[arg(long, default_value = "target/clones")]
    out: PathBuf,
    /// Also write VTK structured points (ParaView) of every level set.
    #[arg(long)]
    vtk: bool,
    /// Also write binary STL surfaces.
    #[arg(long)]
    stl: bool,
    /// Do not write LS-DEM morph files.
    #[arg(long)]
    no_lsdem: bool,
    /// Surface nodes per LS-DEM morph file.
    #[arg(long, default_value_t = 1000)]
    nodes: usize,
    /// Master seed (default: the calibrated one).
    #[arg(long)]
    seed: Option<u64>,
    /// Generate only shard K of N (`K/N`, 1-based): the union of all shards
    /// equals the unsharded run.
    #[arg(long)]
    shard: Option<String>,
    /// The calibrated configuration (default: the committed Ottawa one).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Where the parents come from (default: the embedded Ottawa grains).
    #[command(flatten)]
    source: crate::parents::ParentArgs,
}

struct Clock(Instant);

impl cloner::Clock for Clock {
    fn now_ns(&self) -> u64 {
        self.0.elapsed().as_nanos() as u64
    }
}

impl Clone {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        let start = Instant::now();
        let path = self
            .config
            .clone()
            .unwrap_or_else(|| root.join("fixtures/calibrated/gsc2-ottawa.ron"));
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let cal =
            Calibrated::from_ron(&text).with_context(|| format!("parsing {}", path.display()))?;
        let range = match &self.shard {
            None => 0..self.count,
            Some(s) => {
                let (k, n) = s.split_once('/').context("--shard takes K/N, e.g. 1/4")?;
                shard_range(self.count, k.trim().parse()?, n.trim().parse()?)?
            }
        };
        if range.is_empty() {
            bail!(
                "no clone to generate (count {}, shard {:?})",
                self.count,
                self.shard
            );
        }
        let files = !self.no_lsdem || self.vtk || self.stl;
        let mut params = cal.params;
        params.outputs = Outputs {
            level_set: files,
            dna: true,
        };
        if let Some(s) = self.seed {
            params.seed = s;
        }
        let t_parents = Instant::now();
        let (parents, summary) = match &self.source.parents {
            None => {
                eprintln!("preparing the default Ottawa-sand parents…");
                (
                    validate::grains::ottawa_parents()?,
                    String::from(
                        "Default parents: 71 Ottawa-sand grains drawn at random from NIST's population",
                    ),
                )
            }
            Some(p) => {
                let loaded = crate::parents::load(&self.source, p)?;
                let summary = loaded.summary(p);
                let (parents, _, dna_s) = crate::parents::measure(loaded)?;
                (parents, format!("{summary}, DNA {dna_s:.2} s"))
            }
        };
        if self.config.is_some() && cal.parents != parents.len() {
            eprintln!(
                "note: {} was calibrated on {} parents, these are {}",
                path.display(),
                cal.parents,
                parents.len()
            );
        }
        let parents_s = t_parents.elapsed().as_secs_f64();
        let t_clone = Instant::now();
        let model = CloneModel::fit(&parents, &params)?;
        let pb = crate::progress::bar("cloning", range.end - range.start, self.quiet);
        let cb = crate::progress::clone_callback(&pb);
        let clock = Clock(Instant::now());
        let run = model.run(
            range.clone(),
            Hooks {
                clock: &clock,
                progress: Some(&cb),
            },
        )?;
        let clone_s = t_clone.elapsed().as_secs_f64();
        let t_write = Instant::now();
        let dir = root.join(&self.out);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        for c in &run.clones {
            let Some(g) = &c.grid else { continue };
            let mut formats = Vec::new();
            if !self.no_lsdem {
                formats.push((Format::LsDem { nodes: self.nodes }, "dat"));
            }
            if self.vtk {
                formats.push((Format::Vtk, "vtk"));
            }
            if self.stl {
                formats.push((Format::Stl, "stl"));
            }
            for (f, ext) in formats {
                let p = dir.join(format!("clone-{:06}.{ext}", c.index));
                let mut buf = Vec::new();
                write_grid(
                    g,
                    f,
                    &format!("grainforge clone {}", c.index),
                    BufWriter::new(&mut buf),
                )
                .with_context(|| format!("writing {}", p.display()))?;
                crate::progress::write_atomic(&p, &buf)?;
            }
        }
        let table = run.dna_table()?;
        let stem = format!("clones-{}-{}", range.start, range.end);
        let mut buf = Vec::new();
        table.write_csv(&mut buf)?;
        crate::progress::write_atomic(&dir.join(format!("{stem}.csv")), &buf)?;
        let mut buf = Vec::new();
        table.write_ron(&mut buf)?;
        crate::progress::write_atomic(&dir.join(format!("{stem}.ron")), &buf)?;
        let write_s = t_write.elapsed().as_secs_f64();
        println!(
            "{summary}. {} clones ({}..{}) of `{}` in {}: parents {parents_s:.1} s, cloning {clone_s:.1} s ({} candidates, acceptance {:.1} %), writing {write_s:.1} s; {:.1} s in all.",
            run.clones.len(),
            range.start,
            range.end,
            cal.name,
            dir.display(),
            run.stats.attempts,
            100.0 * run.stats.acceptance_rate(),
            start.elapsed().as_secs_f64()
        );
        Ok(())
    }
}
