//! Parents: the grains the cloner copies.
//!
//! * `parents/ottawa-representative` — the default parents (71 Ottawa grains
//!   drawn at random from NIST's 2,201) have the population's shape: their
//!   median flatness and elongation are within 0.03 of NIST's population
//!   medians of thickness/width (0.744) and width/length (0.804), compared
//!   like with like.
//!
//! **How our dimensions relate to NIST's.** NIST's length, width and
//! thickness are calipers: L the longest surface-to-surface distance, W the
//! longest perpendicular to L, T the longest perpendicular to both
//! (Garboczi 2002). Our `MajorExtent ≥ IntermediateExtent ≥ MinorExtent` are
//! calipers too, taken along the grain's principal axes of inertia; our
//! `Elongation = I/L` and `Flatness = S/I` use the inertia-equivalent
//! ellipsoid's axes instead (smoother, less sensitive to one protruding
//! point). For an ellipsoid all three definitions coincide. The like-with-like
//! comparison with NIST's T/W and W/L is therefore made with the extent
//! ratios `MinorExtent / IntermediateExtent` and `IntermediateExtent /
//! MajorExtent`; the inertia-based medians are reported beside them, and the
//! offset between our extent ratios and NIST's own ratios on the same grains
//! is checked too (it shows the two caliper definitions agree).

use morph_dna::{Descriptor, MeasureParams};

use crate::grains::{self, DEFAULT_PARENTS};
use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

/// NIST's population medians over all 2,201 Ottawa grains
/// (`fixtures/grains/README.md`): thickness/width and width/length.
pub const POPULATION_T_OVER_W: f64 = 0.744;
/// See [`POPULATION_T_OVER_W`].
pub const POPULATION_W_OVER_L: f64 = 0.804;

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "parents/ottawa-representative",
            description: "median flatness and elongation of the default parents (71 random Ottawa grains, caliper extents along the principal axes) within 0.03 of NIST's population medians T/W 0.744 and W/L 0.804",
            fast: false,
            heavy: false,
            run: ottawa_representative,
        },
        Case {
            name: "parents/ma107-6-calibrated",
            description: "GSC 2.0 clones of the crushed aggregate MA107-6 (60 angular grains) at the configuration calibrated on it through the file path: average mean error <= 3 %, average std error <= 15 %, every KS <= 0.15 on 500 clones; committed scores reproduced",
            fast: false,
            heavy: false,
            run: ma107_calibrated,
        },
        Case {
            name: "parents/roundtrip-npy",
            description: "40 calibrated Ottawa clones painted into a labelled u16 .npy image (30 voxels across the median grain), written, read back and extracted as parents: image identical, every grain back, each DNA parameter within tolerances derived from h/D",
            fast: false,
            heavy: false,
            run: roundtrip_npy,
        },
        Case {
            name: "parents/roundtrip-npy-20",
            description: "the round trip through .npy at 20 voxels across the median clone: every grain back, DNA within the h/D tolerances, roundness within 10 % of the clones' own on average",
            fast: false,
            heavy: false,
            run: roundtrip_npy_20,
        },
        Case {
            name: "parents/roundtrip-tiff",
            description: "the same clones through a multi-page TIFF stack: image identical, every grain back, DNA within the h/D tolerances",
            fast: false,
            heavy: false,
            run: roundtrip_tiff,
        },
        Case {
            name: "parents/roundtrip-stl",
            description: "the same clones as binary STL surfaces (marching cubes of their level sets), read back, checked closed and outward (Refuse policy), re-rasterised at 45³: DNA within the h/D tolerances",
            fast: false,
            heavy: false,
            run: roundtrip_stl,
        },
    ]
}

/// Why the voxel roundness misses issue 31's targets at 30 voxels per diameter (our finding).
const VOXEL_ROUNDNESS_REASON: &str = "issue 31, not met, and out of reach of any reading of the image at 30 voxels per diameter (our finding; ignored tests roundtrip_ambiguity and roundtrip_ambiguity_all of validate): for each clone, radii on its own 28 × 18 mesh whose painted image is identical voxel for voxel have own roundness from lo to hi around the clone's, so any reading errs on one of the three grains by at least (hi - lo)/(hi + lo): 11.5 % on average over the 40 clones (median 9.0 %; above 5 % for 34, above 20 % for 5, 38 % at most). Besides: the clones' own roundness is the corner rule read at their 45³ grid's scale, and even their exact surface re-gridded onto another 45³ cube (the canonical grid) reproduces it only to 2.6 % mean / 8.1 % worst, Spearman 0.947, slope 0.905 (at the voxel spacing: 5.9 % / 31.6 %, Spearman 0.73); a 30-voxel image quantises the corners (radii of 3-6 voxels) to ±h/2, and no reconstruction tried keeps both the corners and no staircase curvature: σ = 0.7 + canonical grid (the image path) 7.0 % / 38.6 %, Spearman 0.53, slope 0.34, bias +0.6 % on the clones of the issue-30 calibration (6.1 % / 35 %, 0.56, 0.38 on the previous calibration's clones; with the canonical grid reinitialised by fast sweeping 5.6 % / 31 %, 0.59, 0.42, at 6-7 ms more per grain; today's σ = 1 on the crop: 14 % / 68 %, 0.12, 0.03); σ = 1 / 1.5 + canonical +13 % / +24 % bias; constrained (sign-preserving) smoothing Spearman ≤ 0.75 with ±10 % bias; SH fits of degree 16-32 of the voxel surface Spearman ≤ 0.76 with +7-17 % bias; blur with a σ²H/2 curvature de-bias +21 % at σ = 2; the plain voxel surface fitted in the clones' own representation (28 × 18 Catmull-Rom radii, branch radial-fit-roundness) 4.9 % / 16 %, Spearman 0.83, slope 0.72, but each node keeps ±0.4 voxel of staircase that smooth grains read as corners (an ellipsoid reading 0.82 on its own level set reads 0.57 at 30 voxels), unbiased on the clones only by cancellation; the floor of every reconstruction: a voxelised sphere (roundness 1) of radius 8 / 12 / 20 voxels reads 0.48 / 0.45 / 0.42 through the image path, and the clones' own roundness (0.38-0.59, mean 0.50) sits near it, so the mean bias is small by coincidence (σ = 1 / 1.5 lift that sphere to 0.65 / 0.82 at 30 voxels but bias the clones +15 / +27 %; corner margins 0.25-1 lower every reading)";

/// Why the minimal-bending extraction misses issue 31's round-trip targets (our finding).
const BENDING_ROUNDTRIP_REASON: &str = "issue 31, not met, and out of reach of any reading of the image at 30 voxels per diameter (our finding; ignored tests roundtrip_ambiguity and roundtrip_ambiguity_all of validate): for each clone, radii on its own 28 × 18 mesh whose painted image is identical voxel for voxel have own roundness from lo to hi around the clone's, so any reading errs on one of the three grains by at least (hi - lo)/(hi + lo): 11.5 % on average over the 40 clones (median 9.0 %; above 5 % for 34, above 20 % for 5, 38 % at most). Besides: the minimal-bending surface (Lempitsky 2010: the least-bending level set that keeps every voxel centre on its side) with the calibrated corner correction (morph_dna::BENDING_CORNER_OFFSET) reads analytic grains within 4.1 % (levelset/voxel-roundness: ρ/a = 0.5 and superballs p = 3, 4 at 20-60 voxels across) and ranks the clones better than the image path (30 voxels per diameter: Spearman 0.76, slope 0.73, worst 26 %, against 0.53, 0.34, 39 %; 20 voxels: Spearman 0.70, slope 0.91, bias +0.6 %), but its mean error stays 7.7 % (+5.6 % bias) at 30 and 12 % at 20 voxels (without the correction it reads the clones 24 % rounder): the clones' own roundness counts relief of their 28 × 18 radial mesh (nodes about 3.4 voxels apart at 30 voxels per diameter) below what a voxel image resolves; how little relief matters: their 45³ roundness moves by 2.2 % mean (slope 0.91) under 0.75 % rms noise on their radii (0.11 voxel here) and by 3.7 % (slope 0.85) under 1 %, while radii least-squares fitted to the voxels in the clones' true frame differ from the true radii by 0.21 voxel rms although both keep 98-99 % of the voxel centres on their sides (a logistic fit to the voxel labels started from it: 0.22), so the image does not pin the radii closely enough for a slope of 0.9";

pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
    ExpectedFailure {
        case: "parents/ottawa-representative",
        metric: "median inertia elongation I/L vs population W/L (reported)",
        reason: "not like with like (our finding): I/L of the inertia-equivalent ellipsoid is not NIST's caliper W/L; on the same 71 grains it is 0.770 against NIST's 0.825, while our caliper I/L (0.816) agrees with NIST's own W/L to -0.004 and with the population to 0.012; the like-with-like checks above are the acceptance",
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "roundness mean |rel. error| <= 5 %",
        reason: VOXEL_ROUNDNESS_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "roundness worst |rel. error| <= 20 %",
        reason: VOXEL_ROUNDNESS_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "roundness Spearman rank correlation with the clones' own >= 0.9",
        reason: VOXEL_ROUNDNESS_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "roundness slope (voxel on own, least squares) 0.9-1.1",
        reason: VOXEL_ROUNDNESS_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "minimal bending: roundness mean |rel. error| <= 5 %",
        reason: BENDING_ROUNDTRIP_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "minimal bending: roundness worst |rel. error| <= 20 %",
        reason: BENDING_ROUNDTRIP_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "minimal bending: roundness mean signed rel. error within 5 % (no bias)",
        reason: BENDING_ROUNDTRIP_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "minimal bending: roundness Spearman rank correlation with the clones' own >= 0.9",
        reason: BENDING_ROUNDTRIP_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy",
        metric: "minimal bending: roundness slope (voxel on own, least squares) 0.9-1.1",
        reason: BENDING_ROUNDTRIP_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy-20",
        metric: "minimal bending: roundness mean |rel. error| <= 10 %",
        reason: BENDING_ROUNDTRIP_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy-20",
        metric: "minimal bending: roundness worst |rel. error| <= 40 %",
        reason: BENDING_ROUNDTRIP_REASON,
    },
    ExpectedFailure {
        case: "parents/roundtrip-npy-20",
        metric: "minimal bending: roundness Spearman rank correlation with the clones' own >= 0.9",
        reason: BENDING_ROUNDTRIP_REASON,
    },
];

fn err(e: impl std::fmt::Display) -> Error {
    Error::Computation {
        message: e.to_string(),
    }
}

/// Median of a non-empty sample (mean of the two middle values for an even count).
#[must_use]
pub fn median(values: &[f64]) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Shape medians of one set of grains.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeMedians {
    /// Grains.
    pub grains: usize,
    /// Median caliper flatness `MinorExtent / IntermediateExtent` (NIST T/W).
    pub extent_flatness: f64,
    /// Median caliper elongation `IntermediateExtent / MajorExtent` (NIST W/L).
    pub extent_elongation: f64,
    /// Median inertia-based flatness `S / I`.
    pub flatness: f64,
    /// Median inertia-based elongation `I / L`.
    pub elongation: f64,
    /// NIST's median thickness/width over the same grains.
    pub nist_t_over_w: f64,
    /// NIST's median width/length over the same grains.
    pub nist_w_over_l: f64,
    /// Median over the grains of (our caliper flatness − NIST's T/W).
    pub flatness_offset: f64,
    /// Median over the grains of (our caliper elongation − NIST's W/L).
    pub elongation_offset: f64,
}

/// Shape medians of the embedded Ottawa folder `folder` (45³ level sets of
/// the SH models, as the parents are built), beside NIST's rows for the
/// same grains.
///
/// # Errors
/// Fixture and measurement errors; a grain NIST's tables do not list.
pub fn shape_medians(folder: &str) -> Result<ShapeMedians, Error> {
    let models = grains::vcctl_models(folder)?;
    let wanted = [
        Descriptor::MajorExtent,
        Descriptor::IntermediateExtent,
        Descriptor::MinorExtent,
        Descriptor::Elongation,
        Descriptor::Flatness,
    ];
    let mut cols: [Vec<f64>; 8] = Default::default();
    for (name, model, _) in &models {
        let grid = cloner::grid_from_sh(model, 45, 1.1).map_err(err)?;
        let v = morph_dna::measure(&grid, &wanted, &MeasureParams::default()).map_err(err)?;
        let row = grains::geom_row(&format!("{name}.dat"))?
            .ok_or_else(|| err(format!("{name} is in no NIST geometry table")))?;
        let [l, w, t] = row.ltw;
        let (ef, ee) = (v[2] / v[1], v[1] / v[0]);
        let (tw, wl) = (t / w, w / l);
        for (c, x) in cols
            .iter_mut()
            .zip([ef, ee, v[4], v[3], tw, wl, ef - tw, ee - wl])
        {
            c.push(x);
        }
    }
    Ok(ShapeMedians {
        grains: models.len(),
        extent_flatness: median(&cols[0]),
        extent_elongation: median(&cols[1]),
        flatness: median(&cols[2]),
        elongation: median(&cols[3]),
        nist_t_over_w: median(&cols[4]),
        nist_w_over_l: median(&cols[5]),
        flatness_offset: median(&cols[6]),
        elongation_offset: median(&cols[7]),
    })
}

fn ottawa_representative() -> Result<Vec<Check>, Error> {
    let m = shape_medians(DEFAULT_PARENTS)?;
    Ok(vec![
        Check::new(
            "median caliper flatness (S/I extents) vs population T/W",
            POPULATION_T_OVER_W,
            m.extent_flatness,
            Tolerance::Within(0.03),
        ),
        Check::new(
            "median caliper elongation (I/L extents) vs population W/L",
            POPULATION_W_OVER_L,
            m.extent_elongation,
            Tolerance::Within(0.03),
        ),
        Check::new(
            "median inertia flatness S/I vs population T/W (reported)",
            POPULATION_T_OVER_W,
            m.flatness,
            Tolerance::Within(0.03),
        ),
        Check::new(
            "median inertia elongation I/L vs population W/L (reported)",
            POPULATION_W_OVER_L,
            m.elongation,
            Tolerance::Within(0.03),
        ),
        Check::new(
            "median (our caliper flatness - NIST T/W), same grains",
            0.0,
            m.flatness_offset,
            Tolerance::Within(0.03),
        ),
        Check::new(
            "median (our caliper elongation - NIST W/L), same grains",
            0.0,
            m.elongation_offset,
            Tolerance::Within(0.03),
        ),
        Check::new("grains", 71.0, m.grains as f64, Tolerance::Within(0.0)),
    ])
}

/// Grids painted one per cell of a cubic lattice into a labelled image
/// (labels `1..=n` in the grids' order), each cell the largest grid box plus
/// `gap` background voxels on every side, so no grain touches another or
/// the border. Used by the round-trip cases and `cargo xtask synth-scan`.
///
/// # Errors
/// [`Error::Computation`] for a non-positive voxel size, no grids, or a
/// painting error.
pub fn paint_lattice(
    grids: &[levelset::Grid],
    voxel: f64,
    gap: usize,
) -> Result<levelset::LabelImage, Error> {
    if !(voxel.is_finite() && voxel > 0.0) || grids.is_empty() {
        return Err(err(format!(
            "paint_lattice: voxel {voxel}, {} grids",
            grids.len()
        )));
    }
    let extent = grids
        .iter()
        .map(|g| {
            let s = g.spec();
            s.dims.iter().copied().max().unwrap_or(0) as f64 * s.spacing
        })
        .fold(0.0f64, f64::max);
    let cell = (extent / voxel).ceil() as usize + 2 * gap;
    let m = (1..).find(|m| m * m * m >= grids.len()).unwrap_or(1);
    let mut image =
        levelset::LabelImage::zeros([m * cell, m * cell, m * cell], voxel).map_err(err)?;
    for (n, g) in grids.iter().enumerate() {
        let (i, j, k) = (n % m, (n / m) % m, n / (m * m));
        let corner = levelset::nalgebra::Vector3::new(
            ((i * cell + gap) as f64) * voxel,
            ((j * cell + gap) as f64) * voxel,
            ((k * cell + gap) as f64) * voxel,
        );
        let offset = corner - g.spec().origin.coords;
        let label = u32::try_from(n + 1).map_err(err)?;
        image.paint(label, g, offset).map_err(err)?;
    }
    Ok(image)
}

/// Clones of the round trips: the first [`ROUNDTRIP_CLONES`] clones of the
/// calibrated Ottawa configuration, with their level sets and their own DNA
/// (the cloner's [`cloner::DNA`] order). Computed once per process.
pub const ROUNDTRIP_CLONES: u64 = 40;

/// Voxels across the median clone's equivalent diameter in the labelled
/// round trips (a typical CT resolution for sand: 20–40 voxels per grain).
pub const ROUNDTRIP_VOXELS_PER_DIAMETER: f64 = 30.0;

/// Level sets of clones and their own DNA rows.
type GridsAndDna = (Vec<levelset::Grid>, Vec<Vec<f64>>);

/// The clone model of the round trips (the calibrated Ottawa configuration, level sets and
/// DNA on) and its first [`ROUNDTRIP_CLONES`] clones.
pub(crate) fn roundtrip_model() -> Result<(cloner::CloneModel, cloner::Run), Error> {
    let text = crate::fixtures::calibrated("gsc2-ottawa.ron")?;
    let cal = cloner::Calibrated::from_ron(text).map_err(err)?;
    let mut params = cal.params;
    params.outputs = cloner::Outputs {
        level_set: true,
        dna: true,
    };
    let parents = grains::ottawa_parents()?;
    let model = cloner::CloneModel::fit(&parents, &params).map_err(err)?;
    let run = model
        .run(0..ROUNDTRIP_CLONES, cloner::Hooks::default())
        .map_err(err)?;
    Ok((model, run))
}

fn roundtrip_clones() -> Result<&'static GridsAndDna, Error> {
    static CLONES: std::sync::OnceLock<Result<GridsAndDna, String>> = std::sync::OnceLock::new();
    CLONES
        .get_or_init(|| {
            let run = || -> Result<GridsAndDna, Error> {
                let (_, run) = roundtrip_model()?;
                let mut grids = Vec::new();
                let mut dna = Vec::new();
                for c in run.clones {
                    if let (Some(g), Some(d)) = (c.grid, c.dna) {
                        grids.push(g);
                        dna.push(d);
                    }
                }
                Ok((grids, dna))
            };
            run().map_err(|e| e.to_string())
        })
        .as_ref()
        .map_err(|m| Error::Computation { message: m.clone() })
}

/// Per-descriptor relative differences |re-read − clone| / clone.
fn relative_differences(own: &[Vec<f64>], reread: &[Vec<f64>]) -> Vec<Vec<f64>> {
    (0..cloner::DNA.len())
        .map(|k| {
            own.iter()
                .zip(reread)
                .map(|(a, b)| ((b[k] - a[k]) / a[k]).abs())
                .collect()
        })
        .collect()
}

fn measure_dna(grids: &[&levelset::Grid], params: &MeasureParams) -> Result<Vec<Vec<f64>>, Error> {
    grids
        .iter()
        .map(|g| morph_dna::measure(g, &cloner::DNA, params).map_err(err))
        .collect()
}

/// A round trip's checks, the clones' own DNA rows and the re-read ones (same order).
type RoundTrip = (
    Vec<Check>,
    Vec<Vec<f64>>,
    Vec<Vec<f64>>,
    levelset::LabelImage,
);

/// Round trip through a labelled image written and read by `write`/`read`, at
/// `voxels_per_diameter` voxels across the median clone, extracted and measured as the
/// image path does ([`levelset::ExtractParams::voxel_images`],
/// [`MeasureParams::voxel_images`]): the checks, the clones' own DNA rows and the re-read
/// ones (in the extraction's label order), and the image read back.
fn roundtrip_image(
    voxels_per_diameter: f64,
    write: impl Fn(&levelset::LabelImage) -> Result<Vec<u8>, levelset::Error>,
    read: impl Fn(&[u8], f64) -> Result<levelset::LabelImage, levelset::Error>,
) -> Result<RoundTrip, Error> {
    let (grids, own) = roundtrip_clones()?;
    let d: Vec<f64> = own.iter().map(|r| r[1]).collect();
    let h = median(&d) / voxels_per_diameter;
    let image = paint_lattice(grids, h, 3)?;
    let bytes = write(&image).map_err(err)?;
    let back = read(&bytes, h).map_err(err)?;
    let same = back.dims == image.dims && back.labels == image.labels;
    let ex = back
        .extract(&levelset::ExtractParams::voxel_images())
        .map_err(err)?;
    let mut checks = vec![
        Check::new(
            "image read back voxel for voxel (1 = identical)",
            1.0,
            f64::from(u8::from(same)),
            Tolerance::Within(0.0),
        ),
        Check::new(
            "grains extracted",
            grids.len() as f64,
            ex.grains.len() as f64,
            Tolerance::Within(0.0),
        ),
    ];
    let by_label: Vec<&levelset::Grid> = ex.grains.iter().map(|g| &g.grid).collect();
    let labels: Vec<usize> = ex.grains.iter().map(|g| g.label as usize - 1).collect();
    let reread = measure_dna(&by_label, &MeasureParams::voxel_images())?;
    let own: Vec<Vec<f64>> = labels.iter().map(|&i| own[i].clone()).collect();
    dna_checks(&mut checks, &own, &reread, h / median(&d), "voxel");
    Ok((checks, own, reread, back))
}

/// Index of the roundness in [`cloner::DNA`].
fn roundness_column() -> Result<usize, Error> {
    cloner::DNA
        .iter()
        .position(|d| *d == Descriptor::Roundness)
        .ok_or_else(|| err("roundness is not a DNA parameter"))
}

/// Spearman's rank correlation (average ranks for ties).
#[must_use]
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let ranks = |v: &[f64]| {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&i, &j| v[i].total_cmp(&v[j]));
        let mut r = vec![0.0; v.len()];
        let mut s = 0;
        while s < idx.len() {
            let mut e = s + 1;
            while e < idx.len() && v[idx[e]] == v[idx[s]] {
                e += 1;
            }
            let avg = 0.5 * (s + e - 1) as f64;
            for &i in &idx[s..e] {
                r[i] = avg;
            }
            s = e;
        }
        r
    };
    let (ra, rb) = (ranks(a), ranks(b));
    let n = ra.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in ra.iter().zip(&rb) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

/// Least-squares slope of `y` on `x`.
#[must_use]
pub fn ols_slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
    }
    sxy / sxx
}

/// The issue-31 acceptance of the voxel roundness against the clones' own: mean and worst
/// relative error, and (`ranking`) Spearman's ρ ≥ 0.9 and a slope of 0.9–1.1 (no pull
/// toward the population mean).
fn roundness_checks(
    checks: &mut Vec<Check>,
    x: &[f64],
    y: &[f64],
    (mean_max, worst_max): (f64, f64),
    ranking: bool,
    prefix: &str,
) {
    let rel: Vec<f64> = x.iter().zip(y).map(|(a, b)| ((b - a) / a).abs()).collect();
    let mean = rel.iter().sum::<f64>() / rel.len().max(1) as f64;
    let worst = rel.iter().fold(0.0f64, |a, b| a.max(*b));
    let bias = x.iter().zip(y).map(|(a, b)| (b - a) / a).sum::<f64>() / x.len().max(1) as f64;
    checks.push(Check::new(
        format!(
            "{prefix}roundness mean |rel. error| <= {:.0} %",
            100.0 * mean_max
        ),
        mean_max,
        mean,
        Tolerance::AtMost(0.0),
    ));
    checks.push(Check::new(
        format!(
            "{prefix}roundness worst |rel. error| <= {:.0} %",
            100.0 * worst_max
        ),
        worst_max,
        worst,
        Tolerance::AtMost(0.0),
    ));
    checks.push(Check::new(
        format!("{prefix}roundness mean signed rel. error within 5 % (no bias)"),
        0.0,
        bias,
        Tolerance::Within(0.05),
    ));
    if ranking {
        checks.push(Check::new(
            format!("{prefix}roundness Spearman rank correlation with the clones' own >= 0.9"),
            0.9,
            spearman(x, y),
            Tolerance::AtLeast(0.0),
        ));
        checks.push(Check::new(
            format!("{prefix}roundness slope (voxel on own, least squares) 0.9-1.1"),
            1.0,
            ols_slope(x, y),
            Tolerance::Within(0.1),
        ));
    }
}

/// The tolerances of the round trips, derived from the resolution `h / D`
/// (`h` the voxel or grid spacing, `D` the median equivalent diameter; both
/// round trips here have h/D = 1/30):
///
/// * **equivalent diameter** — the re-read surface is fitted to the voxel
///   count (labelled) or integrated over the marching-cubes mesh (STL), so
///   the volume error is a boundary-layer term: a surface misplaced by at
///   most δ = h/4 on average changes V by A·δ, i.e. ΔV/V = 6·δ/D for a
///   sphere and ΔD/D = ΔV/3V = 2·δ/D = h/(2D); mean tolerance h/(2D), worst
///   2× that;
/// * **aspect ratio, min principal dimension, flatness** — second moments of
///   the same volume: the boundary term ΔI/I ≈ 10·δ/D shifts a principal
///   length by 5·δ/D = 5h/(4D) at most; mean tolerance 5h/(4D), worst 2×;
/// * **V/S** — the area of a re-sampled surface differs by its sub-grid
///   roughness (the smoothing of voxel staircases or of the marching-cubes
///   facets), ≈ 2·h/D on curved grains: mean tolerance 2h/D, worst 2×;
/// * **roundness** — a curvature ratio (corner curvature radius over the
///   inscribed radius): curvature is a second derivative of the surface, so
///   its resampling error is O(1) per corner where the corner radius is a
///   few h, and only the average over corners is stable; mean tolerance
///   4h/D·(D / r_corner ≈ 5) = 20h/D, worst 2×.
fn dna_checks(checks: &mut Vec<Check>, own: &[Vec<f64>], reread: &[Vec<f64>], hd: f64, what: &str) {
    let rel = relative_differences(own, reread);
    let factors = [1.25, 0.5, 20.0, 2.0, 1.25, 1.25];
    for (k, d) in cloner::DNA.iter().enumerate() {
        let mean = rel[k].iter().sum::<f64>() / rel[k].len().max(1) as f64;
        let worst = rel[k].iter().fold(0.0f64, |a, b| a.max(*b));
        let tol = factors[k] * hd;
        checks.push(Check::new(
            format!(
                "{} mean |rel. diff| <= {:.2} {what}/D",
                d.name(),
                factors[k]
            ),
            tol,
            mean,
            Tolerance::AtMost(0.0),
        ));
        checks.push(Check::new(
            format!(
                "{} worst |rel. diff| <= {:.2} {what}/D",
                d.name(),
                2.0 * factors[k]
            ),
            2.0 * tol,
            worst,
            Tolerance::AtMost(0.0),
        ));
    }
}

fn roundtrip_npy_at(voxels_per_diameter: f64) -> Result<RoundTrip, Error> {
    roundtrip_image(
        voxels_per_diameter,
        |img| {
            let mut buf = Vec::new();
            levelset::io::write_npy(&mut buf, img, levelset::io::Dtype::U16)?;
            Ok(buf)
        },
        |b, h| levelset::io::read_npy(b, h),
    )
}

fn roundtrip_npy() -> Result<Vec<Check>, Error> {
    roundtrip_npy_roundness(ROUNDTRIP_VOXELS_PER_DIAMETER, (0.05, 0.20), true)
}

fn roundtrip_npy_20() -> Result<Vec<Check>, Error> {
    roundtrip_npy_roundness(20.0, (0.10, 0.40), false)
}

/// The round trip through `.npy` with the roundness checks of the image path (`ranking`:
/// also Spearman and slope) and of the minimal-bending path on the same image read back.
fn roundtrip_npy_roundness(
    voxels_per_diameter: f64,
    bounds: (f64, f64),
    ranking: bool,
) -> Result<Vec<Check>, Error> {
    let (mut checks, own, reread, image) = roundtrip_npy_at(voxels_per_diameter)?;
    let k = roundness_column()?;
    let column = |rows: &[Vec<f64>]| -> Vec<f64> { rows.iter().map(|r| r[k]).collect() };
    roundness_checks(
        &mut checks,
        &column(&own),
        &column(&reread),
        bounds,
        ranking,
        "",
    );
    let (own, bent) = bending_roundness(&image)?;
    roundness_checks(&mut checks, &own, &bent, bounds, true, BENDING);
    Ok(checks)
}

/// Prefix of the round-trip checks of the minimal-bending extraction
/// (`levelset::ExtractParams::minimal_bending`), measured beside the image path.
const BENDING: &str = "minimal bending: ";

/// The clones' own roundness and that of the grains of the round trip's `image` (label
/// `i + 1` is clone `i`) extracted with `levelset::ExtractParams::minimal_bending` and
/// measured with `morph_dna::MeasureParams::minimal_bending`, in the extraction's order.
fn bending_roundness(image: &levelset::LabelImage) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let (_, own) = roundtrip_clones()?;
    let k = roundness_column()?;
    let ex = image
        .extract(&levelset::ExtractParams::minimal_bending())
        .map_err(err)?;
    let mut x = Vec::with_capacity(ex.grains.len());
    let mut y = Vec::with_capacity(ex.grains.len());
    for g in &ex.grains {
        let i = g.label as usize - 1;
        let row = own.get(i).ok_or_else(|| err("a label without its clone"))?;
        x.push(row[k]);
        y.push(
            morph_dna::measure(
                &g.grid,
                &[Descriptor::Roundness],
                &MeasureParams::minimal_bending(),
            )
            .map_err(err)?[0],
        );
    }
    Ok((x, y))
}

fn roundtrip_tiff() -> Result<Vec<Check>, Error> {
    Ok(roundtrip_image(
        ROUNDTRIP_VOXELS_PER_DIAMETER,
        |img| {
            let mut buf = std::io::Cursor::new(Vec::new());
            levelset::io::write_tiff(&mut buf, img)?;
            Ok(buf.into_inner())
        },
        |b, h| levelset::io::read_tiff(std::io::Cursor::new(b), h),
    )?
    .0)
}

fn roundtrip_stl() -> Result<Vec<Check>, Error> {
    let (grids, own) = roundtrip_clones()?;
    let d: Vec<f64> = own.iter().map(|r| r[1]).collect();
    let mut reread_grids = Vec::new();
    let mut hd = 0.0f64;
    for g in grids {
        let mut buf = Vec::new();
        levelset::io::write_stl_binary(&mut buf, &g.marching_cubes()).map_err(err)?;
        let mesh = levelset::io::read_stl(buf.as_slice()).map_err(err)?;
        let (mesh, _) = mesh
            .prepare_closed(levelset::Orientation::Refuse)
            .map_err(err)?;
        let r = cloner::grid_from_mesh(&mesh, 45, 1.1).map_err(err)?;
        hd = hd.max(r.spec().spacing.max(g.spec().spacing));
        reread_grids.push(r);
    }
    let hd = hd / median(&d);
    let refs: Vec<&levelset::Grid> = reread_grids.iter().collect();
    let reread = measure_dna(&refs, &MeasureParams::default())?;
    let mut checks = vec![Check::new(
        "grains read back",
        grids.len() as f64,
        reread.len() as f64,
        Tolerance::Within(0.0),
    )];
    dna_checks(&mut checks, own, &reread, hd, "h");
    Ok(checks)
}

/// The committed calibration of the crushed aggregate MA107-6 (written by
/// `cargo xtask calibrate --parents fixtures/grains/vcctl/MA107-6-fine --out
/// fixtures/calibrated/gsc2-ma107-6.ron --target-mean 3 --target-std 15
/// --target-ks 0.15`), re-run on the embedded grains, built exactly as the
/// file path builds them (45³ level sets of each file's own degree).
fn ma107_calibrated() -> Result<Vec<Check>, Error> {
    let name = "gsc2-ma107-6.ron";
    let parents = grains::vcctl_parents("vcctl/MA107-6-fine")?;
    let (cal, s, clones, attempts) = super::cloner::rerun_calibration(name, &parents)?;
    let mut out = Vec::new();
    for (k, d) in cloner::TABLES_4_5.iter().enumerate() {
        out.push(Check::new(
            format!("{d} KS <= 0.15 (target; 5 % critical value for 60 vs 500 is 0.19)"),
            0.15,
            s.ks[k],
            Tolerance::AtMost(0.0),
        ));
    }
    out.extend([
        Check::new(
            "average mean error % <= 3 (target)",
            3.0,
            s.mean_error_avg_pct,
            Tolerance::AtMost(0.0),
        ),
        Check::new(
            "average std error % <= 15 (target)",
            15.0,
            s.std_error_avg_pct,
            Tolerance::AtMost(0.0),
        ),
        Check::new(
            "parents",
            60.0,
            parents.len() as f64,
            Tolerance::Within(0.0),
        ),
        Check::new(
            "clones >= 500",
            500.0,
            clones as f64,
            Tolerance::AtLeast(0.0),
        ),
        Check::new(
            "average mean error reproduces the committed calibration",
            cal.scores.mean_error_avg_pct,
            s.mean_error_avg_pct,
            Tolerance::Relative(1e-6),
        ),
        Check::new(
            "candidates drawn reproduce the committed calibration",
            cal.attempts as f64,
            attempts as f64,
            Tolerance::Within(0.0),
        ),
    ]);
    Ok(out)
}
