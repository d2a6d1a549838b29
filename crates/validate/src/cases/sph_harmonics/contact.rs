//! Radvilaitė 2016 Table 3.6: Hertz contact with curvature correction, the
//! analytic rows and the curvature radii of a degree-60 spheroid.

use std::f64::consts::PI;

use sph_harmonics::contact::hertz;
use sph_harmonics::curvature::CurvatureEvaluator;
use sph_harmonics::fit::quadrature_transform;
use sph_harmonics::grid::RingGrid;
use sph_harmonics::shapes::Shape;

use super::err;
use crate::fixtures::Table;
use crate::{Case, Check, Error, Tolerance};

/// The group's cases, in registration order.
pub(super) fn cases() -> Vec<Case> {
    vec![Case {
        name: "sph-harmonics/table3.6-contact",
        description: "Hertz contact with curvature correction, analytic rows: c_cor, ρ_e (±0.5e-4), F̄ (±0.5 in the printed 4th digit); rows 1 and 3 radii from our own curvature of a degree-60 spheroid",
        fast: true,
        heavy: false,
        run: table_3_6,
    }]
}

fn table_3_6() -> Result<Vec<Check>, Error> {
    let t = Table::reference("radvilaite2016_table3_6_contact_analysis.csv")?;
    let mut checks = Vec::new();
    // Our own curvature radii of the oblate spheroid a = 2, c = 1 (R = b = 2), degree 60.
    let shape = Shape::Ellipsoid {
        a: 2.0,
        b: 2.0,
        c: 1.0,
    };
    let grid = RingGrid::gauss_legendre(60).map_err(err)?;
    let values: Vec<f64> = grid
        .points()
        .iter()
        .map(|&(th, p)| shape.radius(th, p))
        .collect();
    let model = quadrature_transform(&grid, &values, 60).map_err(err)?;
    let ev = CurvatureEvaluator::new(&model).map_err(err)?;
    let equator = ev.at(PI / 2.0, 0.0).map_err(err)?.principal_radii();
    let pole = ev.at(0.0, 0.0).map_err(err)?.principal_radii();
    let ours_radii = [
        ("1", equator[0] / 2.0, equator[1] / 2.0),
        ("3", pole[0] / 2.0, pole[1] / 2.0),
    ];
    for (no, rn, rt) in ours_radii {
        let row = t.row_where("no", no)?;
        checks.push(Check::new(
            format!("row{no}/rho_n_from_sh_curvature"),
            t.number(row, "rho_n_rel")?,
            rn,
            Tolerance::Within(0.5e-3),
        ));
        checks.push(Check::new(
            format!("row{no}/rho_t_from_sh_curvature"),
            t.number(row, "rho_t_rel")?,
            rt,
            Tolerance::Within(0.5e-3),
        ));
    }
    for row in t.rows_where("solution_type", "analytical")? {
        let no = t.text(row, "no")?.to_owned();
        let rn = t.number(row, "rho_n_rel")?;
        let rt = t.number(row, "rho_t_rel")?;
        let h = hertz([rn, rt], [f64::INFINITY; 2], 0.0).map_err(err)?;
        checks.push(Check::new(
            format!("row{no}/c_cor"),
            t.number(row, "c_cor")?,
            h.c_cor,
            Tolerance::Within(0.5e-4),
        ));
        checks.push(Check::new(
            format!("row{no}/rho_e"),
            t.number(row, "rho_e_rel")?,
            h.rho_eff,
            Tolerance::Within(0.5e-4),
        ));
        let f = t.number(row, "F_rel_nondim")?;
        checks.push(Check::new(
            format!("row{no}/F_rel"),
            f,
            h.force(1.0, 0.01),
            Tolerance::Relative(6e-4),
        ));
    }
    Ok(checks)
}
