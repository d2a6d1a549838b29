//! A grain as radii on the spherical mesh: interpolation (the radius function
//! handed to `levelset`'s star builder), Laplacian smoothing, and the cheap
//! *surface DNA* — volume, area, principal dimensions and roundness computed
//! from the node radii alone, used to steer and reject candidates before any
//! level set is built.
//!
//! # Geometry
//!
//! Nodes follow [`SphericalMesh`] (north pole = flat index 0, ring node
//! `(i, j)` = `1 + (j − 1) n_az + i`, south pole last); ring `j` sits at
//! `θ_j = j Δθ`, `Δθ = π / (n_pol + 1)`, and `φ_i = i Δφ`, `Δφ = 2π / n_az`,
//! in the grain's principal frame (θ from the minor axis, φ from the major
//! axis). The surface is `x(θ, φ) = r(θ, φ) u(θ, φ)`.
//!
//! # Surface DNA (design choices)
//!
//! * **Quadrature:** each node carries the solid angle of its cell (rings:
//!   `Δφ ∫ sin θ dθ` over `θ_j ± Δθ/2`; poles: the cap of half-angle
//!   `Δθ/2`), which sums to 4π exactly. `V = Σ w r³/3`,
//!   `A = Σ w r √(r² + r_θ² + r_φ²/sin²θ)`, second moments `Σ w r⁵/5 u uᵀ`.
//! * **Derivatives** are central differences on the mesh (which are exactly
//!   the node tangents of the Catmull-Rom interpolant); at the first and last
//!   ring the pole is the neighbour across θ.
//! * **Principal curvatures** at ring nodes from the first and second
//!   fundamental forms of `x(θ, φ)`; poles carry no curvature sample (their
//!   cells cover 0.2 % of the sphere at 28 × (18 + 2)).
//! * **Roundness** mirrors `morph-dna`'s level-set definition (corner rule
//!   κ₁ > 1/r_ins, curvature-averaged corner radius over r_ins) with
//!   `r_ins ≈ min r` (the largest sphere about the mesh centre) and κ₁ capped
//!   at the curvature a level set of the target resolution can resolve,
//!   `1/h` with `h = 2 · margin · r_max / (n − 1)`.
//!
//! These are estimates of the same quantities `morph-dna` measures on the
//! rasterised level set; the population model computes them for the parents
//! with the same code, so the construction is steered in one consistent
//! measure and judged in the other (see the crate docs).

use nalgebra::{Matrix3, Point3, SymmetricEigen, Unit, Vector3};
use serde::{Deserialize, Serialize};

use morph_dna::{PrincipalFrame, SphericalMesh};

use std::f64::consts::{PI, TAU};

/// How node radii are interpolated between nodes (the clone's radius
/// function, rasterised by `levelset`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Interpolation {
    /// Bilinear in (θ, φ): C⁰, with creases along mesh lines (the seed's
    /// Matlab-style linear interpolation).
    Bilinear,
    /// Catmull-Rom cubic in φ (periodic) and θ (continued across the poles):
    /// C¹, interpolating, tangents equal to the central differences the
    /// surface DNA uses. Default.
    #[default]
    CatmullRom,
}

/// Precomputed geometry of a [`SphericalMesh`].
#[derive(Debug, Clone)]
pub struct MeshGeometry {
    mesh: SphericalMesh,
    dtheta: f64,
    dphi: f64,
    /// Unit direction of every node.
    dirs: Vec<Vector3<f64>>,
    /// Solid angle of every node's cell.
    weights: Vec<f64>,
    /// Per node: `[u_θ, u_φ, u_θφ, u_φφ]` and `1/sin²θ` (rings only).
    frames: Vec<([Vector3<f64>; 4], f64)>,
    /// Ring nodes: [i+1, i−1, j+1, j−1] neighbours (poles: unused).
    nbrs: Vec<[usize; 4]>,
    /// Ring nodes: [(i+1, j+1), (i−1, j+1), (i+1, j−1), (i−1, j−1)].
    diag: Vec<[usize; 4]>,
}

/// Cheap DNA of a mesh surface (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SurfaceDna {
    /// Volume.
    pub volume: f64,
    /// Surface area.
    pub area: f64,
    /// Principal dimensions `[L, I, S]` (inertia-equivalent ellipsoid scaled
    /// to the volume, as `morph-dna`).
    pub dims: [f64; 3],
    /// Roundness estimate in (0, 1].
    pub roundness: f64,
    /// Smallest node radius.
    pub r_min: f64,
    /// Largest node radius.
    pub r_max: f64,
}

impl SurfaceDna {
    /// Aspect ratio `S / L`.
    pub fn aspect_ratio(&self) -> f64 {
        self.dims[2] / self.dims[0]
    }
    /// Flatness `S / I`.
    pub fn flatness(&self) -> f64 {
        self.dims[2] / self.dims[1]
    }
    /// Volume/surface ratio.
    pub fn volume_surface_ratio(&self) -> f64 {
        self.volume / self.area
    }
    /// Equivalent-sphere diameter.
    pub fn equivalent_diameter(&self) -> f64 {
        (6.0 * self.volume / PI).cbrt()
    }
}

impl MeshGeometry {
    /// Geometry of `mesh` (which must be valid: `n_az ≥ 3`, `n_pol ≥ 1`).
    pub fn new(mesh: SphericalMesh) -> Self {
        let (n_az, n_pol) = (mesh.n_az, mesh.n_pol);
        let dtheta = PI / (n_pol + 1) as f64;
        let dphi = TAU / n_az as f64;
        let n = mesh.n_nodes();
        let angles = mesh.node_angles();
        let dirs = angles
            .iter()
            .map(|&(t, p)| Vector3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()))
            .collect();
        let mut weights = vec![0.0; n];
        let cap = TAU * (1.0 - (0.5 * dtheta).cos());
        weights[0] = cap;
        weights[n - 1] = cap;
        for j in 1..=n_pol {
            let t = j as f64 * dtheta;
            let band = ((t - 0.5 * dtheta).cos() - (t + 0.5 * dtheta).cos()) * dphi;
            for i in 0..n_az {
                weights[1 + (j - 1) * n_az + i] = band;
            }
        }
        let idx = |i: isize, j: usize| -> usize {
            let i = i.rem_euclid(n_az as isize) as usize;
            mesh.index(i, j).unwrap_or(0)
        };
        let mut nbrs = vec![[0usize; 4]; n];
        let mut diag = vec![[0usize; 4]; n];
        for j in 1..=n_pol {
            for i in 0..n_az {
                let ii = i as isize;
                let f = 1 + (j - 1) * n_az + i;
                nbrs[f] = [
                    idx(ii + 1, j),
                    idx(ii - 1, j),
                    idx(ii, j + 1),
                    idx(ii, j - 1),
                ];
                diag[f] = [
                    idx(ii + 1, j + 1),
                    idx(ii - 1, j + 1),
                    idx(ii + 1, j - 1),
                    idx(ii - 1, j - 1),
                ];
            }
        }
        let frames = angles
            .iter()
            .map(|&(t, p)| {
                let (st, ct) = t.sin_cos();
                let (sp, cp) = p.sin_cos();
                (
                    [
                        Vector3::new(ct * cp, ct * sp, -st),
                        Vector3::new(-st * sp, st * cp, 0.0),
                        Vector3::new(-ct * sp, ct * cp, 0.0),
                        Vector3::new(-st * cp, -st * sp, 0.0),
                    ],
                    if st > 0.0 { 1.0 / (st * st) } else { 0.0 },
                )
            })
            .collect();
        Self {
            mesh,
            dtheta,
            dphi,
            dirs,
            weights,
            frames,
            nbrs,
            diag,
        }
    }

    /// The mesh.
    pub fn mesh(&self) -> SphericalMesh {
        self.mesh
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.dirs.len()
    }

    /// Unit direction of node `n` (mesh frame).
    pub fn direction(&self, n: usize) -> Vector3<f64> {
        self.dirs[n]
    }

    /// Solid angle of node `n`'s cell (they sum to 4π).
    pub fn weight(&self, n: usize) -> f64 {
        self.weights[n]
    }

    /// The four stencil neighbours `(i+1, j), (i−1, j), (i, j+1), (i, j−1)`
    /// of ring node `n` (Medina 2018, Table 2), `None` at the poles.
    pub fn neighbours(&self, n: usize) -> Option<[usize; 4]> {
        (n != 0 && n + 1 != self.n_nodes()).then(|| self.nbrs[n])
    }

    /// Radius of the ellipsoid with semi-axes `semi` (along the mesh frame's
    /// x, y, z) in the direction of node `n`.
    pub fn ellipsoid_radius(&self, n: usize, semi: [f64; 3]) -> f64 {
        let u = self.dirs[n];
        1.0 / ((u.x / semi[0]).powi(2) + (u.y / semi[1]).powi(2) + (u.z / semi[2]).powi(2)).sqrt()
    }

    /// One umbrella-Laplacian step `ρ ← ρ + λ (mean of neighbours − ρ)`
    /// (ring nodes: the four stencil neighbours; poles: their adjacent ring),
    /// written into `out`.
    pub fn smooth_into(&self, field: &[f64], lambda: f64, out: &mut [f64]) {
        let (n_az, n_pol) = (self.mesh.n_az, self.mesh.n_pol);
        let n = field.len();
        let ring_mean = |j: usize| -> f64 {
            let s: f64 = field[1 + (j - 1) * n_az..1 + j * n_az].iter().sum();
            s / n_az as f64
        };
        out[0] = field[0] + lambda * (ring_mean(1) - field[0]);
        out[n - 1] = field[n - 1] + lambda * (ring_mean(n_pol) - field[n - 1]);
        for f in 1..n - 1 {
            let nb = self.nbrs[f];
            let m = 0.25 * (field[nb[0]] + field[nb[1]] + field[nb[2]] + field[nb[3]]);
            out[f] = field[f] + lambda * (m - field[f]);
        }
    }

    /// Derivatives `(r_θ, r_φ, r_θθ, r_φφ, r_θφ)` at ring node `f`.
    fn derivatives(&self, r: &[f64], f: usize) -> [f64; 5] {
        let nb = self.nbrs[f];
        let dg = self.diag[f];
        let (dt, dp) = (self.dtheta, self.dphi);
        let c = r[f];
        [
            (r[nb[2]] - r[nb[3]]) / (2.0 * dt),
            (r[nb[0]] - r[nb[1]]) / (2.0 * dp),
            (r[nb[2]] - 2.0 * c + r[nb[3]]) / (dt * dt),
            (r[nb[0]] - 2.0 * c + r[nb[1]]) / (dp * dp),
            (r[dg[0]] - r[dg[1]] - r[dg[2]] + r[dg[3]]) / (4.0 * dt * dp),
        ]
    }

    /// Area element factor and largest principal curvature at ring node `f`.
    fn ring_geometry(&self, r: &[f64], f: usize) -> (f64, f64) {
        let ([ut, up, utp, upp], inv_s2) = self.frames[f];
        let [rt, rp, rtt, rpp, rtp] = self.derivatives(r, f);
        let rr = r[f];
        let u = self.dirs[f];
        let xt = rt * u + rr * ut;
        let xp = rp * u + rr * up;
        let xtt = rtt * u + 2.0 * rt * ut - rr * u;
        let xtp = rtp * u + rt * up + rp * ut + rr * utp;
        let xpp = rpp * u + 2.0 * rp * up + rr * upp;
        let cross = xt.cross(&xp);
        let cn = cross.norm();
        let dens = rr * (rr * rr + rt * rt + rp * rp * inv_s2).sqrt();
        if cn.is_nan() || cn <= 0.0 {
            return (dens, 0.0);
        }
        let nrm = cross / cn;
        let (e, ff, g) = (xt.dot(&xt), xt.dot(&xp), xp.dot(&xp));
        let (l, m, nn) = (xtt.dot(&nrm), xtp.dot(&nrm), xpp.dot(&nrm));
        let det = e * g - ff * ff;
        let k = (l * nn - m * m) / det;
        let h = -(e * nn - 2.0 * ff * m + g * l) / (2.0 * det);
        let k1 = h + (h * h - k).max(0.0).sqrt();
        (dens, if k1.is_finite() { k1 } else { 0.0 })
    }

    /// Area element factor at ring node `f` (the first derivatives only; the
    /// same value as [`MeshGeometry::ring_geometry`]'s).
    fn ring_density(&self, r: &[f64], f: usize) -> f64 {
        let nb = self.nbrs[f];
        let rt = (r[nb[2]] - r[nb[3]]) / (2.0 * self.dtheta);
        let rp = (r[nb[0]] - r[nb[1]]) / (2.0 * self.dphi);
        let rr = r[f];
        rr * (rr * rr + rt * rt + rp * rp * self.frames[f].1).sqrt()
    }

    /// Area element factor at a pole (slope from the adjacent ring).
    fn pole_density(&self, r: &[f64], pole: usize) -> f64 {
        let (n_az, n_pol) = (self.mesh.n_az, self.mesh.n_pol);
        let ring = if pole == 0 { 1 } else { n_pol };
        let (mut gx, mut gy) = (0.0, 0.0);
        for i in 0..n_az {
            let d = r[1 + (ring - 1) * n_az + i] - r[pole];
            let p = i as f64 * self.dphi;
            gx += d * p.cos();
            gy += d * p.sin();
        }
        let s = 2.0 / (n_az as f64 * self.dtheta);
        let (gx, gy) = (gx * s, gy * s);
        let rr = r[pole];
        rr * (rr * rr + gx * gx + gy * gy).sqrt()
    }

    /// Estimated radius of the grain's largest inscribed sphere: the largest
    /// distance from a point to the nearest surface node, maximised by a
    /// compass (pattern) search from the mesh centre (steps of a quarter of
    /// the current radius along ±x, ±y, ±z, halved when no step improves,
    /// down to 1e-3 of the radius). The nodes stand for the surface, so this
    /// slightly overestimates the level set's inscribed radius; it predicts it
    /// closely (correlation 0.996 on Ottawa clones), which is what the
    /// roundness prediction needs (`r_ins` sets the corner threshold and
    /// the roundness scale). `None` for invalid radii.
    pub fn inscribed_radius(&self, r: &[f64]) -> Option<f64> {
        if r.len() != self.n_nodes() || r.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return None;
        }
        // the nodes as coordinate arrays, in chunks of `LANES` (padded by copies of
        // the first node, which change no minimum)
        const LANES: usize = 8;
        let n = r.len().div_ceil(LANES) * LANES;
        let mut xyz = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (i, (u, &v)) in self.dirs.iter().zip(r).enumerate() {
            let p = u * v;
            for a in 0..3 {
                xyz[a][i] = p[a];
            }
        }
        for coord in &mut xyz {
            let first = coord[0];
            coord[r.len()..].fill(first);
        }
        // the squared distance from `c` to the nearest node if it exceeds `floor`,
        // else None (stops at the first chunk at or below `floor`); the same value
        // as the full minimum, whose terms are each `(x−cx)² + (y−cy)² + (z−cz)²`
        let nearest2_above = |c: &Vector3<f64>, floor: f64| {
            let mut m = f64::INFINITY;
            for ((xs, ys), zs) in xyz[0]
                .chunks_exact(LANES)
                .zip(xyz[1].chunks_exact(LANES))
                .zip(xyz[2].chunks_exact(LANES))
            {
                let mut lane = [f64::INFINITY; LANES];
                for l in 0..LANES {
                    let (dx, dy, dz) = (xs[l] - c.x, ys[l] - c.y, zs[l] - c.z);
                    let d = dx * dx + dy * dy + dz * dz;
                    lane[l] = if d < lane[l] { d } else { lane[l] };
                }
                let cm = lane
                    .iter()
                    .fold(f64::INFINITY, |a, &b| if b < a { b } else { a });
                if cm <= floor {
                    return None;
                }
                m = if cm < m { cm } else { m };
            }
            Some(m)
        };
        let mut c = Vector3::zeros();
        let mut best2 = nearest2_above(&c, f64::NEG_INFINITY)?;
        let mut step = 0.25 * best2.sqrt();
        for _ in 0..200 {
            let mut moved = false;
            for a in 0..3 {
                for sign in [-1.0, 1.0] {
                    let mut q = c;
                    q[a] += sign * step;
                    if let Some(d2) = nearest2_above(&q, best2) {
                        best2 = d2;
                        c = q;
                        moved = true;
                    }
                }
            }
            if !moved {
                step *= 0.5;
                if step < 1e-3 * best2.sqrt() {
                    break;
                }
            }
        }
        let v = best2.sqrt();
        (v.is_finite() && v > 0.0).then_some(v)
    }

    /// Roundness estimate only (see the module docs); `resolution` is the
    /// level-set nodes per axis and `margin` the grid half-width over `r_max`.
    pub fn roundness(&self, r: &[f64], resolution: usize, margin: f64) -> f64 {
        let (r_min, _) = min_max(r);
        self.roundness_about(r, resolution, margin, r_min)
    }

    /// As [`MeshGeometry::roundness`] with the inscribed radius `r_ins`
    /// instead of `min r` in the corner rule (κ₁ > 1/r_ins) and as the
    /// scale, as `morph-dna` measures it on a level set (e.g. `r_ins` from
    /// [`MeshGeometry::inscribed_radius`]).
    pub fn roundness_about(&self, r: &[f64], resolution: usize, margin: f64, r_ins: f64) -> f64 {
        let (r_min, r_max) = (r_ins, min_max(r).1);
        let cap = (resolution.saturating_sub(1)) as f64 / (2.0 * margin * r_max);
        let threshold = 1.0 / r_min;
        let (mut sw, mut swk) = (0.0, 0.0);
        for f in 1..r.len() - 1 {
            let (dens, k1) = self.ring_geometry(r, f);
            if k1 > threshold {
                let w = self.weights[f] * dens;
                sw += w;
                swk += w * k1.min(cap);
            }
        }
        if sw == 0.0 || swk == 0.0 {
            return 1.0;
        }
        ((sw / swk) / r_min).min(1.0)
    }

    /// The full surface DNA, `None` for a degenerate field (non-positive or
    /// non-finite radii, or moments of a flat body).
    pub fn surface_dna(&self, r: &[f64], resolution: usize, margin: f64) -> Option<SurfaceDna> {
        self.surface_dna_with(r, resolution, margin, true)
    }

    /// As [`MeshGeometry::surface_dna`]; without `roundness` the curvatures
    /// are skipped (the cost of most of it) and the roundness reads NaN.
    pub(crate) fn surface_dna_with(
        &self,
        r: &[f64],
        resolution: usize,
        margin: f64,
        roundness: bool,
    ) -> Option<SurfaceDna> {
        let with_roundness = roundness;
        if r.len() != self.n_nodes() || r.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return None;
        }
        let (r_min, r_max) = min_max(r);
        let cap = (resolution.saturating_sub(1)) as f64 / (2.0 * margin * r_max);
        let threshold = 1.0 / r_min;
        let n = r.len();
        let (mut vol, mut area) = (0.0, 0.0);
        let mut first = Vector3::zeros();
        let mut second = Matrix3::zeros();
        let (mut sw, mut swk) = (0.0, 0.0);
        for f in 0..n {
            let rr = r[f];
            let w = self.weights[f];
            let u = self.dirs[f];
            let r3 = rr * rr * rr;
            vol += w * r3 / 3.0;
            first += u * (w * r3 * rr / 4.0);
            second += (u * u.transpose()) * (w * r3 * rr * rr / 5.0);
            if f == 0 || f == n - 1 {
                area += w * self.pole_density(r, f);
            } else if with_roundness {
                let (dens, k1) = self.ring_geometry(r, f);
                area += w * dens;
                if k1 > threshold {
                    sw += w * dens;
                    swk += w * dens * k1.min(cap);
                }
            } else {
                area += w * self.ring_density(r, f);
            }
        }
        let roundness = if !with_roundness {
            f64::NAN
        } else if sw == 0.0 || swk == 0.0 {
            1.0
        } else {
            ((sw / swk) / r_min).min(1.0)
        };
        let c = first / vol;
        let j0 = Matrix3::identity() * second.trace() - second;
        let jc = j0 - (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * vol;
        let eig = SymmetricEigen::new(jc);
        let mut m = [eig.eigenvalues[0], eig.eigenvalues[1], eig.eigenvalues[2]];
        m.sort_by(f64::total_cmp);
        let frame = PrincipalFrame {
            centroid: Point3::from(c),
            axes: Matrix3::identity(),
            moments: Vector3::new(m[0], m[1], m[2]),
            volume: vol,
            area,
        };
        let dims = frame.principal_dimensions().ok()?;
        let out = SurfaceDna {
            volume: vol,
            area,
            dims,
            roundness,
            r_min,
            r_max,
        };
        (out.volume.is_finite() && out.area.is_finite() && out.area > 0.0).then_some(out)
    }

    /// Interpolated radius in direction `(θ, φ)` of the mesh frame.
    pub fn interpolate(&self, r: &[f64], theta: f64, phi: f64, how: Interpolation) -> f64 {
        self.eval(&self.plan(theta, phi, how), r)
    }

    /// How [`MeshGeometry::interpolate`] combines the node radii in direction `(θ, φ)`
    /// (the interpolation is linear in the radii): node indices and weights, for
    /// [`MeshGeometry::eval`] at many fields.
    pub fn plan(&self, theta: f64, phi: f64, how: Interpolation) -> DirectionPlan {
        let n_pol = self.mesh.n_pol;
        let t = (theta / self.dtheta).clamp(0.0, (n_pol + 1) as f64);
        let j0 = (t.floor() as usize).min(n_pol);
        let ft = t - j0 as f64;
        let phi = phi.rem_euclid(TAU);
        let mut rows = [RowPlan::Node(0); 4];
        let w = match how {
            Interpolation::Bilinear => {
                rows[0] = self.row_linear(j0 as isize, phi);
                rows[1] = self.row_linear(j0 as isize + 1, phi);
                [ft, 0.0, 0.0, 0.0]
            }
            Interpolation::CatmullRom => {
                for (k, row) in rows.iter_mut().enumerate() {
                    *row = self.row_cubic(j0 as isize - 1 + k as isize, phi);
                }
                catmull_rom_weights(ft)
            }
        };
        DirectionPlan { how, w, rows }
    }

    /// The radius of field `r` by a plan of [`MeshGeometry::plan`]: the arithmetic of
    /// [`MeshGeometry::interpolate`], so the same value bit for bit.
    #[inline]
    pub fn eval(&self, plan: &DirectionPlan, r: &[f64]) -> f64 {
        let row = |p: &RowPlan| match *p {
            RowPlan::Node(i) => r[i as usize],
            RowPlan::Linear(i, j, f) => {
                let (a, b) = (r[i as usize], r[j as usize]);
                a + f * (b - a)
            }
            RowPlan::Cubic(idx, w) => {
                let mut s = 0.0;
                for (wk, &i) in w.iter().zip(&idx) {
                    s += wk * r[i as usize];
                }
                s
            }
        };
        match plan.how {
            Interpolation::Bilinear => {
                let (a, b) = (row(&plan.rows[0]), row(&plan.rows[1]));
                a + plan.w[0] * (b - a)
            }
            Interpolation::CatmullRom => {
                let mut s = 0.0;
                for (wk, p) in plan.w.iter().zip(&plan.rows) {
                    s += wk * row(p);
                }
                s
            }
        }
    }

    /// Maps a row index beyond a pole onto the ring reflected across it.
    fn reflect(&self, j: isize, phi: f64) -> (usize, f64) {
        let last = (self.mesh.n_pol + 1) as isize;
        if j < 0 {
            ((-j) as usize, phi + PI)
        } else if j > last {
            ((2 * last - j) as usize, phi + PI)
        } else {
            (j as usize, phi)
        }
    }

    /// Index of node `i` of ring `j` (the poles for j = 0 and j > n_pol).
    fn ring_index(&self, j: usize, i: isize) -> u32 {
        let n_az = self.mesh.n_az;
        let k = if j == 0 {
            0
        } else if j > self.mesh.n_pol {
            self.dirs.len() - 1
        } else {
            1 + (j - 1) * n_az + i.rem_euclid(n_az as isize) as usize
        };
        // meshes are far below 2³² nodes (validated)
        u32::try_from(k).unwrap_or(u32::MAX)
    }

    fn row_linear(&self, j: isize, phi: f64) -> RowPlan {
        let (j, phi) = self.reflect(j, phi);
        let p = phi.rem_euclid(TAU) / self.dphi;
        let i0 = p.floor();
        let fp = p - i0;
        let i0 = i0 as isize;
        RowPlan::Linear(self.ring_index(j, i0), self.ring_index(j, i0 + 1), fp)
    }

    fn row_cubic(&self, j: isize, phi: f64) -> RowPlan {
        let (j, phi) = self.reflect(j, phi);
        if j == 0 || j > self.mesh.n_pol {
            return RowPlan::Node(self.ring_index(j, 0));
        }
        let p = phi.rem_euclid(TAU) / self.dphi;
        let i0 = p.floor();
        let w = catmull_rom_weights(p - i0);
        let i0 = i0 as isize;
        let mut idx = [0u32; 4];
        for (k, x) in idx.iter_mut().enumerate() {
            *x = self.ring_index(j, i0 - 1 + k as isize);
        }
        RowPlan::Cubic(idx, w)
    }

    /// The radius function of the field for `levelset::Grid::from_star`
    /// (directions in the mesh frame).
    pub fn radius_fn<'a>(
        &'a self,
        r: &'a [f64],
        how: Interpolation,
    ) -> impl FnMut(Unit<Vector3<f64>>) -> f64 + 'a {
        move |u: Unit<Vector3<f64>>| {
            let (theta, phi) = angles(&u);
            self.interpolate(r, theta, phi, how)
        }
    }

    /// The plans of [`MeshGeometry::radius_fn`] at `directions` (a cube map's, for
    /// `levelset::Grid::from_star_table`): `eval` of plan `t` at a field is the radius
    /// function in direction `t`, bit for bit.
    pub fn plans(
        &self,
        directions: &[Unit<Vector3<f64>>],
        how: Interpolation,
    ) -> Vec<DirectionPlan> {
        directions
            .iter()
            .map(|u| {
                let (theta, phi) = angles(u);
                self.plan(theta, phi, how)
            })
            .collect()
    }
}

/// One θ-row of a [`DirectionPlan`].
#[derive(Debug, Clone, Copy, PartialEq)]
enum RowPlan {
    /// A pole's radius.
    Node(u32),
    /// Two azimuthal taps `a + f·(b − a)` (bilinear).
    Linear(u32, u32, f64),
    /// Four azimuthal Catmull-Rom taps.
    Cubic([u32; 4], [f64; 4]),
}

/// The node indices and weights of [`MeshGeometry::interpolate`] in one direction
/// ([`MeshGeometry::plan`], [`MeshGeometry::eval`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionPlan {
    how: Interpolation,
    /// θ weights (Catmull-Rom), or `[ft, …]` (bilinear).
    w: [f64; 4],
    rows: [RowPlan; 4],
}

/// Polar and azimuthal angles of a unit direction.
#[inline]
fn angles(u: &Unit<Vector3<f64>>) -> (f64, f64) {
    (u.z.clamp(-1.0, 1.0).acos(), u.y.atan2(u.x))
}

/// Catmull-Rom weights of the four taps `−1, 0, 1, 2` at `t ∈ [0, 1]`.
fn catmull_rom_weights(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

fn min_max(r: &[f64]) -> (f64, f64) {
    r.iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)))
}

#[cfg(test)]
mod tests;
