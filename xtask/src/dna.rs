//! `cargo xtask dna`: the morphological DNA of every shipped real grain.
//!
//! Each NIST/VCCTL grain (embedded fixtures) is read as spherical-harmonic
//! coefficients (`sph-harmonics`), evaluated at min(`Nnn`, degree in file)
//! for the Ottawa grains (NIST's own degree, see `fixtures/grains/README.md`)
//! and at the file degree for the crushed sets, rasterised as a 45³ level set
//! over its bounding cube (`levelset`, GSC 2.0's resolution) and measured
//! (`morph-dna`). The table is written to `fixtures/dna/vcctl-dna.csv`;
//! `--check` recomputes it and fails if the committed table differs. A
//! markdown report compares the Ottawa grains with NIST's geometry table and
//! the parents' correlation matrix with Medina 2018, Table 1.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::Args;
use morph_dna::{CorrelationMethod, Descriptor, DnaTable, MeasureParams, correlation_matrix};
use sph_harmonics::ShModel;

/// Flags of `cargo xtask dna`.
#[derive(Debug, Args)]
pub(crate) struct Dna {
    /// Recompute and compare with the committed table instead of writing it.
    #[arg(long)]
    check: bool,
    /// Directory for the markdown report.
    #[arg(long, default_value = "target/dna-report")]
    report: PathBuf,
    /// Level-set nodes per axis.
    #[arg(long, default_value_t = 45)]
    resolution: usize,
}

const SETS: [&str; 3] = ["ottawa", "MA106A-1-fine", "MA107-6-fine"];
const TABLE: &str = "fixtures/dna/vcctl-dna.csv";

/// One measured grain.
struct Row {
    set: &'static str,
    grain: String,
    degree: usize,
    values: Vec<f64>,
}

/// NIST geometry-table columns used by the report.
struct Geom {
    volume: f64,
    area: f64,
    norm_surf_area: f64,
    nnn: usize,
    l_over_t: f64,
    w_over_t: f64,
}

fn geom_table() -> anyhow::Result<Vec<(String, Geom)>> {
    let text = validate::fixtures::grain("vcctl/Ottawa-sand-geom-shipped.txt")?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .context("empty geom table")?
        .split_whitespace()
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .with_context(|| format!("geom table lacks {name}"))
    };
    let (iv, ia, inorm, innn, ilt, iwt) = (
        col("volume")?,
        col("surf._area")?,
        col("norm_surf_area")?,
        col("Nnn")?,
        col("L/T")?,
        col("W/T")?,
    );
    let mut out = Vec::new();
    for (n, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split('\t').map(str::trim).collect();
        let num = |i: usize| -> anyhow::Result<f64> {
            f.get(i)
                .with_context(|| format!("geom table line {}: missing field {i}", n + 2))?
                .parse::<f64>()
                .with_context(|| format!("geom table line {}: field {i}", n + 2))
        };
        out.push((
            f[0].to_owned(),
            Geom {
                volume: num(iv)?,
                area: num(ia)?,
                norm_surf_area: num(inorm)?,
                nnn: num(innn)? as usize,
                l_over_t: num(ilt)?,
                w_over_t: num(iwt)?,
            },
        ));
    }
    Ok(out)
}

fn measure_grain(model: &ShModel, resolution: usize) -> anyhow::Result<Vec<f64>> {
    // the bounding cube ×1.1 of the grain (shared with the cloner's parents)
    let grid = cloner::grid_from_sh(model, resolution, 1.1)?;
    Ok(morph_dna::measure(
        &grid,
        &Descriptor::ALL,
        &MeasureParams::default(),
    )?)
}

fn measure_all(geom: &[(String, Geom)], resolution: usize) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for set in SETS {
        let files = validate::fixtures::grains_in(&format!("vcctl/{set}"), ".dat");
        eprintln!("measuring {} grains of {set}", files.len());
        for (name, text) in files {
            let file = name.rsplit('/').next().unwrap_or(name);
            let coeffs = sph_harmonics::vcctl::read_anm(text.as_bytes())
                .with_context(|| format!("reading {name}"))?;
            let nnn = geom.iter().find(|(g, _)| g == file).map(|(_, g)| g.nnn);
            let (model, degree) = coeffs.to_model(nnn.unwrap_or(coeffs.degree))?;
            let values =
                measure_grain(&model, resolution).with_context(|| format!("measuring {name}"))?;
            rows.push(Row {
                set,
                grain: file.trim_end_matches(".dat").to_owned(),
                degree,
                values,
            });
        }
    }
    Ok(rows)
}

fn to_csv(rows: &[Row]) -> String {
    let mut out = String::from("set,grain,sh_degree");
    for d in Descriptor::ALL {
        out.push(',');
        out.push_str(d.name());
    }
    out.push('\n');
    for r in rows {
        let _ = write!(out, "{},{},{}", r.set, r.grain, r.degree);
        for v in &r.values {
            let _ = write!(out, ",{v:.9e}");
        }
        out.push('\n');
    }
    out
}

fn column(rows: &[&Row], d: Descriptor) -> Vec<f64> {
    let i = Descriptor::ALL.iter().position(|x| *x == d).unwrap_or(0);
    rows.iter().map(|r| r.values[i]).collect()
}

fn report(rows: &[Row], geom: &[(String, Geom)]) -> anyhow::Result<String> {
    let mut md = String::from("# Morphological DNA of the shipped VCCTL grains\n\n");
    let _ = writeln!(
        md,
        "Level sets of 45³ nodes over each grain's bounding cube (×1.1); descriptors as defined in `morph-dna` (`measure` module docs).\n"
    );
    md.push_str("| set | grains | aspect ratio S/L | roundness | sphericity | convexity | V/A (scan units) |\n|---|---:|---|---|---|---|---|\n");
    for set in SETS {
        let sel: Vec<&Row> = rows.iter().filter(|r| r.set == set).collect();
        let ms = |d| -> anyhow::Result<String> {
            let c = column(&sel, d);
            Ok(format!(
                "{:.3} ± {:.3}",
                morph_dna::stats::mean(&c)?,
                morph_dna::stats::sample_std(&c)?
            ))
        };
        let _ = writeln!(
            md,
            "| {set} | {} | {} | {} | {} | {} | {} |",
            sel.len(),
            ms(Descriptor::AspectRatio)?,
            ms(Descriptor::Roundness)?,
            ms(Descriptor::Sphericity)?,
            ms(Descriptor::Convexity)?,
            ms(Descriptor::VolumeSurfaceRatio)?
        );
    }
    // Ottawa vs NIST geometry table
    let ottawa: Vec<&Row> = rows.iter().filter(|r| r.set == "ottawa").collect();
    let mut pairs = Vec::new();
    for r in &ottawa {
        if let Some((_, g)) = geom
            .iter()
            .find(|(n, _)| n.trim_end_matches(".dat") == r.grain)
        {
            pairs.push((*r, g));
        }
    }
    let ours = |d: Descriptor| -> Vec<f64> {
        column(&pairs.iter().map(|(r, _)| *r).collect::<Vec<_>>(), d)
    };
    let l_over_s: Vec<f64> = ours(Descriptor::AspectRatio)
        .iter()
        .map(|a| 1.0 / a)
        .collect();
    let i_over_s: Vec<f64> = ours(Descriptor::Flatness).iter().map(|f| 1.0 / f).collect();
    let nist_lt: Vec<f64> = pairs.iter().map(|(_, g)| g.l_over_t).collect();
    let nist_wt: Vec<f64> = pairs.iter().map(|(_, g)| g.w_over_t).collect();
    let sph = ours(Descriptor::Sphericity);
    let nist_sph: Vec<f64> = pairs.iter().map(|(_, g)| 1.0 / g.norm_surf_area).collect();
    let vol = ours(Descriptor::Volume);
    let area = ours(Descriptor::SurfaceArea);
    let vol_err: Vec<f64> = pairs
        .iter()
        .zip(&vol)
        .map(|((_, g), v)| v / (g.volume * 1e6) - 1.0)
        .collect();
    let area_err: Vec<f64> = pairs
        .iter()
        .zip(&area)
        .map(|((_, g), a)| a / (g.area * 1e4) - 1.0)
        .collect();
    let _ = writeln!(
        md,
        "\n## Ottawa sand ({} grains) against NIST's geometry table\n",
        pairs.len()
    );
    md.push_str("| ours | NIST | Pearson | Spearman |\n|---|---|---:|---:|\n");
    for (a, b, an, bn) in [
        (&l_over_s, &nist_lt, "L/S (1 / aspect ratio)", "L/T"),
        (&i_over_s, &nist_wt, "I/S (1 / flatness)", "W/T"),
        (&sph, &nist_sph, "Wadell sphericity", "1 / norm_surf_area"),
    ] {
        let _ = writeln!(
            md,
            "| {an} | {bn} | {:.3} | {:.3} |",
            morph_dna::stats::pearson(a, b)?,
            morph_dna::stats::spearman(a, b)?
        );
    }
    let stat = |v: &[f64]| -> String {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let worst = v.iter().fold(0.0f64, |w, x| w.max(x.abs()));
        format!("mean {:+.2} %, worst |{:.2}| %", 100.0 * m, 100.0 * worst)
    };
    let _ = writeln!(
        md,
        "\nLevel-set (45³) volume vs NIST volume: {}; area vs NIST area: {}. NIST integrates the SH surface itself; the level set smooths roughness below its spacing, so its area is lower.\n",
        stat(&vol_err),
        stat(&area_err)
    );
    // correlation matrix beside Medina 2018, Table 1
    let table = DnaTable::from_columns(
        Descriptor::MEDINA_2018_TABLE_1.to_vec(),
        Descriptor::MEDINA_2018_TABLE_1
            .iter()
            .map(|d| column(&ottawa, *d))
            .collect(),
    )?;
    let corr = correlation_matrix(&table, CorrelationMethod::Pearson)?;
    let seed = validate::fixtures::Table::reference("gsc2018_table1_correlation_matrix.csv")?;
    let cols = [
        "aspect_ratio",
        "roundness",
        "volume_surface_ratio",
        "min_principal_direction",
    ];
    md.push_str("\n## Parents' correlation matrix (Pearson): Ottawa sand (ours) / regolith simulant (Medina 2018, Table 1)\n\n");
    md.push_str(
        "| | aspect ratio | roundness | V/A | min. principal dim. |\n|---|---|---|---|---|\n",
    );
    for (i, a) in Descriptor::MEDINA_2018_TABLE_1.iter().enumerate() {
        let _ = write!(md, "| {} |", a.name());
        for (j, b) in Descriptor::MEDINA_2018_TABLE_1.iter().enumerate() {
            let ours = corr.get(*a, *b).unwrap_or(f64::NAN);
            let theirs = seed.number(i, cols[j])?;
            let _ = write!(md, " {ours:+.2} / {theirs:+.2} |");
        }
        md.push('\n');
    }
    md.push_str("\nThe seed's parents are a regolith simulant, ours Ottawa sand: the signs and magnitudes need not agree.\n");
    Ok(md)
}

fn compare(committed: &str, fresh: &str) -> anyhow::Result<()> {
    let (a, b): (Vec<&str>, Vec<&str>) = (committed.lines().collect(), fresh.lines().collect());
    if a.len() != b.len() {
        bail!(
            "{TABLE}: {} lines committed, {} recomputed; run `cargo xtask dna`",
            a.len(),
            b.len()
        );
    }
    for (n, (la, lb)) in a.iter().zip(&b).enumerate() {
        let (fa, fb): (Vec<&str>, Vec<&str>) = (la.split(',').collect(), lb.split(',').collect());
        if fa.len() != fb.len() || fa[..3] != fb[..3] {
            bail!(
                "{TABLE}:{}: differs from the recomputation; run `cargo xtask dna`",
                n + 1
            );
        }
        if n == 0 {
            continue;
        }
        for (x, y) in fa[3..].iter().zip(&fb[3..]) {
            let (x, y): (f64, f64) = (x.parse()?, y.parse()?);
            // platform libm differences only: 1e-9 relative
            if (x - y).abs() > 1e-9 * x.abs().max(y.abs()) {
                bail!(
                    "{TABLE}:{}: {x} committed, {y} recomputed; run `cargo xtask dna`",
                    n + 1
                );
            }
        }
    }
    Ok(())
}

impl Dna {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        let start = std::time::Instant::now();
        let geom = geom_table()?;
        let rows = measure_all(&geom, self.resolution)?;
        let csv = to_csv(&rows);
        let path = root.join(TABLE);
        if self.check {
            let committed = std::fs::read_to_string(&path)
                .with_context(|| format!("reading {}", path.display()))?;
            compare(&committed, &csv)?;
            println!(
                "{TABLE} is up to date ({} grains, {:.1} s)",
                rows.len(),
                start.elapsed().as_secs_f64()
            );
            return Ok(());
        }
        std::fs::write(&path, &csv).with_context(|| format!("writing {}", path.display()))?;
        let md = report(&rows, &geom)?;
        let dir = root.join(&self.report);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let rp = dir.join("dna.md");
        std::fs::write(&rp, &md).with_context(|| format!("writing {}", rp.display()))?;
        println!("{md}");
        println!(
            "wrote {} and {} ({:.1} s)",
            path.display(),
            rp.display(),
            start.elapsed().as_secs_f64()
        );
        Ok(())
    }
}
