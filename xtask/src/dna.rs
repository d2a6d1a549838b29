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
use rayon::prelude::*;
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
    /// No progress bars.
    #[arg(long)]
    quiet: bool,
    /// With `--parents`: directory of the DNA table (CSV + RON) and report.
    #[arg(long, default_value = "target/dna-parents")]
    out: PathBuf,
    /// The user's grains (see `--format`); without it, every shipped grain.
    #[command(flatten)]
    source: crate::parents::ParentArgs,
}

const SETS: [&str; 4] = ["ottawa", "ottawa-random", "MA106A-1-fine", "MA107-6-fine"];
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

/// NIST's rows of both embedded Ottawa tables (`validate::grains`).
fn geom_table() -> anyhow::Result<Vec<(String, Geom)>> {
    let mut out = Vec::new();
    for t in validate::grains::GEOM_TABLES {
        for r in validate::grains::geom_table(t)? {
            out.push((
                r.file,
                Geom {
                    volume: r.volume,
                    area: r.area,
                    norm_surf_area: r.normalised_area,
                    nnn: r.nnn,
                    l_over_t: r.lt_wt[0],
                    w_over_t: r.lt_wt[1],
                },
            ));
        }
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
        // in parallel, collected in file order (results do not depend on threads)
        let measured: Vec<Row> = files
            .par_iter()
            .map(|(name, text)| -> anyhow::Result<Row> {
                let file = name.rsplit('/').next().unwrap_or(name);
                let coeffs = sph_harmonics::vcctl::read_anm(text.as_bytes())
                    .with_context(|| format!("reading {name}"))?;
                let nnn = geom.iter().find(|(g, _)| g == file).map(|(_, g)| g.nnn);
                let (model, degree) = coeffs.to_model(nnn.unwrap_or(coeffs.degree))?;
                let values = measure_grain(&model, resolution)
                    .with_context(|| format!("measuring {name}"))?;
                Ok(Row {
                    set,
                    grain: file.trim_end_matches(".dat").to_owned(),
                    degree,
                    values,
                })
            })
            .collect::<anyhow::Result<_>>()?;
        rows.extend(measured);
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

/// The Markdown report: DNA per shipped set, the Ottawa sets against NIST's
/// geometry table, their medians beside NIST's, and the default parents'
/// correlation matrix beside Medina 2018, Table 1.
fn report(rows: &[Row], geom: &[(String, Geom)]) -> anyhow::Result<String> {
    let mut md = String::from("# Morphological DNA of the shipped VCCTL grains\n\n");
    let _ = writeln!(
        md,
        "Level sets of 45³ nodes over each grain's bounding cube (×1.1); descriptors as defined in `morph-dna` (`measure` module docs).\n"
    );
    md_sets(&mut md, rows)?;
    // Ottawa vs NIST geometry table
    for set in ["ottawa", "ottawa-random"] {
        md_against_nist(&mut md, rows, geom, set)?;
    }
    // representativeness: medians beside NIST's, for each Ottawa set
    md_medians(&mut md)?;
    md_correlation(&mut md, rows)?;
    Ok(md)
}

/// Mean ± standard deviation of the main descriptors of every shipped set.
fn md_sets(md: &mut String, rows: &[Row]) -> anyhow::Result<()> {
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
    Ok(())
}

/// The Ottawa set `set` against NIST's geometry table: correlations of the
/// caliper ratios and sphericity, volume and area errors.
fn md_against_nist(
    md: &mut String,
    rows: &[Row],
    geom: &[(String, Geom)],
    set: &str,
) -> anyhow::Result<()> {
    let ottawa: Vec<&Row> = rows.iter().filter(|r| r.set == set).collect();
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
        "\n## Ottawa sand `{set}` ({} grains) against NIST's geometry table\n",
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
    Ok(())
}

/// Shape medians of each Ottawa set beside NIST's, for the same grains and
/// for the population.
fn md_medians(md: &mut String) -> anyhow::Result<()> {
    md.push_str("\n## Are the Ottawa parents representative? Medians beside NIST's\n\n");
    md.push_str("NIST's length L, width W and thickness T are calipers (L the longest surface-to-surface distance, W the longest perpendicular to L, T the longest perpendicular to both). Like with like, our caliper ratios are the extents along the principal axes of inertia: flatness S/I = minor/intermediate extent (NIST T/W), elongation I/L = intermediate/major extent (NIST W/L). Our `flatness`/`elongation` descriptors use the inertia-equivalent ellipsoid's axes instead (same for an ellipsoid, smoother for rough grains) and are shown beside. Population: NIST's medians over all 2,201 Ottawa grains.\n\n");
    md.push_str("| set | grains | caliper S/I (ours) | NIST T/W, same grains | population T/W | caliper I/L (ours) | NIST W/L, same grains | population W/L | inertia S/I | inertia I/L |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for set in ["ottawa", "ottawa-random"] {
        let m = validate::cases::parents::shape_medians(&format!("vcctl/{set}"))?;
        let _ = writeln!(
            md,
            "| {set}{} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            if format!("vcctl/{set}") == validate::grains::DEFAULT_PARENTS {
                " (default parents)"
            } else {
                ""
            },
            m.grains,
            m.extent_flatness,
            m.nist_t_over_w,
            validate::cases::parents::POPULATION_T_OVER_W,
            m.extent_elongation,
            m.nist_w_over_l,
            validate::cases::parents::POPULATION_W_OVER_L,
            m.flatness,
            m.elongation
        );
    }
    Ok(())
}

/// The default parents' Pearson correlation matrix beside Medina 2018,
/// Table 1 (a regolith simulant).
fn md_correlation(md: &mut String, rows: &[Row]) -> anyhow::Result<()> {
    let ottawa: Vec<&Row> = rows
        .iter()
        .filter(|r| format!("vcctl/{}", r.set) == validate::grains::DEFAULT_PARENTS)
        .collect();
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
    md.push_str("\n## Parents' correlation matrix (Pearson): Ottawa sand, default parents (ours) / regolith simulant (Medina 2018, Table 1)\n\n");
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
    Ok(())
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

/// The DNA of the user's grains: table (CSV + RON, one row per grain, in
/// the loader's order, with a `grain` column in the CSV) and a report with
/// per-descriptor histograms and the correlation matrix.
fn user_dna(args: &Dna, root: &Path, source: &Path) -> anyhow::Result<()> {
    let start = std::time::Instant::now();
    let loaded = crate::parents::load(&args.source, source)?;
    let summary = loaded.summary(source);
    let t = std::time::Instant::now();
    let params = loaded.measure;
    let pb = crate::progress::bar("measuring DNA", loaded.grids.len() as u64, args.quiet);
    let values: Vec<Vec<f64>> = loaded
        .grids
        .par_iter()
        .zip(&loaded.names)
        .map(|(g, name)| {
            let v = morph_dna::measure(g, &Descriptor::ALL, &params)
                .with_context(|| format!("measuring {name}"));
            pb.inc(1);
            v
        })
        .collect::<anyhow::Result<_>>()?;
    pb.finish_and_clear();
    let dna_s = t.elapsed().as_secs_f64();
    let table = DnaTable::from_rows(Descriptor::ALL.to_vec(), &values)?;
    let dir = root.join(&args.out);
    let mut csv = String::from("grain");
    for d in Descriptor::ALL {
        csv.push(',');
        csv.push_str(d.name());
    }
    csv.push('\n');
    for (name, row) in loaded.names.iter().zip(&values) {
        csv.push_str(name);
        for v in row {
            let _ = write!(csv, ",{v:.9e}");
        }
        csv.push('\n');
    }
    crate::progress::write_atomic(&dir.join("dna.csv"), csv.as_bytes())?;
    let mut ron = Vec::new();
    table.write_ron(&mut ron)?;
    crate::progress::write_atomic(&dir.join("dna.ron"), &ron)?;
    // report: summary statistics, histograms, correlation matrix
    let mut md = format!(
        "# Morphological DNA of `{}`\n\n{summary}, DNA {dna_s:.2} s.\n\n",
        source.display()
    );
    md.push_str(
        "| descriptor | mean | std | min | median | max |\n|---|---:|---:|---:|---:|---:|\n",
    );
    for d in Descriptor::ALL {
        let c = table.column(d)?;
        let mut sorted = c.to_vec();
        sorted.sort_by(f64::total_cmp);
        let _ = writeln!(
            md,
            "| {} | {:.4e} | {:.4e} | {:.4e} | {:.4e} | {:.4e} |",
            d.name(),
            morph_dna::stats::mean(c)?,
            morph_dna::stats::sample_std(c)?,
            sorted[0],
            validate::cases::parents::median(c),
            sorted[sorted.len() - 1]
        );
        let (lo, hi) = (sorted[0], sorted[sorted.len() - 1]);
        let chart = crate::svg::Chart {
            title: format!("{} ({} grains)", d.name(), c.len()),
            x_label: d.name().into(),
            y_label: "density".into(),
            log_x: false,
            series: vec![crate::svg::Series::line(
                "grains",
                crate::svg::density_steps(c, lo, hi.max(lo * (1.0 + 1e-9) + 1e-300), 20),
            )],
        };
        crate::progress::write_atomic(
            &dir.join(format!("histogram_{}.svg", d.name())),
            crate::svg::render(&chart).as_bytes(),
        )?;
    }
    let sub = DnaTable::from_columns(
        Descriptor::MEDINA_2018_TABLE_1.to_vec(),
        Descriptor::MEDINA_2018_TABLE_1
            .iter()
            .map(|d| table.column(*d).map(<[f64]>::to_vec))
            .collect::<Result<_, _>>()?,
    )?;
    let corr = correlation_matrix(&sub, CorrelationMethod::Pearson)?;
    md.push_str("\n## Correlation matrix (Pearson)\n\n| | aspect ratio | roundness | V/A | min. principal dim. |\n|---|---|---|---|---|\n");
    for a in Descriptor::MEDINA_2018_TABLE_1 {
        let _ = write!(md, "| {} |", a.name());
        for b in Descriptor::MEDINA_2018_TABLE_1 {
            let _ = write!(md, " {:+.2} |", corr.get(a, b).unwrap_or(f64::NAN));
        }
        md.push('\n');
    }
    md.push_str("\nHistograms: `histogram_<descriptor>.svg`.\n");
    crate::progress::write_atomic(&dir.join("dna.md"), md.as_bytes())?;
    println!(
        "{summary}, DNA {dna_s:.2} s; {} grains measured, table and report in {} ({:.1} s in all).",
        values.len(),
        dir.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

impl Dna {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        if let Some(src) = self.source.parents.clone() {
            if self.check {
                bail!(
                    "--check verifies the committed table of the shipped grains; it takes no --parents"
                );
            }
            return user_dna(&self, root, &src);
        }
        let start = std::time::Instant::now();
        let geom = geom_table()?;
        let rows = measure_all(&geom, self.source.resolution)?;
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
