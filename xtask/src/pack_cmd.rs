//! `cargo xtask pack`: pack a 2D domain with disks (Pinto 2009's advancing
//! front, `packer-quadtree`) and write the packing for DEM tools: CSV, VTU
//! (ParaView), LIGGGHTS/LAMMPS `read_data`, Yade text and an SVG picture.
//! Every packing is checked by the independent overlap checker before it is
//! written; a packing that fails the check is not written.
//!
//! Lengths are in mm (the seed's unit), as are the output coordinates.

use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use nalgebra::Point2;
use packer_contact::{GrainShape, PicPacking, PicParams, check_pic, pack_pic, write_pic_vtu};
use packer_quadtree::{
    Domain, Grading, PackParams, check_packing, pack_seeded, porosity, write_csv,
    write_lammps_data, write_svg, write_vtu, write_yade,
};

/// Parameter presets of the packer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum Preset {
    /// `PackParams::default()`: reproduces the seed's porosities.
    Default,
    /// `PackParams::dense()`: the densest (about twice the cost).
    Dense,
    /// `PackParams::seed()`: the text's literal configuration.
    Seed,
}

/// Output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum Output {
    /// `packing.csv`: `x,y,r` per disk.
    Csv,
    /// `packing.vtu`: vertex cells with a radius array (ParaView).
    Vtu,
    /// `packing.data`: LIGGGHTS/LAMMPS `read_data`, `atom_style sphere`.
    Lammps,
    /// `packing.txt`: Yade `ymport.text` (`x y z r`).
    Yade,
    /// `packing.svg`: a picture of the domain and the disks.
    Svg,
}

/// Flags of `cargo xtask pack`.
#[derive(Debug, Args)]
pub(crate) struct Pack {
    /// Domain, in mm: `rect:W,H`, `slot:W,H` (fracture aperture W, height
    /// H), `circle:R`, `trapezoid:H,BOTTOM,TOP`, or `polygon:x,y;x,y;...`.
    #[arg(long, default_value = "rect:100,100")]
    domain: String,
    /// Grading, in mm: `pinto-3.4` (Pinto 2009, Table 3.4), `ap5`
    /// (Table 4.1), `constant:D`, `uniform:MIN,MAX`,
    /// `lognormal:MEDIAN,SIGMA,MIN,MAX` (σ of ln d, truncated), or
    /// `sieve:SIZE:PASSING%,SIZE:PASSING%,...` (increasing sizes, 0 % first,
    /// 100 % last).
    #[arg(long, default_value = "pinto-3.4")]
    grading: String,
    /// Packer parameters.
    #[arg(long, value_enum, default_value_t = Preset::Default)]
    preset: Preset,
    /// Seed of the size sampling (ChaCha8).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output formats (comma separated).
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "csv,vtu,lammps,yade,svg"
    )]
    formats: Vec<Output>,
    /// Particle density for the LAMMPS file (in the file's mass/length³).
    #[arg(long, default_value_t = 2.65e-3)]
    density: f64,
    /// Output directory.
    #[arg(long, default_value = "target/packing")]
    out: PathBuf,
    /// Grain shape: `disk` (the Pinto 2009 packer above), or one of the
    /// particle-in-contact packer (Pérez Morales 2016) in the square/cube
    /// `[0, --side]^D`: `sphere` (3D), `ball`, `capsule:ASPECT`,
    /// `cluster:ASPECT[,N]` (N disks/spheres, default 4),
    /// `polygon:MIN[,MAX]` (sides; hull vertices in 3D),
    /// `mix:SHARE[,MIN,MAX]` (disks and polygons), or `row:P1`…`row:P5`
    /// (the seed's rows). ASPECT is width/length = r/R in (0, 1].
    /// These write `packing.vtu` only.
    #[arg(long, default_value = "disk")]
    shape: String,
    /// Dimension: 2 (disks, or the particle-in-contact packer with
    /// `--shape`) or 3 (spheres in `--container` by the 3D advancing front;
    /// with `--shape`, the particle-in-contact packer in 3D).
    #[arg(long, default_value_t = 2)]
    dim: usize,
    /// 3D container, lengths in the grading's unit:
    /// `box:LX,LY,LZ[,periodic|periodic-x]` (walls, or periodic in x and y /
    /// in x), `cylinder:D[,H]` (vertical, H = 2 D by default: the triaxial
    /// specimen) or `mesh:FILE` (a closed STL or OBJ surface). Implies
    /// `--dim 3`; default with `--dim 3`: `box:80,80,80`.
    #[arg(long)]
    container: Option<String>,
    /// 3D only: after the front, densify (affine compression with FIRE
    /// overlap relaxation, `packer-spheres::densify`) to this solid fraction
    /// of the container, in (0, 0.74], or to `jammed` (the container shrinks
    /// to the jamming point). Also allows `box:LX,LY,LZ,periodic-xyz`.
    #[arg(long)]
    target_fraction: Option<String>,
    /// Side of the square/cube of the particle-in-contact packer.
    #[arg(long, default_value_t = 20.0)]
    side: f64,
    /// Circumscribed radii `MIN,MAX` (uniform) of the particle-in-contact packer.
    #[arg(long, default_value = "1,2")]
    radii: String,
    /// Orientations tried per grain (1 = the drawn random orientation).
    #[arg(long, default_value_t = 1)]
    orientations: usize,
}

/// Parses `--shape` (other than `disk`) into a dimension and parameters.
pub(crate) fn parse_shape(
    s: &str,
    dim: usize,
    side: f64,
    radii: &str,
    orientations: usize,
) -> anyhow::Result<(usize, PicParams)> {
    let (kind, rest) = s.split_once(':').unwrap_or((s, ""));
    if kind == "row" {
        return Ok(PicParams::perezmorales2016(rest)?);
    }
    let [radius_min, radius_max] = exactly(numbers(radii, "radii")?, "--radii")?;
    let nums = |what: &str| numbers(rest, what);
    let shape = match kind {
        "sphere" | "ball" => GrainShape::Ball,
        "capsule" => {
            let [aspect] = exactly(nums("capsule")?, "capsule")?;
            GrainShape::Capsule { aspect }
        }
        "cluster" => {
            let v = nums("cluster")?;
            let aspect = *v.first().context("cluster needs ASPECT")?;
            let spheres = v.get(1).copied().unwrap_or(4.0);
            if spheres.fract() != 0.0 || spheres < 0.0 {
                bail!("cluster: N must be a whole number, got {spheres}");
            }
            GrainShape::Cluster {
                aspect,
                spheres: spheres as usize,
            }
        }
        "polygon" | "mix" => {
            let v = nums(kind)?;
            let whole = |x: f64| -> anyhow::Result<usize> {
                if x.fract() != 0.0 || x < 0.0 {
                    bail!("{kind}: side counts must be whole numbers, got {x}");
                }
                Ok(x as usize)
            };
            if kind == "polygon" {
                let lo = whole(*v.first().context("polygon needs MIN")?)?;
                let hi = whole(v.get(1).copied().unwrap_or(lo as f64))?;
                GrainShape::Polygon {
                    sides_min: lo,
                    sides_max: hi,
                }
            } else {
                let share = *v.first().context("mix needs SHARE")?;
                let lo = whole(v.get(1).copied().unwrap_or(4.0))?;
                let hi = whole(v.get(2).copied().unwrap_or(8.0))?;
                GrainShape::Mix {
                    polygon_share: share,
                    sides_min: lo,
                    sides_max: hi,
                }
            }
        }
        _ => bail!(
            "unknown shape `{kind}` (disk, sphere, ball, capsule, cluster, polygon, mix, row)"
        ),
    };
    let dim = if kind == "sphere" { 3 } else { dim };
    if dim != 2 && dim != 3 {
        bail!("--dim must be 2 or 3, got {dim}");
    }
    let params = PicParams {
        side,
        radius_min,
        radius_max,
        shape,
        orientations,
        ..PicParams::default()
    };
    params.validate(dim)?;
    Ok((dim, params))
}

fn write_pic<const D: usize>(p: &PicPacking<D>, dir: &Path, secs: f64) -> anyhow::Result<()> {
    let rep = check_pic(p, 1e-9)?;
    if rep.min_relative_gap < -1e-9 || rep.min_relative_wall_gap < -1e-9 {
        bail!(
            "the independent checker rejects this packing (min gap / d {:.2e}, wall {:.2e}): \
             nothing written; please report it with the command line",
            rep.min_relative_gap,
            rep.min_relative_wall_gap
        );
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = dir.join("packing.vtu");
    let w = BufWriter::new(
        std::fs::File::create(&path).with_context(|| format!("creating {}", path.display()))?,
    );
    write_pic_vtu(p, w).with_context(|| format!("writing {}", path.display()))?;
    println!(
        "{} grains ({} discarded) in {secs:.2} s = {:.0} grains/s: fraction {:.4}, coordination \
         number {:.2}, min gap / d {:.2e}; written to {}",
        p.grains.len(),
        p.rejected,
        p.grains.len() as f64 / secs.max(1e-9),
        p.fraction(),
        rep.coordination,
        rep.min_relative_gap,
        path.display()
    );
    Ok(())
}

fn numbers(s: &str, what: &str) -> anyhow::Result<Vec<f64>> {
    s.split(',')
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .with_context(|| format!("{what}: `{t}` is not a number"))
        })
        .collect()
}

fn exactly<const N: usize>(v: Vec<f64>, what: &str) -> anyhow::Result<[f64; N]> {
    let n = v.len();
    v.try_into()
        .map_err(|_| anyhow::anyhow!("{what} takes {N} numbers, got {n}"))
}

/// Parses `--domain`.
pub(crate) fn parse_domain(s: &str) -> anyhow::Result<Domain> {
    let (kind, rest) = s.split_once(':').unwrap_or((s, ""));
    Ok(match kind {
        "rect" => {
            let [width, height] = exactly(numbers(rest, "rect")?, "rect")?;
            Domain::Rectangle { width, height }
        }
        "slot" => {
            let [width, height] = exactly(numbers(rest, "slot")?, "slot")?;
            Domain::FractureSlot { width, height }
        }
        "circle" => {
            let [radius] = exactly(numbers(rest, "circle")?, "circle")?;
            Domain::Circle { radius }
        }
        "trapezoid" => {
            let [height, bottom, top] = exactly(numbers(rest, "trapezoid")?, "trapezoid")?;
            Domain::Trapezoid {
                height,
                bottom,
                top,
            }
        }
        "polygon" => {
            let mut vertices = Vec::new();
            for v in rest.split(';') {
                let [x, y] = exactly(numbers(v, "polygon vertex")?, "a polygon vertex")?;
                vertices.push(Point2::new(x, y));
            }
            Domain::Polygon { vertices }
        }
        _ => bail!("unknown domain `{kind}` (rect, slot, circle, trapezoid, polygon)"),
    })
}

/// Parses `--grading`.
pub(crate) fn parse_grading(s: &str) -> anyhow::Result<Grading> {
    let (kind, rest) = s.split_once(':').unwrap_or((s, ""));
    let g = match kind {
        "pinto-3.4" => Grading::pinto_table_3_4(),
        "ap5" => Grading::pinto_ap5(),
        "constant" => {
            let [diameter] = exactly(numbers(rest, "constant")?, "constant")?;
            Grading::Constant { diameter }
        }
        "uniform" => {
            let [min, max] = exactly(numbers(rest, "uniform")?, "uniform")?;
            Grading::Uniform { min, max }
        }
        "lognormal" => {
            let [median, sigma, min, max] = exactly(numbers(rest, "lognormal")?, "lognormal")?;
            Grading::LogNormal {
                median,
                sigma,
                min,
                max,
            }
        }
        "sieve" | "sieve-mass" => {
            let (mut sizes, mut passing) = (Vec::new(), Vec::new());
            for pair in rest.split(',') {
                let (d, p) = pair
                    .split_once(':')
                    .with_context(|| format!("sieve point `{pair}` is not SIZE:PASSING"))?;
                sizes.push(
                    d.trim()
                        .parse::<f64>()
                        .with_context(|| format!("sieve size `{d}`"))?,
                );
                passing.push(
                    p.trim()
                        .parse::<f64>()
                        .with_context(|| format!("passing `{p}`"))?,
                );
            }
            if kind == "sieve-mass" {
                Grading::sieve_by_mass(sizes, passing)?
            } else {
                Grading::Sieve { sizes, passing }
            }
        }
        _ => {
            bail!(
                "unknown grading `{kind}` (pinto-3.4, ap5, constant, uniform, lognormal, sieve, sieve-mass)"
            )
        }
    };
    g.validate()?;
    Ok(g)
}

impl Pack {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        if self.shape == "disk" && (self.dim == 3 || self.container.is_some()) {
            let container = self.container.as_deref().unwrap_or("box:80,80,80");
            return crate::pack3d_cmd::Run3 {
                container,
                grading: parse_grading(&self.grading)?,
                preset: self.preset,
                seed: self.seed,
                formats: &self.formats,
                density: self.density,
                out: self.out.clone(),
                target: self.target_fraction.as_deref(),
            }
            .run(root);
        }
        if self.target_fraction.is_some() {
            bail!("--target-fraction applies to --dim 3 sphere packings only");
        }
        if self.shape != "disk" {
            let (dim, params) = parse_shape(
                &self.shape,
                self.dim,
                self.side,
                &self.radii,
                self.orientations,
            )?;
            let dir = root.join(&self.out);
            let start = Instant::now();
            return if dim == 2 {
                let p = pack_pic::<2>(&params, self.seed)?;
                write_pic(&p, &dir, start.elapsed().as_secs_f64())
            } else {
                let p = pack_pic::<3>(&params, self.seed)?;
                write_pic(&p, &dir, start.elapsed().as_secs_f64())
            };
        }
        let domain = parse_domain(&self.domain)?;
        let grading = parse_grading(&self.grading)?;
        let params = match self.preset {
            Preset::Default => PackParams::default(),
            Preset::Dense => PackParams::dense(),
            Preset::Seed => PackParams::seed(),
        };
        if self.formats.contains(&Output::Lammps)
            && !(self.density.is_finite() && self.density > 0.0)
        {
            bail!(
                "--density must be positive and finite, got {}",
                self.density
            );
        }
        let start = Instant::now();
        let p = pack_seeded(&domain, &grading, &params, self.seed)?;
        let packed = start.elapsed().as_secs_f64();
        let phi = porosity(&domain, &p.disks)?;
        let rep = check_packing(&domain, &p.disks, 1e-9, 1e-9)?;
        if !rep.is_clean() {
            bail!(
                "the independent checker rejects this packing ({} overlapping pairs, {} disks \
                 outside): nothing written; please report it with the command line",
                rep.overlapping_pairs.len(),
                rep.outside.len()
            );
        }
        let dir = root.join(&self.out);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        for f in &self.formats {
            let name = match f {
                Output::Csv => "packing.csv",
                Output::Vtu => "packing.vtu",
                Output::Lammps => "packing.data",
                Output::Yade => "packing.txt",
                Output::Svg => "packing.svg",
            };
            let path = dir.join(name);
            let w = BufWriter::new(
                std::fs::File::create(&path)
                    .with_context(|| format!("creating {}", path.display()))?,
            );
            match f {
                Output::Csv => write_csv(&p.disks, w),
                Output::Vtu => write_vtu(&p.disks, w),
                Output::Lammps => write_lammps_data(&p.disks, self.density, w),
                Output::Yade => write_yade(&p.disks, w),
                Output::Svg => write_svg(&domain, &p.disks, w),
            }
            .with_context(|| format!("writing {}", path.display()))?;
        }
        println!(
            "{} disks in {packed:.2} s ({:?} preset, seed {}): porosity {phi:.4}, coordination \
             number {:.2}, min gap / d {:.2e}; written to {}",
            p.disks.len(),
            self.preset,
            self.seed,
            rep.coordination_number(p.disks.len()),
            rep.min_relative_gap,
            dir.display()
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{parse_domain, parse_grading, parse_shape};
    use packer_quadtree::{Domain, Grading};

    #[test]
    fn domains_and_gradings_parse() {
        assert_eq!(
            parse_domain("slot:2.6,8000").expect("slot"),
            Domain::FractureSlot {
                width: 2.6,
                height: 8000.0
            }
        );
        assert!(matches!(
            parse_domain("polygon:0,0;10,0;5,8").expect("polygon"),
            Domain::Polygon { vertices } if vertices.len() == 3
        ));
        assert_eq!(
            parse_grading("sieve:1.2:0,1.3:100").expect("sieve"),
            Grading::Sieve {
                sizes: vec![1.2, 1.3],
                passing: vec![0.0, 100.0]
            }
        );
    }

    #[test]
    fn bad_flags_are_errors() {
        for d in ["rect:1", "rect:a,b", "hexagon:3", "polygon:0,0;1"] {
            assert!(parse_domain(d).is_err(), "{d}");
        }
        for sh in [
            "capsule:1.5",
            "capsule:0",
            "cluster:0.5,1",
            "polygon:2",
            "polygon:3.5",
            "mix:2",
            "row:P9",
            "cone:1",
        ] {
            assert!(parse_shape(sh, 2, 20.0, "1,2", 1).is_err(), "{sh}");
        }
        assert!(
            parse_shape("capsule:0.5", 2, 3.0, "1,2", 1).is_err(),
            "domain too small"
        );
        assert!(
            parse_shape("ball", 2, 20.0, "0,2", 1).is_err(),
            "zero radius"
        );
        assert!(parse_shape("capsule:0.5", 2, 20.0, "1,2", 1).is_ok());
        assert!(parse_shape("row:P4", 2, 20.0, "1,2", 1).is_ok_and(|(d, _)| d == 3));
        for g in [
            "uniform:2",
            "sieve:1.3:0,1.2:100",
            "sieve:1.2:10,1.3:100",
            "constant:-1",
            "weibull:1",
        ] {
            assert!(parse_grading(g).is_err(), "{g}");
        }
    }
}
