//! The specimen's DNA and grading report (`report.md`) with SVG plots: the
//! clones' measured DNA against the parents' (Medina 2018 Tables 4–5
//! errors and KS distances, through `cloner::score`) and the specimen's
//! grading (volume-weighted passing curve of the placed grains'
//! volume-equivalent diameters; Cu, Cc) beside the parents'.

use std::fmt::Write as _;

use rayon::prelude::*;

use cloner::{Parents, Run, TABLES_4_5, score};
use morph_dna::{Descriptor, GradingCurve, GradingInterpolation, GradingWeight};

use super::scene::Clones;
use crate::svg;

/// The report files: `(name relative to out_dir, contents)`, report.md first.
///
/// `diameters`: the placed grains' volume-equivalent diameters (after any
/// rescaling of a graded scene).
pub(crate) fn write(
    parents: &Parents,
    run: &Run,
    diameters: &[f64],
    clones: &Clones,
    config: &str,
) -> anyhow::Result<Vec<(String, String)>> {
    let dna = run.dna_table()?;
    let scores = score(parents.dna(), &dna)?;
    let mut md = String::new();
    let _ = writeln!(md, "# Specimen report\n");
    let _ = writeln!(
        md,
        "{} clones of `{config}` against {} parents.\n",
        run.clones.len(),
        parents.len()
    );
    let _ = writeln!(
        md,
        "## DNA: clones vs parents (measured on level sets)\n\n\
         | parameter | parents mean | clones mean | mean error % | parents sd | clones sd | sd error % | KS |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for (k, d) in TABLES_4_5.iter().enumerate() {
        let (p, c) = (parents.dna().column(*d)?, dna.column(*d)?);
        let (pm, ps) = mean_sd(p);
        let (cm, cs) = mean_sd(c);
        let _ = writeln!(
            md,
            "| {} | {pm:.4} | {cm:.4} | {:.2} | {ps:.4} | {cs:.4} | {:.2} | {:.3} |",
            d.name(),
            scores.mean_error_pct[k],
            scores.std_error_pct[k],
            scores.ks[k]
        );
    }
    let _ = writeln!(
        md,
        "\nAverage mean error {:.2} %, average sd error {:.2} %, largest KS distance {:.3}.",
        scores.mean_error_avg_pct, scores.std_error_avg_pct, scores.ks_max
    );
    if matches!(clones, Clones::Graded { .. }) {
        let _ = writeln!(
            md,
            "\nThe scene grades the sizes: each clone was rescaled after cloning, so the table \
             compares the cloner's (unscaled) clones with the parents; the grading below is the \
             specimen's."
        );
    }
    let parent_d = parents.dna().column(Descriptor::EquivalentDiameter)?;
    let pc = GradingCurve::from_diameters(parent_d, GradingWeight::Volume)?;
    let sc = GradingCurve::from_diameters(diameters, GradingWeight::Volume)?;
    let (pg, sg) = (
        pc.coefficients(GradingInterpolation::LogDiameter)?,
        sc.coefficients(GradingInterpolation::LogDiameter)?,
    );
    let _ = writeln!(
        md,
        "\n## Grading (volume passing of volume-equivalent diameters)\n\n\
         | | D10 | D30 | D60 | Cu | Cc |\n| --- | --- | --- | --- | --- | --- |\n\
         | parents | {:.4} | {:.4} | {:.4} | {:.3} | {:.3} |\n\
         | specimen | {:.4} | {:.4} | {:.4} | {:.3} | {:.3} |",
        pg.d10, pg.d30, pg.d60, pg.cu, pg.cc, sg.d10, sg.d30, sg.d60, sg.cu, sg.cc
    );
    let _ = writeln!(
        md,
        "\nPlots: `plots/grading.svg`, `plots/histogram_<parameter>.svg`."
    );
    let mut files = vec![("report.md".to_owned(), md)];
    let line = |label: &str, g: &GradingCurve| {
        svg::Series::line(
            label,
            g.diameters
                .iter()
                .zip(&g.passing_percent)
                .map(|(d, p)| (*d, *p))
                .collect(),
        )
    };
    files.push((
        "plots/grading.svg".into(),
        svg::render(&svg::Chart {
            title: "Grading curves (volume passing)".into(),
            x_label: "volume-equivalent diameter (log)".into(),
            y_label: "% passing".into(),
            log_x: true,
            series: vec![line("parents", &pc), line("specimen", &sc)],
        }),
    ));
    for d in TABLES_4_5 {
        let (p, c) = (parents.dna().column(d)?, dna.column(d)?);
        let lo = p.iter().chain(c).fold(f64::INFINITY, |a, v| a.min(*v));
        let hi = p.iter().chain(c).fold(f64::NEG_INFINITY, |a, v| a.max(*v));
        let hi = if hi > lo { hi } else { lo + 1.0 };
        files.push((
            format!("plots/histogram_{}.svg", d.name()),
            svg::render(&svg::Chart {
                title: format!("{}: parents vs clones", d.name()),
                x_label: d.name().into(),
                y_label: "density".into(),
                log_x: false,
                series: vec![
                    svg::Series::line(
                        &format!("parents ({})", p.len()),
                        svg::density_steps(p, lo, hi, 20),
                    ),
                    svg::Series::line(
                        &format!("clones ({})", c.len()),
                        svg::density_steps(c, lo, hi, 20),
                    ),
                ],
            }),
        ));
    }
    Ok(files)
}

/// The report's section on the clumps as delivered (after trimming): their DNA, each
/// union rasterised on its grain's own grid, and their union mass against the level sets.
pub(crate) fn clump_dna_section(
    spheres: &[Vec<(nalgebra::Point3<f64>, f64)>],
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
            let theirs = morph_dna::measure(
                &union,
                &::specimen::CLUMP_DNA,
                &morph_dna::MeasureParams::default(),
            )?;
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
    for (i, d) in ::specimen::CLUMP_DNA.iter().enumerate() {
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

fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len().max(1) as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, v.sqrt())
}
