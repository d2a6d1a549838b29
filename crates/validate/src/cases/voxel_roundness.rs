//! `levelset/voxel-roundness` (issue 31): the roundness of analytic grains voxelised at 20,
//! 30 and 60 voxels across, through the image path (`levelset::ExtractParams::voxel_images`,
//! `morph_dna::MeasureParams::voxel_images`), against closed-form values, not against the
//! pipeline at high resolution.
//!
//! * **Sphere** of radius `a`: κ₁ = 1/a = 1/r_ins everywhere, no corner, roundness **1**
//!   (the limit of both families below); it shows the floor of the voxel reading.
//! * **Rounded cube** of half-side `a` whose edges and corners are rounded with radius ρ
//!   (the Minkowski sum of a cube of half-side a − ρ and a ball of radius ρ): faces are
//!   flat, edges are cylinders and corners spheres of radius ρ, so every corner point has
//!   κ₁ = 1/ρ > 1/a, the inscribed radius is `a`, and the roundness is **ρ / a** exactly.
//! * **Superball** `|x|ᵖ + |y|ᵖ + |z|ᵖ = aᵖ` (p > 2): it contains the ball of radius `a`
//!   (its inscribed radius) and its curvature varies continuously, so there is no single
//!   corner radius; the reference is the definition itself (module docs of
//!   `morph_dna::measure`: corners κ₁ > 1/r_ins, `r_corner = 1/⟨κ₁⟩` area-weighted,
//!   roundness `r_corner / r_ins`) evaluated on the analytic surface:
//!   [`superball_roundness`], κ₁ from the implicit function's gradient and Hessian in
//!   closed form, integrated by the midpoint rule over (θ, φ) with the area element
//!   `r² / (n·u) sin θ dθ dφ` of a star-shaped surface.
//!
//! The grains are rotated and placed off the voxel lattice, so the staircases are generic.
//! Every grain is measured twice: through the image path, and extracted with
//! `levelset::ExtractParams::minimal_bending` (checks prefixed "minimal bending: ").

use std::f64::consts::PI;

use levelset::nalgebra::{Matrix3, Point3, Rotation3, Unit, Vector3};
use levelset::{ExtractParams, LabelImage};
use morph_dna::{Descriptor, MeasureParams};

use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![Case {
        name: "levelset/voxel-roundness",
        description: "a sphere, rounded cubes (ρ/a = 0.3, 0.5) and superballs (p = 3, 4) voxelised at 20, 30 and 60 voxels across (rotated, off-lattice), extracted and measured as the image path does: roundness within 5 % of the closed form at 30 and 60 voxels (reported at 20, within 10 %)",
        fast: false,
        heavy: false,
        run: voxel_roundness,
    }]
}

/// Why the analytic grains miss the closed forms (our finding, issue 31).
const REASON: &str = "issue 31, not met (our finding): with σ = 0.7 (the blur under which the clones' round trip is unbiased) the voxel staircase leaves curvature noise that the corner rule (κ₁ > 1/r_ins) counts on the gently curved parts, so every shape reads 0.35-0.48 (a pull toward one value); exact surfaces on the canonical 45³ grid read 0.335-0.377 for ρ/a = 0.3 (ρ is 4 cells: the grid's floor), 0.51-0.52 for ρ/a = 0.5, 0.665-0.68 for p = 3 (0.664) and 0.527-0.567 for p = 4 (0.526); a σ = 2 blur with a σ²H/2 curvature de-bias reaches 0.35 / 0.52 / 0.63 / 0.52 at 60 voxels but biases the clones' round trip by +21 %; the plain voxel surface fitted in the clones' 28 × 18 Catmull-Rom representation (branch radial-fit-roundness) reads ρ/a = 0.5 within 3 % at 30 and 60 voxels and p = 4 within 1 % at 60, but ρ/a = 0.3 +22 % (the mesh cannot carry it) and p = 3 -19 % / p = 4 -6 % at 30 (node staircase read as corners); even a voxelised sphere (roundness 1) of radius 8 / 12 / 20 voxels reads 0.48 / 0.45 / 0.42 through the image path";

/// Why even the sphere misses (our finding, issue 31).
const SPHERE_REASON: &str = "issue 31, not met (our finding): the floor of the voxel roundness; the corner rule's threshold κ₁ > 1/r_ins is a sphere's own curvature, so on a voxelised sphere the staircase's curvature noise (local curvature estimators of digitised surfaces converge only as h^(1/3), Coeurjolly, Lachaud & Levallois 2014: ≈ 40 % at a 15-voxel radius) sorts points into corners; it reads 0.42-0.51 at 16-90 voxels across through the image path, 0.17-0.58 on the native grid; a σ = 1.5 blur lifts it to 0.82 at 30 voxels but biases the clones' round trip by +27 %";

/// Why the minimal-bending extraction still misses the closed forms (our finding, issue 31).
const BENDING_REASON: &str = "issue 31, not met (our finding): ρ/a = 0.3 is below the canonical 45³ grid's floor (its corner radius is 4 grid cells: exact surfaces on that grid read 0.335-0.377); the minimal-bending surface with the calibrated corner correction (levelset::ExtractParams::minimal_bending, morph_dna::MeasureParams::minimal_bending) reads 0.370 / 0.343 / 0.328 at 20 / 30 / 60 voxels across (without the correction 0.46 / 0.40 / 0.36: the least-bending surface inside the voxel tube widens corners by about 0.8 voxel of radius), while ρ/a = 0.5 and the superballs p = 3, 4 read within 4.1 % at every resolution";

/// Why the minimal-bending extraction still misses the sphere (our finding, issue 31).
const BENDING_SPHERE_REASON: &str = "issue 31, not met (our finding): the minimal-bending surface lifts the voxelised sphere from 0.44-0.47 (the image path) to 0.84 / 0.91 / 0.88 at 20 / 30 / 60 voxels across, 0.79 / 0.88 / 0.87 with the corner correction (which makes every point of a sphere a candidate corner); the rest is curvature that survives where the surface touches the voxel centres: more iterations change nothing (50 and 1000 read the same) and a wider band (6 voxels: 0.93 at 30 and 60 without the correction) widens the corners of the other shapes";

pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "sphere at 20 voxels across",
        reason: SPHERE_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "sphere at 30 voxels across",
        reason: SPHERE_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "sphere at 60 voxels across",
        reason: SPHERE_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "rounded cube ρ/a = 0.3 at 20 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "rounded cube ρ/a = 0.3 at 30 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "rounded cube ρ/a = 0.3 at 60 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "rounded cube ρ/a = 0.5 at 20 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "rounded cube ρ/a = 0.5 at 30 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "rounded cube ρ/a = 0.5 at 60 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "superball p = 3 at 20 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "superball p = 3 at 30 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "superball p = 3 at 60 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "superball p = 4 at 20 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "superball p = 4 at 30 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "superball p = 4 at 60 voxels across",
        reason: REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "minimal bending: sphere at 20 voxels across",
        reason: BENDING_SPHERE_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "minimal bending: sphere at 30 voxels across",
        reason: BENDING_SPHERE_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "minimal bending: sphere at 60 voxels across",
        reason: BENDING_SPHERE_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "minimal bending: rounded cube ρ/a = 0.3 at 20 voxels across",
        reason: BENDING_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "minimal bending: rounded cube ρ/a = 0.3 at 30 voxels across",
        reason: BENDING_REASON,
    },
    ExpectedFailure {
        case: "levelset/voxel-roundness",
        metric: "minimal bending: rounded cube ρ/a = 0.3 at 60 voxels across",
        reason: BENDING_REASON,
    },
];

/// Prefix of the checks of the minimal-bending extraction
/// (`levelset::ExtractParams::minimal_bending`), measured beside the image path.
const BENDING: &str = "minimal bending: ";

fn err(e: impl std::fmt::Display) -> Error {
    Error::Computation {
        message: e.to_string(),
    }
}

/// An analytic grain: inside test in its own frame, and its closed-form roundness.
#[derive(Debug, Clone, Copy)]
enum Shape {
    /// The unit ball: no point is sharper than the inscribed sphere, roundness 1 (the
    /// limit of both families, ρ/a = 1 and p = 2).
    Sphere,
    /// Half-side `a` = 1, corner radius ρ.
    RoundedCube { rho: f64 },
    /// `|x|ᵖ + |y|ᵖ + |z|ᵖ = 1`.
    Superball { p: f64 },
}

impl Shape {
    fn inside(self, q: &Vector3<f64>) -> bool {
        match self {
            Self::Sphere => q.norm() < 1.0,
            Self::RoundedCube { rho } => {
                let d = q.abs() - Vector3::repeat(1.0 - rho);
                let outside = d.sup(&Vector3::zeros()).norm();
                outside + d.max().min(0.0) - rho < 0.0
            }
            Self::Superball { p } => q.iter().map(|x| x.abs().powf(p)).sum::<f64>() < 1.0,
        }
    }

    fn reference(self) -> f64 {
        match self {
            Self::Sphere => 1.0,
            Self::RoundedCube { rho } => rho,
            Self::Superball { p } => superball_roundness(p, 800),
        }
    }

    fn name(self) -> String {
        match self {
            Self::Sphere => "sphere".to_owned(),
            Self::RoundedCube { rho } => format!("rounded cube ρ/a = {rho}"),
            Self::Superball { p } => format!("superball p = {p}"),
        }
    }
}

/// The roundness of the superball `|x|ᵖ + |y|ᵖ + |z|ᵖ = 1` (p ≥ 2, inscribed radius 1) by
/// the definition of `morph_dna::measure`, integrated on the analytic surface with `n × 2n`
/// midpoint cells in (θ, φ). p = 2 (the sphere, no corner) gives 1.
#[must_use]
pub(crate) fn superball_roundness(p: f64, n: usize) -> f64 {
    let (mut sw, mut swk) = (0.0, 0.0);
    let d = PI / n as f64;
    for i in 0..n {
        let theta = (i as f64 + 0.5) * d;
        for j in 0..2 * n {
            let phi = (j as f64 + 0.5) * d;
            let u = Vector3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let r = u
                .iter()
                .map(|x| x.abs().powf(p))
                .sum::<f64>()
                .powf(-1.0 / p);
            let x = u * r;
            let g = x.map(|c| p * c.signum() * c.abs().powf(p - 1.0));
            let hess = Matrix3::from_diagonal(&x.map(|c| p * (p - 1.0) * c.abs().powf(p - 2.0)));
            let gn = g.norm();
            let nrm = g / gn;
            let helper = if nrm.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            let t1 = nrm.cross(&helper).normalize();
            let t2 = nrm.cross(&t1);
            let (a, b, c) = (
                t1.dot(&(hess * t1)) / gn,
                t1.dot(&(hess * t2)) / gn,
                t2.dot(&(hess * t2)) / gn,
            );
            let k1 = 0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt();
            let da = r * r / nrm.dot(&u) * theta.sin() * d * d;
            if k1 > 1.0 {
                sw += da;
                swk += da * k1;
            }
        }
    }
    if swk == 0.0 { 1.0 } else { sw / swk }
}

/// The shape scaled to `across` voxels across (2a = across·h, h = 1), rotated and placed
/// off the lattice, as a one-label image.
fn voxelise(shape: Shape, across: f64) -> Result<LabelImage, Error> {
    voxelise_posed(
        shape,
        across,
        Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)), 0.5),
        Vector3::new(0.37, 0.21, 0.13),
    )
}

/// [`voxelise`] with the rotation and the centre's offset from the lattice given.
fn voxelise_posed(
    shape: Shape,
    across: f64,
    rot: Rotation3<f64>,
    offset: Vector3<f64>,
) -> Result<LabelImage, Error> {
    let a = 0.5 * across;
    let inv = rot.inverse();
    let n = (2.0 * a * 3f64.sqrt()).ceil() as usize + 8;
    let centre = Point3::from(Vector3::repeat(0.5 * n as f64) + offset);
    let mut image = LabelImage::zeros([n, n, n], 1.0).map_err(err)?;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let q = inv * (image.voxel_centre(i, j, k) - centre) / a;
                if shape.inside(&q) {
                    let idx = image.index(i, j, k);
                    image.labels[idx] = 1;
                }
            }
        }
    }
    Ok(image)
}

fn voxel_roundness() -> Result<Vec<Check>, Error> {
    let shapes = [
        Shape::Sphere,
        Shape::RoundedCube { rho: 0.3 },
        Shape::RoundedCube { rho: 0.5 },
        Shape::Superball { p: 3.0 },
        Shape::Superball { p: 4.0 },
    ];
    let mut checks = Vec::new();
    for shape in shapes {
        let reference = shape.reference();
        for across in [20.0, 30.0, 60.0] {
            let image = voxelise(shape, across)?;
            for (method, params, measure) in [
                (
                    "",
                    ExtractParams::voxel_images(),
                    MeasureParams::voxel_images(),
                ),
                (
                    BENDING,
                    ExtractParams::minimal_bending(),
                    MeasureParams::minimal_bending(),
                ),
            ] {
                let ex = image.extract(&params).map_err(err)?;
                let grain = ex
                    .grains
                    .first()
                    .ok_or_else(|| err("the grain was not extracted"))?;
                let r = morph_dna::measure(&grain.grid, &[Descriptor::Roundness], &measure)
                    .map_err(err)?[0];
                let tol = if across < 25.0 { 0.10 } else { 0.05 };
                checks.push(Check::new(
                    format!("{method}{} at {across} voxels across", shape.name()),
                    reference,
                    r,
                    Tolerance::Relative(tol),
                ));
            }
        }
    }
    Ok(checks)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quadrature of the reference: the sphere (p = 2) has no corner; the superball's
    /// value converges (800 and 1600 cells per half-turn agree to 1e-3) and falls with p.
    #[test]
    fn superball_reference_converges_and_orders() {
        assert!((superball_roundness(2.0, 50) - 1.0).abs() < 1e-12);
        let (r3, r4) = (superball_roundness(3.0, 800), superball_roundness(4.0, 800));
        assert!(
            (r3 - superball_roundness(3.0, 1600)).abs() < 1e-3 * r3,
            "{r3}"
        );
        assert!(
            (r4 - superball_roundness(4.0, 1600)).abs() < 1e-3 * r4,
            "{r4}"
        );
        assert!(r4 < r3 && r3 < 1.0, "{r3} {r4}");
    }

    /// The calibration of `morph_dna::BENDING_CORNER_OFFSET`: voxelised analytic grains
    /// that `levelset/voxel-roundness` does not use (rounded cubes ρ/a = 0.4, 0.6 and
    /// superballs p = 2.5, 3.5 at 25, 40 and 50 voxels across, another rotation and
    /// lattice offset), extracted with `ExtractParams::minimal_bending`; the offset on a
    /// 0.1-voxel grid in [0, 1.5] that minimises the RMS relative error against the closed
    /// forms is the constant (measured: 0.8, RMS 3.96 %; 0.7 and 0.9: 4.09 % and 4.12 %;
    /// no correction: 9.45 %). Slow in the test profile: `cargo test --release -p validate -- --ignored
    /// bending_offset_calibration --nocapture`.
    #[test]
    #[ignore = "calibration sweep: run in release with --ignored"]
    #[allow(clippy::print_stdout, reason = "the calibration table")]
    fn bending_offset_calibration() {
        let shapes = [
            Shape::RoundedCube { rho: 0.4 },
            Shape::RoundedCube { rho: 0.6 },
            Shape::Superball { p: 2.5 },
            Shape::Superball { p: 3.5 },
        ];
        let offsets: Vec<f64> = (0..=15).map(|i| f64::from(i) * 0.1).collect();
        let mut errors = vec![Vec::new(); offsets.len()];
        let rot =
            Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(3.0, 1.0, 2.0)), 0.9);
        for shape in shapes {
            let reference = shape.reference();
            for across in [25.0, 40.0, 50.0] {
                let image = voxelise_posed(shape, across, rot, Vector3::new(0.11, 0.47, 0.29))
                    .expect("image");
                let ex = image
                    .extract(&ExtractParams::minimal_bending())
                    .expect("extract");
                let grid = &ex.grains[0].grid;
                let mut line = format!("{} at {across}:", shape.name());
                for (o, e) in offsets.iter().zip(errors.iter_mut()) {
                    let p = MeasureParams {
                        corner_radius_offset: *o,
                        ..MeasureParams::minimal_bending()
                    };
                    let r = morph_dna::measure(grid, &[Descriptor::Roundness], &p).expect("r")[0];
                    e.push(r / reference - 1.0);
                    line += &format!(" {o:.1}: {:+.1} %", 100.0 * (r / reference - 1.0));
                }
                println!("{line}");
            }
        }
        let rms: Vec<f64> = errors
            .iter()
            .map(|e| (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt())
            .collect();
        let best = (0..rms.len())
            .min_by(|&a, &b| rms[a].total_cmp(&rms[b]))
            .expect("offsets");
        for (o, r) in offsets.iter().zip(&rms) {
            println!("offset {o:.1}: RMS {:.2} %", 100.0 * r);
        }
        assert!(
            (offsets[best] - morph_dna::BENDING_CORNER_OFFSET).abs() < 1e-9,
            "calibrated {} against the constant {}",
            offsets[best],
            morph_dna::BENDING_CORNER_OFFSET
        );
    }

    /// The rounded cube's inside test against its closed form (face, edge, corner).
    #[test]
    fn rounded_cube_inside_test() {
        let s = Shape::RoundedCube { rho: 0.5 };
        assert!(s.inside(&Vector3::new(0.99, 0.0, 0.0)));
        assert!(!s.inside(&Vector3::new(1.01, 0.0, 0.0)));
        // corner sphere centred at (0.5, 0.5, 0.5), radius 0.5
        let c = Vector3::repeat(0.5) + Vector3::repeat(0.5 / 3f64.sqrt()) * 0.99;
        assert!(s.inside(&c));
        let c = Vector3::repeat(0.5) + Vector3::repeat(0.5 / 3f64.sqrt()) * 1.01;
        assert!(!s.inside(&c));
    }
}
