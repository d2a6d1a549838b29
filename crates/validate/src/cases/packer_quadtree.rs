//! packer-quadtree reproductions of Pinto 2009 (Tables 3.5/3.6, 3.13, 3.14,
//! 3.16, §3.3 supplementary domains, Table 4.2, §4.3 layers).
//!
//! Two configurations, chosen by what a row asks, not per row:
//! * reproduce the seed (Tables 3.5/3.6: porosity within ±0.01 of 0.225 and
//!   the particle count; Tables 4.2/4.3, whose GA searches the grading for a
//!   packer): [`PackParams::default`] — exact walls, contact halos, best of
//!   the stack, sorted and candidate-keyed front orders;
//! * beat or match the seed (Tables 3.13, 3.14, 3.16, §3.3: porosity ≤
//!   reference + tolerance): [`PackParams::dense`] — the same portfolio plus
//!   the three runs with wall attraction, the densest kept. Table 3.5 also
//!   reports it, as a "≤ 0.225 + 0.01" row.
//!
//! Three seeded runs per row (ChaCha8 seeds 1, 2, 3), like the seed's
//! three runs. Porosity is
//! Eq. 4-2 over the whole domain; the reference for a row is the mean of
//! the seed's runs. Every packing is also checked by the independent
//! overlap checker: the metric `min gap / d` must be ≥ −1e-9.

use packer_quadtree::{
    Domain, GaParams, Grading, PackParams, check_packing, graded_layers, optimise_porosity,
    pack_seeded, porosity,
};

use crate::fixtures::Table;
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

const SEEDS: [u64; 3] = [1, 2, 3];

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "packer-quadtree/pinto2009-table3-5-channel",
            description: "Pinto 2009 Tables 3.5/3.6: 8.6 × 62.5 mm, Table 3.4 grading, porosity within ±0.01 of 0.225",
            fast: true,
            heavy: false,
            run: table3_5,
        },
        Case {
            name: "packer-quadtree/pinto2009-table3-13-small-squares",
            description: "Pinto 2009 Table 3.13, squares 10–50 mm: porosity ≤ reference mean + 0.005",
            fast: true,
            heavy: false,
            run: || table3_13(|w| w <= 50.0),
        },
        Case {
            name: "packer-quadtree/pinto2009-table3-13-large-squares",
            description: "Pinto 2009 Table 3.13, squares 100–1000 mm: porosity ≤ reference mean + 0.005",
            fast: false,
            heavy: false,
            run: || table3_13(|w| w > 50.0),
        },
        Case {
            name: "packer-quadtree/pinto2009-table3-14-long-domains",
            description: "Pinto 2009 Table 3.14: 10, 12, 15 mm × 100 m, porosity ≤ reference mean + 0.01",
            fast: false,
            heavy: false,
            run: table3_14,
        },
        Case {
            name: "packer-quadtree/pinto2009-table3-16-wells",
            description: "Pinto 2009 Tables 3.15/3.16: Petrobras fracture slots, porosity ≤ reference mean + 0.01",
            fast: false,
            heavy: false,
            run: table3_16,
        },
        Case {
            name: "packer-quadtree/pinto2009-sec3-3-domains",
            description: "Pinto 2009 §3.3: trapezoid, inverted trapezoid, circle, porosity ≤ reference + 0.01",
            fast: true,
            heavy: false,
            run: sec3_3,
        },
        Case {
            name: "packer-quadtree/pinto2009-table4-2-ga",
            description: "Pinto 2009 Table 4.2: GA porosity control AP-1..AP-5 (20 mm square, target 0.5)",
            fast: false,
            heavy: false,
            run: table4_2,
        },
        Case {
            name: "packer-quadtree/pinto2009-table4-3-layers",
            description: "Pinto 2009 §4.3 / Table 4.3: MGF-1..3 property layers on one packing",
            fast: true,
            heavy: false,
            run: table4_3,
        },
    ]
}

/// None: with [`PackParams::dense`] every "≤ reference" row passes (the
/// 12 mm × 100 m row and the 2.6 mm slot were expected failures with the
/// default parameters, 0.202 and 0.256; they are 0.165 and 0.244 now).
pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[];

fn err(e: packer_quadtree::Error) -> Error {
    Error::Computation {
        message: e.to_string(),
    }
}

/// Packs `domain` with `grading` for every seed; returns (count, porosity,
/// worst relative gap) per run.
fn runs(
    domain: &Domain,
    grading: &Grading,
    params: &PackParams,
) -> Result<Vec<(usize, f64, f64)>, Error> {
    SEEDS
        .iter()
        .map(|&s| {
            let p = pack_seeded(domain, grading, params, s).map_err(err)?;
            let phi = porosity(domain, &p.disks).map_err(err)?;
            let rep = check_packing(domain, &p.disks, 1e-9, 1e-9).map_err(err)?;
            let gap = if rep.outside.is_empty() {
                rep.min_relative_gap.min(1.0)
            } else {
                f64::NEG_INFINITY
            };
            Ok((p.disks.len(), phi, gap))
        })
        .collect()
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0.0), |(s, n), x| (s + x, n + 1.0));
    s / n
}

/// Porosity and overlap checks of one row.
fn row_checks(
    label: &str,
    reference: f64,
    tol: Tolerance,
    r: &[(usize, f64, f64)],
    out: &mut Vec<Check>,
) {
    out.push(Check::new(
        format!("{label} porosity (mean of 3)"),
        reference,
        mean(r.iter().map(|x| x.1)),
        tol,
    ));
    let worst = r.iter().map(|x| x.2).fold(f64::INFINITY, f64::min);
    out.push(Check::new(
        format!("{label} min gap / d"),
        -1e-9,
        worst,
        Tolerance::AtLeast(0.0),
    ));
}

fn table3_5() -> Result<Vec<Check>, Error> {
    let domain = Domain::Rectangle {
        width: 8.6,
        height: 62.5,
    };
    let r = runs(&domain, &Grading::pinto_table_3_4(), &PackParams::default())?;
    let dense = runs(&domain, &Grading::pinto_table_3_4(), &PackParams::dense())?;
    let mut counts = Vec::new();
    for name in [
        "pinto2009_table3_5_proposed_algorithm.csv",
        "pinto2009_table3_6_proposed_recompiled.csv",
    ] {
        let t = Table::reference(name)?;
        for row in 0..t.rows.len() {
            counts.push(t.number(row, "particles_generated")?);
        }
    }
    let mut out = Vec::new();
    for (i, x) in r.iter().enumerate() {
        out.push(Check::new(
            format!("run {} porosity", i + 1),
            0.225,
            x.1,
            Tolerance::Within(0.01),
        ));
    }
    out.push(Check::new(
        "particle count (mean of 3)",
        mean(counts.into_iter()),
        mean(r.iter().map(|x| x.0 as f64)),
        Tolerance::Relative(0.03),
    ));
    out.push(Check::new(
        "dense preset porosity (mean of 3)",
        0.225,
        mean(dense.iter().map(|x| x.1)),
        Tolerance::AtMost(0.01),
    ));
    let worst = r
        .iter()
        .chain(&dense)
        .map(|x| x.2)
        .fold(f64::INFINITY, f64::min);
    out.push(Check::new(
        "min gap / d",
        -1e-9,
        worst,
        Tolerance::AtLeast(0.0),
    ));
    Ok(out)
}

fn table3_13(select: fn(f64) -> bool) -> Result<Vec<Check>, Error> {
    let t = Table::reference("pinto2009_table3_13_square_domains.csv")?;
    let mut sides: Vec<f64> = Vec::new();
    for row in 0..t.rows.len() {
        let w = t.number(row, "width_mm")?;
        if select(w) && !sides.contains(&w) {
            sides.push(w);
        }
    }
    let mut out = Vec::new();
    for w in sides {
        let mut refs = Vec::new();
        for row in 0..t.rows.len() {
            if t.number(row, "width_mm")? == w {
                refs.push(t.number(row, "porosity")?);
            }
        }
        let domain = Domain::Rectangle {
            width: w,
            height: w,
        };
        let r = runs(&domain, &Grading::pinto_table_3_4(), &PackParams::dense())?;
        row_checks(
            &format!("{w} mm"),
            mean(refs.into_iter()),
            Tolerance::AtMost(0.005),
            &r,
            &mut out,
        );
    }
    Ok(out)
}

fn table3_14() -> Result<Vec<Check>, Error> {
    let t = Table::reference("pinto2009_table3_14_large_domains.csv")?;
    let mut out = Vec::new();
    for w in [10.0, 12.0, 15.0] {
        let mut refs = Vec::new();
        let mut length_m = 0.0;
        for row in 0..t.rows.len() {
            if t.number(row, "width_mm")? == w {
                refs.push(t.number(row, "porosity")?);
                length_m = t.number(row, "length_m")?;
            }
        }
        let domain = Domain::Rectangle {
            width: w,
            height: 1000.0 * length_m,
        };
        let r = runs(&domain, &Grading::pinto_table_3_4(), &PackParams::dense())?;
        row_checks(
            &format!("{w} mm × {length_m} m"),
            mean(refs.into_iter()),
            Tolerance::AtMost(0.01),
            &r,
            &mut out,
        );
    }
    Ok(out)
}

fn table3_16() -> Result<Vec<Check>, Error> {
    let wells = Table::reference("pinto2009_table3_15_petrobras_fractures.csv")?;
    let res = Table::reference("pinto2009_table3_16_petrobras_wells_results.csv")?;
    let mut out = Vec::new();
    for row in 0..wells.rows.len() {
        let well = wells.text(row, "well")?;
        let width = wells.number(row, "fracture_width_mm")?;
        let height_m = wells.number(row, "fracture_height_m")?;
        let mut refs = Vec::new();
        for r in res.rows_where("well", well)? {
            refs.push(res.number(r, "porosity")?);
        }
        let domain = Domain::FractureSlot {
            width,
            height: 1000.0 * height_m,
        };
        let r = runs(&domain, &Grading::pinto_table_3_4(), &PackParams::dense())?;
        row_checks(
            well,
            mean(refs.into_iter()),
            Tolerance::AtMost(0.01),
            &r,
            &mut out,
        );
    }
    Ok(out)
}

fn sec3_3() -> Result<Vec<Check>, Error> {
    let t = Table::reference("pinto2009_sec3_3_supplementary_domains.csv")?;
    let mut out = Vec::new();
    for row in 0..t.rows.len() {
        let kind = t.text(row, "domain")?;
        let domain = match kind {
            "trapezoid" => Domain::pinto_trapezoid(),
            "inverted trapezoid" => Domain::pinto_inverted_trapezoid(),
            _ => Domain::Circle {
                radius: t.number(row, "radius_mm")?,
            },
        };
        let (lo, hi) = (t.number(row, "d_min_mm")?, t.number(row, "d_max_mm")?);
        let grading = match t.text(row, "grading")? {
            "constant" => Grading::Constant { diameter: lo },
            _ => Grading::Uniform { min: lo, max: hi },
        };
        let r = runs(&domain, &grading, &PackParams::dense())?;
        let label = format!(
            "{kind} {} ({})",
            t.text(row, "grading")?,
            t.text(row, "figure")?
        );
        row_checks(
            &label,
            t.number(row, "porosity")?,
            Tolerance::AtMost(0.01),
            &r,
            &mut out,
        );
    }
    Ok(out)
}

fn table4_2() -> Result<Vec<Check>, Error> {
    let t = Table::reference("pinto2009_table4_2_ga_porosity_tests.csv")?;
    let domain = Domain::Rectangle {
        width: 20.0,
        height: 20.0,
    };
    let mut out = Vec::new();
    let mut ours = Vec::new();
    let mut refs = Vec::new();
    for row in 0..t.rows.len() {
        let test = t.text(row, "test")?;
        let (lo, hi) = (t.number(row, "d_min_mm")?, t.number(row, "d_max_mm")?);
        let grading = match t.text(row, "grading")? {
            "constant" => Grading::Constant { diameter: lo },
            "uniform" => Grading::Uniform { min: lo, max: hi },
            _ => Grading::pinto_ap5(),
        };
        let ga = GaParams {
            target_porosity: t.number(row, "target_porosity")?,
            ..GaParams::default()
        };
        let res =
            optimise_porosity(&domain, &grading, &PackParams::default(), &ga, 1).map_err(err)?;
        let reference = t.number(row, "porosity_achieved")?;
        out.push(Check::new(
            format!("{test} porosity"),
            reference,
            res.porosity,
            Tolerance::AtMost(0.01),
        ));
        out.push(Check::new(
            format!("{test} porosity not above target"),
            ga.target_porosity,
            res.porosity,
            Tolerance::AtMost(0.0),
        ));
        ours.push(res.porosity);
        refs.push(reference);
    }
    let rising = ours.windows(2).filter(|w| w[1] > w[0]).count() as f64;
    let rising_ref = refs.windows(2).filter(|w| w[1] > w[0]).count() as f64;
    out.push(Check::new(
        "AP-1..AP-5 rising steps (direction)",
        rising_ref,
        rising,
        Tolerance::Within(0.0),
    ));
    if let (Some(a), Some(b), Some(ra), Some(rb)) =
        (ours.first(), ours.last(), refs.first(), refs.last())
    {
        out.push(Check::new(
            "AP-5 − AP-1 porosity rise (size)",
            rb - ra,
            b - a,
            Tolerance::Within(0.1),
        ));
    }
    Ok(out)
}

fn table4_3() -> Result<Vec<Check>, Error> {
    let t = Table::reference("pinto2009_table4_3_ga_fgm_tests.csv")?;
    let domain = Domain::Rectangle {
        width: 20.0,
        height: 20.0,
    };
    let p = pack_seeded(
        &domain,
        &Grading::Constant { diameter: 1.2 },
        &PackParams::default(),
        1,
    )
    .map_err(err)?;
    let mut out = Vec::new();
    for row in 0..t.rows.len() {
        let n = t.number(row, "n_properties_layers")?;
        let layers = graded_layers(&p.disks, n as usize, 0.0, 20.0).map_err(err)?;
        let mut present: Vec<usize> = layers.clone();
        present.sort_unstable();
        present.dedup();
        out.push(Check::new(
            format!("{} property layers present", t.text(row, "test")?),
            n,
            present.len() as f64,
            Tolerance::Within(0.0),
        ));
    }
    Ok(out)
}
