//! Specimens of cloned grains (issue "Specimens of cloned grains"), the
//! part that stands today: multi-sphere clumps of calibrated Ottawa clones
//! for DEM codes without level sets ([`levelset::clump`]: the
//! distance-transform placement of the CLUMP toolbox on the level set, then
//! one radius offset that matches the level set's volume). Over 500 clones
//! of the calibrated configuration (`fixtures/calibrated/gsc2-ottawa.ron`),
//! with 10, 20 and 50 spheres per clump: mean |volume error| and mean
//! |mean-principal-moment error| of the sphere union against the clone's
//! level set (the issue: volume error ≤ 3 % at 50 spheres), and the mean
//! surface deviation in equivalent diameters.

use cloner::{Calibrated, CloneModel, Hooks};
use levelset::clump::{ClumpParams, clump, clump_quality};
use rayon::prelude::*;

use crate::fixtures;
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![Case {
        name: "specimen/clumps",
        description: "multi-sphere clumps of 500 calibrated Ottawa clones, 10/20/50 spheres: mean volume error ≤ 3 % at 50, moment error and surface deviation reported",
        fast: false,
        run: clumps,
    }]
}

/// Known failures with their reasons.
pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[];

fn clumps() -> Result<Vec<Check>, Error> {
    let err = Error::computation;
    let parents = crate::grains::ottawa_parents()?;
    let mut cal = Calibrated::from_ron(fixtures::calibrated("gsc2-ottawa.ron")?).map_err(err)?;
    cal.params.outputs.level_set = true;
    let model = CloneModel::fit(&parents, &cal.params).map_err(err)?;
    let run = model.run(0..500, Hooks::default()).map_err(err)?;
    let grids: Vec<&levelset::Grid> = run.clones.iter().filter_map(|c| c.grid.as_ref()).collect();
    if grids.len() != run.clones.len() {
        return Err(Error::computation("a clone came without its level set"));
    }
    let mut out = Vec::new();
    for n in [10usize, 20, 50] {
        let params = ClumpParams {
            n_spheres: n,
            ..ClumpParams::default()
        };
        let q: Vec<(f64, f64, f64)> = grids
            .par_iter()
            .map(|g| {
                let c = clump(g, &params).map_err(Error::computation)?;
                let q = clump_quality(g, &c).map_err(Error::computation)?;
                Ok((
                    q.volume_error.abs(),
                    q.mean_moment_error.abs(),
                    q.surface_mean,
                ))
            })
            .collect::<Result<_, Error>>()?;
        let k = q.len() as f64;
        let vol = 100.0 * q.iter().map(|x| x.0).sum::<f64>() / k;
        let mom = 100.0 * q.iter().map(|x| x.1).sum::<f64>() / k;
        let dev = q.iter().map(|x| x.2).sum::<f64>() / k;
        out.push(Check::new(
            format!("{n} spheres: mean |volume error| %"),
            3.0,
            vol,
            Tolerance::AtMost(0.0),
        ));
        out.push(Check::new(
            format!("{n} spheres: mean |mean-moment error| %"),
            5.0,
            mom,
            Tolerance::AtMost(0.0),
        ));
        out.push(Check::new(
            format!("{n} spheres: mean surface deviation / d_eq"),
            0.05,
            dev,
            Tolerance::AtMost(0.0),
        ));
    }
    Ok(out)
}
