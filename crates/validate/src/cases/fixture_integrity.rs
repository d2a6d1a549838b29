//! Fixture integrity: every reference table parses with its documented row
//! count, and the arithmetic the sources allow is recomputed from the printed
//! numbers (averages, percentage errors, derived quantities).
//!
//! Each recomputation yields a *strict* check (printed inputs taken as exact)
//! and a *rounding* check (inputs anywhere inside their print intervals; see
//! [`super::rounding`]). A strict failure whose rounding check passes is a
//! rounding artefact of the source; a rounding failure is a real
//! inconsistency. Both kinds are listed in [`EXPECTED_FAILURES`] with the
//! `fixtures/reference/NOTES.md` item that documents them.

use std::f64::consts::PI;

use super::rounding::{Iv, cell, consistent, recompute};
use crate::fixtures::{Table, reference, reference_files};
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "fixtures/reference-index",
            description: "every reference CSV parses and has the row count its README documents",
            fast: true,
            heavy: false,
            run: reference_index,
        },
        Case {
            name: "fixtures/gsc2018-table4-average",
            description: "GSC 2018 Table 4: the Average row is the mean of the four parameters",
            fast: true,
            heavy: false,
            run: || table_average("gsc2018_table4_mean_error_pct.csv"),
        },
        Case {
            name: "fixtures/gsc2018-table5-average",
            description: "GSC 2018 Table 5: the Average row is the mean of the four parameters",
            fast: true,
            heavy: false,
            run: || table_average("gsc2018_table5_std_error_pct.csv"),
        },
        Case {
            name: "fixtures/gsc2018-sec4-prose-errors",
            description: "GSC 2018 Sec. 4 prose errors equal Tables 4/5, trial 4",
            fast: true,
            heavy: false,
            run: gsc_prose_errors,
        },
        Case {
            name: "fixtures/gsc2018-grading-errors",
            description: "GSC 2018 Sec. 4: Cu and Cc errors recomputed from parents/clones",
            fast: true,
            heavy: false,
            run: gsc_grading_errors,
        },
        Case {
            name: "fixtures/gsc2018-table9-errors",
            description: "GSC 2018 Table 9 errors recomputed from Table 8",
            fast: true,
            heavy: false,
            run: gsc_table9,
        },
        Case {
            name: "fixtures/gsc2018-table10-errors",
            description: "GSC 2018 Table 10 error row recomputed from the parents/clones rows",
            fast: true,
            heavy: false,
            run: gsc_table10,
        },
        Case {
            name: "fixtures/gsc2018-stress-tensors",
            description: "GSC 2018 Sec. 5: p = tr(σ)/3, s = σ − p·1, J2 = s:s/2",
            fast: true,
            heavy: false,
            run: gsc_stress,
        },
        Case {
            name: "fixtures/radvilaite2016-table3-1",
            description: "Radvilaitė 2016 Table 3.1 (ellipsoid L = 1): δ_LS, average, δ_S, δ_V, N_k",
            fast: true,
            heavy: false,
            run: radvilaite_table3_1,
        },
        Case {
            name: "fixtures/radvilaite2016-table3-2",
            description: "Radvilaitė 2016 Table 3.2 (cylinder L = 3): δ_LS, average, δ_S, N_k",
            fast: true,
            heavy: false,
            run: radvilaite_table3_2,
        },
        Case {
            name: "fixtures/radvilaite2016-table3-3",
            description: "Radvilaitė 2016 Table 3.3 (cylinder L = 2): δ_LS, threshold average, N_k",
            fast: true,
            heavy: false,
            run: radvilaite_table3_3,
        },
        Case {
            name: "fixtures/radvilaite2016-table3-4",
            description: "Radvilaitė 2016 Table 3.4 (parallelepiped L = 3): δ_e, average, δ_A, δ_V, N_k",
            fast: true,
            heavy: false,
            run: radvilaite_table3_4,
        },
        Case {
            name: "fixtures/radvilaite2016-table3-6",
            description: "Radvilaitė 2016 Table 3.6: ρ_e = √(ρ_n ρ_t), F = 4/3 c_cor √ρ_e u^1.5, ratios",
            fast: true,
            heavy: false,
            run: radvilaite_table3_6,
        },
        Case {
            name: "fixtures/radvilaite2016-analytic-values",
            description: "Radvilaitė 2016 analytic V and S of the reference shapes, threshold grid size",
            fast: true,
            heavy: false,
            run: radvilaite_analytic,
        },
        Case {
            name: "fixtures/pinto2009-profiles",
            description: "Pinto 2009 Tables 3.2/3.3 percentages and the quadtree speed-up",
            fast: true,
            heavy: false,
            run: pinto_profiles,
        },
        Case {
            name: "fixtures/pinto2009-mean-particle-area",
            description: "Pinto 2009: A(1 − φ)/N of every packing table matches the Table 3.4 grading",
            fast: true,
            heavy: false,
            run: pinto_mean_area,
        },
        Case {
            name: "fixtures/pinto2009-pfc2d-domain",
            description: "Pinto 2009 Sec. 3.2.1: PFC2D domain size and particle-count estimate (Eq. 3-1)",
            fast: true,
            heavy: false,
            run: pinto_domain,
        },
    ]
}

const G5: &str = "NOTES G5: the stated Cu/Cc errors do not recompute from the printed coefficients (8.73 % vs 8.29 %, 3.95 % vs 4.28 %); the rounding check passes, so rounding of the coefficients explains them";
const G6: &str = "NOTES G6: Table 9 prints 4.98 % for the height-diameter ratio, 4.74 % recomputes from Table 8; the rounding check passes (2.11/2.01 are rounded)";
const G7: &str = "NOTES G7: Table 10 prints 12.11 % for the friction angle, (35.36 − 31.05)/35.36 = 12.19 %; not explained by rounding (12.16–12.22 %)";
const G8: &str = "NOTES G8: deviatoric components rounded inconsistently (parents s33 = 1.3767 printed 1.37, clones s11 = 0.7533 printed 0.76) and J2 computed from the rounded s; rounding checks pass";
const R1A: &str =
    "NOTES R1a: Table 3.1 q=1 k=4 prints δ_LS 0.1724, recomputed 0.1172 (transposed digits)";
const R1B: &str =
    "NOTES R1b: Table 3.1 q=2 k=1 prints δ_V 0.0027, recomputed 0.0269 (decimal shift)";
const R1C: &str = "NOTES R1c: Table 3.1 prints S = 34.721 (an approximation formula); the exact oblate-spheroid area is 34.688";
const R4B: &str =
    "NOTES R4b: Table 3.4 threshold row prints 0.0000285, but 4.6622/16380 = 0.000285 (factor 10)";
const LAST_DIGIT_31: &str = "found by this check, not in NOTES: last printed digit disagrees with E/16258 (resp. E/3.9519 − 1) beyond the print rounding of E; 4 of the 5 average deviations agree with E/16250 instead";
const T34_AVG: &str = "found by this check, not in NOTES: Table 3.4 average deviations are not E/16380 as documented (NOTES R4a) at the printed 7 decimals; 19 of 20 equal E/16384 (128², the threshold grid without poles) truncated to 7 decimals";

pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
    ExpectedFailure {
        case: "fixtures/gsc2018-grading-errors",
        metric: "Cu error %",
        reason: G5,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-grading-errors",
        metric: "Cc error %",
        reason: G5,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-table9-errors",
        metric: "Height-diameter ratio",
        reason: G6,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-table10-errors",
        metric: "friction_angle",
        reason: G7,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-table10-errors",
        metric: "friction_angle (rounding)",
        reason: G7,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-stress-tensors",
        metric: "parents s_33",
        reason: G8,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-stress-tensors",
        metric: "clones s_11",
        reason: G8,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-stress-tensors",
        metric: "parents J2 from sigma",
        reason: G8,
    },
    ExpectedFailure {
        case: "fixtures/gsc2018-stress-tensors",
        metric: "clones J2 from sigma",
        reason: G8,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q1 k4 delta_LS",
        reason: R1A,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q2 k1 delta_V",
        reason: R1B,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-analytic-values",
        metric: "ellipsoid S (Table 3.1)",
        reason: R1C,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "threshold avg_deviation",
        reason: R4B,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q1 k2 avg_deviation",
        reason: LAST_DIGIT_31,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q1 k3 delta_LS",
        reason: LAST_DIGIT_31,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q2 k3 avg_deviation",
        reason: LAST_DIGIT_31,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q2 k4 avg_deviation",
        reason: LAST_DIGIT_31,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q3 k2 avg_deviation",
        reason: LAST_DIGIT_31,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q3 k4 avg_deviation",
        reason: LAST_DIGIT_31,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-1",
        metric: "q4 k4 delta_LS",
        reason: LAST_DIGIT_31,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q5 k5 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q5 k6 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q5 k3 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q5 k7 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q5 k8 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q6 k5 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q6 k6 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q6 k3 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q6 k7 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q6 k8 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q7 k5 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q7 k6 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q7 k3 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q7 k7 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q7 k8 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q8 k5 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q8 k6 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q8 k3 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q8 k7 avg_deviation",
        reason: T34_AVG,
    },
    ExpectedFailure {
        case: "fixtures/radvilaite2016-table3-4",
        metric: "q8 k8 avg_deviation",
        reason: T34_AVG,
    },
];

/// `fixtures/reference/README.md` rows of the form "| `file.csv` | rows | …".
fn documented_row_counts() -> Result<Vec<(String, usize)>, Error> {
    let readme = reference("README.md")?;
    let mut out = Vec::new();
    for line in readme.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 3 {
            continue;
        }
        let file = cells[1].trim_matches('`');
        if !file.ends_with(".csv") || !cells[1].starts_with('`') {
            continue;
        }
        // "18 (16 models + threshold + analytical)": the leading integer
        let digits: String = cells[2].chars().take_while(char::is_ascii_digit).collect();
        if let Ok(n) = digits.parse::<usize>() {
            out.push((file.to_owned(), n));
        }
    }
    Ok(out)
}

fn reference_index() -> Result<Vec<Check>, Error> {
    let documented = documented_row_counts()?;
    let csvs: Vec<&(&str, &str)> = reference_files()
        .iter()
        .filter(|(n, _)| n.ends_with(".csv"))
        .collect();
    let mut checks = Vec::new();
    let undocumented = csvs
        .iter()
        .filter(|(n, _)| !documented.iter().any(|(d, _)| d == n))
        .count();
    checks.push(Check::new(
        "CSV files not in README",
        0.0,
        undocumented as f64,
        Tolerance::Within(0.0),
    ));
    for (file, rows) in &documented {
        let ours = match csvs.iter().find(|(n, _)| n == file) {
            Some((name, text)) => Table::parse(name, text)?.rows.len() as f64,
            None => f64::NAN, // documented but missing: fails
        };
        checks.push(Check::new(
            format!("{file} rows"),
            *rows as f64,
            ours,
            Tolerance::Within(0.0),
        ));
    }
    Ok(checks)
}

fn table_average(file: &str) -> Result<Vec<Check>, Error> {
    let t = Table::reference(file)?;
    let avg = t.row_where("morphological_parameter", "average_error")?;
    let params: Vec<usize> = (0..t.rows.len()).filter(|&r| r != avg).collect();
    let mut checks = Vec::new();
    for trial in t.columns.iter().filter(|c| c.starts_with("trial_")) {
        let mut sum = Iv::exact(0.0);
        for &r in &params {
            sum = sum.add(cell(&t, r, trial)?);
        }
        let mean = sum.scale(1.0 / params.len() as f64);
        checks.extend(recompute(trial, cell(&t, avg, trial)?, mean));
    }
    Ok(checks)
}

fn gsc_prose_errors() -> Result<Vec<Check>, Error> {
    let prose = Table::reference("gsc2018_sec4_prose_morphology_errors.csv")?;
    let t4 = Table::reference("gsc2018_table4_mean_error_pct.csv")?;
    let t5 = Table::reference("gsc2018_table5_std_error_pct.csv")?;
    let mut checks = Vec::new();
    for r in 0..prose.rows.len() {
        let param = prose.text(r, "morphological_parameter")?;
        let trial = format!("trial_{}", prose.text(r, "same_as_table4_5_trial")?);
        let mean = t4.number(t4.row_where("morphological_parameter", param)?, &trial)?;
        let std = t5.number(t5.row_where("morphological_parameter", param)?, &trial)?;
        checks.push(Check::new(
            format!("{param} mean"),
            mean,
            prose.number(r, "mean_error_pct")?,
            Tolerance::Within(0.0),
        ));
        checks.push(Check::new(
            format!("{param} std"),
            std,
            prose.number(r, "std_error_pct")?,
            Tolerance::Within(0.0),
        ));
    }
    Ok(checks)
}

/// Relative error in percent of `b` against `a`.
fn rel_err_pct(a: Iv, b: Iv) -> Iv {
    b.sub(a).abs().div(a.abs()).scale(100.0)
}

fn gsc_grading_errors() -> Result<Vec<Check>, Error> {
    let t = Table::reference("gsc2018_sec4_grading_coefficients.csv")?;
    let mut checks = Vec::new();
    for r in 0..t.rows.len() {
        let name = t.text(r, "coefficient")?;
        let e = rel_err_pct(cell(&t, r, "parents")?, cell(&t, r, "clones")?);
        checks.extend(recompute(
            &format!("{name} error %"),
            cell(&t, r, "error_pct_as_stated")?,
            e,
        ));
    }
    Ok(checks)
}

fn gsc_table9() -> Result<Vec<Check>, Error> {
    let t8 = Table::reference("gsc2018_table8_triaxial_initial_conditions.csv")?;
    let t9 = Table::reference("gsc2018_table9_initial_condition_errors.csv")?;
    let mut checks = Vec::new();
    for r in 0..t9.rows.len() {
        let name = t9.text(r, "initial_condition")?;
        let r8 = t8.row_where("initial_condition", name)?;
        let e = rel_err_pct(cell(&t8, r8, "parents")?, cell(&t8, r8, "clones")?);
        checks.extend(recompute(name, cell(&t9, r, "error_pct")?, e));
    }
    Ok(checks)
}

fn gsc_table10() -> Result<Vec<Check>, Error> {
    let t = Table::reference("gsc2018_table10_triaxial_results.csv")?;
    let (p, c, e) = (
        t.row_where("row", "parents")?,
        t.row_where("row", "clones")?,
        t.row_where("row", "error")?,
    );
    let mut checks = Vec::new();
    for col in ["friction_angle", "strain", "sigma1"] {
        let err = rel_err_pct(cell(&t, p, col)?, cell(&t, c, col)?);
        checks.extend(recompute(col, cell(&t, e, col)?, err));
    }
    Ok(checks)
}

fn gsc_stress() -> Result<Vec<Check>, Error> {
    let t = Table::reference("gsc2018_sec5_stress_tensors.csv")?;
    let mut checks = Vec::new();
    for r in 0..t.rows.len() {
        let sample = t.text(r, "sample")?.to_owned();
        let s = [
            cell(&t, r, "sigma_11")?,
            cell(&t, r, "sigma_22")?,
            cell(&t, r, "sigma_33")?,
        ];
        // p = tr/3 and s_ii = σ_ii − p written as linear forms of σ so the
        // interval is tight: s_11 = (2σ11 − σ22 − σ33)/3.
        let p = s[0].add(s[1]).add(s[2]).scale(1.0 / 3.0);
        checks.extend(recompute(
            &format!("{sample} p"),
            cell(&t, r, "p_mean_normal_stress")?,
            p,
        ));
        let mut dev = Vec::new();
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let d = s[i].scale(2.0).sub(s[j]).sub(s[k]).scale(1.0 / 3.0);
            dev.push(d);
            let col = format!("s_{0}{0}", i + 1);
            checks.extend(recompute(&format!("{sample} {col}"), cell(&t, r, &col)?, d));
        }
        let j2_sigma = dev[0]
            .square()
            .add(dev[1].square())
            .add(dev[2].square())
            .scale(0.5);
        checks.extend(recompute(
            &format!("{sample} J2 from sigma"),
            cell(&t, r, "J2")?,
            j2_sigma,
        ));
        let printed_s = [
            cell(&t, r, "s_11")?,
            cell(&t, r, "s_22")?,
            cell(&t, r, "s_33")?,
        ];
        let j2_s = printed_s[0]
            .square()
            .add(printed_s[1].square())
            .add(printed_s[2].square())
            .scale(0.5);
        checks.extend(recompute(
            &format!("{sample} J2 from printed s"),
            cell(&t, r, "J2")?,
            j2_s,
        ));
    }
    Ok(checks)
}

/// `N_k = (n_φ + 1)·n_θ + 1` (NOTES R9e).
fn node_count_check(t: &Table, r: usize, label: &str) -> Result<Check, Error> {
    let nt = t.number(r, "grid_n_theta")?;
    let np = t.number(r, "grid_n_phi")?;
    Ok(Check::new(
        format!("{label} N_k"),
        t.number(r, "N_k_points")?,
        (np + 1.0) * nt + 1.0,
        Tolerance::Within(0.0),
    ))
}

fn model_rows(t: &Table) -> Result<Vec<(usize, String)>, Error> {
    let mut out = Vec::new();
    for r in t.rows_where("row_type", "model")? {
        out.push((
            r,
            format!(
                "q{} k{}",
                t.text(r, "q_strategy")?,
                t.text(r, "k_reference_model")?
            ),
        ));
    }
    Ok(out)
}

fn threshold_row(t: &Table) -> Result<usize, Error> {
    t.row_where("row_type", "threshold")
}

/// `δ = |x − x_ref| / x_ref` of the printed `value` column, against the
/// printed `delta` column.
fn relative_deviation(
    t: &Table,
    r: usize,
    label: &str,
    value: &str,
    delta: &str,
    reference: Iv,
) -> Result<Check, Error> {
    let x = cell(t, r, value)?;
    Ok(consistent(
        &format!("{label} {delta}"),
        cell(t, r, delta)?,
        x.sub(reference).abs().div(reference),
    ))
}

/// `δ_LS = |E / E_thr − 1|` under the metric `delta_LS` and, with
/// `n_thr`, the average deviation `E / N_thr` under `avg_deviation`.
fn least_squares_checks(
    t: &Table,
    r: usize,
    label: &str,
    thr: Iv,
    n_thr: Option<Iv>,
) -> Result<Vec<Check>, Error> {
    let e = cell(t, r, "LS_error_norm")?;
    let mut checks = vec![consistent(
        &format!("{label} delta_LS"),
        cell(t, r, "delta_LS")?,
        e.div(thr).sub(Iv::exact(1.0)).abs(),
    )];
    if let Some(n) = n_thr {
        checks.push(consistent(
            &format!("{label} avg_deviation"),
            cell(t, r, "avg_deviation")?,
            e.div(n),
        ));
    }
    Ok(checks)
}

fn radvilaite_table3_1() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_1_ellipsoid_L1.csv")?;
    let thr = cell(&t, threshold_row(&t)?, "LS_error_norm")?;
    let an = t.row_where("row_type", "analytical")?;
    let (s_ref, v_ref) = (cell(&t, an, "S_surface_area")?, cell(&t, an, "V_volume")?);
    // the threshold model uses (N_θ − 1)·N_φ + 2 = 16258 points (Sec. 3.1.2)
    let n_thr = Iv::exact(16258.0);
    let mut checks = Vec::new();
    for (r, label) in model_rows(&t)? {
        checks.extend(least_squares_checks(&t, r, &label, thr, Some(n_thr))?);
        checks.push(relative_deviation(
            &t,
            r,
            &label,
            "S_surface_area",
            "delta_S",
            s_ref,
        )?);
        checks.push(relative_deviation(
            &t, r, &label, "V_volume", "delta_V", v_ref,
        )?);
        checks.push(node_count_check(&t, r, &label)?);
    }
    Ok(checks)
}

fn radvilaite_table3_2() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_2_cylinder_L3.csv")?;
    let tr = threshold_row(&t)?;
    let thr = cell(&t, tr, "LS_error_norm")?;
    let n_thr = Iv::exact(t.number(tr, "N_k_points")?);
    let s_ref = cell(&t, t.row_where("row_type", "analytical")?, "S_surface_area")?;
    let mut checks = Vec::new();
    for (r, label) in model_rows(&t)? {
        checks.extend(least_squares_checks(&t, r, &label, thr, Some(n_thr))?);
        checks.push(relative_deviation(
            &t,
            r,
            &label,
            "S_surface_area",
            "delta_S",
            s_ref,
        )?);
        checks.push(node_count_check(&t, r, &label)?);
    }
    Ok(checks)
}

fn radvilaite_table3_3() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_3_cylinder_L2.csv")?;
    let tr = threshold_row(&t)?;
    let thr = cell(&t, tr, "LS_error_norm")?;
    let n_thr = Iv::exact(t.number(tr, "N_k_points")?);
    let mut checks = Vec::new();
    checks.push(consistent(
        "threshold avg_error",
        cell(&t, tr, "avg_error")?,
        thr.div(n_thr),
    ));
    for (r, label) in model_rows(&t)? {
        checks.extend(least_squares_checks(&t, r, &label, thr, None)?);
        checks.push(node_count_check(&t, r, &label)?);
    }
    Ok(checks)
}

fn radvilaite_table3_4() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_4_parallelepiped_L3.csv")?;
    let tr = threshold_row(&t)?;
    let thr = cell(&t, tr, "LS_error_norm")?;
    let n_thr = Iv::exact(t.number(tr, "N_k_points")?);
    let an = t.row_where("row_type", "analytical")?;
    let (a_ref, v_ref) = (cell(&t, an, "A_surface_area")?, cell(&t, an, "V_volume")?);
    let mut checks = Vec::new();
    checks.push(consistent(
        "threshold avg_deviation",
        cell(&t, tr, "avg_deviation")?,
        thr.div(n_thr),
    ));
    for (r, label) in model_rows(&t)? {
        checks.extend(least_squares_checks(&t, r, &label, thr, Some(n_thr))?);
        checks.push(relative_deviation(
            &t,
            r,
            &label,
            "A_surface_area",
            "delta_A",
            a_ref,
        )?);
        checks.push(relative_deviation(
            &t, r, &label, "V_volume", "delta_V", v_ref,
        )?);
        checks.push(node_count_check(&t, r, &label)?);
    }
    Ok(checks)
}

fn radvilaite_table3_6() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_6_contact_analysis.csv")?;
    // u_rel = 0.01 (Sec. 3.4), so u^1.5 = 1e-3 exactly.
    let u15 = 0.01f64.powf(1.5);
    let norm_row = t.row_where("model_identification", "NORM_MOD_ANL")?;
    let f_max = cell(&t, norm_row, "F_rel_nondim")?;
    let mut checks = Vec::new();
    for r in t.rows_where("solution_type", "analytical")? {
        let id = t.text(r, "model_identification")?.to_owned();
        let rho_e = cell(&t, r, "rho_n_rel")?
            .mul(cell(&t, r, "rho_t_rel")?)
            .sqrt();
        checks.push(consistent(
            &format!("{id} rho_e"),
            cell(&t, r, "rho_e_rel")?,
            rho_e,
        ));
        let f = cell(&t, r, "c_cor")?
            .mul(cell(&t, r, "rho_e_rel")?.sqrt())
            .scale(4.0 / 3.0 * u15);
        checks.push(consistent(
            &format!("{id} F"),
            cell(&t, r, "F_rel_nondim")?,
            f,
        ));
    }
    for r in 0..t.rows.len() {
        let id = t.text(r, "model_identification")?.to_owned();
        let ratio = cell(&t, r, "F_rel_nondim")?.div(f_max);
        checks.push(consistent(
            &format!("{id} F/F_max"),
            cell(&t, r, "F_rel_over_F_rel_max")?,
            ratio,
        ));
    }
    Ok(checks)
}

fn radvilaite_analytic() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_analytic_reference_values.csv")?;
    let value = |shape: &str, quantity: &str| -> Result<Iv, Error> {
        let rows = t.rows_where("shape", shape)?;
        let r = rows
            .into_iter()
            .find(|&r| t.text(r, "quantity").is_ok_and(|q| q == quantity))
            .ok_or_else(|| Error::MissingRow {
                table: t.name.clone(),
                column: "quantity".into(),
                value: format!("{shape}/{quantity}"),
            })?;
        cell(&t, r, "value")
    };
    let mut checks = Vec::new();
    // oblate spheroid a = b = 2, c = 1
    let (a, c) = (
        value("ellipsoid", "a_semi_axis")?.mid(),
        value("ellipsoid", "c_semi_axis")?.mid(),
    );
    let e = (1.0 - c * c / (a * a)).sqrt();
    let s_exact = 2.0 * PI * a * a + PI * c * c / e * ((1.0 + e) / (1.0 - e)).ln();
    checks.push(consistent(
        "ellipsoid V",
        value("ellipsoid", "V_analytical")?,
        Iv::exact(4.0 / 3.0 * PI * a * a * c),
    ));
    checks.push(Check::new(
        "ellipsoid S (Table 3.1)",
        value("ellipsoid", "S_analytical")?.mid(),
        s_exact,
        Tolerance::Within(value("ellipsoid", "S_analytical")?.half_width()),
    ));
    let (ra, rc) = (
        value("cylinder", "a_radius")?.mid(),
        value("cylinder", "c_half_height")?.mid(),
    );
    checks.push(consistent(
        "cylinder V",
        value("cylinder", "V_analytical")?,
        Iv::exact(PI * ra * ra * 2.0 * rc),
    ));
    checks.push(consistent(
        "cylinder S",
        value("cylinder", "S_analytical")?,
        Iv::exact(2.0 * PI * ra * ra + 2.0 * PI * ra * 2.0 * rc),
    ));
    checks.push(consistent(
        "cylinder edge angle / pi",
        value("cylinder", "edge_angle_theta_over_pi")?,
        Iv::exact((ra / rc).atan() / PI),
    ));
    checks.push(consistent(
        "cylinder max radius",
        value("cylinder", "max_radius_at_edge")?,
        Iv::exact(ra.hypot(rc)),
    ));
    // 4 × 4 × 2 box (NOTES R4d: the only reading consistent with V = 32, S = 64)
    checks.push(consistent(
        "parallelepiped V (4x4x2)",
        value("parallelepiped", "V_analytical")?,
        Iv::exact(32.0),
    ));
    checks.push(consistent(
        "parallelepiped S (4x4x2)",
        value("parallelepiped", "S_analytical")?,
        Iv::exact(2.0 * (16.0 + 8.0 + 8.0)),
    ));
    let (nt, np) = (
        value("ellipsoid", "threshold_N_theta")?.mid(),
        value("ellipsoid", "threshold_N_phi")?.mid(),
    );
    checks.push(Check::new(
        "threshold N = (N_theta - 1) N_phi + 2",
        value("ellipsoid", "threshold_N_points")?.mid(),
        (nt - 1.0) * np + 2.0,
        Tolerance::Within(0.0),
    ));
    Ok(checks)
}

fn pinto_profiles() -> Result<Vec<Check>, Error> {
    let mut checks = Vec::new();
    let mut totals = Vec::new();
    for file in [
        "pinto2009_table3_2_profile_initial.csv",
        "pinto2009_table3_3_profile_mx_quadtree.csv",
    ] {
        let t = Table::reference(file)?;
        let total_row = t.row_where("rank", "0")?;
        let total = cell(&t, total_row, "time_ms")?;
        totals.push(total);
        let tag = if file.contains("3_2") { "3.2" } else { "3.3" };
        for r in 0..t.rows.len() {
            let rank = t.text(r, "rank")?.to_owned();
            let pct = cell(&t, r, "time_ms")?.div(total).scale(100.0);
            checks.push(consistent(
                &format!("table {tag} rank {rank} %"),
                cell(&t, r, "time_pct_of_total")?,
                pct,
            ));
        }
    }
    let facts = Table::reference("pinto2009_prose_facts.csv")?;
    let r = facts.row_where("quantity", "time_reduction_with_mx_quadtree")?;
    let reduction = Iv::exact(1.0).sub(totals[1].div(totals[0])).scale(100.0);
    checks.push(consistent(
        "quadtree time reduction %",
        cell(&facts, r, "value")?,
        reduction,
    ));
    let t = Table::reference("pinto2009_table3_2_profile_initial.csv")?;
    let share = cell(&t, 1, "time_pct_of_total")?.add(cell(&t, 2, "time_pct_of_total")?);
    let r = facts.row_where("quantity", "share_of_two_costliest_methods_initial")?;
    checks.push(consistent(
        "two costliest methods share %",
        cell(&facts, r, "value")?,
        share,
    ));
    Ok(checks)
}

/// Mean disk area π/4·E[d²] of the Table 3.4 grading, with the diameter
/// uniform inside each sieve interval (the intervals are 1 % wide, so the
/// seed's semi-log interpolation changes this by < 0.01 %).
fn grading_mean_area() -> Result<f64, Error> {
    let t = Table::reference("pinto2009_table3_4_grading.csv")?;
    let mut e_d2 = 0.0;
    for r in 1..t.rows.len() {
        let (a, b) = (t.number(r - 1, "diameter_mm")?, t.number(r, "diameter_mm")?);
        let p = (t.number(r, "cumulative_passing_pct")?
            - t.number(r - 1, "cumulative_passing_pct")?)
            / 100.0;
        e_d2 += p * (a * a + a * b + b * b) / 3.0;
    }
    Ok(PI / 4.0 * e_d2)
}

fn pinto_mean_area() -> Result<Vec<Check>, Error> {
    let expected = grading_mean_area()?;
    // The implied mean area A(1 − φ)/N is the sample mean of N disk areas:
    // with areas spread ±4 % around the mean (d from 1.200 to 1.295 mm), the
    // smallest packing (N ≈ 54) has a 1σ sampling error of ≈ 0.3 %, so 1 %
    // is ≈ 3σ there and far more for the large packings.
    let tol = Tolerance::Relative(0.01);
    let mut checks = Vec::new();
    for file in [
        "pinto2009_table3_5_proposed_algorithm.csv",
        "pinto2009_table3_6_proposed_recompiled.csv",
    ] {
        let t = Table::reference(file)?;
        let tag = if file.contains("3_5") { "3.5" } else { "3.6" };
        for r in 0..t.rows.len() {
            let area = 8.6 * 62.5;
            let implied =
                area * (1.0 - t.number(r, "porosity")?) / t.number(r, "particles_generated")?;
            checks.push(Check::new(
                format!("table {tag} run {}", t.text(r, "run")?),
                expected,
                implied,
                tol,
            ));
        }
    }
    let t = Table::reference("pinto2009_table3_13_square_domains.csv")?;
    for r in 0..t.rows.len() {
        let area = t.number(r, "width_mm")? * t.number(r, "height_mm")?;
        let implied =
            area * (1.0 - t.number(r, "porosity")?) / t.number(r, "particles_generated")?;
        let label = format!(
            "table 3.13 {}x{} run {}",
            t.text(r, "width_mm")?,
            t.text(r, "height_mm")?,
            t.text(r, "run")?
        );
        checks.push(Check::new(label, expected, implied, tol));
    }
    let t = Table::reference("pinto2009_table3_14_large_domains.csv")?;
    for r in 0..t.rows.len() {
        // header "(mm × m)": width in mm, length in m (NOTES T1)
        let area = t.number(r, "width_mm")? * t.number(r, "length_m")? * 1000.0;
        let implied =
            area * (1.0 - t.number(r, "porosity")?) / t.number(r, "particles_generated")?;
        let label = format!(
            "table 3.14 {} mm x {} m run {}",
            t.text(r, "width_mm")?,
            t.text(r, "length_m")?,
            t.text(r, "run")?
        );
        checks.push(Check::new(label, expected, implied, tol));
    }
    let wells = Table::reference("pinto2009_table3_15_petrobras_fractures.csv")?;
    let t = Table::reference("pinto2009_table3_16_petrobras_wells_results.csv")?;
    for r in 0..t.rows.len() {
        let well = t.text(r, "well")?;
        let w = wells.row_where("well", well)?;
        let area =
            wells.number(w, "fracture_width_mm")? * wells.number(w, "fracture_height_m")? * 1000.0;
        let implied =
            area * (1.0 - t.number(r, "porosity")?) / t.number(r, "particles_generated")?;
        checks.push(Check::new(
            format!("table 3.16 {well} run {}", t.text(r, "run")?),
            expected,
            implied,
            tol,
        ));
    }
    Ok(checks)
}

fn pinto_domain() -> Result<Vec<Check>, Error> {
    let f = Table::reference("pinto2009_prose_facts.csv")?;
    let v = |q: &str| -> Result<Iv, Error> { cell(&f, f.row_where("quantity", q)?, "value") };
    let mut checks = Vec::new();
    let (wr, dp, lr) = (
        v("normalized_width_W_r")?,
        v("mean_diameter_d_p")?,
        v("normalized_length_L_r")?,
    );
    let w = wr.add(Iv::exact(2.0)).mul(dp);
    let l = lr.mul(dp);
    checks.push(consistent("W = (W_r + 2) d_p", v("domain_width_W")?, w));
    checks.push(consistent("L = L_r d_p", v("domain_length_L")?, l));
    checks.push(consistent(
        "A_d = W L",
        v("A_d")?,
        v("domain_width_W")?.mul(v("domain_length_L")?),
    ));
    let dmed = v("d_med")?;
    checks.push(consistent(
        "A_p,med = pi d_med^2 / 4",
        v("A_p_med")?,
        dmed.square().scale(PI / 4.0),
    ));
    checks.push(consistent(
        "n_aprox = A_d / A_p,med (Eq. 3-1)",
        v("n_aprox")?,
        v("A_d")?.div(v("A_p_med")?),
    ));
    Ok(checks)
}
