//! Multi-sphere clumps of two analytic grains at the cloner's level-set resolution (45³
//! nodes over ±1.1 · r_max, `cloner::Params::default()`): an ellipsoid with semi-axes
//! 2 : 1.5 : 1 and a 2 × 1.5 × 1 box with edges rounded at radius 0.15. For N = 10, 20, 50
//! spheres, as placed by the CLUMP generator (inscribed spheres) and with the offset volume
//! correction (the default), it prints the volume error of the union, the relative errors
//! of the mean and the worst principal moment of inertia, and the mean and largest distance
//! from the grain's surface to the clump's, in equivalent diameters.
//!
//! Run with `cargo run --release -p levelset --example clump_report`.
// An example prints its report (the library never does).
#![allow(clippy::print_stdout)]

use levelset::nalgebra::{Isometry3, Vector3};
use levelset::{
    ClumpParams, Cuboid, Ellipsoid, Grid, GridSpec, Result, Shape, VolumeCorrection, clump,
    clump_quality,
};

/// Nodes per axis and margin of the cloner's grids.
const RESOLUTION: usize = 45;
const MARGIN: f64 = 1.1;

fn main() -> Result<()> {
    let e = Ellipsoid::new(Vector3::new(2.0, 1.5, 1.0))?;
    let ellipsoid = Grid::from_shape(
        GridSpec::cube(RESOLUTION, -MARGIN * 2.0, MARGIN * 2.0)?,
        &e,
        &Isometry3::identity(),
    )?;
    // rounded box: the box shrunk by the rounding radius, offset by it (an exact distance)
    let rho = 0.15;
    let core = Vector3::new(1.0, 0.75, 0.5) - Vector3::repeat(rho);
    let inner = Cuboid::new(core)?;
    let r_max = core.norm() + rho;
    let rounded = Grid::from_fn(
        GridSpec::cube(RESOLUTION, -MARGIN * r_max, MARGIN * r_max)?,
        |p| inner.signed_distance(p) - rho,
    )?;
    println!(
        "{:<12} {:>3} {:<7} {:>8} {:>9} {:>9} {:>9} {:>9} {:>6}",
        "grain", "N", "volume", "V err", "mean I", "worst I", "dev mean", "dev max", "δ/d_eq"
    );
    for (name, grid) in [("ellipsoid", &ellipsoid), ("rounded box", &rounded)] {
        for correction in [VolumeCorrection::None, VolumeCorrection::Offset] {
            for n_spheres in [10, 20, 50] {
                let params = ClumpParams {
                    n_spheres,
                    volume_correction: correction,
                    ..ClumpParams::default()
                };
                let c = clump(grid, &params)?;
                let q = clump_quality(grid, &c)?;
                let worst = q
                    .moment_errors
                    .iter()
                    .fold(0.0f64, |m, e| if e.abs() > m.abs() { *e } else { m });
                println!(
                    "{:<12} {:>3} {:<7} {:>+7.2}% {:>+8.2}% {:>+8.2}% {:>9.4} {:>9.4} {:>6.4}",
                    name,
                    c.spheres.len(),
                    format!("{correction:?}"),
                    100.0 * q.volume_error,
                    100.0 * q.mean_moment_error,
                    100.0 * worst,
                    q.surface_mean,
                    q.surface_max,
                    c.correction / q.equivalent_diameter,
                );
            }
        }
    }
    Ok(())
}
