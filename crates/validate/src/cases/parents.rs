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
    vec![Case {
        name: "parents/ottawa-representative",
        description: "median flatness and elongation of the default parents (71 random Ottawa grains, caliper extents along the principal axes) within 0.03 of NIST's population medians T/W 0.744 and W/L 0.804",
        fast: false,
        run: ottawa_representative,
    }]
}

pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[ExpectedFailure {
    case: "parents/ottawa-representative",
    metric: "median inertia elongation I/L vs population W/L (reported)",
    reason: "not like with like (our finding): I/L of the inertia-equivalent ellipsoid is not NIST's caliper W/L; on the same 71 grains it is 0.770 against NIST's 0.825, while our caliper I/L (0.816) agrees with NIST's own W/L to -0.004 and with the population to 0.012; the like-with-like checks above are the acceptance",
}];

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
