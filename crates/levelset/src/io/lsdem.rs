//! LS-DEM specimens as LS-DEM reads them: morph files in the grain's principal-axis frame
//! and the `Morphologies/` + `InitState/` layout with LS-DEM's quaternion convention.
//!
//! # Layout
//! The 3D LS-DEM codes descended from Kawamoto's (Kawamoto, Andò, Viggiani, Andrade 2016,
//! 2018; e.g. the MPI `init_simulation` of its Berkeley descendant) read, below one input
//! folder:
//!
//! - `InitState/positions_<NAME>.dat`: one `x y z` line per grain (`readPositionFile`),
//! - `InitState/rotations_<NAME>.dat`: one quaternion `q0 q1 q2 q3` per grain
//!   (`readQuaternionFile`), in the convention of [`lsdem_quaternion`],
//! - `Morphologies/morph_<k>.dat` for the `k`-th line (1-based) of the two files above.
//!
//! Names come from [`morph_path`], [`positions_path`] and [`rotations_path`].
//!
//! # Principal frame
//! LS-DEM integrates rotations with Euler's equations in the morph frame and reads the three
//! moments of a morph file as the **diagonal** of the inertia tensor there (zero products of
//! inertia); `fix rigid/ls/dem` of the LAMMPS LS-DEM fork stops on a grid whose frame is
//! not principal. [`principal_morph`] therefore resamples a grain's level set once
//! (trilinear) onto a lattice aligned with the principal axes of the source grid, centred on
//! its centre of mass. The discrete inertia of the resampled grid still has products of
//! inertia of about 1e-4 of its largest moment (discretisation), and turning the lattice
//! again does not remove them: measured on nearly round Ottawa clones (principal moments a
//! few percent apart) the residual wanders at 1e-4, because each resampling changes the
//! discretisation error by as much as the turn removes. They are removed instead by a
//! smooth correction of the resampled values, `φ += a·xy + b·xz + c·yz` (coordinates about
//! the centre of mass over the grain's reach), with `(a, b, c)` from a Newton iteration on
//! the three products (Jacobian by forward differences, kept while each step gains a
//! decade), until `max |I_ij| / I_max` is below [`PRINCIPAL_TOLERANCE`] (at worst
//! [`ACCEPTED_RESIDUAL`]). The correction moves the surface by
//! [`PrincipalMorph::correction`] at most, about 1e-3 of a grid spacing, far below the
//! resampling error itself.
//!
//! The inertia is the marching-tetrahedra integral of the piecewise-linear zero set,
//! [`Grid::mass_properties_linear`]: the sharp-feature correction of
//! [`Grid::mass_properties`] switches on and off per cell with a threshold on the corners'
//! gradients, which no iteration on the values can follow (measured: the products stalled
//! at 7e-5 on a cloned grain). Mass, centre of mass and the moments written (the corrected
//! tensor's diagonal, in x, y, z order) all come from that integral.

use std::io::Write;

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::MorphFile;
use crate::error::{Error, Result};
use crate::grid::{Grid, GridSpec};

/// Largest `|I_ij| / max_k I_kk` (i ≠ j) accepted for a principal morph frame.
pub const PRINCIPAL_TOLERANCE: f64 = 1e-12;

/// Correction steps of [`principal_morph`] at most.
const MAX_TURNS: usize = 12;

/// Largest residual accepted when [`PRINCIPAL_TOLERANCE`] is not reached (floating-point
/// noise of the inertia sums).
pub const ACCEPTED_RESIDUAL: f64 = 1e-10;

/// Path of the morph file of the `k`-th grain (1-based), relative to LS-DEM's input folder.
pub fn morph_path(k: usize) -> String {
    format!("Morphologies/morph_{k}.dat")
}

/// Path of the positions file of the test `name`, relative to LS-DEM's input folder.
pub fn positions_path(name: &str) -> String {
    format!("InitState/positions_{name}.dat")
}

/// Path of the rotations file of the test `name`, relative to LS-DEM's input folder.
pub fn rotations_path(name: &str) -> String {
    format!("InitState/rotations_{name}.dat")
}

/// A morph file in its grain's principal frame and where that frame sits in the source
/// grid's frame.
#[derive(Debug, Clone)]
pub struct PrincipalMorph {
    /// The morph file: spacing-1 level set in the principal frame, the moments the diagonal
    /// of its inertia tensor (x, y, z order), the points relative to the centre of mass.
    pub morph: MorphFile,
    /// Morph frame → source frame, in source lengths: a morph point `p` (grid units,
    /// relative to the centre of mass) is at `frame * (spacing · p)` in the source grid's
    /// frame. Its translation is the centre of mass in the source frame.
    pub frame: Isometry3<f64>,
    /// Source length of one morph grid unit.
    pub spacing: f64,
    /// Largest `|I_ij| / max_k I_kk` (i ≠ j) of the written level set's inertia.
    pub off_diagonal: f64,
    /// Correction steps done (module docs).
    pub turns: usize,
    /// Largest change of a level-set value made by the correction (source lengths): a
    /// bound of how far the surface moved.
    pub correction: f64,
}

/// The morph file of `grid` in its principal-axis frame (module docs), resampled
/// (trilinear) at `spacing` on a cube lattice about the centre of mass that covers the
/// grain with two cells to spare, with `node_count` surface nodes and mass and moments for
/// `density` in grid units (as [`MorphFile::from_grid`]).
///
/// # Errors
/// [`Error::InvalidParameter`] for a non-positive or non-finite spacing or density, or if
/// the frame does not become principal within 12 resamplings (the message gives the
/// residual); errors of [`Grid::mass_properties`] and [`Grid::surface_nodes`].
pub fn principal_morph(
    grid: &Grid,
    spacing: f64,
    density: f64,
    node_count: usize,
) -> Result<PrincipalMorph> {
    for (name, v) in [("spacing", spacing), ("density", density)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::InvalidParameter {
                name,
                value: v,
                requirement: "finite and positive",
            });
        }
    }
    let mp = grid.mass_properties()?;
    let centre = mp.centroid;
    // the farthest inside node bounds the grain about its centre of mass
    let reach = inside_reach(grid, &centre) + 2.0 * grid.spacing();
    let cells = (reach / spacing).ceil() as usize + 2;
    let n = 2 * cells + 1;
    let half = cells as f64 * spacing;
    let rot = Rotation3::from_matrix_unchecked(right_handed(mp.principal().axes));
    let frame = Isometry3::from_parts(Translation3::from(centre.coords), rot.into());
    let spec = GridSpec {
        dims: [n; 3],
        origin: Point3::new(-half, -half, -half),
        spacing,
    };
    let mut local = Grid::from_fn(spec, |p| grid.value(&(frame * p)))?;
    // the resampled grid's own products of inertia (discretisation, ~1e-4 of I_max) are
    // removed by a smooth quadratic correction of its values (module docs)
    let basis = |p: &Point3<f64>, c: &Point3<f64>| {
        let d = (p - c) / reach;
        [d.x * d.y, d.x * d.z, d.y * d.z]
    };
    let products = |i: &Matrix3<f64>| Vector3::new(i[(0, 1)], i[(0, 2)], i[(1, 2)]);
    let mut lp = local.mass_properties_linear()?;
    let c0 = lp.centroid;
    let mut jacobian: Option<Matrix3<f64>> = None;
    let mut shift = Vector3::zeros();
    let mut turns = 0;
    let mut last = f64::INFINITY;
    loop {
        let off = off_diagonal(&lp.inertia);
        if off > 0.1 * last {
            // a chord step that did not gain a decade: a fresh Jacobian (Newton)
            jacobian = None;
        }
        last = off;
        if off <= PRINCIPAL_TOLERANCE || turns >= MAX_TURNS {
            if off > ACCEPTED_RESIDUAL {
                return Err(Error::InvalidParameter {
                    name: "principal frame residual |I_ij| / I_max",
                    value: off,
                    requirement: "at most 1e-10",
                });
            }
            let moved = shift.abs().sum() * spacing;
            return finish(
                local, lp, frame, spacing, density, node_count, off, turns, moved,
            );
        }
        turns += 1;
        let jac = match jacobian {
            Some(j) => j,
            None => {
                let j = shape_jacobian(&local, &lp.centroid, &c0, reach);
                jacobian = Some(j);
                j
            }
        };
        let Some(step) = jac.lu().solve(&(-products(&lp.inertia))) else {
            return Err(Error::InvalidParameter {
                name: "principal frame correction (singular)",
                value: off,
                requirement: "a correctable residual",
            });
        };
        shift += step;
        let spec = *local.spec();
        let values: Vec<f64> = local
            .values()
            .iter()
            .enumerate()
            .map(|(idx, v)| {
                let b = basis(&node_of(&spec, idx), &c0);
                v + step.x * b[0] + step.y * b[1] + step.z * b[2]
            })
            .collect();
        local = Grid::new(spec, values)?;
        lp = local.mass_properties_linear()?;
    }
}

/// `∂(I_xy, I_xz, I_yz) / ∂(a, b, c)` of the correction `φ += a·xy + b·xz + c·yz`
/// (coordinates about `c0` over `reach`), by the shape derivative: raising φ by `δφ` moves
/// the zero set inward by `δφ / |∇φ|`, so `∂/∂a ∫_Ω f dV = −∫_∂Ω f · xy / |∇φ| dA`; with
/// `I_xy = −∫ x y dV` about the centroid (its shift is second order there) the column of
/// `a` is `∫_∂Ω (xy, xz, yz) · xy dA` (|∇φ| ≈ 1 near the zero set of a distance field),
/// summed over the marching-cubes triangles at their centroids. One surface pass instead
/// of three integrations by finite differences; a Newton step only needs it approximately.
fn shape_jacobian(
    grid: &Grid,
    centroid: &Point3<f64>,
    c0: &Point3<f64>,
    reach: f64,
) -> Matrix3<f64> {
    let mesh = grid.marching_cubes();
    let v = mesh.vertices();
    let mut j = Matrix3::zeros();
    for t in mesh.triangles() {
        let (a, b, c) = (v[t[0]], v[t[1]], v[t[2]]);
        let area = 0.5 * (b - a).cross(&(c - a)).norm();
        let m = Point3::from((a.coords + b.coords + c.coords) / 3.0);
        let x = m - centroid;
        let d = (m - c0) / reach;
        let prods = Vector3::new(x.x * x.y, x.x * x.z, x.y * x.z);
        let basis = Vector3::new(d.x * d.y, d.x * d.z, d.y * d.z);
        j += area * prods * basis.transpose();
    }
    j
}

/// Position of the node of storage index `idx` (x fastest).
fn node_of(spec: &GridSpec, idx: usize) -> Point3<f64> {
    let [nx, ny, _] = spec.dims;
    spec.node(idx % nx, (idx / nx) % ny, idx / (nx * ny))
}

/// Builds the morph file of a principal grid `local` (spacing `h`, origin `−half`).
#[allow(clippy::too_many_arguments)]
fn finish(
    local: Grid,
    lp: crate::MassProperties,
    frame: Isometry3<f64>,
    h: f64,
    density: f64,
    node_count: usize,
    off: f64,
    turns: usize,
    moved: f64,
) -> Result<PrincipalMorph> {
    let nodes = local.surface_nodes(node_count)?;
    let origin = local.origin();
    let points: Vec<Point3<f64>> = nodes
        .iter()
        .map(|p| Point3::from((p - lp.centroid) / h))
        .collect();
    let bounding_radius = points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
    let spec = GridSpec {
        dims: local.dims(),
        origin: Point3::origin(),
        spacing: 1.0,
    };
    let values = local.values().iter().map(|v| v / h).collect();
    let d = lp.inertia.diagonal();
    let morph = MorphFile {
        mass: density * lp.volume / h.powi(3),
        principal_moments: density * Vector3::new(d.x, d.y, d.z) / h.powi(5),
        centroid: Point3::from((lp.centroid - origin) / h),
        points,
        bounding_radius,
        grid: Grid::new(spec, values)?,
    };
    // the centre of mass of the resampled grid, in the source frame
    let com = frame * lp.centroid;
    Ok(PrincipalMorph {
        morph,
        frame: Isometry3::from_parts(Translation3::from(com.coords), frame.rotation),
        spacing: h,
        off_diagonal: off,
        turns,
        correction: moved,
    })
}

/// Largest distance from `c` to a node with `φ ≤ 0` (0 for none).
fn inside_reach(grid: &Grid, c: &Point3<f64>) -> f64 {
    let [nx, ny, nz] = grid.dims();
    let mut r2 = 0.0f64;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                if grid.at(i, j, k) <= 0.0 {
                    r2 = r2.max((grid.spec().node(i, j, k) - c).norm_squared());
                }
            }
        }
    }
    r2.sqrt()
}

/// `|I_ij|` (i ≠ j) over the largest diagonal term.
pub fn off_diagonal(inertia: &Matrix3<f64>) -> f64 {
    let d = inertia.diagonal().amax();
    let mut off = 0.0f64;
    for i in 0..3 {
        for j in 0..3 {
            if i != j {
                off = off.max(inertia[(i, j)].abs());
            }
        }
    }
    if d > 0.0 { off / d } else { f64::INFINITY }
}

/// `axes` with the last column flipped if needed so that the determinant is +1.
fn right_handed(mut axes: Matrix3<f64>) -> Matrix3<f64> {
    if axes.determinant() < 0.0 {
        let c = -axes.column(2);
        axes.set_column(2, &c);
    }
    axes
}

/// The LS-DEM quaternion `[q0, q1, q2, q3]` of a body → world rotation.
///
/// LS-DEM (`Grain3d::updateRotationMatrix` of the Kawamoto/Andrade code and its
/// descendants) stores `(X, Y, Z, W)` but builds its rotation matrix with a sign and axis
/// convention of its own: for a Hamilton unit quaternion `w + x i + y j + z k` whose matrix
/// is the body → world rotation `R` (world point = `R · morph point + position`, its
/// `_pointList = _rotMatrix * _refPointList + _position`), LS-DEM's matrix equals `R` when
/// the file holds `q0 = y, q1 = −x, q2 = −z, q3 = w`; the sign is chosen so that `q3 ≥ 0`.
/// [`lsdem_matrix`] is LS-DEM's matrix written out term by term.
pub fn lsdem_quaternion(rotation: &UnitQuaternion<f64>) -> [f64; 4] {
    let q = rotation.quaternion();
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.j, -s * q.i, -s * q.k, s * q.w]
}

/// LS-DEM's rotation matrix of a file quaternion `[q0, q1, q2, q3]`
/// (`Grain3d::updateRotationMatrix`, term by term): the body → world rotation a simulation
/// will apply.
pub fn lsdem_matrix(q: [f64; 4]) -> Matrix3<f64> {
    let [a, b, c, d] = q;
    Matrix3::new(
        -a * a + b * b - c * c + d * d,
        -2.0 * (a * b - c * d),
        2.0 * (b * c + a * d),
        -2.0 * (a * b + c * d),
        a * a - b * b - c * c + d * d,
        -2.0 * (a * c - b * d),
        2.0 * (b * c - a * d),
        -2.0 * (a * c + b * d),
        -a * a - b * b + c * c + d * d,
    )
}

/// Writes `positions_<NAME>.dat`: `x y z` per line, Rust's shortest round-trip floats.
///
/// # Errors
/// [`Error::Io`] on write failure; [`Error::InvalidParameter`] for a non-finite coordinate.
pub fn write_positions(w: impl Write, positions: &[Point3<f64>]) -> Result<()> {
    write_rows(w, "position", positions.iter().map(|p| [p.x, p.y, p.z]))
}

/// Writes `rotations_<NAME>.dat`: the [`lsdem_quaternion`] of each body → world rotation,
/// `q0 q1 q2 q3` per line.
///
/// # Errors
/// [`Error::Io`] on write failure; [`Error::InvalidParameter`] for a non-finite rotation.
pub fn write_rotations(w: impl Write, rotations: &[UnitQuaternion<f64>]) -> Result<()> {
    write_rows(w, "rotation", rotations.iter().map(lsdem_quaternion))
}

/// Rows of `N` finite numbers, space-separated, one per line.
fn write_rows<const N: usize>(
    mut w: impl Write,
    name: &'static str,
    rows: impl Iterator<Item = [f64; N]>,
) -> Result<()> {
    let mut s = String::new();
    for row in rows {
        for (k, v) in row.iter().enumerate() {
            finite(name, *v)?;
            if k > 0 {
                s.push(' ');
            }
            super::fmt_f64(&mut s, *v);
        }
        s.push('\n');
    }
    w.write_all(s.as_bytes())?;
    Ok(())
}

/// One file of an LS-DEM input folder, relative to it.
#[derive(Debug, Clone, PartialEq)]
pub enum LayoutEntry {
    /// A file and its bytes.
    File {
        /// Path relative to the input folder.
        path: String,
        /// Contents.
        bytes: Vec<u8>,
    },
    /// A relative symbolic link: `path` reads the morph file `target` (same folder).
    Link {
        /// Path relative to the input folder.
        path: String,
        /// The link's target, relative to `path`'s folder.
        target: String,
    },
}

/// The LS-DEM input folder of `grains` beside their morph files (written by the caller as
/// [`morph_path`]`(m + 1)` for each distinct morph `m`): `InitState/positions_<NAME>.dat`
/// (the centres of mass, grid units), `InitState/rotations_<NAME>.dat`
/// ([`lsdem_quaternion`]), and for every grain `k` that reuses morph `m ≠ k` a link
/// `Morphologies/morph_<k+1>.dat → morph_<m+1>.dat`, so that any LS-DEM reader finds the
/// `k`-th line's morph file under its own number while the disk holds each shape once.
///
/// `grains[k] = (m, pose)`: grain `k` uses morph `m` (0-based) and `pose` maps the morph's
/// frame (grid units, origin at its centre of mass) to the world (grid units).
///
/// # Errors
/// [`Error::InvalidParameter`] for a test name that is empty or not made of ASCII letters,
/// digits, `_` and `-`, a morph index above its grain's (morph `m` must be written as a
/// file, i.e. be some grain's own), or a non-finite pose.
pub fn layout(name: &str, grains: &[(usize, Isometry3<f64>)]) -> Result<Vec<LayoutEntry>> {
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(Error::InvalidParameter {
            name: "LS-DEM test name length",
            value: name.len() as f64,
            requirement: "a non-empty name of ASCII letters, digits, `_` and `-`",
        });
    }
    let mut positions = Vec::with_capacity(grains.len());
    let mut rotations = Vec::with_capacity(grains.len());
    let mut out = Vec::new();
    for (k, (m, pose)) in grains.iter().enumerate() {
        if *m > k {
            return Err(Error::InvalidParameter {
                name: "LS-DEM morph index",
                value: *m as f64,
                requirement: "at most its grain's index (the morph of a grain that comes first)",
            });
        }
        positions.push(Point3::from(pose.translation.vector));
        rotations.push(pose.rotation);
        if *m != k {
            out.push(LayoutEntry::Link {
                path: morph_path(k + 1),
                target: format!("morph_{}.dat", m + 1),
            });
        }
    }
    let mut pos = Vec::new();
    write_positions(&mut pos, &positions)?;
    let mut rot = Vec::new();
    write_rotations(&mut rot, &rotations)?;
    out.insert(
        0,
        LayoutEntry::File {
            path: rotations_path(name),
            bytes: rot,
        },
    );
    out.insert(
        0,
        LayoutEntry::File {
            path: positions_path(name),
            bytes: pos,
        },
    );
    Ok(out)
}

/// Reads a positions or rotations file: `n` whitespace-separated numbers per non-empty line.
///
/// # Errors
/// [`Error::Parse`] with the line for a line of another length or a bad number; [`Error::Io`].
pub fn read_rows<const N: usize>(
    r: impl std::io::BufRead,
    format: &'static str,
) -> Result<Vec<[f64; N]>> {
    let mut rows = Vec::new();
    for (k, line) in r.lines().enumerate() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let vals: Vec<f64> = line
            .split_whitespace()
            .map(str::parse::<f64>)
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| Error::Parse {
                format,
                line: k + 1,
                reason: e.to_string(),
            })?;
        let row: [f64; N] = vals.try_into().map_err(|v: Vec<f64>| Error::Parse {
            format,
            line: k + 1,
            reason: format!("{} numbers, expected {N}", v.len()),
        })?;
        if row.iter().any(|v| !v.is_finite()) {
            return Err(Error::Parse {
                format,
                line: k + 1,
                reason: "non-finite number".into(),
            });
        }
        rows.push(row);
    }
    Ok(rows)
}

fn finite(name: &'static str, v: f64) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name,
            value: v,
            requirement: "finite",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{Ellipsoid, Shape};
    use approx::assert_relative_eq;

    /// A tilted ellipsoid off the origin: its principal frame is known in closed form.
    fn tilted() -> (Grid, UnitQuaternion<f64>, Point3<f64>) {
        let q = UnitQuaternion::from_euler_angles(0.4, -0.3, 1.1);
        let c = Point3::new(0.1, -0.05, 0.07);
        let e = Ellipsoid::new(Vector3::new(1.0, 0.7, 0.45)).expect("ellipsoid");
        let spec = GridSpec::cube(41, -1.3, 1.3).expect("spec");
        let inv = q.inverse();
        let g =
            Grid::from_fn(spec, |p| e.signed_distance(&Point3::from(inv * (p - c)))).expect("grid");
        (g, q, c)
    }

    #[test]
    fn principal_morph_is_diagonal_and_maps_back() {
        let (g, q, c) = tilted();
        let h = 0.05;
        let pm = principal_morph(&g, h, 1.0, 300).expect("morph");
        assert!(
            pm.off_diagonal <= PRINCIPAL_TOLERANCE,
            "{}",
            pm.off_diagonal
        );
        // the written level set, read as LS-DEM has it (spacing 1), is principal too
        let again = pm.morph.grid.mass_properties_linear().expect("mass");
        assert!(off_diagonal(&again.inertia) <= 1e-9);
        // moments in x, y, z order: the ellipsoid's long axis (a = 1) has the smallest
        let m = pm.morph.principal_moments;
        assert!(m.x < m.y && m.y < m.z, "{m:?}");
        // the morph frame's x axis is the ellipsoid's long axis (up to sign)
        let ax = pm.frame.rotation * Vector3::x();
        assert_relative_eq!(ax.dot(&(q * Vector3::x())).abs(), 1.0, epsilon = 1e-3);
        // the centre of mass maps to the ellipsoid's centre
        assert!((pm.frame.translation.vector - c.coords).norm() < 1e-3);
        // surface points map back onto the source surface
        for p in &pm.morph.points {
            let x = pm.frame * (p * pm.spacing);
            assert!(g.value(&x).abs() < 0.02, "{}", g.value(&x));
        }
        assert!(pm.turns >= 1 && pm.turns <= MAX_TURNS);
    }

    /// A nearly round lumpy grain on a coarse grid (principal moments within a few
    /// percent, like Ottawa sand): turning the lattice alone stalls at ~1e-4 here.
    #[test]
    fn nearly_round_grains_on_coarse_grids_become_principal() {
        for (n, h) in [(21, 0.13), (45, 0.06), (31, 0.2)] {
            let spec = GridSpec::cube(n, -1.4, 1.4).expect("spec");
            let g = Grid::from_fn(spec, |p| {
                let r = p.coords.norm().max(1e-12);
                let u = p.coords / r;
                r - (1.0 + 0.06 * (3.0 * u.x).sin() * u.y + 0.04 * (2.0 * u.z).cos() * u.x
                    - 0.05 * u.z * u.y)
            })
            .expect("grid");
            let pm = principal_morph(&g, h, 1.0, 200).expect("morph");
            assert!(
                pm.off_diagonal <= ACCEPTED_RESIDUAL,
                "{n}: {:e}",
                pm.off_diagonal
            );
            let again = pm.morph.grid.mass_properties_linear().expect("mass");
            assert!(off_diagonal(&again.inertia) <= 1e-9, "{n}");
            assert!(pm.correction <= 0.05 * h, "{n}: moved {:e}", pm.correction);
        }
    }

    #[test]
    fn quaternion_convention_round_trips() {
        for (a, b, c) in [(0.3, -1.2, 2.0), (3.0, 0.1, -0.5), (0.0, 0.0, 0.0)] {
            let q = UnitQuaternion::from_euler_angles(a, b, c);
            let m = lsdem_matrix(lsdem_quaternion(&q));
            assert_relative_eq!(m, *q.to_rotation_matrix().matrix(), epsilon = 1e-14);
            assert!(lsdem_quaternion(&q)[3] >= 0.0);
        }
    }

    #[test]
    fn positions_and_rotations_round_trip_exactly() {
        let ps = vec![
            Point3::new(1.0 / 3.0, -2e-7, 1e20),
            Point3::new(0.0, 5.5, -1.25),
        ];
        let qs = vec![UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3)];
        let mut a = Vec::new();
        write_positions(&mut a, &ps).expect("write");
        let back = read_rows::<3>(a.as_slice(), "positions").expect("read");
        for (p, r) in ps.iter().zip(&back) {
            assert_eq!(p.coords.as_slice(), r.as_slice());
        }
        let mut b = Vec::new();
        write_rotations(&mut b, &qs).expect("write");
        let back = read_rows::<4>(b.as_slice(), "rotations").expect("read");
        assert_eq!(back[0], lsdem_quaternion(&qs[0]));
        assert!(write_positions(Vec::new(), &[Point3::new(f64::NAN, 0.0, 0.0)]).is_err());
        assert!(read_rows::<3>("1 2\n".as_bytes(), "positions").is_err());
        assert!(read_rows::<3>("1 2 x\n".as_bytes(), "positions").is_err());
        assert!(read_rows::<3>("1 2 inf\n".as_bytes(), "positions").is_err());
    }

    #[test]
    fn bad_parameters_are_errors() {
        let (g, _, _) = tilted();
        assert!(principal_morph(&g, 0.0, 1.0, 10).is_err());
        assert!(principal_morph(&g, f64::NAN, 1.0, 10).is_err());
        assert!(principal_morph(&g, 0.05, -1.0, 10).is_err());
    }

    #[test]
    fn layout_links_reused_morphs_and_refuses_bad_input() {
        let p = |x: f64| Isometry3::translation(x, 0.0, 0.0);
        let grains = [(0, p(1.0)), (1, p(2.0)), (0, p(3.0)), (1, p(4.0))];
        let l = layout("t", &grains).expect("layout");
        assert_eq!(l.len(), 4);
        assert!(
            matches!(&l[0], LayoutEntry::File { path, .. } if path == "InitState/positions_t.dat")
        );
        assert!(
            matches!(&l[1], LayoutEntry::File { path, .. } if path == "InitState/rotations_t.dat")
        );
        assert_eq!(
            l[2],
            LayoutEntry::Link {
                path: "Morphologies/morph_3.dat".into(),
                target: "morph_1.dat".into()
            }
        );
        if let LayoutEntry::File { bytes, .. } = &l[0] {
            let rows = read_rows::<3>(bytes.as_slice(), "positions").expect("rows");
            assert_eq!(rows[3], [4.0, 0.0, 0.0]);
        }
        assert!(layout("", &grains).is_err());
        assert!(layout("a/b", &grains).is_err());
        assert!(layout("t", &[(1, p(0.0))]).is_err());
        let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
        assert!(layout("t", &[(0, nan)]).is_err());
    }

    #[test]
    fn layout_names() {
        assert_eq!(morph_path(1), "Morphologies/morph_1.dat");
        assert_eq!(positions_path("sand"), "InitState/positions_sand.dat");
        assert_eq!(rotations_path("sand"), "InitState/rotations_sand.dat");
    }
}
