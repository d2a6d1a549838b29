//! Specimens of cloned grains (issue "Specimens of cloned grains").
//!
//! `specimen/clumps`: multi-sphere clumps of calibrated Ottawa clones
//! for DEM codes without level sets ([`levelset::clump`](fn@levelset::clump): the
//! distance-transform placement of the CLUMP toolbox on the level set, then
//! one radius offset that matches the level set's volume). Over 500 clones
//! of the calibrated configuration (`fixtures/calibrated/gsc2-ottawa.ron`),
//! with 10, 20 and 50 spheres per clump: mean |volume error| and mean
//! |mean-principal-moment error| of the sphere union against the clone's
//! level set (the issue: volume error ≤ 3 % at 50 spheres), and the mean
//! surface deviation in equivalent diameters.
//!
//! `specimen/cylinder-10k`: 10 000 clones packed in a triaxial cylinder
//! (H = 2 D) at a solid fraction of 0.50 by `packer_quadtree::pack_grains`
//! and checked by `check_grain_overlaps` (1000 nodes per grain on the zero
//! of its 32³ level set, sampled in every neighbour's; the 16 closest
//! pairs rasterised 4× finer); the packed grading (Cu, Cc) against the
//! requested one and the fabric of the major axes.
//!
//! Public helpers ([`ottawa_star_grains`], [`pack_specimen`], [`mass_cu_cc`]) let the
//! `specimen_cylinder` example time the stages (this crate has no clock).

use cloner::{Calibrated, CloneModel, Hooks};
use levelset::clump::{ClumpParams, clump, clump_quality};
use levelset::nalgebra::Vector3;
use packer_quadtree::{
    CheckParams, Container, GrainPackParams, StarGrain, check_grain_overlaps, container_for,
    orientation_fabric, pack_grains,
};
use rayon::prelude::*;

use crate::fixtures;
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "specimen/clumps",
            description: "multi-sphere clumps of 500 calibrated Ottawa clones, 10/20/50 spheres: mean volume error ≤ 3 % at 50, moment error and surface deviation reported",
            fast: false,
            run: clumps,
        },
        Case {
            name: "specimen/cylinder-10k",
            description: "10 000 calibrated Ottawa clones packed without overlap in a cylinder H = 2D: solid fraction ≥ 0.50 (aim 0.56), LS-DEM node check φ/d ≥ −1e-6 on 32³ level sets with 1000 nodes per grain, 4×-finer raster cross-check, Cu/Cc within 5 %, fabric of the major axes",
            fast: false,
            run: cylinder_10k,
        },
    ]
}

/// Known failures with their reasons (none: the solid fraction, the node
/// check and the raster cross-check of `specimen/cylinder-10k` pass).
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

/// Cube-map cells per face of the packed grains' star tables (1734 radii).
pub const SPECIMEN_FACE_CELLS: usize = 16;

/// Solid fractions tried in turn by [`pack_specimen`], densest first (the
/// issue asks ≥ 0.50, which converges in ~730 sweeps on 10 000 clones; the
/// lower ones only turn a failure into a measured fraction below the
/// check's bound).
pub const SPECIMEN_FRACTIONS: [f64; 3] = [0.56, 0.53, 0.50];

/// Sweeps allowed per fraction.
pub const SPECIMEN_SWEEPS: usize = 3000;

/// `count` calibrated Ottawa clones (indices `0..count`) as packer grains:
/// each clone's radii → `CloneModel::star_table(&radii, 16)` →
/// `StarGrain::from_table(16, &table)`.
///
/// # Errors
/// Fixture, fitting, cloning and table errors.
pub fn ottawa_star_grains(count: u64) -> Result<Vec<StarGrain>, Error> {
    let err = Error::computation;
    let parents = crate::grains::ottawa_parents()?;
    let mut cal = Calibrated::from_ron(fixtures::calibrated("gsc2-ottawa.ron")?).map_err(err)?;
    cal.params.outputs.level_set = false;
    cal.params.outputs.dna = false;
    let model = CloneModel::fit(&parents, &cal.params).map_err(err)?;
    let run = model.run(0..count, Hooks::default()).map_err(err)?;
    run.clones
        .par_iter()
        .map(|c| {
            let table = model
                .star_table(&c.radii, SPECIMEN_FACE_CELLS)
                .map_err(err)?;
            StarGrain::from_table(SPECIMEN_FACE_CELLS, &table).map_err(Error::computation)
        })
        .collect()
}

/// Packs `grains` in a cylinder `H = 2D` (or `shape` scaled) sized for the
/// densest of [`SPECIMEN_FRACTIONS`] that converges; returns the container
/// and the packing.
///
/// # Errors
/// Packing errors of the last fraction tried.
pub fn pack_specimen(
    grains: &[StarGrain],
    shape: &Container,
) -> Result<(Container, packer_quadtree::GrainPacking), Error> {
    let mut last = None;
    for f in SPECIMEN_FRACTIONS {
        let c = container_for(shape, grains, f).map_err(Error::computation)?;
        let params = GrainPackParams {
            max_sweeps: SPECIMEN_SWEEPS,
            ..GrainPackParams::default()
        };
        match pack_grains(grains, &c, &params) {
            Ok(p) => return Ok((c, p)),
            Err(e) => last = Some(e),
        }
    }
    Err(Error::computation(last.map_or_else(
        || "no fraction tried".to_string(),
        |e| e.to_string(),
    )))
}

/// Mass-based `(Cu, Cc)` of volume-equivalent diameters.
pub fn mass_cu_cc(d: &[f64]) -> (f64, f64) {
    let mut v: Vec<f64> = d.to_vec();
    v.sort_by(f64::total_cmp);
    let total: f64 = v.iter().map(|x| x.powi(3)).sum();
    let at = |frac: f64| {
        let mut acc = 0.0;
        for x in &v {
            acc += x.powi(3);
            if acc >= frac * total {
                return *x;
            }
        }
        v.last().copied().unwrap_or(f64::NAN)
    };
    let (d10, d30, d60) = (at(0.1), at(0.3), at(0.6));
    (d60 / d10, d30 * d30 / (d10 * d60))
}

fn cylinder_10k() -> Result<Vec<Check>, Error> {
    let err = Error::computation;
    let grains = ottawa_star_grains(10_000)?;
    let (container, packing) = pack_specimen(&grains, &Container::triaxial(1.0))?;
    let report = check_grain_overlaps(&grains, &packing.poses, &container, &CheckParams::default())
        .map_err(err)?;
    let fabric = orientation_fabric(&packing.poses, &Vector3::x()).map_err(err)?;
    // Every grain given is packed and inside (the check's wall test): the
    // packed grading is the requested one.
    let d: Vec<f64> = grains.iter().map(StarGrain::equivalent_diameter).collect();
    let (cu, cc) = mass_cu_cc(&d);
    let inside: Vec<f64> = d
        .iter()
        .zip(&packing.poses)
        .filter(|(_, p)| container.clearance(&p.translation.vector.into()) > 0.0)
        .map(|(x, _)| *x)
        .collect();
    let (cu_p, cc_p) = mass_cu_cc(&inside);
    Ok(vec![
        Check::new(
            "solid fraction (aim 0.56)",
            0.50,
            packing.stats.solid_fraction,
            Tolerance::AtLeast(0.0),
        ),
        Check::new(
            "grains packed",
            grains.len() as f64,
            packing.poses.len() as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "worst node phi / d (1000 nodes, 32^3)",
            -1e-6,
            report.worst_phi_over_d,
            Tolerance::AtLeast(0.0),
        ),
        Check::new(
            "overlapping nodes",
            0.0,
            report.overlapping_nodes as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "nodes outside the container",
            0.0,
            report.nodes_outside as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "raster overlap voxels (4x finer)",
            0.0,
            report.raster_overlap_voxels as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "raster pairs checked",
            16.0,
            report.raster_pairs as f64,
            Tolerance::AtLeast(0.0),
        ),
        Check::new("Cu relative deviation", cu, cu_p, Tolerance::Relative(0.05)),
        Check::new("Cc relative deviation", cc, cc_p, Tolerance::Relative(0.05)),
        Check::new(
            "fabric deviatoric norm (major axes)",
            0.1,
            fabric.deviatoric_norm,
            Tolerance::AtMost(0.0),
        ),
    ])
}
