//! `--parents PATH`: the user's own grains as cloner parents, for `dna`,
//! `calibrate` and `clone`.
//!
//! Formats (parsers live in the library that owns the representation; this
//! module only knows paths, picks the format and reports):
//!
//! | input | PATH | parser | level set |
//! |---|---|---|---|
//! | labelled image, NumPy | `scan.npy` | `levelset::io::read_npy` | per label, exact EDT of its padded crop (`LabelImage::extract`) |
//! | labelled image, TIFF stack | `scan.tif` | `levelset::io::read_tiff` | as above |
//! | labelled image, raw | `scan.raw` + `--raw-dims --raw-dtype` | `levelset::io::read_raw` | as above |
//! | one closed mesh per grain | directory of `.stl` or `.obj` | `levelset::io::read_stl` / `read_obj`, `TriMesh::prepare_closed` | exact signed distance, `--resolution`³ cube about the centroid (`cloner::grid_from_mesh`) |
//! | VCCTL spherical harmonics | directory of `*-anm-*.dat` | `sph_harmonics::vcctl::read_anm` | `cloner::grid_from_sh`, at `--sh-degree` or each file's own degree |
//! | LS-DEM level sets | directory of morph files (`.dat`) | `levelset::io::read_morph` | the file's grid |
//!
//! A directory must hold one format only (README/NOTICE/`.txt`/`.md`/`.csv`/
//! `.sst`/`.ron` files are ignored and counted); a mix is an error naming two
//! files. Every error names the file (and the line, offset or label the
//! parser reports). Fewer than two usable parents is an error.

use std::fmt::Write as _;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use levelset::Grid;
use rayon::prelude::*;

/// The input formats of `--parents`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, serde::Deserialize)]
pub(crate) enum InputFormat {
    /// NumPy `.npy` labelled image.
    Npy,
    /// Multi-page TIFF labelled image.
    Tiff,
    /// Raw binary labelled image (`--raw-dims`, `--raw-dtype`).
    Raw,
    /// A directory of STL meshes, one grain per file.
    Stl,
    /// A directory of OBJ meshes, one grain per file.
    Obj,
    /// A directory of VCCTL spherical-harmonic `anm` files.
    Anm,
    /// A directory of LS-DEM morph files.
    Morph,
}

impl InputFormat {
    /// File extensions of the format (lower case).
    fn extensions(self) -> &'static [&'static str] {
        match self {
            Self::Npy => &["npy"],
            Self::Tiff => &["tif", "tiff"],
            Self::Raw => &["raw", "bin"],
            Self::Stl => &["stl"],
            Self::Obj => &["obj"],
            Self::Anm | Self::Morph => &["dat", "anm", "morph"],
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Npy => "NumPy labelled image",
            Self::Tiff => "TIFF labelled image",
            Self::Raw => "raw labelled image",
            Self::Stl => "STL meshes",
            Self::Obj => "OBJ meshes",
            Self::Anm => "VCCTL spherical harmonics",
            Self::Morph => "LS-DEM morph level sets",
        }
    }
}

/// Flags that say where the parents come from.
#[derive(Debug, Clone, Args)]
pub(crate) struct ParentArgs {
    /// The user's grains: a labelled image file (`.npy`, `.tif`/`.tiff`,
    /// `.raw`) or a directory of per-grain files (STL, OBJ, VCCTL `anm`,
    /// LS-DEM morph). Default: the embedded Ottawa-sand parents.
    #[arg(long, value_name = "PATH")]
    pub(crate) parents: Option<PathBuf>,
    /// Input format (default: from the extension and contents). In a
    /// directory, only files with this format's extensions are read.
    #[arg(long, value_enum)]
    pub(crate) format: Option<InputFormat>,
    /// Voxel spacing of a labelled image, in the physical unit of the output
    /// (e.g. 0.01 for 10 µm voxels in mm).
    #[arg(long)]
    pub(crate) spacing: Option<f64>,
    /// Raw image dimensions `NX,NY,NZ` (x fastest).
    #[arg(long, value_name = "NX,NY,NZ")]
    pub(crate) raw_dims: Option<String>,
    /// Raw image voxel type (u8, u16, u32, i32, i64).
    #[arg(long, value_name = "DTYPE")]
    pub(crate) raw_dtype: Option<String>,
    /// Raw image is big-endian.
    #[arg(long)]
    pub(crate) big_endian: bool,
    /// Keep grains that touch the image border (excluded by default: they are cut).
    #[arg(long)]
    pub(crate) keep_border: bool,
    /// Skip labels with fewer voxels (default: the library's).
    #[arg(long)]
    pub(crate) min_voxels: Option<usize>,
    /// Reject labels made of several connected components (default: keep the largest).
    #[arg(long)]
    pub(crate) reject_split: bool,
    /// Gaussian smoothing σ (voxels) of each label before its level set
    /// (default: the image path's, `levelset::ROUNDNESS_SMOOTHING` = 0.7; 1 =
    /// the library's default; 0 = exact EDT of the binary crop).
    #[arg(long)]
    pub(crate) smoothing: Option<f64>,
    /// Measure the roundness of labelled-image grains on their own grid, at the
    /// scan's resolution (before issue 31), instead of the canonical grid the clones
    /// and the mesh/SH parents are measured on.
    #[arg(long)]
    pub(crate) native_roundness: bool,
    /// Reconstruct each labelled-image grain's surface by minimal bending (the least-curved
    /// surface that keeps every voxel on its side, `levelset::ExtractParams::minimal_bending`)
    /// and read its corners with the calibrated correction
    /// (`morph_dna::MeasureParams::minimal_bending`): analytic grains within 4 % at 20-60
    /// voxels across and clones ranked better (Spearman 0.76 against 0.53 at 30 voxels),
    /// but clones at 20 voxels 12 % off on average (8.7 % by default) and several times
    /// the extraction's cost (issue 31; README).
    #[arg(long, conflicts_with = "native_roundness")]
    pub(crate) minimal_bending: bool,
    /// Spherical-harmonic degree of `anm` files (default: each file's own).
    #[arg(long)]
    pub(crate) sh_degree: Option<usize>,
    /// Level-set nodes per axis for mesh and SH grains.
    #[arg(long, default_value_t = 45)]
    pub(crate) resolution: usize,
}

/// Grains read from `--parents`, with what was skipped and the stage times.
pub(crate) struct Loaded {
    /// One name per grid (file stem or `label-N`).
    pub(crate) names: Vec<String>,
    /// The level sets, in the names' order.
    pub(crate) grids: Vec<Grid>,
    /// The format read.
    pub(crate) format: InputFormat,
    /// Files read.
    pub(crate) files: usize,
    /// Files ignored (README, NOTICE, tables).
    pub(crate) ignored: usize,
    /// Skipped grains: (name, reason).
    pub(crate) skipped: Vec<(String, String)>,
    /// Seconds reading and parsing.
    pub(crate) read_s: f64,
    /// Seconds building level sets.
    pub(crate) levelset_s: f64,
    /// How these grains are measured ([`measure_params`]).
    pub(crate) measure: morph_dna::MeasureParams,
    /// What the user must know about these grains' roundness (labelled images).
    pub(crate) roundness_note: Option<String>,
}

impl Loaded {
    /// A one-paragraph summary (to which the caller appends its own stages).
    pub(crate) fn summary(&self, source: &Path) -> String {
        let mut s = format!(
            "Read {} usable grain(s) from {} ({}, {} file(s)",
            self.grids.len(),
            source.display(),
            self.format.name(),
            self.files
        );
        if self.ignored > 0 {
            let _ = write!(s, ", {} non-grain file(s) ignored", self.ignored);
        }
        s.push_str(").");
        if self.skipped.is_empty() {
            s.push_str(" Nothing skipped.");
        } else {
            let mut reasons: Vec<(String, usize)> = Vec::new();
            for (_, r) in &self.skipped {
                match reasons.iter_mut().find(|(x, _)| x == r) {
                    Some((_, n)) => *n += 1,
                    None => reasons.push((r.clone(), 1)),
                }
            }
            let _ = write!(s, " Skipped {}:", self.skipped.len());
            for (k, (r, n)) in reasons.iter().enumerate() {
                let _ = write!(s, "{} {n} {r}", if k == 0 { "" } else { ";" });
            }
            s.push('.');
        }
        if let Some(n) = &self.roundness_note {
            let _ = write!(s, " {n}");
        }
        let _ = write!(
            s,
            " Reading {:.2} s, level sets {:.2} s",
            self.read_s, self.levelset_s
        );
        s
    }
}

const IGNORED_EXT: [&str; 8] = ["txt", "md", "csv", "sst", "ron", "json", "yml", "yaml"];

fn ext(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Tells a VCCTL `anm` file (four numbers per line) from an LS-DEM morph
/// file (one number on its first line) by its first non-empty line.
fn sniff_dat(path: &Path) -> anyhow::Result<InputFormat> {
    use std::io::BufRead as _;
    let f = std::fs::File::open(path).with_context(|| format!("opening {}", path.display()))?;
    for line in BufReader::new(f).lines() {
        let line = line.with_context(|| format!("reading {}", path.display()))?;
        let n = line.split_whitespace().count();
        match n {
            0 => {}
            4 => return Ok(InputFormat::Anm),
            1 => return Ok(InputFormat::Morph),
            _ => bail!(
                "{}: neither a VCCTL anm file (4 numbers per line) nor an LS-DEM morph file (one number on the first line): the first line has {n} fields",
                path.display()
            ),
        }
    }
    bail!("{}: empty file", path.display())
}

fn classify(path: &Path) -> anyhow::Result<Option<InputFormat>> {
    Ok(match ext(path).as_str() {
        "npy" => Some(InputFormat::Npy),
        "tif" | "tiff" => Some(InputFormat::Tiff),
        "raw" | "bin" => Some(InputFormat::Raw),
        "stl" => Some(InputFormat::Stl),
        "obj" => Some(InputFormat::Obj),
        "dat" | "anm" | "morph" => Some(sniff_dat(path)?),
        e if IGNORED_EXT.contains(&e) => None,
        _ => {
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().to_ascii_uppercase())
                .unwrap_or_default();
            if name.starts_with("README") || name.starts_with("NOTICE") || name.starts_with('.') {
                None
            } else {
                bail!(
                    "{}: unknown grain file type (expected .npy, .tif, .raw, .stl, .obj, or VCCTL/LS-DEM .dat)",
                    path.display()
                )
            }
        }
    })
}

/// Reads `--parents` into level sets.
pub(crate) fn load(args: &ParentArgs, source: &Path) -> anyhow::Result<Loaded> {
    let t0 = Instant::now();
    let meta =
        std::fs::metadata(source).with_context(|| format!("reading {}", source.display()))?;
    if meta.is_file() {
        let format = match args.format {
            Some(f) => f,
            None => classify(source)?.with_context(|| {
                format!("{}: not a grain file (give --format)", source.display())
            })?,
        };
        return match format {
            InputFormat::Npy | InputFormat::Tiff | InputFormat::Raw => {
                load_image(args, source, format, t0)
            }
            _ => bail!(
                "{}: a single {} file is one grain; give a directory of them (at least two parents are needed)",
                source.display(),
                format.name()
            ),
        };
    }
    // a directory of per-grain files
    let mut entries: Vec<PathBuf> = std::fs::read_dir(source)
        .with_context(|| format!("listing {}", source.display()))?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()
        .with_context(|| format!("listing {}", source.display()))?;
    entries.retain(|p| p.is_file());
    entries.sort();
    let mut files: Vec<PathBuf> = Vec::new();
    let mut ignored = 0usize;
    let mut format: Option<(InputFormat, PathBuf)> = None;
    for p in entries {
        // with --format, files of that format's extensions are read and the
        // rest ignored (e.g. the .dat of a clone folder that also holds STL);
        // without it, every file is classified and a mix is an error
        let f = match args.format {
            Some(f) if f.extensions().contains(&ext(&p).as_str()) => Some(f),
            Some(_) => None,
            None => classify(&p)?,
        };
        let Some(f) = f else {
            ignored += 1;
            continue;
        };
        match &format {
            None => format = Some((f, p.clone())),
            Some((g, first)) if *g != f => bail!(
                "{} mixes formats: {} is {} but {} is {}; put one format per directory",
                source.display(),
                first.display(),
                g.name(),
                p.display(),
                f.name()
            ),
            Some(_) => {}
        }
        files.push(p);
    }
    let Some((format, _)) = format else {
        bail!("{}: no grain files found", source.display());
    };
    if matches!(
        format,
        InputFormat::Npy | InputFormat::Tiff | InputFormat::Raw
    ) {
        bail!(
            "{}: a directory of labelled images; give one image file as --parents",
            source.display()
        );
    }
    let mut out = match format {
        InputFormat::Stl | InputFormat::Obj => load_meshes(args, &files, format)?,
        InputFormat::Anm => load_sh(args, &files)?,
        InputFormat::Morph => load_morph(&files)?,
        _ => unreachable!("images are handled above"),
    };
    out.ignored = ignored;
    check_count(&out, source)?;
    Ok(out)
}

fn check_count(out: &Loaded, source: &Path) -> anyhow::Result<()> {
    if out.grids.len() < cloner::MIN_PARENTS {
        let mut msg = format!(
            "{}: {} usable parent(s), at least {} are needed",
            source.display(),
            out.grids.len(),
            cloner::MIN_PARENTS
        );
        for (n, r) in out.skipped.iter().take(5) {
            let _ = write!(msg, "; {n}: {r}");
        }
        bail!(msg);
    }
    Ok(())
}

fn spacing(args: &ParentArgs, source: &Path) -> anyhow::Result<f64> {
    let s = args.spacing.with_context(|| {
        format!(
            "{}: a labelled image needs --spacing (voxel size in the output's length unit)",
            source.display()
        )
    })?;
    if !(s.is_finite() && s > 0.0) {
        bail!("--spacing must be finite and positive, got {s}");
    }
    Ok(s)
}

fn load_image(
    args: &ParentArgs,
    source: &Path,
    format: InputFormat,
    t0: Instant,
) -> anyhow::Result<Loaded> {
    let h = spacing(args, source)?;
    let file =
        std::fs::File::open(source).with_context(|| format!("opening {}", source.display()))?;
    let ctx = || format!("reading {}", source.display());
    let image = match format {
        InputFormat::Npy => levelset::io::read_npy(BufReader::new(file), h).with_context(ctx)?,
        InputFormat::Tiff => levelset::io::read_tiff(BufReader::new(file), h).with_context(ctx)?,
        InputFormat::Raw => {
            let dims = args
                .raw_dims
                .as_deref()
                .context("a raw image needs --raw-dims NX,NY,NZ")?;
            let d: Vec<usize> = dims
                .split(',')
                .map(|x| x.trim().parse::<usize>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--raw-dims {dims:?}: three integers NX,NY,NZ"))?;
            let [nx, ny, nz] = d[..] else {
                bail!("--raw-dims {dims:?}: three integers NX,NY,NZ");
            };
            let dtype = args
                .raw_dtype
                .as_deref()
                .context("a raw image needs --raw-dtype (u8, u16, u32, i32, i64)")?;
            let layout = levelset::io::RawLayout {
                dims: [nx, ny, nz],
                dtype: dtype
                    .parse()
                    .with_context(|| format!("--raw-dtype {dtype:?}"))?,
                little_endian: !args.big_endian,
            };
            levelset::io::read_raw(BufReader::new(file), &layout, h).with_context(ctx)?
        }
        _ => unreachable!("only images here"),
    };
    let read_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let mut params = levelset::ExtractParams {
        exclude_border: !args.keep_border,
        ..if args.minimal_bending {
            levelset::ExtractParams::minimal_bending()
        } else {
            levelset::ExtractParams::voxel_images()
        }
    };
    if let Some(m) = args.min_voxels {
        params.min_voxels = m;
    }
    if args.reject_split {
        params.components = levelset::ComponentPolicy::Reject;
    }
    if let Some(s) = args.smoothing {
        params.smoothing = (s > 0.0).then_some(s);
    }
    let ex = image
        .extract(&params)
        .with_context(|| format!("extracting the grains of {}", source.display()))?;
    let levelset_s = t1.elapsed().as_secs_f64();
    let skipped = ex
        .skipped
        .iter()
        .map(|s| {
            let why = match &s.reason {
                levelset::SkipReason::Border => "touching the image border".to_owned(),
                levelset::SkipReason::TooSmall => {
                    format!("below {} voxels", params.min_voxels)
                }
                levelset::SkipReason::SeveralComponents { .. } => {
                    "split into several components (--reject-split)".to_owned()
                }
                levelset::SkipReason::NoSurface => {
                    "thinner than the smoothing blur (no surface)".to_owned()
                }
                _ => format!("skipped ({:?})", s.reason),
            };
            (format!("label {}", s.label), why)
        })
        .collect();
    let across = median_voxels_across(ex.grains.iter().map(|g| g.voxels));
    let mut names = Vec::with_capacity(ex.grains.len());
    let mut grids = Vec::with_capacity(ex.grains.len());
    let mut split = 0usize;
    for g in ex.grains {
        if g.components > 1 {
            split += 1;
        }
        names.push(format!("label-{}", g.label));
        grids.push(g.grid);
    }
    if split > 0 {
        eprintln!(
            "note: {split} label(s) of {} had several connected components; their largest was kept (--reject-split to reject them)",
            source.display()
        );
    }
    let out = Loaded {
        names,
        grids,
        format,
        files: 1,
        ignored: 0,
        skipped,
        read_s,
        levelset_s,
        measure: measure_params(format, args.native_roundness, args.minimal_bending),
        roundness_note: Some(roundness_note(across, args.minimal_bending)),
    };
    check_count(&out, source)?;
    Ok(out)
}

fn load_meshes(
    args: &ParentArgs,
    files: &[PathBuf],
    format: InputFormat,
) -> anyhow::Result<Loaded> {
    let t0 = Instant::now();
    let meshes: Vec<(String, levelset::TriMesh, levelset::MeshRepair)> = files
        .par_iter()
        .map(|p| -> anyhow::Result<_> {
            let f = std::fs::File::open(p).with_context(|| format!("opening {}", p.display()))?;
            let r = BufReader::new(f);
            let mesh = match format {
                InputFormat::Stl => levelset::io::read_stl(r),
                _ => levelset::io::read_obj(r),
            }
            .with_context(|| format!("reading {}", p.display()))?;
            let (mesh, repair) = mesh
                .prepare_closed(levelset::Orientation::Repair)
                .with_context(|| format!("{}: not a closed manifold grain surface", p.display()))?;
            Ok((stem(p), mesh, repair))
        })
        .collect::<anyhow::Result<_>>()?;
    let read_s = t0.elapsed().as_secs_f64();
    for (name, _, rep) in &meshes {
        if rep.flipped > 0 || rep.inverted {
            eprintln!(
                "note: {name}: orientation repaired ({} triangle(s) flipped{})",
                rep.flipped,
                if rep.inverted {
                    ", whole mesh turned outward"
                } else {
                    ""
                }
            );
        }
    }
    let t1 = Instant::now();
    let grids: Vec<Grid> = meshes
        .par_iter()
        .map(|(name, mesh, _)| {
            cloner::grid_from_mesh(mesh, args.resolution, 1.1)
                .with_context(|| format!("level set of {name}"))
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(Loaded {
        names: meshes.into_iter().map(|(n, _, _)| n).collect(),
        grids,
        format,
        files: files.len(),
        ignored: 0,
        skipped: Vec::new(),
        read_s,
        levelset_s: t1.elapsed().as_secs_f64(),
        measure: morph_dna::MeasureParams::default(),
        roundness_note: None,
    })
}

fn load_sh(args: &ParentArgs, files: &[PathBuf]) -> anyhow::Result<Loaded> {
    let t0 = Instant::now();
    let models: Vec<(String, sph_harmonics::ShModel)> = files
        .par_iter()
        .map(|p| -> anyhow::Result<_> {
            let f = std::fs::File::open(p).with_context(|| format!("opening {}", p.display()))?;
            let c = sph_harmonics::vcctl::read_anm(BufReader::new(f))
                .with_context(|| format!("reading {}", p.display()))?;
            let (model, _) = c
                .to_model(args.sh_degree.unwrap_or(c.degree))
                .with_context(|| format!("{}: degree", p.display()))?;
            Ok((stem(p), model))
        })
        .collect::<anyhow::Result<_>>()?;
    let read_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let grids: Vec<Grid> = models
        .par_iter()
        .map(|(name, m)| {
            cloner::grid_from_sh(m, args.resolution, 1.1)
                .with_context(|| format!("level set of {name}"))
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(Loaded {
        names: models.into_iter().map(|(n, _)| n).collect(),
        grids,
        format: InputFormat::Anm,
        files: files.len(),
        ignored: 0,
        skipped: Vec::new(),
        read_s,
        levelset_s: t1.elapsed().as_secs_f64(),
        measure: morph_dna::MeasureParams::default(),
        roundness_note: None,
    })
}

fn load_morph(files: &[PathBuf]) -> anyhow::Result<Loaded> {
    let t0 = Instant::now();
    let grids: Vec<(String, Grid)> = files
        .par_iter()
        .map(|p| -> anyhow::Result<_> {
            let f = std::fs::File::open(p).with_context(|| format!("opening {}", p.display()))?;
            let m = levelset::io::read_morph(BufReader::new(f))
                .with_context(|| format!("reading {}", p.display()))?;
            Ok((stem(p), m.grid))
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(Loaded {
        names: grids.iter().map(|(n, _)| n.clone()).collect(),
        grids: grids.into_iter().map(|(_, g)| g).collect(),
        format: InputFormat::Morph,
        files: files.len(),
        ignored: 0,
        skipped: Vec::new(),
        read_s: t0.elapsed().as_secs_f64(),
        levelset_s: 0.0,
        measure: morph_dna::MeasureParams::default(),
        roundness_note: None,
    })
}

/// The median equivalent diameter, in voxels, of grains of these voxel counts.
fn median_voxels_across(counts: impl Iterator<Item = usize>) -> f64 {
    let mut v: Vec<usize> = counts.collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_unstable();
    let m = v[v.len() / 2] as f64;
    (6.0 * m / std::f64::consts::PI).cbrt()
}

/// What a user of a voxel image must know about its 3D roundness (issue 31; numbers in
/// the README and the validate cases `parents/roundtrip-npy`, `levelset/voxel-roundness`).
fn roundness_note(across: f64, bending: bool) -> String {
    if bending {
        format!(
            "Median equivalent diameter {across:.0} voxels: 3D roundness read from the \
             minimal-bending surfaces (--minimal-bending; issue 31): analytic grains read within \
             4 % at 20-60 voxels across, but corner radii below about 4 voxels read large \
             and a voxelised sphere (roundness 1) reads 0.79-0.88; clones at 30 voxels per \
             diameter read 7.7 % off on average (26 % at worst, Spearman 0.76), at 20 voxels \
             12 %."
        )
    } else {
        format!(
            "Median equivalent diameter {across:.0} voxels: 3D roundness \
             read from voxels is not yet faithful (issue 31): a voxelised sphere (roundness 1) \
             reads 0.42-0.51 at 16-90 voxels across, so grains rounder than about 0.5 read too \
             angular, and clones at 30 voxels per diameter read 7 % off on average (38 % at \
             worst), where aspect ratio, diameter, V/S and principal dimensions are within 1 %; \
             --minimal-bending reads analytic grains within 4 % (README)."
        )
    }
}

/// The measurement of grains read in `format`: labelled images measure their roundness
/// on the canonical grid (`morph_dna::MeasureParams::voxel_images`), the same relative
/// resolution as the mesh, SH and LS-DEM parents built at `--resolution` and as the
/// clones; every other format keeps the defaults.
/// (`--native-roundness` keeps the scan's own grid; `--minimal-bending` adds the corner
/// correction of the minimal-bending surfaces).
pub(crate) fn measure_params(
    format: InputFormat,
    native: bool,
    bending: bool,
) -> morph_dna::MeasureParams {
    match format {
        InputFormat::Npy | InputFormat::Tiff | InputFormat::Raw if bending => {
            morph_dna::MeasureParams::minimal_bending()
        }
        InputFormat::Npy | InputFormat::Tiff | InputFormat::Raw if !native => {
            morph_dna::MeasureParams::voxel_images()
        }
        _ => morph_dna::MeasureParams::default(),
    }
}

/// Measures the loaded grains as cloner parents, naming the grain of any
/// measurement error. Returns the parents and the DNA stage's seconds.
pub(crate) fn measure(loaded: Loaded) -> anyhow::Result<(cloner::Parents, Vec<String>, f64)> {
    let t = Instant::now();
    let names = loaded.names;
    let parents =
        cloner::Parents::from_grids(loaded.grids, &loaded.measure).map_err(|e| match &e {
            cloner::Error::DegenerateParent { index, reason } => anyhow::anyhow!(
                "parent {} cannot be measured: {reason}",
                names.get(*index).map_or("?", String::as_str)
            ),
            _ => anyhow::Error::new(e),
        })?;
    Ok((parents, names, t.elapsed().as_secs_f64()))
}

#[cfg(test)]
mod tests {
    //! Bad input through the file path: every error names the file (and
    //! what the parser located), nothing is half-written.

    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("grainforge-parents-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    }

    fn args() -> ParentArgs {
        ParentArgs {
            parents: None,
            format: None,
            spacing: None,
            raw_dims: None,
            raw_dtype: None,
            big_endian: false,
            keep_border: false,
            min_voxels: None,
            reject_split: false,
            smoothing: None,
            native_roundness: false,
            minimal_bending: false,
            sh_degree: None,
            resolution: 21,
        }
    }

    fn err_of(a: &ParentArgs, p: &Path) -> String {
        match load(a, p) {
            Ok(l) => panic!("expected an error, read {} grains", l.grids.len()),
            Err(e) => format!("{e:#}"),
        }
    }

    fn cube(open: bool) -> levelset::TriMesh {
        let v: Vec<nalgebra::Point3<f64>> = (0..8)
            .map(|c| {
                nalgebra::Point3::new(
                    f64::from(c & 1),
                    f64::from((c >> 1) & 1),
                    f64::from((c >> 2) & 1),
                )
            })
            .collect();
        let mut t = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        if open {
            t.truncate(10);
        }
        levelset::TriMesh::new(v, t).expect("cube")
    }

    fn write_stl(p: &Path, m: &levelset::TriMesh) {
        let mut buf = Vec::new();
        levelset::io::write_stl_binary(&mut buf, m).expect("stl");
        std::fs::write(p, buf).expect("write");
    }

    fn write_npy(p: &Path, img: &levelset::LabelImage) {
        let mut buf = Vec::new();
        levelset::io::write_npy(&mut buf, img, levelset::io::Dtype::U16).expect("npy");
        std::fs::write(p, buf).expect("write");
    }

    /// Two separated cubes of `side` voxels, labels 1 and 2.
    fn two_grains(side: usize, at_border: bool) -> levelset::LabelImage {
        let n = 2 * side + 8;
        let mut img = levelset::LabelImage::zeros([n, side + 6, side + 6], 1.0).expect("image");
        let o = usize::from(!at_border) * 3;
        for (label, x0) in [(1u32, o), (2, side + 6)] {
            for k in o..o + side {
                for j in o..o + side {
                    for i in x0..x0 + side {
                        let idx = img.index(i, j, k);
                        img.labels[idx] = label;
                    }
                }
            }
        }
        img
    }

    #[test]
    fn a_directory_mixing_formats_names_two_files() {
        let d = tmp("mixed");
        write_stl(&d.join("a.stl"), &cube(false));
        let mut obj = Vec::new();
        levelset::io::write_obj(&mut obj, &cube(false)).expect("obj");
        std::fs::write(d.join("b.obj"), obj).expect("write");
        let e = err_of(&args(), &d);
        assert!(
            e.contains("mixes formats") && e.contains("a.stl") && e.contains("b.obj"),
            "{e}"
        );
    }

    #[test]
    fn an_open_stl_is_an_error_naming_the_file() {
        let d = tmp("open");
        write_stl(&d.join("good.stl"), &cube(false));
        write_stl(&d.join("holey.stl"), &cube(true));
        let e = err_of(&args(), &d);
        assert!(e.contains("holey.stl") && e.contains("closed"), "{e}");
    }

    #[test]
    fn closed_meshes_load_and_one_parent_is_too_few() {
        let d = tmp("meshes");
        write_stl(&d.join("a.stl"), &cube(false));
        std::fs::write(d.join("README.md"), "ignored").expect("write");
        let e = err_of(&args(), &d);
        assert!(
            e.contains("1 usable parent") && e.contains("at least 2"),
            "{e}"
        );
        write_stl(&d.join("b.stl"), &cube(false));
        let l = load(&args(), &d).expect("two cubes");
        assert_eq!((l.grids.len(), l.files, l.ignored), (2, 2, 1));
        assert!(l.summary(&d).contains("2 usable grain(s)"));
    }

    #[test]
    fn labelled_images_need_a_valid_spacing() {
        let d = tmp("spacing");
        let p = d.join("scan.npy");
        write_npy(&p, &two_grains(6, false));
        let mut a = args();
        assert!(err_of(&a, &p).contains("--spacing"));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            a.spacing = Some(bad);
            assert!(err_of(&a, &p).contains("finite and positive"), "{bad}");
        }
        a.spacing = Some(0.5);
        let l = load(&a, &p).expect("two grains");
        assert_eq!(l.names, ["label-1", "label-2"]);
    }

    #[test]
    fn border_grains_small_grains_and_truncated_files_are_clear_errors() {
        let d = tmp("labels");
        let mut a = args();
        a.spacing = Some(1.0);
        // every label on the border
        let p = d.join("border.npy");
        write_npy(&p, &two_grains(6, true));
        let e = err_of(&a, &p);
        assert!(e.contains("border.npy") && e.contains("border"), "{e}");
        // one-voxel grains
        let mut img = levelset::LabelImage::zeros([9, 9, 9], 1.0).expect("image");
        let (i1, i2) = (img.index(3, 3, 3), img.index(6, 6, 6));
        img.labels[i1] = 1;
        img.labels[i2] = 2;
        let p = d.join("specks.npy");
        write_npy(&p, &img);
        let e = err_of(&a, &p);
        assert!(e.contains("specks.npy"), "{e}");
        // an empty image
        let p = d.join("empty.npy");
        write_npy(
            &p,
            &levelset::LabelImage::zeros([5, 5, 5], 1.0).expect("image"),
        );
        assert!(err_of(&a, &p).contains("empty.npy"));
        // truncated
        let p = d.join("cut.npy");
        let mut buf = Vec::new();
        levelset::io::write_npy(&mut buf, &two_grains(6, false), levelset::io::Dtype::U16)
            .expect("npy");
        buf.truncate(buf.len() - 7);
        std::fs::write(&p, buf).expect("write");
        assert!(err_of(&a, &p).contains("cut.npy"));
        // raw without its layout
        let p = d.join("scan.raw");
        std::fs::write(&p, [0u8; 64]).expect("write");
        assert!(err_of(&a, &p).contains("--raw-dims"));
    }

    #[test]
    fn unknown_files_and_empty_directories_are_errors() {
        let d = tmp("unknown");
        assert!(err_of(&args(), &d).contains("no grain files"));
        std::fs::write(d.join("grain.xyz"), "1 2 3").expect("write");
        assert!(err_of(&args(), &d).contains("grain.xyz"));
        assert!(err_of(&args(), &d.join("missing")).contains("missing"));
    }

    #[test]
    fn nothing_is_half_written() {
        let d = tmp("atomic");
        let target = d.join("out.ron");
        crate::progress::write_atomic(&target, b"first").expect("write");
        // a folder in the way of the rename: the old file stays, no temp file is left
        let blocked = d.join("dir");
        std::fs::create_dir_all(blocked.join("x")).expect("dir");
        assert!(crate::progress::write_atomic(&blocked, b"second").is_err());
        let left: Vec<String> = std::fs::read_dir(&d)
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        assert!(left.iter().all(|n| !n.contains(".tmp-")), "{left:?}");
        assert_eq!(std::fs::read(&target).expect("read"), b"first");
    }

    /// The voxel-roundness note names the grains' size in voxels.
    #[test]
    fn roundness_note_names_the_voxels_across() {
        // a 30³ cube of voxels: equivalent diameter (6·27000/π)^⅓ ≈ 37.2
        let d = super::median_voxels_across([27_000usize, 1, 30_000].into_iter());
        assert!((d - 37.2).abs() < 0.1, "{d}");
        assert!(super::median_voxels_across(std::iter::empty()).is_nan());
        for bending in [false, true] {
            let n = super::roundness_note(d, bending);
            assert!(
                n.contains("diameter 37 voxels") && n.contains("issue 31"),
                "{n}"
            );
            assert!(n.contains("minimal-bending"), "{n}");
        }
    }
}
