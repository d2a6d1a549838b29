//! Coefficients from sampled radii: least squares (Radvilaitė 2016, Eqs. 2.17–2.20)
//! and the quadrature transform.
//!
//! * [`least_squares`] works on any directions. It solves the weighted problem
//!   `min Σ w_i (r_i − Y_i·a)²` by faer's Householder QR. Diagnostics come from the
//!   singular values of the triangular factor R (equal to those of the design matrix):
//!   rank, condition number. When the rank is deficient the Moore–Penrose solution
//!   (thesis Eq. 2.19 in its generalised form) is computed from a thin SVD instead, and
//!   [`FitDiagnostics::rank_deficient`] says so.
//! * [`least_squares_rings`] gives the *same* least-squares solution on ring grids whose
//!   rings carry ≥ 2L+1 equally spaced azimuths (or sit on a pole): the discrete
//!   orthogonality of cos mφ, sin mφ on such rings makes the normal matrix block diagonal
//!   in (m, cos/sin), so the problem splits into 2L+1 small problems (rows = rings,
//!   columns = degrees l ≥ m). The singular values of the full design matrix are the union
//!   of the blocks' singular values, so rank and condition number are exact too.
//! * [`quadrature_transform`] integrates `r·Y_lm` with the grid's weights; exact for
//!   band-limited data on [`RingGrid::gauss_legendre`].

use crate::basis::{Legendre, coefficient_count, fill_row, index, tri};
use crate::error::{Error, check_angles, check_finite};
use crate::grid::{Ring, RingGrid};
use crate::model::ShModel;
use faer::Mat;
use faer::linalg::solvers::SolveLstsq;

/// Condition numbers above this are flagged as ill-conditioned.
pub const ILL_CONDITIONED: f64 = 1e10;

/// Which algorithm produced the coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitMethod {
    /// Householder QR of the full design matrix (faer).
    Qr,
    /// Moore–Penrose pseudo-inverse from a thin SVD (rank-deficient design).
    PseudoInverse,
    /// Block-diagonal least squares on a ring grid (QR per block, SVD when a block is deficient).
    RingBlocks,
    /// Quadrature transform.
    Quadrature,
}

/// Diagnostics of a fit. A deficient or badly conditioned design is reported here.
#[derive(Debug, Clone, PartialEq)]
pub struct FitDiagnostics {
    /// Algorithm used.
    pub method: FitMethod,
    /// Number of samples.
    pub n_points: usize,
    /// Number of unknown coefficients `(L+1)²`.
    pub n_coefficients: usize,
    /// Numerical rank of the (weighted) design matrix.
    pub rank: usize,
    /// Largest singular value.
    pub singular_max: f64,
    /// Smallest singular value.
    pub singular_min: f64,
    /// `singular_max / singular_min` (infinite when singular).
    pub condition_number: f64,
    /// `rank < n_coefficients`: the solution is the minimum-norm (Moore–Penrose) one.
    pub rank_deficient: bool,
    /// `condition_number > ILL_CONDITIONED`.
    pub ill_conditioned: bool,
    /// Root-mean-square of the (weighted) residual at the samples.
    pub rms_residual: f64,
}

/// A fitted model with its diagnostics.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The model.
    pub model: ShModel,
    /// How good the design was.
    pub diagnostics: FitDiagnostics,
}

fn check_radii(values: &[f64]) -> Result<(), Error> {
    for (index, &value) in values.iter().enumerate() {
        if !value.is_finite() {
            return Err(Error::NonFinite {
                what: "radius",
                index,
                value,
            });
        }
        if value <= 0.0 {
            return Err(Error::NonPositiveRadius { index, value });
        }
    }
    Ok(())
}

fn check_weights(weights: &[f64]) -> Result<(), Error> {
    for (index, &value) in weights.iter().enumerate() {
        if !(value.is_finite() && value >= 0.0) {
            return Err(Error::InvalidWeight { index, value });
        }
    }
    Ok(())
}

fn rank_from(sv: &[f64], rows: usize, cols: usize) -> (usize, f64, f64, f64) {
    let smax = sv.iter().copied().fold(0.0_f64, f64::max);
    let smin = sv.iter().copied().fold(f64::INFINITY, f64::min);
    let tol = smax * (rows.max(cols) as f64) * f64::EPSILON;
    let rank = sv.iter().filter(|&&s| s > tol).count();
    let cond = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    (rank, smax, smin, cond)
}

/// Minimum-norm least-squares solution by thin SVD; returns (x, singular values).
fn pseudo_inverse_solve(a: &Mat<f64>, b: &[f64]) -> Result<Vec<f64>, Error> {
    let svd = a.thin_svd().map_err(|_| Error::LinearAlgebra {
        what: "thin svd did not converge",
    })?;
    let (u, s, v) = (svd.U(), svd.S(), svd.V());
    let k = s.dim();
    let sv: Vec<f64> = (0..k).map(|i| s[i]).collect();
    let (_, smax, _, _) = rank_from(&sv, a.nrows(), a.ncols());
    let tol = smax * (a.nrows().max(a.ncols()) as f64) * f64::EPSILON;
    let mut x = vec![0.0; a.ncols()];
    for i in 0..k {
        if sv[i] <= tol {
            continue;
        }
        let mut ub = 0.0;
        for (r, &bv) in b.iter().enumerate() {
            ub += u[(r, i)] * bv;
        }
        let f = ub / sv[i];
        for (c, xc) in x.iter_mut().enumerate() {
            *xc += v[(c, i)] * f;
        }
    }
    Ok(x)
}

/// Least-squares coefficients of degree `degree` for radii at arbitrary directions (θ, φ),
/// optionally weighted (Radvilaitė 2016, Eqs. 2.17–2.20).
///
/// # Errors
/// [`Error::LengthMismatch`], [`Error::AngleOutOfRange`], [`Error::NonFinite`],
/// [`Error::NonPositiveRadius`], [`Error::InvalidWeight`],
/// [`Error::DegreeTooHighForGrid`] when there are fewer samples (with positive weight) than
/// coefficients, [`Error::LinearAlgebra`] if the SVD fails.
pub fn least_squares(
    directions: &[(f64, f64)],
    radii: &[f64],
    weights: Option<&[f64]>,
    degree: usize,
) -> Result<Fit, Error> {
    if radii.len() != directions.len() {
        return Err(Error::LengthMismatch {
            what: "radii",
            expected: directions.len(),
            got: radii.len(),
        });
    }
    if let Some(w) = weights {
        if w.len() != directions.len() {
            return Err(Error::LengthMismatch {
                what: "weights",
                expected: directions.len(),
                got: w.len(),
            });
        }
        check_weights(w)?;
    }
    for &(t, p) in directions {
        check_angles(t, p)?;
    }
    check_radii(radii)?;
    let n_coef = coefficient_count(degree);
    let used = match weights {
        Some(w) => w.iter().filter(|&&x| x > 0.0).count(),
        None => directions.len(),
    };
    if used < n_coef {
        return Err(Error::DegreeTooHighForGrid {
            degree,
            needed: n_coef,
            available: used,
        });
    }
    let leg = Legendre::new(degree)?;
    let mut vals = leg.buffer(0);
    let rows = directions.len();
    let mut a = Mat::<f64>::zeros(rows, n_coef);
    let mut b = vec![0.0; rows];
    let mut row = vec![0.0; n_coef];
    for (i, &(t, p)) in directions.iter().enumerate() {
        let sw = weights.map_or(1.0, |w| w[i].sqrt());
        leg.compute(t, &mut vals);
        fill_row(degree, &vals.p, p, &mut row);
        for (c, &v) in row.iter().enumerate() {
            a[(i, c)] = sw * v;
        }
        b[i] = sw * radii[i];
    }
    let qr = a.qr();
    let r_factor = qr.thin_R();
    let sv = r_factor
        .singular_values()
        .map_err(|_| Error::LinearAlgebra {
            what: "singular values of R did not converge",
        })?;
    let (rank, smax, smin, cond) = rank_from(&sv, rows, n_coef);
    let (x, method) = if rank < n_coef {
        (pseudo_inverse_solve(&a, &b)?, FitMethod::PseudoInverse)
    } else {
        let rhs = Mat::<f64>::from_fn(rows, 1, |i, _| b[i]);
        let sol = qr.solve_lstsq(&rhs);
        ((0..n_coef).map(|i| sol[(i, 0)]).collect(), FitMethod::Qr)
    };
    check_finite("fitted coefficient", &x)?;
    let mut ss = 0.0;
    for (i, bi) in b.iter().enumerate() {
        let mut pred = 0.0;
        for (c, xc) in x.iter().enumerate() {
            pred += a[(i, c)] * xc;
        }
        ss += (pred - bi).powi(2);
    }
    let model = ShModel::new(degree, x)?;
    Ok(Fit {
        model,
        diagnostics: FitDiagnostics {
            method,
            n_points: rows,
            n_coefficients: n_coef,
            rank,
            singular_max: smax,
            singular_min: smin,
            condition_number: cond,
            rank_deficient: rank < n_coef,
            ill_conditioned: cond > ILL_CONDITIONED,
            rms_residual: (ss / rows as f64).sqrt(),
        },
    })
}

/// Least squares on a ring grid, weighted by the rings' weights, solved block by block.
///
/// Gives the same solution as [`least_squares`] on [`RingGrid::points`] with
/// [`RingGrid::weights`]. Falls back to [`least_squares`] when a non-polar ring has fewer than
/// `2·degree + 1` azimuths (the blocks would couple through aliasing).
///
/// # Errors
/// As [`least_squares`].
pub fn least_squares_rings(grid: &RingGrid, radii: &[f64], degree: usize) -> Result<Fit, Error> {
    if radii.len() != grid.len() {
        return Err(Error::LengthMismatch {
            what: "radii",
            expected: grid.len(),
            got: radii.len(),
        });
    }
    check_radii(radii)?;
    let separable = grid
        .rings()
        .iter()
        .all(|r| r.is_pole() || r.n_phi > 2 * degree);
    if !separable {
        return least_squares(&grid.points(), radii, Some(&grid.weights()), degree);
    }
    let n_coef = coefficient_count(degree);
    let used: usize = grid
        .rings()
        .iter()
        .filter(|r| r.weight > 0.0)
        .map(|r| r.n_phi)
        .sum();
    if used < n_coef {
        return Err(Error::DegreeTooHighForGrid {
            degree,
            needed: n_coef,
            available: used,
        });
    }
    let leg = Legendre::new(degree)?;
    let rings = grid.rings();
    let projections = project_rings(rings, radii, degree, &leg);
    let blocks = solve_ring_blocks(rings, &projections, degree, n_coef)?;
    let coef = blocks.coefficients;
    check_finite("fitted coefficient", &coef)?;
    let (rank, smax, smin, cond) = rank_from(&blocks.singular_values, grid.len(), n_coef);
    let rank_deficient = blocks.any_deficient || rank < n_coef;
    let model = ShModel::new(degree, coef)?;
    let ss = (projections.total_ss - blocks.explained).max(0.0);
    Ok(Fit {
        model,
        diagnostics: FitDiagnostics {
            method: FitMethod::RingBlocks,
            n_points: grid.len(),
            n_coefficients: n_coef,
            rank,
            singular_max: smax,
            singular_min: smin,
            condition_number: cond,
            rank_deficient,
            ill_conditioned: cond > ILL_CONDITIONED,
            rms_residual: (ss / grid.len() as f64).sqrt(),
        },
    })
}

/// The data of a separable ring grid reduced ring by ring (see [`project_rings`]).
struct RingProjections {
    /// Legendre values `P_lm(cos θ)` per ring (indexed by [`tri`]).
    legendre: Vec<Vec<f64>>,
    /// Weighted projections per ring and order: `proj[ring][m] = (cos part, sin part)`.
    proj: Vec<Vec<(f64, f64)>>,
    /// Weighted sum of squares of all data, `Σ w_i r_i²`.
    total_ss: f64,
}

/// Legendre values and projected data of every ring of a separable grid: the data of a
/// ring projected on its orthonormal cos mφ, sin mφ (m ≤ degree; m = 0 only on a pole),
/// scaled by the square root of the ring's weight.
fn project_rings(rings: &[Ring], radii: &[f64], degree: usize, leg: &Legendre) -> RingProjections {
    let mut vals = leg.buffer(0);
    let nr = rings.len();
    // Legendre values per ring and projected data per ring: proj[ring][m] = (cos part, sin part).
    let mut ptab = Vec::with_capacity(nr);
    let mut proj = vec![vec![(0.0, 0.0); degree + 1]; nr];
    let mut total_ss = 0.0;
    let mut offset = 0;
    for (i, ring) in rings.iter().enumerate() {
        leg.compute(ring.theta, &mut vals);
        ptab.push(vals.p.clone());
        let n = ring.n_phi;
        let sw = ring.weight.sqrt();
        let data = &radii[offset..offset + n];
        offset += n;
        total_ss += ring.weight * data.iter().map(|v| v * v).sum::<f64>();
        let mmax = if ring.is_pole() { 0 } else { degree };
        for (m, slot) in proj[i].iter_mut().enumerate().take(mmax + 1) {
            *slot = ring_projection(ring, data, m, sw);
        }
    }
    RingProjections {
        legendre: ptab,
        proj,
        total_ss,
    }
}

/// The projection of one ring's `data` on the orthonormal cos mφ, sin mφ of the ring,
/// scaled by `sw` (the square root of the ring's weight): (cos part, sin part).
fn ring_projection(ring: &Ring, data: &[f64], m: usize, sw: f64) -> (f64, f64) {
    let n = ring.n_phi;
    // Σ_j r_j cos(m φ_j), Σ_j r_j sin(m φ_j) by an angle-addition recurrence.
    let (sm0, cm0) = (m as f64 * ring.phi0).sin_cos();
    let (ms1, mc1) = if m == 0 {
        (0.0, 1.0)
    } else {
        (m as f64 * 2.0 * std::f64::consts::PI / n as f64).sin_cos()
    };
    let (mut s, mut c) = (sm0, cm0);
    let (mut cs, mut ss) = (0.0, 0.0);
    for &v in data {
        cs += v * c;
        ss += v * s;
        let cn = c * mc1 - s * ms1;
        s = s * mc1 + c * ms1;
        c = cn;
    }
    let nf = n as f64;
    if m == 0 {
        (sw * cs / nf.sqrt(), 0.0)
    } else {
        let norm = (nf / 2.0).sqrt();
        (sw * cs / norm, sw * ss / norm)
    }
}

/// The solution of the block-diagonal problem of [`least_squares_rings`].
struct RingBlocks {
    /// The coefficients, in [`index`] order.
    coefficients: Vec<f64>,
    /// Singular values of the full design (every block column counted once per part).
    singular_values: Vec<f64>,
    /// Whether some block was solved by its pseudo-inverse.
    any_deficient: bool,
    /// `Σ (‖b‖² − ‖b − A x‖²)` over the blocks: the explained sum of squares.
    explained: f64,
}

/// Solves the 2L+1 blocks (order m; cos part, and sin part for m > 0) by QR, or by the
/// pseudo-inverse when a block is rank deficient or has fewer rows than columns.
fn solve_ring_blocks(
    rings: &[Ring],
    projections: &RingProjections,
    degree: usize,
    n_coef: usize,
) -> Result<RingBlocks, Error> {
    let (ptab, proj) = (&projections.legendre, &projections.proj);
    let nr = rings.len();
    let mut coef = vec![0.0; n_coef];
    let mut all_sv = Vec::with_capacity(n_coef);
    let mut any_deficient = false;
    let mut explained = 0.0;
    for m in 0..=degree {
        let ncol = degree - m + 1;
        let a = block_design(rings, ptab, m, degree);
        let sv = a.singular_values().map_err(|_| Error::LinearAlgebra {
            what: "block singular values did not converge",
        })?;
        let (brank, _, _, _) = rank_from(&sv, nr, ncol);
        let parts: &[usize] = if m == 0 { &[0] } else { &[0, 1] };
        for &part in parts {
            let b: Vec<f64> = (0..nr)
                .map(|i| {
                    if part == 0 {
                        proj[i][m].0
                    } else {
                        proj[i][m].1
                    }
                })
                .collect();
            let x = if brank < ncol || nr < ncol {
                any_deficient = true;
                pseudo_inverse_solve(&a, &b)?
            } else {
                let rhs = Mat::<f64>::from_fn(nr, 1, |i, _| b[i]);
                let sol = a.qr().solve_lstsq(&rhs);
                (0..ncol).map(|i| sol[(i, 0)]).collect()
            };
            // ‖b‖² − ‖b − A x‖² is the explained part of this block.
            let mut res = 0.0;
            for (i, bi) in b.iter().enumerate() {
                let mut pred = 0.0;
                for (c, xc) in x.iter().enumerate() {
                    pred += a[(i, c)] * xc;
                }
                res += (pred - bi).powi(2);
            }
            explained += b.iter().map(|v| v * v).sum::<f64>() - res;
            for l in m..=degree {
                let k = if part == 0 {
                    index(l, m as i64)
                } else {
                    index(l, -(m as i64))
                };
                coef[k] = x[l - m];
            }
            // Singular values of the full design: every block column counts once.
            let mut padded = sv.clone();
            padded.resize(ncol, 0.0);
            all_sv.extend_from_slice(&padded);
        }
    }
    Ok(RingBlocks {
        coefficients: coef,
        singular_values: all_sv,
        any_deficient,
        explained,
    })
}

/// The design matrix of block m: one row per ring, one column per degree l = m..=degree,
/// entries `√(w·n_φ)·P_lm(cos θ)`.
fn block_design(rings: &[Ring], ptab: &[Vec<f64>], m: usize, degree: usize) -> Mat<f64> {
    let ncol = degree - m + 1;
    let mut a = Mat::<f64>::zeros(rings.len(), ncol);
    for (i, ring) in rings.iter().enumerate() {
        let f = (ring.weight * ring.n_phi as f64).sqrt();
        for l in m..=degree {
            a[(i, l - m)] = f * ptab[i][tri(l, m)];
        }
    }
    a
}

/// Coefficients by quadrature, `a_lm = Σ w_i r_i Y_lm(θ_i, φ_i)` with the grid's weights.
///
/// Exact (to rounding) for data of degree ≤ `degree` on `RingGrid::gauss_legendre(degree)`.
/// Values may be any finite numbers (used also for non-radius functions).
///
/// # Errors
/// [`Error::LengthMismatch`], [`Error::NonFinite`], [`Error::DegreeTooHighForGrid`] when a
/// non-polar ring has ≤ 2·degree azimuths (aliasing).
pub fn quadrature_transform(
    grid: &RingGrid,
    values: &[f64],
    degree: usize,
) -> Result<ShModel, Error> {
    if values.len() != grid.len() {
        return Err(Error::LengthMismatch {
            what: "values",
            expected: grid.len(),
            got: values.len(),
        });
    }
    check_finite("value", values)?;
    if let Some(r) = grid
        .rings()
        .iter()
        .find(|r| !r.is_pole() && r.n_phi <= 2 * degree)
    {
        return Err(Error::DegreeTooHighForGrid {
            degree,
            needed: 2 * degree + 1,
            available: r.n_phi,
        });
    }
    let leg = Legendre::new(degree)?;
    let mut vals = leg.buffer(0);
    let sqrt2 = std::f64::consts::SQRT_2;
    let mut coef = vec![0.0; coefficient_count(degree)];
    let mut cs = vec![0.0; degree + 1];
    let mut ss = vec![0.0; degree + 1];
    let mut offset = 0;
    for ring in grid.rings() {
        let n = ring.n_phi;
        let data = &values[offset..offset + n];
        offset += n;
        leg.compute(ring.theta, &mut vals);
        for m in 0..=degree {
            let (sm0, cm0) = (m as f64 * ring.phi0).sin_cos();
            let (ms1, mc1) = (m as f64 * 2.0 * std::f64::consts::PI / n as f64).sin_cos();
            let (mut s, mut c) = (sm0, cm0);
            let (mut a, mut b) = (0.0, 0.0);
            for &v in data {
                a += v * c;
                b += v * s;
                let cn = c * mc1 - s * ms1;
                s = s * mc1 + c * ms1;
                c = cn;
            }
            cs[m] = a * ring.weight;
            ss[m] = b * ring.weight;
        }
        for m in 0..=degree {
            for l in m..=degree {
                let p = vals.p[tri(l, m)];
                if m == 0 {
                    coef[index(l, 0)] += p * cs[0];
                } else {
                    coef[index(l, m as i64)] += sqrt2 * p * cs[m];
                    coef[index(l, -(m as i64))] += sqrt2 * p * ss[m];
                }
            }
        }
    }
    ShModel::new(degree, coef)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_model(degree: usize, seed: u64) -> ShModel {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut c: Vec<f64> = (0..coefficient_count(degree))
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        c[0] = 200.0;
        ShModel::new(degree, c).expect("model")
    }

    fn max_diff(a: &ShModel, b: &ShModel) -> f64 {
        a.coefficients()
            .iter()
            .zip(b.coefficients())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn quadrature_round_trip_degree_30() {
        let model = random_model(30, 42);
        let grid = RingGrid::gauss_legendre(30).expect("grid");
        let values = model.evaluate_grid(&grid).expect("values");
        let back = quadrature_transform(&grid, &values, 30).expect("transform");
        let err = max_diff(&model, &back);
        assert!(err < 1e-12, "max coefficient error {err:e} (seeds 42/43)");
    }

    #[test]
    fn ring_least_squares_round_trip_degree_30_on_threshold_grid() {
        let model = random_model(30, 43);
        let grid = RingGrid::threshold();
        let values = model.evaluate_grid(&grid).expect("values");
        let fit = least_squares_rings(&grid, &values, 30).expect("fit");
        let err = max_diff(&model, &fit.model);
        assert!(err < 1e-12, "max coefficient error {err:e} (seeds 42/43)");
        assert_eq!(fit.diagnostics.rank, 961);
        assert!(!fit.diagnostics.rank_deficient);
        assert!(fit.diagnostics.rms_residual < 1e-9);
    }

    #[test]
    fn general_least_squares_round_trip_and_agreement_with_rings() {
        let degree = 10;
        let model = random_model(degree, 44);
        let grid = RingGrid::equiangular_with_poles(24, 24).expect("grid");
        let mut values = model.evaluate_grid(&grid).expect("values");
        let fit = least_squares(&grid.points(), &values, None, degree).expect("fit");
        assert!(max_diff(&model, &fit.model) < 1e-12);
        assert_eq!(fit.diagnostics.method, FitMethod::Qr);
        // With noise the two paths must still agree (same least-squares problem).
        for (i, v) in values.iter_mut().enumerate() {
            *v += 0.3 * ((i * 7919) as f64).sin();
        }
        let a = least_squares(&grid.points(), &values, None, degree).expect("fit");
        let b = least_squares_rings(&grid, &values, degree).expect("fit");
        assert!(max_diff(&a.model, &b.model) < 1e-11);
        assert_abs_diff_eq!(
            a.diagnostics.rms_residual,
            b.diagnostics.rms_residual,
            epsilon = 1e-9
        );
        assert_abs_diff_eq!(
            a.diagnostics.condition_number,
            b.diagnostics.condition_number,
            epsilon = 1e-8 * a.diagnostics.condition_number
        );
    }

    #[test]
    fn rank_deficient_grid_is_reported() {
        // All samples in the upper hemisphere at only 3 polar angles: degree 4 is not determined.
        let mut dirs = Vec::new();
        for &t in &[0.3, 0.6, 0.9] {
            for j in 0..20 {
                dirs.push((t, j as f64 * 0.314));
            }
        }
        let radii = vec![1.0; dirs.len()];
        let fit = least_squares(&dirs, &radii, None, 4).expect("fit");
        assert!(fit.diagnostics.rank_deficient);
        assert!(fit.diagnostics.rank < 25);
        assert_eq!(fit.diagnostics.method, FitMethod::PseudoInverse);
        // The minimum-norm solution still reproduces the data.
        assert!(fit.diagnostics.rms_residual < 1e-10);
        let rings = RingGrid::new(
            [0.3, 0.6, 0.9]
                .iter()
                .map(|&t| crate::grid::Ring {
                    theta: t,
                    n_phi: 20,
                    phi0: 0.0,
                    weight: 1.0,
                })
                .collect(),
        )
        .expect("grid");
        let fit = least_squares_rings(&rings, &radii, 4).expect("fit");
        assert!(fit.diagnostics.rank_deficient);
    }

    #[test]
    fn bad_input_is_rejected() {
        let dirs = vec![(0.1, 0.2); 3];
        assert!(matches!(
            least_squares(&dirs, &[1.0, 1.0], None, 0),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            least_squares(&dirs, &[1.0, f64::NAN, 1.0], None, 0),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            least_squares(&dirs, &[1.0, -1.0, 1.0], None, 0),
            Err(Error::NonPositiveRadius { .. })
        ));
        assert!(matches!(
            least_squares(&dirs, &[1.0, 0.0, 1.0], None, 0),
            Err(Error::NonPositiveRadius { .. })
        ));
        assert!(matches!(
            least_squares(&dirs, &[1.0; 3], None, 2),
            Err(Error::DegreeTooHighForGrid { .. })
        ));
        assert!(matches!(
            least_squares(&dirs, &[1.0; 3], Some(&[1.0, -1.0, 1.0]), 0),
            Err(Error::InvalidWeight { .. })
        ));
        let g = RingGrid::gauss_legendre(3).expect("grid");
        assert!(matches!(
            quadrature_transform(&g, &vec![1.0; g.len()], 5),
            Err(Error::DegreeTooHighForGrid { .. })
        ));
    }

    proptest::proptest! {
        #[test]
        fn fit_evaluate_round_trip(degree in 0usize..10, seed in 0u64..1000) {
            let model = random_model(degree, seed);
            let grid = RingGrid::gauss_legendre(degree).expect("grid");
            let values = model.evaluate_grid(&grid).expect("values");
            let back = quadrature_transform(&grid, &values, degree).expect("transform");
            proptest::prop_assert!(max_diff(&model, &back) < 1e-12, "seed {}", seed);
            let dense = RingGrid::equiangular_with_poles(2 * degree + 4, 2 * degree + 3).expect("grid");
            let values = model.evaluate_grid(&dense).expect("values");
            let fit = least_squares_rings(&dense, &values, degree).expect("fit");
            proptest::prop_assert!(max_diff(&model, &fit.model) < 1e-11, "seed {}", seed);
        }
    }
}
