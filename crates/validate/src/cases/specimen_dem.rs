//! The DEM files of a specimen as the DEM codes read them (issue "Ready-to-run DEM
//! specimens").
//!
//! Every case packs calibrated Ottawa clones with `packer_grains::pack_grains` in a
//! triaxial cylinder at a solid fraction of 0.50 (0.40 for the 60 grains of the LS-DEM
//! case, whose cylinder is only a few grains wide), as `cargo xtask specimen` does, and takes
//! each grain's level set from its packed star table (45³ nodes over ±1.1 r_max).
//!
//! `specimen/lsdem-files`: 60 grains written as an LS-DEM input folder
//! (`levelset::io::lsdem`: principal-frame morph files at one grid spacing,
//! `InitState/positions_<NAME>.dat`, `rotations_<NAME>.dat`, links for reused morphs), then
//! read back the way LS-DEM's loader does (`Morphologies/morph_<i+1>.dat` for line `i`,
//! built here from its own format string): no missing file; each morph file's level set
//! (parsed from the file) principal, `max |I_ij| / I_max ≤ 1e-9` by
//! `Grid::mass_properties_linear`, its moments the diagonal; the surface nodes placed by the
//! parsed positions and LS-DEM's rotation matrix of the parsed quaternions equal to the
//! packed pose applied to the same nodes within 1e-9 d_eq; and those nodes on the packed
//! grain's surface (its level set in the body frame: within one grid spacing, the
//! resampling). A second folder in
//! which 60 grains reuse 20 morphs checks that every line resolves to its shape's file.
//!
//! `specimen/clump-mass`: 200 grains as clumps of 10, 20 and 50 spheres
//! (`levelset::clump`), trimmed against their neighbours and the walls
//! (`packer_grains::separate_clumps`, what is delivered): the union's volume, centre of
//! mass and inertia tensor (`levelset::union_mass_properties`) against the level set's,
//! and the same for the naive sum of the spheres' own masses and inertias (what LAMMPS
//! `fix rigid/small` and Yade `appendClumped` without discretisation compute).
//!
//! `specimen/clump-shape`: the DNA (volume, volume/surface, aspect ratio, 3D roundness;
//! `morph_dna::measure`) of the same delivered clumps, each union rasterised on its grain's
//! own grid, against the grain's level set.

use std::collections::BTreeMap;
use std::sync::OnceLock;

use levelset::io::lsdem;
use levelset::nalgebra::{Isometry3, Matrix3, Point3, Vector3};
use levelset::{ClumpParams, Grid, clump, union_mass_properties};
use morph_dna::{Descriptor, MeasureParams};
use packer_grains::{GrainPackParams, StarGrain, container_for, pack_grains, separate_clumps};
use packer_spheres::Container;
use rayon::prelude::*;

use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "specimen/lsdem-files",
            description: "60 packed Ottawa clones as an LS-DEM input folder read back as LS-DEM does: no missing morph file, each morph's level set principal (|I_ij|/I_max <= 1e-9), positions + rotations reproduce the world surface to 1e-9 d, reused morphs resolve",
            fast: false,
            heavy: false,
            run: lsdem_files,
        },
        Case {
            name: "specimen/clump-mass",
            description: "200 packed Ottawa clones as trimmed clumps of 10/20/50 spheres: union volume, centroid and inertia against the level set's; the naive sum of sphere masses reported",
            fast: false,
            heavy: false,
            run: clump_mass,
        },
        Case {
            name: "specimen/clump-shape",
            description: "DNA (volume, V/S, aspect ratio, roundness) of the delivered clumps of 200 packed Ottawa clones against their level sets, 10/20/50 spheres",
            fast: false,
            heavy: false,
            run: clump_shape,
        },
    ]
}

/// Known failures with their reasons.
pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
    ExpectedFailure {
        case: "specimen/clump-mass",
        metric: "10 spheres: union worst |volume error| %",
        reason: TRIM_10,
    },
    ExpectedFailure {
        case: "specimen/clump-mass",
        metric: "10 spheres: union mean inertia-tensor error %",
        reason: TRIM_10,
    },
    ExpectedFailure {
        case: "specimen/clump-mass",
        metric: "10 spheres: union mean centroid offset / d",
        reason: TRIM_10,
    },
    ExpectedFailure {
        case: "specimen/clump-shape",
        metric: "10 spheres: clump roundness mean |error| %",
        reason: ROUNDNESS,
    },
    ExpectedFailure {
        case: "specimen/clump-shape",
        metric: "20 spheres: clump roundness mean |error| %",
        reason: ROUNDNESS,
    },
    ExpectedFailure {
        case: "specimen/clump-shape",
        metric: "50 spheres: clump roundness mean |error| %",
        reason: ROUNDNESS,
    },
];

const TRIM_10: &str = "A 10-sphere clump of a packed grain loses more to the trimming against its neighbours and the walls (its spheres are larger and reach farther past the grain's surface, across the 1 % packing margin): measured 1.9 % mean (within the 3 % bound) but 9.6 % worst volume, 5.3 % inertia, 0.017 d centroid offset on 200 packed Ottawa clones. Use 20 or more spheres for a specimen (20: 0.7 % / 3.9 %; 50: 0.1 % / 1.0 %).";

const ROUNDNESS: &str = "3D roundness (mean corner curvature radius over the inscribed radius) of a sphere union is set by its spheres, not by the grain's corners: the union is bumpy at the scale of its spheres (convex bumps and concave crevices), so the measured roundness differs from the level set's by 34.5 / 16.2 / 10.1 % at 10 / 20 / 50 spheres (200 packed Ottawa clones of the issue-30 calibration; the previous calibration's clones gave 33 / 15 / 9.9 %, 50 spheres then just within the 10 % bound). Volume, V/S and aspect ratio of the delivered clumps are within 5 % at 20 and 50 spheres; roundness needs more spheres than a DEM run can afford, or a level-set DEM (LS-DEM output).";

/// Level-set nodes per axis of the grains.
const RESOLUTION: usize = 45;
/// Half-width of a grain's grid over its largest radius (the cloner's `grid_margin`).
const MARGIN: f64 = 1.1;
/// Lattice cells per equivalent diameter of the union integration (as `xtask specimen`).
const UNION_CELLS: f64 = 60.0;

/// A clump's spheres: centre and radius.
type Clump = Vec<(Point3<f64>, f64)>;

/// A packed specimen: grains, their level sets, container and poses.
struct Packed {
    grains: Vec<StarGrain>,
    grids: Vec<Grid>,
    container: Container,
    poses: Vec<Isometry3<f64>>,
}

/// `n` calibrated Ottawa clones packed at `fraction` in a cylinder H = 2D, with level sets.
fn packed(n: u64, fraction: f64) -> Result<Packed, Error> {
    // the same clones as `specimen/cylinder-10k` (16 cube-map cells per face)
    let grains = super::specimen::ottawa_star_grains(n)?;
    let container =
        container_for(&Container::triaxial(1.0), &grains, fraction).map_err(Error::computation)?;
    let packing = pack_grains(&grains, &container, &GrainPackParams::default())
        .map_err(Error::computation)?;
    let grids = grains
        .par_iter()
        .map(|g| {
            g.level_set(RESOLUTION, MARGIN * g.r_max())
                .map_err(Error::computation)
        })
        .collect::<Result<_, Error>>()?;
    Ok(Packed {
        grains,
        grids,
        container,
        poses: packing.poses,
    })
}

/// The 200-grain specimen shared by the two clump cases.
fn clump_specimen() -> Result<&'static Packed, Error> {
    static SPECIMEN: OnceLock<Packed> = OnceLock::new();
    if let Some(p) = SPECIMEN.get() {
        return Ok(p);
    }
    let p = packed(200, 0.5)?;
    Ok(SPECIMEN.get_or_init(|| p))
}

fn lsdem_files() -> Result<Vec<Check>, Error> {
    let err = Error::computation;
    // 60 grains fill a cylinder only a few grains wide: a looser 0.40
    let sp = packed(60, 0.4)?;
    // one grid spacing for every morph file: the median grain's own
    let mut own: Vec<f64> = sp.grids.iter().map(Grid::spacing).collect();
    own.sort_by(f64::total_cmp);
    let h = own[own.len() / 2];
    let morphs: Vec<lsdem::PrincipalMorph> = sp
        .grids
        .par_iter()
        .map(|g| levelset::io::principal_morph(g, h, 1.0, 1000).map_err(err))
        .collect::<Result<_, Error>>()?;
    // the folder: morph files, positions, rotations (every grain its own morph)
    let world = |k: usize, m: &lsdem::PrincipalMorph| {
        let w = sp.poses[k] * m.frame;
        Isometry3::from_parts((w.translation.vector / m.spacing).into(), w.rotation)
    };
    let mut folder: BTreeMap<String, Entry> = BTreeMap::new();
    for (k, m) in morphs.iter().enumerate() {
        let mut bytes = Vec::new();
        // as `cargo xtask specimen` writes them: 9 decimals
        levelset::io::write_morph_decimals(&mut bytes, &m.morph, 9).map_err(err)?;
        folder.insert(lsdem::morph_path(k + 1), Entry::File(bytes));
    }
    let grains: Vec<(usize, Isometry3<f64>)> = morphs
        .iter()
        .enumerate()
        .map(|(k, m)| (k, world(k, m)))
        .collect();
    insert_layout(
        &mut folder,
        lsdem::layout("validate", &grains).map_err(err)?,
    );
    // read back as LS-DEM's loader does
    let get = |path: &str| resolve(&folder, path);
    let positions = lsdem::read_rows::<3>(
        get("InitState/positions_validate.dat")
            .ok_or_else(|| Error::computation("no positions file"))?,
        "positions",
    )
    .map_err(err)?;
    let rotations = lsdem::read_rows::<4>(
        get("InitState/rotations_validate.dat")
            .ok_or_else(|| Error::computation("no rotations file"))?,
        "rotations",
    )
    .map_err(err)?;
    let (mut missing, mut worst_off, mut worst_moment, mut worst_place, mut worst_surface) =
        (0usize, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (i, (p, q)) in positions.iter().zip(&rotations).enumerate() {
        let Some(bytes) = get(&format!("Morphologies/morph_{}.dat", i + 1)) else {
            missing += 1;
            continue;
        };
        let m = levelset::io::read_morph(bytes).map_err(err)?;
        let mp = m.grid.mass_properties_linear().map_err(err)?;
        worst_off = worst_off.max(lsdem::off_diagonal(&mp.inertia));
        for a in 0..3 {
            let d = mp.inertia[(a, a)];
            worst_moment = worst_moment.max((m.principal_moments[a] - d).abs() / d);
        }
        let r: Matrix3<f64> = lsdem::lsdem_matrix(*q);
        let pos = Vector3::new(p[0], p[1], p[2]);
        let d = sp.grains[i].equivalent_diameter();
        let exact = sp.poses[i] * morphs[i].frame;
        for node in &m.points {
            let lsdem_world = (pos + r * node.coords) * h;
            let ours = exact * (node * h);
            worst_place = worst_place.max((lsdem_world - ours.coords).norm() / d);
            // on the packed grain's surface: its own level set in the body frame
            let body = sp.poses[i].inverse() * Point3::from(lsdem_world);
            worst_surface = worst_surface.max(sp.grids[i].value(&body).abs() / h);
        }
    }
    // reuse: 60 lines over 20 morphs
    let reused: Vec<(usize, Isometry3<f64>)> = (0..60)
        .map(|k| (k % 20, world(k, &morphs[k % 20])))
        .collect();
    let mut folder2: BTreeMap<String, Entry> = BTreeMap::new();
    for k in 0..20 {
        if let Some(e) = folder.get(&lsdem::morph_path(k + 1)) {
            folder2.insert(lsdem::morph_path(k + 1), e.clone());
        }
    }
    insert_layout(&mut folder2, lsdem::layout("reuse", &reused).map_err(err)?);
    let wrong = (0..60)
        .filter(|&i| {
            resolve(&folder2, &format!("Morphologies/morph_{}.dat", i + 1))
                != resolve(&folder2, &format!("Morphologies/morph_{}.dat", i % 20 + 1))
        })
        .count();
    let stored = folder2
        .values()
        .filter(|e| matches!(e, Entry::File(_)))
        .count();
    Ok(vec![
        Check::new(
            "lines of positions and rotations",
            60.0,
            positions.len().min(rotations.len()) as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "morph files LS-DEM cannot find",
            0.0,
            missing as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "worst |I_ij| / I_max of a morph file's level set",
            1e-9,
            worst_off,
            Tolerance::AtMost(0.0),
        ),
        Check::new(
            "worst relative gap between a file moment and its inertia diagonal",
            1e-9,
            worst_moment,
            Tolerance::AtMost(0.0),
        ),
        Check::new(
            "worst node placement by the files vs the packed pose, / d",
            1e-9,
            worst_place,
            Tolerance::AtMost(0.0),
        ),
        Check::new(
            "worst node distance to the packed grain's surface (its level set), in grid spacings",
            1.0,
            worst_surface,
            Tolerance::AtMost(0.0),
        ),
        Check::new(
            "reused lines resolving to another shape's morph",
            0.0,
            wrong as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "files stored for 60 lines over 20 morphs (20 morphs + positions + rotations)",
            22.0,
            stored as f64,
            Tolerance::Within(0.0),
        ),
    ])
}

/// A file of an in-memory LS-DEM folder.
#[derive(Clone, PartialEq)]
enum Entry {
    File(Vec<u8>),
    Link(String),
}

fn insert_layout(folder: &mut BTreeMap<String, Entry>, entries: Vec<lsdem::LayoutEntry>) {
    for e in entries {
        match e {
            lsdem::LayoutEntry::File { path, bytes } => {
                folder.insert(path, Entry::File(bytes));
            }
            lsdem::LayoutEntry::Link { path, target } => {
                folder.insert(path, Entry::Link(target));
            }
        }
    }
}

/// The bytes at `path`, following links relative to their folder (at most 8).
fn resolve<'a>(folder: &'a BTreeMap<String, Entry>, path: &str) -> Option<&'a [u8]> {
    let mut p = path.to_owned();
    for _ in 0..8 {
        match folder.get(&p)? {
            Entry::File(b) => return Some(b),
            Entry::Link(t) => {
                let dir = p.rsplit_once('/').map_or("", |(d, _)| d);
                p = if dir.is_empty() {
                    t.clone()
                } else {
                    format!("{dir}/{t}")
                };
            }
        }
    }
    None
}

/// The delivered clumps of `sp` at `n` spheres: placed, trimmed against the neighbours and
/// walls.
fn delivered(sp: &Packed, n: usize) -> Result<Vec<Clump>, Error> {
    let params = ClumpParams {
        n_spheres: n,
        ..ClumpParams::default()
    };
    let mut shapes: Vec<Clump> = sp
        .grids
        .par_iter()
        .map(|g| {
            clump(g, &params)
                .map(|c| c.spheres)
                .map_err(Error::computation)
        })
        .collect::<Result<_, Error>>()?;
    separate_clumps(&mut shapes, &sp.poses, |k| k, &sp.container).map_err(Error::computation)?;
    Ok(shapes)
}

/// Relative Frobenius error of `a` against `b`.
fn tensor_error(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

fn clump_mass() -> Result<Vec<Check>, Error> {
    let sp = clump_specimen()?;
    let mut out = Vec::new();
    for n in [10usize, 20, 50] {
        let shapes = delivered(sp, n)?;
        // (union volume, union inertia, union centroid / d, naive volume, naive inertia)
        let e: Vec<[f64; 5]> = shapes
            .par_iter()
            .zip(&sp.grids)
            .map(|(s, g)| {
                let ls = g.mass_properties().map_err(Error::computation)?;
                let d = ls.equivalent_diameter();
                let un = union_mass_properties(s, d / UNION_CELLS).map_err(Error::computation)?;
                // naive: every sphere's own mass and inertia, about the union's centroid
                let mut v = 0.0;
                let mut inertia = Matrix3::zeros();
                for (c, r) in s {
                    let m = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
                    let x = c - un.centroid;
                    v += m;
                    inertia += Matrix3::identity() * (0.4 * m * r * r)
                        + (Matrix3::identity() * x.norm_squared() - x * x.transpose()) * m;
                }
                Ok([
                    (un.volume / ls.volume - 1.0).abs(),
                    tensor_error(&un.inertia, &ls.inertia),
                    (un.centroid - ls.centroid).norm() / d,
                    v / ls.volume - 1.0,
                    tensor_error(&inertia, &ls.inertia),
                ])
            })
            .collect::<Result<_, Error>>()?;
        let mean = |i: usize| e.iter().map(|x| x[i]).sum::<f64>() / e.len() as f64;
        let worst = |i: usize| e.iter().map(|x| x[i]).fold(0.0, f64::max);
        out.push(Check::new(
            format!("{n} spheres: union mean |volume error| %"),
            3.0,
            100.0 * mean(0),
            Tolerance::AtMost(0.0),
        ));
        out.push(Check::new(
            format!("{n} spheres: union worst |volume error| %"),
            6.0,
            100.0 * worst(0),
            Tolerance::AtMost(0.0),
        ));
        out.push(Check::new(
            format!("{n} spheres: union mean inertia-tensor error %"),
            5.0,
            100.0 * mean(1),
            Tolerance::AtMost(0.0),
        ));
        out.push(Check::new(
            format!("{n} spheres: union mean centroid offset / d"),
            0.01,
            mean(2),
            Tolerance::AtMost(0.0),
        ));
        // the naive sum: what a code summing the spheres gets (reported; far off)
        out.push(Check::new(
            format!(
                "{n} spheres: naive sum mean volume over-count % (>= 20: why the union is given)"
            ),
            20.0,
            100.0 * mean(3),
            Tolerance::AtLeast(0.0),
        ));
        out.push(Check::new(
            format!("{n} spheres: naive sum mean inertia-tensor error % (reported)"),
            20.0,
            100.0 * mean(4),
            Tolerance::AtLeast(0.0),
        ));
    }
    Ok(out)
}

fn clump_shape() -> Result<Vec<Check>, Error> {
    let sp = clump_specimen()?;
    let wanted = [
        Descriptor::Volume,
        Descriptor::VolumeSurfaceRatio,
        Descriptor::AspectRatio,
        Descriptor::Roundness,
    ];
    let params = MeasureParams::default();
    let grain_dna: Vec<Vec<f64>> = sp
        .grids
        .par_iter()
        .map(|g| morph_dna::measure(g, &wanted, &params).map_err(Error::computation))
        .collect::<Result<_, Error>>()?;
    let mut out = Vec::new();
    for n in [10usize, 20, 50] {
        let shapes = delivered(sp, n)?;
        let errors: Vec<Vec<f64>> = shapes
            .par_iter()
            .zip(&sp.grids)
            .zip(&grain_dna)
            .map(|((s, g), ours)| {
                let union = Grid::from_fn(*g.spec(), |p| {
                    s.iter()
                        .fold(f64::INFINITY, |m, (c, r)| m.min((p - c).norm() - r))
                })
                .map_err(Error::computation)?;
                let dna =
                    morph_dna::measure(&union, &wanted, &params).map_err(Error::computation)?;
                Ok(dna
                    .iter()
                    .zip(ours)
                    .map(|(c, l)| (c / l - 1.0).abs())
                    .collect())
            })
            .collect::<Result<_, Error>>()?;
        let k = errors.len() as f64;
        for (i, (name, bound)) in [
            ("volume", 3.0),
            ("volume/surface", 5.0),
            ("aspect ratio", 5.0),
            ("roundness", 10.0),
        ]
        .into_iter()
        .enumerate()
        {
            let mean = 100.0 * errors.iter().map(|e| e[i]).sum::<f64>() / k;
            out.push(Check::new(
                format!("{n} spheres: clump {name} mean |error| %"),
                bound,
                mean,
                Tolerance::AtMost(0.0),
            ));
        }
    }
    Ok(out)
}
