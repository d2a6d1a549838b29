//! `cargo xtask clone`: generate clones of the embedded Ottawa-sand parents
//! with the calibrated configuration (`fixtures/calibrated/gsc2-ottawa.ron`)
//! and write them: one LS-DEM morph file per clone (and, on request, VTK
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
}

impl Clone {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        let start = Instant::now();
        let path = root.join("fixtures/calibrated/gsc2-ottawa.ron");
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
        eprintln!("preparing the Ottawa-sand parents…");
        let parents = validate::grains::ottawa_parents()?;
        let model = CloneModel::fit(&parents, &params)?;
        let run = model.run(range.clone(), Hooks::default())?;
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
                let w = BufWriter::new(
                    std::fs::File::create(&p)
                        .with_context(|| format!("creating {}", p.display()))?,
                );
                write_grid(g, f, &format!("grainforge clone {}", c.index), w)
                    .with_context(|| format!("writing {}", p.display()))?;
            }
        }
        let table = run.dna_table()?;
        let stem = format!("clones-{}-{}", range.start, range.end);
        table.write_csv(std::fs::File::create(dir.join(format!("{stem}.csv")))?)?;
        table.write_ron(std::fs::File::create(dir.join(format!("{stem}.ron")))?)?;
        println!(
            "{} clones ({}..{}) of `{}` in {} ({:.1} s; {} candidates, acceptance {:.1} %)",
            run.clones.len(),
            range.start,
            range.end,
            cal.name,
            dir.display(),
            start.elapsed().as_secs_f64(),
            run.stats.attempts,
            100.0 * run.stats.acceptance_rate()
        );
        Ok(())
    }
}
