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
//! (H = 2 D) at a solid fraction of 0.50 by `packer_grains::pack_grains`
//! and checked by `check_grain_overlaps` (1000 nodes per grain on the zero
//! of its 32³ level set, sampled in every neighbour's; the 16 closest
//! pairs rasterised 4× finer); the packed grading (Cu, Cc) against the
//! requested one and the fabric of the major axes.
//!
//! `specimen/dense-0.60` (issue 28): 10 000 clones at solid fraction 0.60 by
//! `pack_grains` with its default compaction stage: zero overlaps by the
//! same check, Cu/Cc within 5 %, fabric ≤ 0.02. `specimen/homogeneity`
//! samples that specimen on a regular grid (spacing d50/6, with
//! `packer_grains::occupied`) in 5 height slices and 3 equal-volume
//! radial shells one d50 off the walls: fractions within ±0.01 of the
//! core's, mass d50 within 3 % of the specimen's (the core against the
//! target 0.60 is an expected failure: the wall zone is looser, so the core
//! is denser than the specimen's mean). `specimen/target-fraction`: 2000
//! clones at 0.50, 0.55 and 0.60, each clean, and 0.72 refused by
//! `container_for` and by `pack_grains` with errors naming the limit.
//!
//! Public helpers ([`ottawa_star_grains`], [`pack_specimen`], [`mass_cu_cc`]) let the
//! `specimen_cylinder` example time the stages (this crate has no clock).

use cloner::{Calibrated, CloneModel, Hooks};
use levelset::clump::{ClumpParams, clump, clump_quality};
use levelset::nalgebra::Vector3;
use packer_grains::{
    CheckParams, GrainPackParams, StarGrain, boundary_for, check_grain_overlaps,
    check_grain_overlaps_in, container_for, occupied_in, orientation_fabric, pack_grains,
    pack_grains_in,
};
use packer_spheres::{Boundary, Container};
use rayon::prelude::*;

use crate::fixtures;
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "specimen/clumps",
            description: "multi-sphere clumps of 500 calibrated Ottawa clones, 10/20/50 spheres: mean volume error ≤ 3 % at 50, moment error and surface deviation reported",
            fast: false,
            heavy: false,
            run: clumps,
        },
        Case {
            name: "specimen/cylinder-10k",
            description: "10 000 calibrated Ottawa clones packed without overlap in a cylinder H = 2D: solid fraction ≥ 0.50 (aim 0.56), LS-DEM node check φ/d ≥ −1e-6 on 32³ level sets with 1000 nodes per grain, 4×-finer raster cross-check, Cu/Cc within 5 %, fabric of the major axes",
            fast: false,
            heavy: false,
            run: cylinder_10k,
        },
        Case {
            name: "specimen/dense-0.60",
            description: "10 000 calibrated Ottawa clones packed by pack_grains (compaction of sphere proxies, then gap minimisation) in a triaxial cylinder at solid fraction 0.60: zero overlaps by the independent check, Cu/Cc within 5 %, fabric ‖N − I/3‖ ≤ 0.02",
            fast: false,
            heavy: false,
            run: dense_060,
        },
        Case {
            name: "specimen/target-fraction",
            description: "2000 calibrated Ottawa clones packed at requested solid fractions 0.50, 0.55 and 0.60, each reached within ±0.005 and clean by the independent check; 0.72 refused with an error naming the limit",
            fast: false,
            heavy: false,
            run: target_fraction,
        },
        Case {
            name: "specimen/periodic",
            description: "2000 calibrated Ottawa clones packed at solid fraction 0.60 in a fully periodic cube and in a box periodic in x and y (walls in z): zero overlaps by the independent check across the periodic faces (pairs through the faces counted), sampled fraction of the periodic cell vs 0.60",
            fast: false,
            heavy: false,
            run: periodic,
        },
        Case {
            name: "specimen/scale",
            description: "20 000 and 50 000 calibrated Ottawa clones packed by pack_grains in triaxial cylinders at solid fractions 0.52 and 0.60: every grain packed, fraction reached, zero overlaps by the independent check (heavy: ~25 min on 2 cores, run with --heavy; times and memory from `cargo xtask specimen`)",
            fast: false,
            heavy: true,
            run: scale,
        },
        Case {
            name: "specimen/homogeneity",
            description: "the 0.60 specimen of specimen/dense-0.60 in 5 height slices and 3 equal-volume radial shells (one d50 next to the walls left out): solid fraction (point sampling, spacing d50/6) within ±0.01 of the core's mean and of 0.60, mass d50 within 3 %",
            fast: false,
            heavy: false,
            run: homogeneity,
        },
    ]
}

/// Known failures with their reasons.
pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[ExpectedFailure {
    case: "specimen/homogeneity",
    metric: "core (one d50 off the walls): solid fraction vs the target 0.60",
    reason: "the target is the specimen's fraction (grain volume over the cylinder); grains cannot fill the zone next to a wall as densely as the interior, so the wall zone is looser (0.556 sampled) and the core denser (0.622 sampled) than 0.60. The core is homogeneous (slices and shells within ±0.01 of its mean, d50 within 3 %), which is what the case guards; a core at 0.60 needs the specimen packed at ~0.58.",
}];

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
) -> Result<(Container, packer_grains::GrainPacking), Error> {
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
    let mut out = vec![
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
    ];
    out.extend(report_checks("", &report));
    out.extend([
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
    ]);
    Ok(out)
}

/// Solid fraction of `specimen/dense-0.60`.
pub const DENSE_FRACTION: f64 = 0.60;

/// The 0.60 specimen, packed once for `specimen/dense-0.60` and
/// `specimen/homogeneity`.
struct Dense {
    grains: Vec<StarGrain>,
    container: Container,
    packing: packer_grains::GrainPacking,
}

fn dense_specimen() -> Result<&'static Dense, Error> {
    static DENSE: std::sync::OnceLock<Result<Dense, String>> = std::sync::OnceLock::new();
    DENSE
        .get_or_init(|| {
            let grains = ottawa_star_grains(10_000).map_err(|e| e.to_string())?;
            let container = container_for(&Container::triaxial(1.0), &grains, DENSE_FRACTION)
                .map_err(|e| e.to_string())?;
            let packing = pack_grains(&grains, &container, &GrainPackParams::default())
                .map_err(|e| e.to_string())?;
            Ok(Dense {
                grains,
                container,
                packing,
            })
        })
        .as_ref()
        .map_err(|e| Error::computation(e.clone()))
}

/// The independent check of a packing as checks (zero overlaps, nothing
/// outside, the raster cross-check).
fn overlap_checks(
    prefix: &str,
    grains: &[StarGrain],
    container: &Container,
    packing: &packer_grains::GrainPacking,
) -> Result<Vec<Check>, Error> {
    let report = check_grain_overlaps(grains, &packing.poses, container, &CheckParams::default())
        .map_err(Error::computation)?;
    Ok(report_checks(prefix, &report))
}

/// The rows of an independent check's report.
fn report_checks(prefix: &str, report: &packer_grains::GrainOverlapReport) -> Vec<Check> {
    vec![
        Check::new(
            format!("{prefix}worst node phi / d (1000 nodes, 32^3)"),
            -1e-6,
            report.worst_phi_over_d,
            Tolerance::AtLeast(0.0),
        ),
        Check::new(
            format!("{prefix}overlapping nodes"),
            0.0,
            report.overlapping_nodes as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            format!("{prefix}nodes outside the container"),
            0.0,
            report.nodes_outside as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            format!("{prefix}raster overlap voxels (4x finer)"),
            0.0,
            report.raster_overlap_voxels as f64,
            Tolerance::Within(0.0),
        ),
    ]
}

fn dense_060() -> Result<Vec<Check>, Error> {
    let d = dense_specimen()?;
    let mut out = vec![
        Check::new(
            "solid fraction",
            DENSE_FRACTION,
            d.packing.stats.solid_fraction,
            Tolerance::AtLeast(0.0),
        ),
        Check::new(
            "grains packed",
            d.grains.len() as f64,
            d.packing.poses.len() as f64,
            Tolerance::Within(0.0),
        ),
    ];
    out.extend(overlap_checks("", &d.grains, &d.container, &d.packing)?);
    // every grain is packed and inside (the check's wall test): the packed
    // grading is the requested one; measured over the grains whose centre
    // is inside the container all the same
    let dia: Vec<f64> = d
        .grains
        .iter()
        .map(StarGrain::equivalent_diameter)
        .collect();
    let (cu, cc) = mass_cu_cc(&dia);
    let inside: Vec<f64> = dia
        .iter()
        .zip(&d.packing.poses)
        .filter(|(_, p)| d.container.clearance(&p.translation.vector.into()) > 0.0)
        .map(|(x, _)| *x)
        .collect();
    let (cu_p, cc_p) = mass_cu_cc(&inside);
    out.push(Check::new("Cu", cu, cu_p, Tolerance::Relative(0.05)));
    out.push(Check::new("Cc", cc, cc_p, Tolerance::Relative(0.05)));
    let fabric = orientation_fabric(&d.packing.poses, &Vector3::x()).map_err(Error::computation)?;
    out.push(Check::new(
        "fabric deviatoric norm (major axes)",
        0.02,
        fabric.deviatoric_norm,
        Tolerance::AtMost(0.0),
    ));
    Ok(out)
}

fn target_fraction() -> Result<Vec<Check>, Error> {
    let grains = ottawa_star_grains(2000)?;
    let mut out = Vec::new();
    for target in [0.50, 0.55, 0.60] {
        let c = container_for(&Container::triaxial(1.0), &grains, target)
            .map_err(Error::computation)?;
        let p = pack_grains(&grains, &c, &GrainPackParams::default())
            .map_err(|e| Error::computation(format!("at {target}: {e}")))?;
        // the fraction measured from the packing itself (grain volumes over
        // the container), not the requested number
        let reached = grains.iter().map(StarGrain::volume).sum::<f64>() / c.volume();
        out.push(Check::new(
            format!("{target:.2}: solid fraction reached"),
            target,
            reached,
            Tolerance::Within(0.005),
        ));
        out.extend(overlap_checks(&format!("{target:.2}: "), &grains, &c, &p)?);
    }
    // beyond what grains can fill: clear errors naming the fraction and
    // the limit, from container_for and from pack_grains itself (the 0.60
    // cylinder shrunk to 0.72)
    let sized = match container_for(&Container::triaxial(1.0), &grains, 0.72) {
        Err(e @ packer_grains::Error::Parameter { .. }) => {
            let m = e.to_string();
            m.contains("0.72") && m.contains("0.70")
        }
        _ => false,
    };
    let c = container_for(&Container::triaxial(1.0), &grains, 0.60).map_err(Error::computation)?;
    let k = (0.60f64 / 0.72).cbrt();
    let shrunk = match c {
        Container::Cylinder {
            base,
            radius,
            height,
        } => Container::Cylinder {
            base,
            radius: radius * k,
            height: height * k,
        },
        other => other,
    };
    let packed = match pack_grains(&grains, &shrunk, &GrainPackParams::default()) {
        Err(e @ packer_grains::Error::TooDense { .. }) => {
            let m = e.to_string();
            m.contains("0.72") && m.contains("0.7")
        }
        _ => false,
    };
    out.push(Check::new(
        "0.72: container_for refuses, naming fraction and limit (1 = yes)",
        1.0,
        f64::from(u8::from(sized)),
        Tolerance::Within(0.0),
    ));
    out.push(Check::new(
        "0.72: pack_grains refuses with TooDense, naming fraction and limit (1 = yes)",
        1.0,
        f64::from(u8::from(packed)),
        Tolerance::Within(0.0),
    ));
    Ok(out)
}

fn periodic() -> Result<Vec<Check>, Error> {
    let err = Error::computation;
    let grains = ottawa_star_grains(2000)?;
    let unit = levelset::nalgebra::Point3::new(1.0, 1.0, 1.0);
    let origin = levelset::nalgebra::Point3::origin();
    let shapes = [
        (
            "periodic cube",
            Boundary::Periodic {
                min: origin,
                max: unit,
            },
        ),
        (
            "x-y periodic box",
            Boundary::Walls(Container::Box {
                min: origin,
                max: unit,
                periodic: [true, true],
            }),
        ),
    ];
    let mut out = Vec::new();
    for (name, shape) in &shapes {
        let cell = boundary_for(shape, &grains, 0.60).map_err(err)?;
        let p = pack_grains_in(&grains, &cell, &GrainPackParams::default())
            .map_err(|e| Error::computation(format!("{name}: {e}")))?;
        let reached = grains.iter().map(StarGrain::volume).sum::<f64>() / cell.volume();
        out.push(Check::new(
            format!("{name}: solid fraction reached"),
            0.60,
            reached,
            Tolerance::Within(0.005),
        ));
        let report = check_grain_overlaps_in(&grains, &p.poses, &cell, &CheckParams::default())
            .map_err(err)?;
        out.extend(report_checks(&format!("{name}: "), &report));
        out.push(Check::new(
            format!("{name}: pairs checked across the periodic faces"),
            1.0,
            report.periodic_pairs as f64,
            Tolerance::AtLeast(0.0),
        ));
        if let Boundary::Periodic { min, max } = &cell {
            // a regular grid over the cell (spacing d50/5): grains that
            // cross a face are found through their images
            let dia: Vec<f64> = grains.iter().map(StarGrain::equivalent_diameter).collect();
            let h = mass_d50(&dia) / 5.0;
            let side = max - min;
            let dims = side.map(|l| (l / h).round().max(1.0) as usize);
            let mut points = Vec::with_capacity(dims.product());
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        let f =
                            |n: usize, d: usize, a: usize| (n as f64 + 0.5) / d as f64 * side[a];
                        points.push(
                            min + levelset::nalgebra::Vector3::new(
                                f(i, dims[0], 0),
                                f(j, dims[1], 1),
                                f(k, dims[2], 2),
                            ),
                        );
                    }
                }
            }
            let inside = occupied_in(&grains, &p.poses, &cell, &points).map_err(err)?;
            let sampled = inside.iter().filter(|&&b| b).count() as f64 / points.len() as f64;
            out.push(Check::new(
                format!("{name}: sampled solid fraction of the cell (spacing d50/5)"),
                reached,
                sampled,
                Tolerance::Within(0.005),
            ));
        }
    }
    Ok(out)
}

fn scale() -> Result<Vec<Check>, Error> {
    let mut out = Vec::new();
    for count in [20_000u64, 50_000] {
        let grains = ottawa_star_grains(count)?;
        for target in [0.52, 0.60] {
            let name = format!("{count} at {target:.2}: ");
            let c = container_for(&Container::triaxial(1.0), &grains, target)
                .map_err(Error::computation)?;
            let p = pack_grains(&grains, &c, &GrainPackParams::default())
                .map_err(|e| Error::computation(format!("{name}{e}")))?;
            let reached = grains.iter().map(StarGrain::volume).sum::<f64>() / c.volume();
            out.push(Check::new(
                format!("{name}grains packed"),
                count as f64,
                p.poses.len() as f64,
                Tolerance::Within(0.0),
            ));
            out.push(Check::new(
                format!("{name}solid fraction reached"),
                target,
                reached,
                Tolerance::Within(0.005),
            ));
            out.extend(overlap_checks(&name, &grains, &c, &p)?);
        }
    }
    Ok(out)
}

/// Mass-weighted median of `d` (diameter at 50 % passing by mass).
fn mass_d50(d: &[f64]) -> f64 {
    let mut v: Vec<f64> = d.to_vec();
    v.sort_by(f64::total_cmp);
    let total: f64 = v.iter().map(|x| x.powi(3)).sum();
    let mut acc = 0.0;
    for x in &v {
        acc += x.powi(3);
        if acc >= 0.5 * total {
            return *x;
        }
    }
    f64::NAN
}

fn homogeneity() -> Result<Vec<Check>, Error> {
    let d = dense_specimen()?;
    let Container::Cylinder {
        base,
        radius,
        height,
    } = d.container
    else {
        return Err(Error::computation("the dense specimen is not a cylinder"));
    };
    let dia: Vec<f64> = d
        .grains
        .iter()
        .map(StarGrain::equivalent_diameter)
        .collect();
    let d50 = mass_d50(&dia);
    // the core: one d50 off every wall
    let (r_core, z0, z1) = (radius - d50, base.z + d50, base.z + height - d50);
    if r_core <= 0.0 || z1 <= z0 {
        return Err(Error::computation("the specimen is thinner than 2 d50"));
    }
    // 3 radial shells of equal volume, 5 height slices; region 8: the wall
    // zone, 9: the whole container
    let shell = |r: f64| ((r / r_core).powi(2) * 3.0).floor().min(2.0) as usize;
    let slice = |z: f64| (((z - z0) / (z1 - z0)) * 5.0).floor().clamp(0.0, 4.0) as usize;
    let in_core = |r: f64, z: f64| r < r_core && z > z0 && z < z1;
    // a regular grid of spacing d50/6 over the whole cylinder (about 110
    // points per grain)
    let h = d50 / 6.0;
    let nr = (radius / h).ceil() as i64;
    let nz = (height / h).ceil() as i64;
    let mut points = Vec::new();
    for k in 0..nz {
        let z = base.z + (k as f64 + 0.5) * h;
        if z >= base.z + height {
            break;
        }
        for i in -nr..nr {
            for j in -nr..nr {
                let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                if x * x + y * y < radius * radius {
                    points.push(levelset::nalgebra::Point3::new(base.x + x, base.y + y, z));
                }
            }
        }
    }
    let inside = packer_grains::occupied(&d.grains, &d.packing.poses, &points)
        .map_err(Error::computation)?;
    let mut hit = [0usize; 10];
    let mut all = [0usize; 10];
    for (p, &ins) in points.iter().zip(&inside) {
        let r = ((p.x - base.x).powi(2) + (p.y - base.y).powi(2)).sqrt();
        let regions: &[usize] = if in_core(r, p.z) {
            &[slice(p.z), 5 + shell(r), 9]
        } else {
            &[8, 9]
        };
        for &reg in regions {
            all[reg] += 1;
            hit[reg] += usize::from(ins);
        }
    }
    let phi = |reg: usize| hit[reg] as f64 / all[reg].max(1) as f64;
    let core = (0..5).map(|r| hit[r]).sum::<usize>() as f64
        / (0..5).map(|r| all[r]).sum::<usize>().max(1) as f64;
    // grains by centre
    let mut members: Vec<Vec<f64>> = vec![Vec::new(); 8];
    for (p, x) in d.packing.poses.iter().zip(&dia) {
        let c = p.translation.vector;
        let r = ((c.x - base.x).powi(2) + (c.y - base.y).powi(2)).sqrt();
        if in_core(r, c.z) {
            members[slice(c.z)].push(*x);
            members[5 + shell(r)].push(*x);
        }
    }
    let mut out = vec![
        // the sampling itself against the packing's exact fraction
        Check::new(
            "whole container: sampled grain volume / container volume vs the packing's fraction",
            d.packing.stats.solid_fraction,
            hit[9] as f64 * h.powi(3) / d.container.volume(),
            Tolerance::Within(0.003),
        ),
        Check::new(
            "core (one d50 off the walls): solid fraction vs the target 0.60",
            DENSE_FRACTION,
            core,
            Tolerance::Within(0.01),
        ),
        Check::new(
            "wall zone (within one d50 of a wall): solid fraction, below the core's",
            core,
            phi(8),
            Tolerance::AtMost(0.0),
        ),
    ];
    for (reg, grains_in) in members.iter().enumerate() {
        let name = if reg < 5 {
            format!("slice {} of 5 (bottom first)", reg + 1)
        } else {
            format!("shell {} of 3 (axis first)", reg - 4)
        };
        out.push(Check::new(
            format!("{name}: solid fraction vs the core's"),
            core,
            phi(reg),
            Tolerance::Within(0.01),
        ));
        out.push(Check::new(
            format!("{name}: mass d50 vs the specimen's"),
            d50,
            mass_d50(grains_in),
            Tolerance::Relative(0.03),
        ));
    }
    Ok(out)
}
