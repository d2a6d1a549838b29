//! Dense non-overlapping 3D packings of star-shaped (e.g. cloned level-set)
//! grains in a box, a cylinder, a mesh or a periodic cell, and an
//! independent LS-DEM overlap check.
//!
//! # Shape
//! A [`StarGrain`] is a star-shaped surface `x = r(u)·u` about the origin of
//! its body frame, tabulated on a cube map ([`levelset::StarTable`]: the
//! bilinear lookup that [`levelset::Grid::from_star_table`] rasterises, so the
//! packer and the level sets of the check see the same surface). 16 cells per
//! face (1734 radii, 6.9 KB as f32) hold the cloner's 28 × 18 mesh with room
//! to spare; 10 000 grains take ~70 MB, where 10 000 grids of 45³ f64 would
//! take 7 GB. Inside test: `|p| < r(p̂)`, exact for the tabulated surface.
//!
//! # Method ([`pack_grains`])
//! Gap minimisation of Pérez Morales et al. (2016) with the LS-DEM
//! node-versus-surface test as the gap function, seeded by the 3D advancing
//! front, refined by local moves:
//! 1. **skeleton**: the advancing front of spheres ([`packer_spheres::pack3d_sizes`])
//!    with one sphere per grain, diameter `s·b`, `b = γ·b_i + (1 − γ)·mean b`
//!    with `b_i = (1−β)·d_eq + β·2 r_max` ([`GrainPackParams::skeleton_blend`]
//!    = β, [`GrainPackParams::skeleton_spread`] = γ; the seed's skeleton is
//!    γ = 1, the default γ = 0 packs equal spheres because a front of the
//!    grains' own sizes lets small spheres settle into its pockets and
//!    gathers the small grains at the bottom), in an order shuffled by the
//!    seed; the scale `s` starts at a sphere fraction of 0.64 and is lowered
//!    (by at most 10 % per try) until every grain has its sphere, so the
//!    grading is kept: every grain given is packed. The heights are then
//!    mapped monotonically so that the spheres' volume below any height
//!    grows linearly from floor to lid (the front's last, partial layer
//!    left the top tenth of a 3000-clone cylinder at a third of the mean
//!    density; after the map the ten height slices lie within ±0.02);
//! 2. **orientations**: uniformly random rotations (Shoemake) from the
//!    stream `(seed, index)`, so the fabric starts isotropic; the moves turn
//!    the grains only as much as their contacts ask (the fabric stays near
//!    isotropic: ‖N − I/3‖ ≈ 0.01 over 10 000 Ottawa clones);
//! 3. **compaction** ([`GrainPackParams::proxy_spheres`] > 0, the
//!    default; beyond the seed): each grain becomes a rigid clump of
//!    spheres inscribed in its star surface (a central sphere, then
//!    greedily the largest sphere tangent from inside at the surface point
//!    the clump reaches least, up to 48, radii 0.08–0.8 r_eq, until every
//!    surface point is within 0.01 r_eq; the clump may stand out of the
//!    surface by 0.04 r_eq where sparse samples allow, up to ~0.11 r_eq on
//!    flat faces). The clumps, each sphere inflated by 0.015 d_eq, start at
//!    the skeleton's scale `λ₀` and grow to full size in steps of up to
//!    0.15 (halved when a step does not relax — within 5000 iterations,
//!    or when its deepest overlap shrinks by less than a tenth over 500 —
//!    down to 2e-3); after every
//!    step FIRE (Bitzek et al. 2006) minimises the harmonic overlap energy
//!    of spheres of different grains and of spheres against the walls
//!    (each wall a separate contact: floor, lid, each side of a box, a
//!    cylinder's mantle; a mesh container's nearest wall) over
//!    the bodies' translations and rotations (generalised velocity
//!    `(v, k·ω)`, `k² = 0.1 d_eq²`), with Verlet lists of sphere pairs
//!    (skin 0.1 d_median, rebuilt when a sphere moved half the skin),
//!    until no overlap exceeds 5e-3 d_min. Why: the gap minimisation
//!    moves one pair's overlap at a time and its growth from `λ₀` stalls
//!    at dense targets (2000 clones at 0.60 did not converge in 3000
//!    sweeps), where the collective minimisation relaxes all contacts at
//!    once; sphere–sphere forces cost a few flops where a node test costs
//!    a table lookup per node. The clumps are inscribed, so the true
//!    surfaces may still overlap by the protrusion and the inflation's
//!    complement: the gap minimisation below finishes from full size
//!    (2000 clones at 0.55: 27.6 s → 7.9 s; 10 000 at 0.60 in ~70 s).
//!    A compaction that jams before full size ends in
//!    [`Error::FractionNotReached`] naming the fraction it reached;
//! 4. **overlap removal**: Jacobi sweeps over the pairs whose bounding
//!    spheres meet (a uniform cell grid of centres). The gap of a pair is
//!    the LS-DEM test both ways: nodes of A (quasi-uniform Fibonacci
//!    directions, grouped in 32 patches with bounding spheres so that only
//!    patches near B are looked at) against B grown by the margin
//!    `μ = margin·d_eq(B)`. An overlapping pair is pushed apart along the
//!    depth-weighted mean of B's outward normals at its penetrating nodes,
//!    by half the deepest penetration plus a quarter margin each, applied
//!    at the depth-weighted contact point: each grain takes the smallest
//!    rigid move that gives the contact point that displacement (the
//!    response of a rigid body to an impulse there, with a sphere's
//!    isotropic inertia `0.1·d_eq²`: translation `t·n`, rotation
//!    `t·(r × n)/k²`, `t = s/(1 + |r × n|²/k²)`; off with
//!    [`GrainPackParams::rotations`] = false, the seed's translations).
//!    A grain's moves are averaged (times [`GrainPackParams::relaxation`],
//!    1.8: over-relaxed Jacobi, 2.3× fewer sweeps than 1.2 on 2000
//!    ellipsoids). Walls are constraints: after each sweep a grain whose
//!    nodes come closer than `μ` to a wall is projected back along the
//!    wall normal. Only pairs with a grain moved in the previous sweep are
//!    tested again, from the moved grain, so late sweeps cost only their
//!    few moving grains. The grains start at the scale `λ₀` at which each
//!    fits its skeleton sphere and, once clean there, grow to full size in
//!    one step (steps of half the remaining scale each ended in the same
//!    slow tail of a few stubborn pairs: 944–2156 sweeps against 320–713
//!    on 2000 Ottawa clones at 0.50, 3 seeds).
//!    - **coarse stage**: [`GrainPackParams::coarse_nodes`] per grain and a
//!      margin of 2.5 μ, radial gaps `|p| − λ r(p̂)`. The wider margin
//!      absorbs what the sparse nodes miss between them: with μ the fine
//!      stage found nearly every contact a hair under the margin and took
//!      2/3 of the time (2000 Ottawa clones at 0.50, grown in small steps:
//!      31 s → 13 s);
//!    - **fine stage**: [`GrainPackParams::fine_nodes`] (the vertices of
//!      the grains' tables) and the margin μ, gaps as first-order
//!      distances `g/|∇g|` of `g(x) = |x| − r(x̂)` (∇g by forward
//!      differences, for nodes within 4 μ radially): a radial gap
//!      over-states the distance where the surface is steep, and the level
//!      sets of the check measure distance;
//! 5. a last pass over every pair records the worst gap
//!    ([`GrainPackStats::worst_gap_over_d`], ≥ the margin on success).
//!
//! Optional **settling under gravity** ([`GrainPackParams::settle`], between
//! steps 3 and 4): the full-size proxies get weights and FIRE brings the
//! pile to rest without friction, then the proxies are separated again (see
//! [`Settle`]); [`bed_top`] gives the height a lid may be lowered to. A
//! packing made to a fraction is spread over its whole container and a DEM
//! code's gravity compacts it (a 200-clone cylinder packed at 0.50 settled
//! to a bed fraction 0.05 higher in LAMMPS and Yade); a settled one is
//! already supported. What a DEM code moves is still a different body (a
//! multi-sphere clump inside the margin): [`close_clump_gaps`] closes the
//! clumps' small gaps (200 clones: the bed then moves by 0.006–0.007 in
//! LAMMPS, LIGGGHTS and Yade).
//!
//! Why: the skeleton gives a uniform, wall-hugging arrangement of the right
//! number of grains at the right density in O(n) (the front is fast), so the
//! gap minimisation only has to remove local overlaps of a few percent of a
//! diameter; node tests on a star surface cost one table lookup each and
//! are exact for the tabulated surface (no grid per grain); the margin
//! absorbs the difference between the star surface and its rasterised level
//! set, so the independent check on grids passes (see
//! [`check_grain_overlaps`]). Rotations matter: with translations only,
//! 2000 Ottawa clones at 0.50 still had 1225 overlapping pairs after 3000
//! sweeps (with rotations: clean after 730), and 2000 random ellipsoids at
//! 0.52 took 2326 sweeps (with rotations: 209). With both, 10 000 Ottawa
//! clones pack at 0.50 in 218 sweeps and at 0.56 in 1290. The density is
//! set by the container
//! ([`container_for`] sizes one from the grains and a target fraction); a
//! target the compaction cannot reach ends in [`Error::FractionNotReached`],
//! one the gap minimisation cannot clean in [`Error::NotConverged`]; beyond
//! [`MAX_FRACTION`] the packer refuses ([`Error::TooDense`]). Local solid
//! fractions of a packing are measured by point sampling with
//! [`occupied`] (validate case `specimen/homogeneity`).
//!
//! # Periodic cells ([`pack_grains_in`])
//! A [`Boundary::Periodic`] cell (periodic in x, y and z) or a box periodic
//! in x and y ([`Container::Box`] with `periodic`, walls in z) has no walls
//! on its periodic faces: a grain may cross one and meets the images of
//! the grains on the other side. Every stage works on images: the centres
//! are wrapped into the cell and the grains within reach of a periodic face
//! are copied beyond the opposite face (up to 7 copies in a corner) for the
//! neighbour searches of the compaction (each sphere pair stores its image
//! as a shift code in the top bits of its list entry) and of the gap
//! minimisation; the independent check makes its own images. The skeleton
//! of a fully periodic cell is packed by the front in the box periodic in x
//! and y with walls in z (its spheres clear the z walls, so none overlaps
//! through them), and the compaction then treats z as periodic. A periodic
//! side must be at least three bounding diameters of the largest grain (a
//! pair meets through one image only). Validate case `specimen/periodic`:
//! 2000 Ottawa clones at 0.60 in a periodic cube (1731 pairs checked
//! across its faces, all clean) and in an x–y periodic box.
//!
//! Determinism: the shuffle and the orientations come from `(seed, index)`
//! streams; the sweeps compute pair pushes in parallel but accumulate them in
//! a fixed order, so the packing is identical for any thread count.

// Seeded randomised tests print their seed (house style).
#![cfg_attr(test, allow(clippy::print_stdout))]

mod check;
mod clump_trim;
mod compact;
mod error;
mod region;
mod relax;

pub use clump_trim::{ClumpReach, ClumpTrim, close_clump_gaps, separate_clumps};
pub use compact::{CompactStats, SettleStats};
pub use error::{Error, Result};
pub use packer_spheres::{Boundary, Container, MeshContainer};

pub use check::{CheckParams, GrainOverlapReport, check_grain_overlaps, check_grain_overlaps_in};

use nalgebra::{
    Isometry3, Matrix3, Point3, Quaternion, Translation3, Unit, UnitQuaternion, Vector3,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::collections::{BTreeMap, VecDeque};

use crate::error::{finite, positive};
use packer_spheres::{Pack3Params, pack3d_sizes};
use region::Region;

/// A star-shaped grain `x = r(u)·u` about the origin of its body frame,
/// tabulated on a cube map (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct StarGrain {
    table: levelset::StarTable,
    r_max: f64,
    r_min: f64,
    volume: f64,
}

/// Fibonacci directions used for the volume quadrature of a [`StarGrain`].
const VOLUME_DIRECTIONS: usize = 4096;

impl StarGrain {
    /// From the radii at `levelset::cube_map_directions(face_cells)`, in that
    /// order (e.g. `cloner::CloneModel::star_table(&clone.radii, 16)`).
    ///
    /// # Errors
    /// [`Error::StarTable`] (levelset's error) for `face_cells` outside 2..=4096,
    /// a wrong number of radii or a radius that is not finite and positive.
    pub fn from_table(face_cells: usize, radii: &[f64]) -> Result<Self> {
        let table = levelset::StarTable::new(face_cells, radii).map_err(Error::StarTable)?;
        let (r_max, r_min) = table.extremes();
        let dirs = fibonacci(VOLUME_DIRECTIONS);
        let mean_r3 =
            dirs.iter().map(|u| table.radius(u).powi(3)).sum::<f64>() / VOLUME_DIRECTIONS as f64;
        let volume = 4.0 / 3.0 * std::f64::consts::PI * mean_r3;
        Ok(Self {
            table,
            r_max,
            r_min,
            volume,
        })
    }

    /// From a radius function, tabulated at `cube_map_directions(face_cells)`
    /// (the generic path: analytic shapes, spherical harmonics).
    ///
    /// # Errors
    /// As [`StarGrain::from_table`].
    pub fn from_fn(face_cells: usize, r: impl Fn(&Unit<Vector3<f64>>) -> f64) -> Result<Self> {
        let dirs = levelset::cube_map_directions(face_cells).map_err(Error::StarTable)?;
        let radii: Vec<f64> = dirs.iter().map(r).collect();
        Self::from_table(face_cells, &radii)
    }

    /// A sphere of `radius` (a 2-cell cube map: the bilinear table is exact).
    ///
    /// # Errors
    /// [`Error::NonPositive`] / [`Error::NonFinite`] for a bad radius.
    pub fn sphere(radius: f64) -> Result<Self> {
        positive("sphere radius", radius)?;
        Self::from_fn(2, |_| radius)
    }

    /// An ellipsoid of semi-axes `a, b, c` along the body x, y, z axes,
    /// tabulated with `face_cells` cells per face.
    ///
    /// # Errors
    /// [`Error::NonPositive`] / [`Error::NonFinite`] for a bad semi-axis, as
    /// [`StarGrain::from_table`] otherwise.
    pub fn ellipsoid(a: f64, b: f64, c: f64, face_cells: usize) -> Result<Self> {
        positive("ellipsoid semi-axis a", a)?;
        positive("ellipsoid semi-axis b", b)?;
        positive("ellipsoid semi-axis c", c)?;
        Self::from_fn(face_cells, |u| {
            1.0 / ((u.x / a).powi(2) + (u.y / b).powi(2) + (u.z / c).powi(2)).sqrt()
        })
    }

    /// Radius in body direction `d` (need not be unit; zero reads as +x).
    #[inline]
    pub fn radius(&self, d: &Vector3<f64>) -> f64 {
        self.table.radius(d)
    }

    /// Whether body-frame point `p` is strictly inside the surface.
    #[inline]
    pub fn contains(&self, p: &Vector3<f64>) -> bool {
        let rho = p.norm();
        rho == 0.0 || rho < self.table.radius(p)
    }

    /// Bounding radius (largest tabulated radius).
    pub fn r_max(&self) -> f64 {
        self.r_max
    }

    /// Smallest tabulated radius.
    pub fn r_min(&self) -> f64 {
        self.r_min
    }

    /// Volume `⅓∮ r³ dΩ` (Fibonacci quadrature on 4096 directions).
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// Volume-equivalent diameter `(6V/π)^⅓`.
    pub fn equivalent_diameter(&self) -> f64 {
        (6.0 * self.volume / std::f64::consts::PI).cbrt()
    }

    /// Cells per face edge of the table.
    pub fn face_cells(&self) -> usize {
        self.table.face_cells()
    }

    /// The table's radii in `cube_map_directions(face_cells)` order (for
    /// [`levelset::Grid::from_star_table`]).
    pub fn table_radii(&self) -> Vec<f64> {
        self.table.radii()
    }

    /// The grain's level set in its body frame: the star table rasterised
    /// ([`levelset::Grid::from_star_table`], cube-map directions) on a cube
    /// of `resolution` nodes per axis spanning `[−half_width, half_width]³`
    /// — the level set that a specimen's outputs and checks are built from.
    ///
    /// # Errors
    /// [`Error::StarTable`] for fewer than 3 nodes or a non-positive or
    /// non-finite `half_width`.
    pub fn level_set(&self, resolution: usize, half_width: f64) -> Result<levelset::Grid> {
        let spec = levelset::GridSpec::cube(resolution, -half_width, half_width)
            .map_err(Error::StarTable)?;
        let params = levelset::StarParams {
            table: levelset::DirectionTable::CubeMap {
                face_cells: self.face_cells(),
            },
            ..levelset::StarParams::default()
        };
        let (grid, _) = levelset::Grid::from_star_table(
            spec,
            &nalgebra::Point3::origin(),
            &self.table_radii(),
            &params,
        )
        .map_err(Error::StarTable)?;
        Ok(grid)
    }
}

/// Most proxy spheres per grain [`GrainPackParams::proxy_spheres`] takes.
pub const MAX_PROXY_SPHERES: usize = 1024;

/// Parameters of [`pack_grains`] (plain data, validated at entry).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrainPackParams {
    /// Seed of the skeleton's order and of the orientations.
    pub seed: u64,
    /// Gap left between star surfaces (and to the walls), as a fraction of
    /// the equivalent diameter of the grain tested against (default 0.01:
    /// with 0.005 the 32³ level sets of 10 000 Ottawa clones still
    /// overlapped by φ/d = −1.5e-3 at 5 of 5.8 million nodes).
    pub margin: f64,
    /// β of the skeleton sphere diameter `(1−β)·d_eq + β·2 r_max`, in [0, 1].
    pub skeleton_blend: f64,
    /// γ in [0, 1]: the skeleton spheres' sizes are `γ·blend + (1 − γ)·mean`
    /// (`blend`: the diameter of [`Self::skeleton_blend`]). 1 is the seed's
    /// skeleton of the grains' own sizes; the advancing front then lets
    /// small spheres settle into the pockets below it, so small grains
    /// gather at the bottom (10 % more grains in the lowest fifth of a
    /// 3000-clone cylinder's core, mass d50 −3.4 % there and +3.6 % in the
    /// upper fifths). 0 (default) packs equal spheres and gives every grain
    /// a site in the shuffled order: no size segregation (d50 of the five
    /// height slices within 1.5 %), the compaction then grows the grains
    /// from a smaller start (about twice its iterations).
    pub skeleton_spread: f64,
    /// Nodes per grain in the first relaxation stage (≥ 32).
    pub coarse_nodes: usize,
    /// Nodes per grain in the final stage (≥ `coarse_nodes`), or 0
    /// (default) for the cube-map directions of the grains' tables (refined
    /// to at least 16 cells per face): the vertices of the tabulated
    /// surface, so a rough surface cannot reach between nodes (1734 for 16
    /// cells per face).
    pub fine_nodes: usize,
    /// Sweeps allowed over both stages before [`Error::NotConverged`].
    pub max_sweeps: usize,
    /// Factor ω on the averaged push of a grain, in (0, 2).
    pub relaxation: f64,
    /// Whether a push also turns the grains (the rigid-body response to an
    /// impulse at the contact point, with a sphere's isotropic inertia);
    /// `false` keeps the orientations drawn at the start (translations
    /// only, the seed's moves).
    pub rotations: bool,
    /// Parameters of the sphere skeleton's advancing front (default: a
    /// look-ahead of 64 sizes, so that a wide grading's large sizes find
    /// room before the front ends).
    pub skeleton: Pack3Params,
    /// Tangent spheres per grain of the proxies that the compaction stage
    /// grows to full size by FIRE (step 3 of the module docs), or 0 for
    /// the seed's growth by the gap minimisation alone.
    pub proxy_spheres: usize,
    /// Clearance added to every proxy sphere, over the grain's `d_eq`.
    pub proxy_inflate: f64,
    /// FIRE iterations per growth step of the compaction.
    pub proxy_iterations: usize,
    /// A gravity settling after the compaction (`None`, the default: the
    /// grains stay where the compaction left them, spread over the whole
    /// container).
    pub settle: Option<Settle>,
}

/// Settling under gravity (along −z) after the compaction, so that the
/// packing is at rest under its own weight and a DEM code's gravity does
/// not compact it further: the full-size proxies of the compaction get a
/// weight each, `weight · d_med · V/V_med` (harmonic overlap force of unit
/// stiffness: a median grain's weight equals the force of an overlap of
/// `weight · d_med`), and FIRE minimises overlap plus potential energy
/// without friction until the grains' mean net generalised force
/// `(F, τ/k)` is at most `rest` times their mean weight (the out-of-balance
/// ratio DEM codes test for a static state). Gravity is then
/// switched off and the proxies are separated to the compaction's
/// tolerance (the bed expands by the loaded overlaps, a few thousandths of
/// a diameter per layer), before the gap minimisation of the star surfaces.
///
/// Why frictionless: a frictionless pile at rest is also at rest with any
/// friction (its contact forces satisfy every Coulomb cone), so a DEM code
/// that adds friction and gravity finds the bodies already supported; the
/// price is that the bed settles to the frictionless (densest random)
/// fraction, whatever the container was sized for. The grains fill the
/// lower part of the container; [`bed_top`] gives the height of the bed.
/// Needs walls below (not a fully periodic cell) and the proxies
/// ([`GrainPackParams::proxy_spheres`] > 0).
///
/// Why a mean and not every grain: a frictionless pile has no angle of
/// repose, so the grains of its surface keep sliding, ever slower, until
/// the surface is flat — a bound on every grain's force was not met within
/// 200 000 iterations on beds of 1000–2000 clones (the largest force
/// wandering between surface grains), while the DEM code's friction holds
/// those grains where they are. The walls are separate contacts (floor,
/// lid, mantle), as in the DEM codes: a sphere in the corner between floor
/// and mantle feels both, so the energy is smooth there.
///
/// Measured: 200 Ottawa clones in a 3-d_max-wide cylinder come to rest in
/// 5 876 iterations, 2000 in an 8.3-d_max-wide one in 9 575 (see the README
/// for the DEM runs of both).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settle {
    /// Weight of the median grain as an overlap over its `d_eq` (default
    /// 1e-3: a 20-layer bed then loads its bottom contacts to overlaps of
    /// about 1e-2 d, removed by the separation).
    pub weight: f64,
    /// Out-of-balance bound of "at rest": the grains' mean net force over
    /// their mean weight (default 0.01, the ratio DEM codes use for a
    /// static state, e.g. Yade's `unbalancedForce() < 0.01`).
    pub rest: f64,
    /// FIRE iterations allowed under gravity (default 200 000).
    pub max_iterations: usize,
}

impl Default for Settle {
    fn default() -> Self {
        Self {
            weight: 1e-3,
            rest: 0.01,
            max_iterations: 200_000,
        }
    }
}

impl Default for GrainPackParams {
    fn default() -> Self {
        Self {
            seed: 1,
            margin: 0.01,
            skeleton_blend: 0.3,
            skeleton_spread: 0.0,
            coarse_nodes: 160,
            fine_nodes: 0,
            max_sweeps: 3000,
            relaxation: 1.8,
            rotations: true,
            skeleton: Pack3Params {
                lookahead: 64,
                ..Pack3Params::default()
            },
            proxy_spheres: 48,
            proxy_inflate: 0.015,
            proxy_iterations: 5000,
            settle: None,
        }
    }
}

impl GrainPackParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::Parameter`] naming the first field out of range.
    pub fn validate(&self) -> Result<()> {
        let bad = |what, value: f64, range| Err(Error::Parameter { what, value, range });
        if !(self.margin.is_finite() && (0.0..0.2).contains(&self.margin)) {
            return bad("margin", self.margin, "[0, 0.2)");
        }
        if !(self.skeleton_blend.is_finite() && (0.0..=1.0).contains(&self.skeleton_blend)) {
            return bad("skeleton_blend", self.skeleton_blend, "[0, 1]");
        }
        if !(self.skeleton_spread.is_finite() && (0.0..=1.0).contains(&self.skeleton_spread)) {
            return bad("skeleton_spread", self.skeleton_spread, "[0, 1]");
        }
        if self.coarse_nodes < 32 {
            return bad("coarse_nodes", self.coarse_nodes as f64, "[32, inf)");
        }
        if self.fine_nodes != 0 && self.fine_nodes < self.coarse_nodes {
            return bad("fine_nodes", self.fine_nodes as f64, "[coarse_nodes, inf)");
        }
        if self.max_sweeps == 0 {
            return bad("max_sweeps", 0.0, "[1, inf)");
        }
        if !(self.relaxation > 0.0 && self.relaxation < 2.0) {
            return bad("relaxation", self.relaxation, "(0, 2)");
        }
        if self.proxy_spheres > MAX_PROXY_SPHERES {
            return bad("proxy_spheres", self.proxy_spheres as f64, "[0, 1024]");
        }
        if !(self.proxy_inflate.is_finite() && (0.0..0.1).contains(&self.proxy_inflate)) {
            return bad("proxy_inflate", self.proxy_inflate, "[0, 0.1)");
        }
        if self.proxy_iterations == 0 {
            return bad("proxy_iterations", 0.0, "[1, inf)");
        }
        if let Some(st) = &self.settle {
            if self.proxy_spheres == 0 {
                return bad(
                    "proxy_spheres (a settling needs the proxies)",
                    0.0,
                    "[1, 1024]",
                );
            }
            if !(st.weight.is_finite() && st.weight > 0.0 && st.weight <= 0.01) {
                return bad("settle.weight", st.weight, "(0, 0.01]");
            }
            if !(st.rest.is_finite() && st.rest > 0.0 && st.rest < 1.0) {
                return bad("settle.rest", st.rest, "(0, 1)");
            }
            if st.max_iterations == 0 {
                return bad("settle.max_iterations", 0.0, "[1, inf)");
            }
        }
        Ok(self.skeleton.validate()?)
    }
}

/// Counters of a grain packing (no timings: the library has no clock).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GrainPackStats {
    /// Sum of grain volumes over the container volume.
    pub solid_fraction: f64,
    /// Skeleton scale `s` that placed every grain.
    pub skeleton_scale: f64,
    /// Skeleton packings run to find it.
    pub skeleton_attempts: usize,
    /// Sweeps with the coarse node set.
    pub coarse_sweeps: usize,
    /// Sweeps with the fine node set.
    pub fine_sweeps: usize,
    /// Pair tests (node sets both ways) over all sweeps.
    pub pair_tests: u64,
    /// Overlapping pairs found in the first sweep.
    pub initial_overlaps: usize,
    /// Deepest radial penetration in the first sweep, over `d_eq`.
    pub initial_depth_over_d: f64,
    /// Smallest radial gap `|p| − r(p̂)` of a fine node of a grain to a
    /// neighbour's surface, over that neighbour's `d_eq`, at the end
    /// (`+inf` with no pair in reach).
    pub worst_gap_over_d: f64,
    /// Smallest wall clearance of a fine node, over the grain's `d_eq`.
    pub worst_wall_over_d: f64,
    /// Pairs whose bounding spheres meet at the end.
    pub near_pairs: usize,
    /// Scale of the grains at the start of the growth (every grain inside
    /// its skeleton sphere).
    pub growth_start: f64,
    /// Counters of the compaction stage (zero without it).
    pub compaction: CompactStats,
    /// Counters of the gravity settling (zero without it).
    pub settle: SettleStats,
}

/// A packing of grains: one body→world pose per input grain, same order.
#[derive(Debug, Clone)]
pub struct GrainPacking {
    /// Pose of grain `i`: world point = `poses[i] * body point`.
    pub poses: Vec<Isometry3<f64>>,
    /// Counters.
    pub stats: GrainPackStats,
}

/// Orientation fabric of a set of grains: the second-order tensor `N =
/// ⟨m ⊗ m⟩` of a body axis `m` mapped to the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fabric {
    /// `N` (trace 1).
    pub tensor: Matrix3<f64>,
    /// Frobenius norm of the deviator `‖N − I/3‖` (0 when isotropic;
    /// `√(2/3)` ≈ 0.816 when every axis is parallel).
    pub deviatoric_norm: f64,
}

/// `n` quasi-uniform unit directions on the Fibonacci sphere.
pub(crate) fn fibonacci(n: usize) -> Vec<Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|k| {
            let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * k as f64;
            Vector3::new(rho * phi.cos(), rho * phi.sin(), z)
        })
        .collect()
}

/// The stream `(seed, index)`.
fn stream(seed: u64, index: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    rng
}

/// A uniformly random (Haar) rotation (Shoemake 1992) from `rng`.
pub fn random_rotation(rng: &mut impl Rng) -> UnitQuaternion<f64> {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    UnitQuaternion::from_quaternion(Quaternion::new(
        b * (tau * u3).cos(),
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
    ))
}

/// Height of the highest point of `grains` at `poses` (world z): the
/// largest z of each grain's star surface sampled at the cube-map vertices
/// of twice its table's cells per face (the bilinear patches between its
/// own vertices bulge by less than the margins the packer keeps). For a
/// settled bed ([`Settle`]) this is the bed's top, where a lid may sit.
///
/// # Errors
/// [`Error::Empty`] without grains; [`Error::Parameter`] when the counts of
/// grains and poses differ; [`Error::NonFinite`] for a non-finite pose.
pub fn bed_top(grains: &[StarGrain], poses: &[Isometry3<f64>]) -> Result<f64> {
    check_poses(grains, poses)?;
    let top = grains
        .par_iter()
        .zip(poses)
        .map(|(g, pose)| {
            let dirs = levelset::cube_map_directions(2 * g.face_cells()).unwrap_or_default();
            dirs.iter()
                .map(|u| (pose * Point3::from(u.into_inner() * g.radius(u))).z)
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .reduce(|| f64::NEG_INFINITY, f64::max);
    Ok(top)
}

/// Validates grains and boundary, returns the total grain volume.
fn check_input(grains: &[StarGrain], boundary: &Boundary) -> Result<f64> {
    if grains.is_empty() {
        return Err(Error::Empty { what: "grain list" });
    }
    let mut total = 0.0;
    let mut largest = 0.0_f64;
    for g in grains {
        finite("grain volume", g.volume)?;
        positive("grain volume", g.volume)?;
        total += g.volume;
        largest = largest.max(2.0 * g.r_max);
    }
    check_boundary(boundary, largest)?;
    Ok(total)
}

/// Validates a boundary for grains of bounding diameter up to `largest`:
/// its geometry, the container holds the largest grain, and the periodic
/// sides are long enough ([`check_periodic_sides`]).
fn check_boundary(boundary: &Boundary, largest: f64) -> Result<()> {
    validate_boundary(boundary)?;
    if let Boundary::Walls(c) = boundary {
        let inscribed = c.inscribed_diameter();
        if inscribed < largest {
            return Err(Error::DomainTooSmall {
                domain: inscribed,
                particle: largest,
            });
        }
    }
    check_periodic_sides(boundary, largest)
}

/// Checks a boundary's geometry: finite corners and positive sides (a
/// periodic cell), or the container's own validation.
fn validate_boundary(boundary: &Boundary) -> Result<()> {
    match boundary {
        Boundary::Periodic { min, max } => {
            for k in 0..3 {
                finite("periodic cell min", min[k])?;
                finite("periodic cell max", max[k])?;
                positive("periodic cell side (max - min)", max[k] - min[k])?;
            }
            Ok(())
        }
        Boundary::Walls(c) => Ok(c.validate()?),
    }
}

/// Every periodic side is at least `3 · largest` (so that a pair of grains
/// of bounding diameter up to `largest` meets through one image only).
fn check_periodic_sides(boundary: &Boundary, largest: f64) -> Result<()> {
    let region = Region::new(boundary);
    for k in 0..3 {
        if region.period()[k] && region.side(k) < 3.0 * largest {
            return Err(Error::DomainTooSmall {
                domain: region.side(k),
                particle: 3.0 * largest,
            });
        }
    }
    Ok(())
}

/// Largest solid fraction [`pack_grains`] attempts (beyond it the grains
/// cannot be separated by translations in practice).
pub const MAX_FRACTION: f64 = 0.70;

/// Packs every grain of `grains` into `container` without overlaps (see
/// the module docs for the method): [`pack_grains_in`] with the
/// container's walls (x/y periodic boxes included).
///
/// # Errors
/// As [`pack_grains_in`].
pub fn pack_grains(
    grains: &[StarGrain],
    container: &Container,
    params: &GrainPackParams,
) -> Result<GrainPacking> {
    pack_grains_in(grains, &Boundary::Walls(container.clone()), params)
}

/// Packs every grain of `grains` into `boundary` without overlaps (see the
/// module docs for the method): a container's walls (a box, periodic or
/// not in x and y, a cylinder or a mesh) or a fully periodic cell.
/// Periodic faces are not walls: a grain may cross one and meets the
/// images of the grains on the other side; the poses' centres are wrapped
/// into the cell on the periodic axes.
///
/// # Errors
/// [`Error::Empty`] without grains; boundary and parameter validation
/// errors; [`Error::DomainTooSmall`] when the container cannot hold the
/// largest grain's bounding sphere or a periodic side is shorter than
/// three bounding diameters; [`Error::TooDense`] when the grains fill more
/// than [`MAX_FRACTION`] of the container or the skeleton cannot place them
/// all; [`Error::FractionNotReached`] (naming the fraction at which the
/// compaction last separated the grains' proxies) when the compaction
/// jams before full size; [`Error::NotConverged`] when overlaps remain
/// after `params.max_sweeps` sweeps.
pub fn pack_grains_in(
    grains: &[StarGrain],
    boundary: &Boundary,
    params: &GrainPackParams,
) -> Result<GrainPacking> {
    params.validate()?;
    if params.settle.is_some() && matches!(boundary, Boundary::Periodic { .. }) {
        return Err(Error::WrongContainer {
            what: "a gravity settling (walls below the grains)",
            expected: "box, cylinder or mesh",
            got: "fully periodic cell",
        });
    }
    let total = check_input(grains, boundary)?;
    let fraction = total / boundary.volume();
    if fraction.is_nan() || fraction > MAX_FRACTION {
        return Err(Error::TooDense {
            fraction,
            limit: MAX_FRACTION,
        });
    }
    let region = Region::new(boundary);
    // The skeleton of a fully periodic cell is packed by the front in the
    // box periodic in x and y with walls in z (its spheres clear of the z
    // walls cannot overlap through them); the compaction then treats z as
    // periodic too.
    let front = match boundary {
        Boundary::Periodic { min, max } => Container::Box {
            min: *min,
            max: *max,
            periodic: [true; 2],
        },
        Boundary::Walls(c) => c.clone(),
    };
    let container = &front;
    let n = grains.len();
    let (centres, scale, attempts) = skeleton(grains, container, params)?;
    let rotations: Vec<UnitQuaternion<f64>> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .map(|i| random_rotation(&mut stream(params.seed, i as u64)))
        .collect();
    let mut stats = GrainPackStats {
        solid_fraction: fraction,
        skeleton_scale: scale,
        skeleton_attempts: attempts,
        ..GrainPackStats::default()
    };
    // Growth starts where every grain fits its skeleton sphere.
    let lam0 = skeleton_bases(grains, params)
        .iter()
        .zip(grains)
        .map(|(b, g)| 0.5 * scale * b / g.r_max)
        .fold(1.0_f64, f64::min);
    let (mut centres, mut rotations) = (centres, rotations);
    let mut lam_relax = lam0;
    if params.proxy_spheres > 0 {
        let proxy = compact::build(grains, params.proxy_spheres);
        stats.compaction = compact::compact(
            grains,
            &proxy,
            &region,
            &mut centres,
            &mut rotations,
            lam0,
            &compact::CompactParams {
                inflate: params.proxy_inflate,
                tolerance: 5e-3,
                max_iterations: params.proxy_iterations,
                rotations: params.rotations,
            },
        )
        .map_err(|e| match e {
            // the proxies separated only at scale λ: grains fill λ³
            Error::NotConverged { scale, .. } => Error::FractionNotReached {
                requested: fraction,
                reached: fraction * scale.powi(3),
            },
            e => e,
        })?;
        lam_relax = 1.0;
        if let Some(settle) = &params.settle {
            stats.settle = compact::settle(
                grains,
                &proxy,
                &region,
                &mut centres,
                &mut rotations,
                &compact::CompactParams {
                    inflate: params.proxy_inflate,
                    tolerance: 5e-3,
                    max_iterations: params.proxy_iterations,
                    rotations: params.rotations,
                },
                settle,
            )?;
        }
    }
    let (centres, rotations) = relax::relax(
        grains, &region, &rotations, centres, lam_relax, params, &mut stats,
    )?;
    stats.growth_start = lam0;
    let poses = centres
        .iter()
        .zip(&rotations)
        .map(|(c, q)| Isometry3::from_parts(Translation3::from(*c), *q))
        .collect();
    Ok(GrainPacking { poses, stats })
}

/// Skeleton sphere diameter of every grain at scale 1: the blend
/// `(1 − β)·d_eq + β·2 r_max`, drawn towards the grains' mean by the size
/// spread `γ`: `γ·blend + (1 − γ)·mean(blend)`.
fn skeleton_bases(grains: &[StarGrain], params: &GrainPackParams) -> Vec<f64> {
    let beta = params.skeleton_blend;
    let blend: Vec<f64> = grains
        .iter()
        .map(|g| (1.0 - beta) * g.equivalent_diameter() + beta * 2.0 * g.r_max)
        .collect();
    let gamma = params.skeleton_spread;
    let mean = blend.iter().sum::<f64>() / blend.len().max(1) as f64;
    blend
        .iter()
        .map(|b| gamma * b + (1.0 - gamma) * mean)
        .collect()
}

/// The sphere skeleton: one centre per grain (input order), the scale and
/// the number of front runs.
fn skeleton(
    grains: &[StarGrain],
    container: &Container,
    params: &GrainPackParams,
) -> Result<(Vec<Vector3<f64>>, f64, usize)> {
    let n = grains.len();
    let base = skeleton_bases(grains, params);
    // Order shuffled by the seed (Fisher–Yates on the stream (seed, u64::MAX)).
    let mut order: Vec<usize> = (0..n).collect();
    let mut rng = stream(params.seed, u64::MAX);
    for k in (1..n).rev() {
        let j = rng.random_range(0..=k);
        order.swap(k, j);
    }
    let vb: f64 = base.iter().map(|d| d.powi(3)).sum::<f64>() * std::f64::consts::PI / 6.0;
    let mut s = (0.64 * container.volume() / vb).cbrt();
    let inscribed = container.inscribed_diameter();
    let b_max = base.iter().fold(0.0_f64, |a, &b| a.max(b));
    s = s.min(0.999 * inscribed / b_max);
    for attempt in 1..=40 {
        let sizes: Vec<f64> = order.iter().map(|&i| s * base[i]).collect();
        let (lo, hi) = sizes
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(l, h), &d| (l.min(d), h.max(d)));
        let placed = match pack3d_sizes(container, &sizes, lo, hi, &params.skeleton) {
            Ok(p) => p.spheres,
            Err(packer_spheres::Error::DomainTooSmall { .. }) => Vec::new(),
            Err(e) => return Err(e.into()),
        };
        if placed.len() == n {
            // Map spheres back to grains by diameter (equal diameters are
            // interchangeable: taken in order).
            let mut by_size: BTreeMap<u64, VecDeque<usize>> = BTreeMap::new();
            for (k, &d) in sizes.iter().enumerate() {
                by_size.entry(d.to_bits()).or_default().push_back(order[k]);
            }
            let mut centres = vec![Vector3::zeros(); n];
            let mut seen = 0;
            for sp in &placed {
                let d = 2.0 * sp.radius;
                if let Some(i) = by_size.get_mut(&d.to_bits()).and_then(VecDeque::pop_front) {
                    centres[i] = sp.center.coords;
                    seen += 1;
                }
            }
            if seen == n {
                // Even out the skeleton's density along z (boxes and
                // cylinders: the front fills from the floor and its last,
                // partial layer leaves the top loose): heights are mapped
                // monotonically so that the spheres' volume below every
                // height is proportional to the height (bins of two
                // largest diameters, linear inside a bin). The map
                // compresses the loose top a little; the compaction's first
                // relaxation, at the proxies' smaller starting scale,
                // removes the few overlaps this creates.
                if matches!(
                    container,
                    Container::Box { .. } | Container::Cylinder { .. }
                ) {
                    even_out_heights(container, &placed, &mut centres, s * b_max);
                }
                return Ok((centres, s, attempt));
            }
        }
        let ratio = (placed.len().max(1) as f64 / n as f64).cbrt();
        // at most 10 % smaller per attempt: a front that stops early
        // (a few spheres placed) must not collapse the scale
        s *= ratio.clamp(0.9, 0.985);
    }
    Err(Error::TooDense {
        fraction: grains.iter().map(|g| g.volume).sum::<f64>() / container.volume(),
        limit: MAX_FRACTION,
    })
}

/// Maps the heights of `centres` (and of the skeleton spheres `placed`,
/// whose volumes weigh the map) monotonically so that the skeleton's
/// volume below any height grows linearly from floor to lid: bins of
/// `2 · d_max` by centre, piecewise-linear cumulative volume.
fn even_out_heights(
    container: &Container,
    placed: &[packer_spheres::Sphere],
    centres: &mut [Vector3<f64>],
    d_max: f64,
) {
    let (lo, hi) = container.bbox();
    let h = hi.z - lo.z;
    if !(h > 0.0 && d_max > 0.0) {
        return;
    }
    let nb = ((h / (2.0 * d_max)).floor() as usize).clamp(1, 256);
    let w = h / nb as f64;
    let bin = |z: f64| (((z - lo.z) / w).floor().max(0.0) as usize).min(nb - 1);
    let mut vol = vec![0.0; nb];
    for sp in placed {
        vol[bin(sp.center.z)] += sp.radius.powi(3);
    }
    let total: f64 = vol.iter().sum();
    if total <= 0.0 {
        return;
    }
    let mut cum = vec![0.0; nb + 1];
    for k in 0..nb {
        cum[k + 1] = cum[k] + vol[k] / total;
    }
    for c in centres.iter_mut() {
        let k = bin(c.z);
        let t = ((c.z - lo.z) / w - k as f64).clamp(0.0, 1.0);
        c.z = lo.z + h * (cum[k] + t * (cum[k + 1] - cum[k]));
    }
}

/// `shape` (a walled box or a cylinder) scaled about its lower corner /
/// base centre so that the grains' volume fills `fraction` of it (at least
/// `fraction`, never a rounding error below).
///
/// # Errors
/// [`Error::Empty`] without grains; [`Error::Parameter`] for a fraction
/// outside (0, [`MAX_FRACTION`]]; [`Error::WrongContainer`] for a mesh.
pub fn container_for(shape: &Container, grains: &[StarGrain], fraction: f64) -> Result<Container> {
    if grains.is_empty() {
        return Err(Error::Empty { what: "grain list" });
    }
    if !(fraction > 0.0 && fraction <= MAX_FRACTION) {
        return Err(Error::Parameter {
            what: "fraction",
            value: fraction,
            range: "(0, 0.70]",
        });
    }
    shape.validate()?;
    let total: f64 = grains.iter().map(StarGrain::volume).sum();
    // Rounded down by a relative 1e-12 so that the grains fill at least
    // `fraction` of the container (not 1 ulp less).
    let k = (total / fraction / shape.volume()).cbrt() * (1.0 - 1e-12);
    match shape {
        Container::Box { min, max, periodic } => Ok(Container::Box {
            min: *min,
            max: min + (max - min) * k,
            periodic: *periodic,
        }),
        Container::Cylinder {
            base,
            radius,
            height,
        } => Ok(Container::Cylinder {
            base: *base,
            radius: radius * k,
            height: height * k,
        }),
        _ => Err(Error::WrongContainer {
            what: "container_for",
            expected: "box or cylinder",
            got: "mesh",
        }),
    }
}

/// [`container_for`] for a [`Boundary`]: a fully periodic cell is scaled
/// about its lower corner like a box.
///
/// # Errors
/// As [`container_for`]; boundary validation errors.
pub fn boundary_for(shape: &Boundary, grains: &[StarGrain], fraction: f64) -> Result<Boundary> {
    match shape {
        Boundary::Walls(c) => Ok(Boundary::Walls(container_for(c, grains, fraction)?)),
        Boundary::Periodic { min, max } => {
            let cell = container_for(
                &Container::Box {
                    min: *min,
                    max: *max,
                    periodic: [true; 2],
                },
                grains,
                fraction,
            )?;
            let (min, max) = cell.bbox();
            Ok(Boundary::Periodic { min, max })
        }
    }
}

/// Orientation fabric of `body_axis` (e.g. the major axis, +x for cloner
/// clones) over `poses`.
///
/// # Errors
/// [`Error::Empty`] without poses; [`Error::NonFinite`] /
/// [`Error::NonPositive`] for a non-finite or zero axis.
pub fn orientation_fabric(poses: &[Isometry3<f64>], body_axis: &Vector3<f64>) -> Result<Fabric> {
    if poses.is_empty() {
        return Err(Error::Empty { what: "pose list" });
    }
    for k in 0..3 {
        finite("body axis", body_axis[k])?;
    }
    let len = positive("body axis length", body_axis.norm())?;
    let a = body_axis / len;
    let mut t = Matrix3::zeros();
    for p in poses {
        let m = p.rotation * a;
        t += m * m.transpose();
    }
    t /= poses.len() as f64;
    for v in t.iter() {
        finite("fabric tensor entry", *v)?;
    }
    let dev = t - Matrix3::identity() / 3.0;
    Ok(Fabric {
        tensor: t,
        deviatoric_norm: dev.norm(),
    })
}

/// Which of `points` lie inside some grain of the packing (`grains[i]` at
/// `poses[i]`): the point sampling behind local solid fractions (a regular
/// grid of points in a region gives the region's solid fraction as the
/// share of points inside). Grains are found through the packer's cell
/// grid of their bounding boxes (a point looks in its own cell), a point is inside
/// grain `i` when its body-frame position `b` has `|b| < r_i(b̂)`.
///
/// # Errors
/// [`Error::Empty`] without grains; [`Error::Parameter`] when the counts
/// of grains and poses differ; [`Error::NonFinite`] for a
/// non-finite pose or point.
pub fn occupied(
    grains: &[StarGrain],
    poses: &[Isometry3<f64>],
    points: &[Point3<f64>],
) -> Result<Vec<bool>> {
    occupied_impl(grains, poses, None, points)
}

/// [`occupied`] in a packing of `boundary`: on its periodic axes points
/// and centres are wrapped into the cell and grains crossing a face are
/// found through their images.
///
/// # Errors
/// As [`occupied`]; boundary validation errors.
pub fn occupied_in(
    grains: &[StarGrain],
    poses: &[Isometry3<f64>],
    boundary: &Boundary,
    points: &[Point3<f64>],
) -> Result<Vec<bool>> {
    validate_boundary(boundary)?;
    occupied_impl(grains, poses, Some(&Region::new(boundary)), points)
}

/// Grains given, one finite pose per grain.
fn check_poses(grains: &[StarGrain], poses: &[Isometry3<f64>]) -> Result<()> {
    if grains.is_empty() {
        return Err(Error::Empty { what: "grain list" });
    }
    if grains.len() != poses.len() {
        return Err(Error::Parameter {
            what: "pose count",
            value: poses.len() as f64,
            range: "equal to the grain count",
        });
    }
    for p in poses {
        for k in 0..3 {
            finite("pose translation", p.translation.vector[k])?;
        }
        for k in 0..4 {
            finite("pose rotation", p.rotation.coords[k])?;
        }
    }
    Ok(())
}

fn occupied_impl(
    grains: &[StarGrain],
    poses: &[Isometry3<f64>],
    region: Option<&Region<'_>>,
    points: &[Point3<f64>],
) -> Result<Vec<bool>> {
    check_poses(grains, poses)?;
    for p in points {
        for k in 0..3 {
            finite("sample point", p[k])?;
        }
    }
    let wrap = |p: &Vector3<f64>| region.map_or(*p, |r| r.wrap(p));
    // the grains (and their periodic images within a bounding radius of a
    // face) in the packer's cell grid of their bounding boxes (cells of
    // twice the median bounding radius): a point looks only in its own cell
    let centres: Vec<Vector3<f64>> = poses.iter().map(|p| wrap(&p.translation.vector)).collect();
    let r_all = grains.iter().map(StarGrain::r_max).fold(0.0, f64::max);
    let (ext, real, _) = match region {
        Some(r) => r.extended(&centres, r_all),
        None => (centres, (0..grains.len() as u32).collect(), Vec::new()),
    };
    let reach: Vec<f64> = real.iter().map(|&i| grains[i as usize].r_max).collect();
    let mut sorted = reach.clone();
    sorted.sort_by(f64::total_cmp);
    let cells = relax::Cells::new(&ext, &reach, 2.0 * sorted[sorted.len() / 2]);
    let rot: Vec<Matrix3<f64>> = poses
        .iter()
        .map(|p| p.rotation.to_rotation_matrix().into_inner())
        .collect();
    Ok(points
        .par_iter()
        .with_min_len(1024)
        .map(|x| {
            let x = wrap(&x.coords);
            cells.at(&x).iter().any(|&e| {
                let i = real[e as usize] as usize;
                let d = x - ext[e as usize];
                let r = d.norm();
                r < grains[i].r_max && r < grains[i].radius(&(rot[i].transpose() * d))
            })
        })
        .collect())
}

/// World position of body point `p` of a grain at `(rotation, centre)`.
#[inline]
pub(crate) fn to_world(r: &Matrix3<f64>, c: &Vector3<f64>, p: &Vector3<f64>) -> Point3<f64> {
    Point3::from(r * p + c)
}

#[cfg(test)]
mod tests;
