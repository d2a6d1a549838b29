//! `cargo xtask synth-scan`: a synthetic labelled CT image of cloned grains,
//! for the scale test of `--parents` (a 512³ u16 image with ≥ 2,000 grains)
//! and for trying the import path without a scanner.
//!
//! Clones of the calibrated Ottawa configuration, each scaled to the largest
//! clone's box (a sieved fraction), are painted one per cell
//! of a cubic lattice (`validate::cases::parents::paint_lattice`), with a
//! background gap so that no two grains touch, and written as `.npy` (u16,
//! C order, axes z, y, x), multi-page TIFF or raw (x fastest, u16 LE).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use cloner::{Calibrated, CloneModel, Hooks, Outputs};

/// Image formats of `synth-scan`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ImageFormat {
    /// NumPy `.npy`.
    Npy,
    /// Multi-page TIFF.
    Tiff,
    /// Raw little-endian u16, x fastest.
    Raw,
}

/// Flags of `cargo xtask synth-scan`.
#[derive(Debug, Args)]
pub(crate) struct SynthScan {
    /// Voxels per image side.
    #[arg(long, default_value_t = 512)]
    size: usize,
    /// Grains (rounded up to a cube number of lattice cells that fit).
    #[arg(long, default_value_t = 2000)]
    grains: usize,
    /// Background voxels around each grain's cell.
    #[arg(long, default_value_t = 2)]
    gap: usize,
    /// Output file.
    #[arg(long, default_value = "target/scan/scan.npy")]
    out: PathBuf,
    /// Image format.
    #[arg(long, value_enum, default_value_t = ImageFormat::Npy)]
    format: ImageFormat,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

impl SynthScan {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        let start = Instant::now();
        if self.grains == 0 || self.size < 8 {
            bail!("--grains must be positive and --size at least 8");
        }
        let m = (1..).find(|m: &usize| m.pow(3) >= self.grains).unwrap_or(1);
        let n = m.pow(3);
        let cell = self.size / m;
        if cell < 2 * self.gap + 8 {
            bail!(
                "{n} grains ({m}³ cells) in {}³ voxels leave {cell} voxels per cell: too small",
                self.size
            );
        }
        let path = root.join("fixtures/calibrated/gsc2-ottawa.ron");
        let cal = Calibrated::from_ron(
            &std::fs::read_to_string(&path)
                .with_context(|| format!("reading {}", path.display()))?,
        )?;
        let mut params = cal.params;
        params.outputs = Outputs {
            level_set: true,
            dna: false,
        };
        let parents = validate::grains::ottawa_parents()?;
        let model = CloneModel::fit(&parents, &params)?;
        let pb = crate::progress::bar("cloning", n as u64, self.quiet);
        let cb = crate::progress::clone_callback(&pb);
        let run = model.run(
            0..n as u64,
            Hooks {
                progress: Some(&cb),
                ..Hooks::default()
            },
        )?;
        let grids: Vec<levelset::Grid> = run.clones.into_iter().filter_map(|c| c.grid).collect();
        let clone_s = start.elapsed().as_secs_f64();
        // every clone scaled to the largest grid box, so that each fills its
        // cell (a sieved fraction: shapes vary, sizes within the fill ratio)
        let box_of = |g: &levelset::Grid| {
            let s = g.spec();
            s.dims.iter().copied().max().unwrap_or(0) as f64 * s.spacing
        };
        let extent = grids.iter().map(box_of).fold(0.0f64, f64::max);
        let grids: Vec<levelset::Grid> = grids
            .iter()
            .map(|g| {
                let f = extent / box_of(g);
                let spec = levelset::GridSpec {
                    origin: g.spec().origin * f,
                    spacing: g.spec().spacing * f,
                    ..*g.spec()
                };
                levelset::Grid::new(spec, g.values().iter().map(|v| v * f).collect())
            })
            .collect::<Result<_, _>>()?;
        let voxel = extent / (cell - 2 * self.gap - 1) as f64;
        let t = Instant::now();
        let mut image = validate::cases::parents::paint_lattice(&grids, voxel, self.gap)?;
        // pad to the requested size (background)
        if image.dims.iter().any(|&d| d > self.size) {
            bail!("lattice {:?} exceeds {}³", image.dims, self.size);
        }
        let s = self.size;
        let mut labels = vec![0u32; s * s * s];
        let [nx, ny, nz] = image.dims;
        for k in 0..nz {
            for j in 0..ny {
                let src = (k * ny + j) * nx;
                let dst = (k * s + j) * s;
                labels[dst..dst + nx].copy_from_slice(&image.labels[src..src + nx]);
            }
        }
        image = levelset::LabelImage::new([s, s, s], 1.0, labels)?;
        let paint_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut buf = std::io::Cursor::new(Vec::new());
        match self.format {
            ImageFormat::Npy => {
                levelset::io::write_npy(&mut buf, &image, levelset::io::Dtype::U16)?
            }
            ImageFormat::Tiff => levelset::io::write_tiff(&mut buf, &image)?,
            ImageFormat::Raw => {
                levelset::io::write_raw(&mut buf, &image, levelset::io::Dtype::U16, true)?;
            }
        }
        let out = root.join(&self.out);
        crate::progress::write_atomic(&out, buf.get_ref())?;
        println!(
            "{} grains ({m}³ lattice, {cell} voxels per cell, voxel = {:.4} of the clones' length unit, written with spacing 1) in a {s}³ u16 image: {} ({:.0} MB); cloning {clone_s:.1} s, painting {paint_s:.1} s, writing {:.1} s",
            grids.len(),
            voxel,
            out.display(),
            buf.get_ref().len() as f64 / 1e6,
            t.elapsed().as_secs_f64()
        );
        Ok(())
    }
}
