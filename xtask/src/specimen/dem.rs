//! Complete DEM decks for the clumps of a specimen, in SI units, one folder per code:
//! LAMMPS (`lammps/in.settle`), LIGGGHTS 3.8 (`liggghts/in.settle`) and Yade 2023
//! (`yade/settle.py`). Each deck runs as written from its own folder, settles the specimen
//! under gravity, checks itself, prints one `grainforge settle:` line per criterion, writes
//! a restart and exits non-zero when a body is lost, the energy is not down or an overlap is
//! too large (LAMMPS `quit 1`, LIGGGHTS an `ERROR`, Yade `SystemExit(1)`), so that a CI step
//! catches it. A bed fraction that moved more than 0.01 is printed as `NOT MET` but does not
//! fail the run: it says the packed specimen was not at rest, which is the packer's business
//! (`cargo xtask specimen-check --strict` fails on it).
//!
//! Pure functions: they return `(path relative to out_dir, bytes)`; `mod.rs` stages them.
//! LAMMPS and Yade also write `initial.dump` and `final.dump` (`id body x y z radius`) that
//! `cargo xtask specimen-check` measures again (`check.rs`; `mod.rs` adds `settle.txt`).
//!
//! # Contact model (the same in the three codes)
//! Hertz–Mindlin, quartz by default: E = 70 GPa, ν = 0.2, E divided by
//! [`Material::stiffness_scale`] (default 100, the most the issue allows); friction 0.5
//! grain–grain and grain–wall, restitution 0.5 (each code's Hertz damping set from it). No
//! global or viscous damping: only the contacts dissipate. Walls: the container's (cylinder
//! side, floor and lid; or the six faces of a box).
//!
//! # Rigid bodies
//! Mass, centre of mass and inertia are the **union**'s of each clump's spheres
//! ([`Template`], from `levelset::union_mass_properties`), not the sum of the spheres' own
//! (≈ 1.9× too heavy for 20-sphere clumps): LAMMPS `fix rigid/small … infile` with gravity
//! applied to each body's total mass at its centre (the fix's `gravity` keyword; a
//! `fix gravity` on the atoms would weigh the summed sphere masses); Yade
//! `appendClumped(…, discretization=…)` (Yade integrates the union on a grid; the deck
//! prints its masses against the union's); LIGGGHTS `particletemplate/multisphere` with the
//! union's `mass` (`use_density`: volume = mass / density) and `inertia_tensor`, its sphere
//! centres relative to the union's centroid (the template's centre of mass).
//!
//! # Time step (Hertz criterion, smallest clump)
//! The Hertz contact duration of the lightest clump against its copy, at the smallest
//! sphere's curvature and the impact speed of a fall through the largest clump's diameter
//! (Johnson 1985 § 11.4; Thornton & Ning 1998):
//! `t_H = 2.87 (m*² / (R* E*² v))^(1/5)`, `m* = m_min / 2`, `R* = r_min / 2`,
//! `E* = E / (2 (1 − ν²))`, `v = √(2 g d_max)`, and `Δt = t_H / 10` (ten steps per contact,
//! a common DEM choice; measured on the 200-clone example against t_H / 20, see the README). The body's mass, not a
//! sphere's, is what a contact of two clumps accelerates, so the Rayleigh step of the
//! smallest sphere (a wave criterion for a solid sphere) is not the binding one; it is
//! written beside for comparison.
//!
//! # Settling and the checks
//! The deck runs in chunks of [`Plan::chunk`] steps, at least [`Plan::min_steps`] (two
//! free-fall times over the largest diameter) and at most [`Plan::max_steps`] (five free-fall
//! times over the container height), and stops when the kinetic energy of the bodies (translation
//! and rotation) is at most `1e-6 · N · m̄ · g · d50` (`m̄` the mean body mass, `d50` the
//! median volume-equivalent diameter). Then it checks: every body present; that energy; the
//! largest overlap of two spheres of different bodies ≤ 1 % of d50; and the bed's solid
//! fraction within 0.01 of the packed one. The **bed fraction** is
//! `φ = V / (A · 2 (z̄ − z_floor))`: `V` the bodies' union volume, `A` the container's
//! cross-section, `z̄` the mean height of all sphere centres (a uniform bed of height `H`
//! has `z̄ = H / 2`); the same formula before (in Rust, [`Plan::packed_fraction`], and in the
//! deck at step 0) and after settling.

use std::f64::consts::PI;
use std::fmt::Write as _;

use anyhow::{Context, bail, ensure};
use nalgebra::{Isometry3, Matrix3, Point3};
use packer_spheres::Container;
use serde::Deserialize;

/// Steps between two kinetic-energy checks.
const CHUNK_STEPS: u64 = 2000;
/// Time-step divisions of the Hertz contact duration.
pub(crate) const STEPS_PER_CONTACT: f64 = 10.0;
/// Largest overlap allowed at the end, as a fraction of d50.
const OVERLAP_LIMIT: f64 = 0.01;
/// Largest change of the bed fraction.
const FRACTION_TOLERANCE: f64 = 0.01;
/// Kinetic-energy limit per `N · m̄ · g · d50`.
const KE_FACTOR: f64 = 1e-6;

/// Material and contact constants of the decks (SI units).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct Material {
    /// Particle density, kg/m³ (quartz 2650).
    pub(crate) density: f64,
    /// Young's modulus, Pa (quartz 70 GPa), before the stiffness scaling.
    pub(crate) youngs_modulus: f64,
    /// Poisson's ratio (quartz 0.2).
    pub(crate) poisson_ratio: f64,
    /// Coulomb friction coefficient, grain–grain and grain–wall.
    pub(crate) friction: f64,
    /// Normal coefficient of restitution, grain–grain and grain–wall.
    pub(crate) restitution: f64,
    /// The decks use `youngs_modulus / stiffness_scale`, in [1, 100].
    pub(crate) stiffness_scale: f64,
    /// Gravitational acceleration, m/s², along −z.
    pub(crate) gravity: f64,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            density: 2650.0,
            youngs_modulus: 70e9,
            poisson_ratio: 0.2,
            friction: 0.5,
            restitution: 0.5,
            stiffness_scale: 100.0,
            gravity: 9.81,
        }
    }
}

impl Material {
    /// Checks the ranges.
    ///
    /// # Errors
    /// A value out of range, named.
    pub(crate) fn validate(&self) -> anyhow::Result<()> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        ensure!(
            pos(self.density),
            "density must be positive, got {}",
            self.density
        );
        ensure!(
            pos(self.youngs_modulus),
            "youngs_modulus must be positive, got {}",
            self.youngs_modulus
        );
        ensure!(
            (0.0..0.5).contains(&self.poisson_ratio),
            "poisson_ratio must be in [0, 0.5), got {}",
            self.poisson_ratio
        );
        ensure!(
            self.friction.is_finite() && self.friction >= 0.0,
            "friction must be non-negative, got {}",
            self.friction
        );
        ensure!(
            self.restitution > 0.0 && self.restitution <= 1.0,
            "restitution must be in (0, 1], got {}",
            self.restitution
        );
        ensure!(
            (1.0..=100.0).contains(&self.stiffness_scale),
            "stiffness_scale must be in [1, 100] (at most 100× softer than the material), got {}",
            self.stiffness_scale
        );
        ensure!(
            pos(self.gravity),
            "gravity must be positive, got {}",
            self.gravity
        );
        Ok(())
    }

    /// The Young's modulus the decks use.
    pub(crate) fn youngs(&self) -> f64 {
        self.youngs_modulus / self.stiffness_scale
    }

    /// Shear modulus of the scaled material.
    fn shear(&self) -> f64 {
        self.youngs() / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Effective modulus of two like bodies, `E / (2 (1 − ν²))`.
    fn effective_youngs(&self) -> f64 {
        self.youngs() / (2.0 * (1.0 - self.poisson_ratio * self.poisson_ratio))
    }
}

/// A clump shape shared by one or more bodies; template frame, metres.
#[derive(Debug, Clone)]
pub(crate) struct Template {
    /// Sphere centres and radii.
    pub(crate) spheres: Vec<(Point3<f64>, f64)>,
    /// Union volume, m³.
    pub(crate) volume: f64,
    /// Union centroid, template frame.
    pub(crate) centroid: Point3<f64>,
    /// Union inertia per unit density about the centroid, template frame, m⁵.
    pub(crate) inertia: Matrix3<f64>,
}

/// A placed body: template frame → world (metres).
#[derive(Debug, Clone)]
pub(crate) struct Body {
    /// The grain's number (line of `poses.csv`); body `k` of the decks is `bodies[k]`.
    pub(crate) id: u64,
    /// Index into the templates.
    pub(crate) template: usize,
    /// Template frame → world.
    pub(crate) pose: Isometry3<f64>,
}

/// Everything a deck needs.
pub(crate) struct DemSpecimen<'a> {
    /// The distinct clump shapes.
    pub(crate) templates: &'a [Template],
    /// The placed bodies.
    pub(crate) bodies: &'a [Body],
    /// The container, metres.
    pub(crate) container: &'a Container,
    /// Constants.
    pub(crate) material: &'a Material,
    /// Header lines to put in every file as comments.
    pub(crate) provenance: &'a [String],
}

/// The numbers the three decks share, computed once in Rust.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plan {
    /// Bodies.
    pub(crate) n: usize,
    /// Spheres.
    pub(crate) atoms: usize,
    /// Mean body mass, kg.
    pub(crate) mean_mass: f64,
    /// Median volume-equivalent diameter, m.
    pub(crate) d50: f64,
    /// Largest volume-equivalent diameter, m.
    pub(crate) d_max: f64,
    /// Kinetic-energy limit `1e-6 · N · m̄ · g · d50`, J.
    pub(crate) ke_limit: f64,
    /// Hertz contact duration of the smallest clump, s.
    pub(crate) t_hertz: f64,
    /// Rayleigh time of the smallest sphere (for comparison), s.
    pub(crate) t_rayleigh: f64,
    /// Time step, s.
    pub(crate) dt: f64,
    /// Lightest body's mass, kg.
    pub(crate) m_min: f64,
    /// Smallest sphere radius, m.
    pub(crate) r_min: f64,
    /// Impact speed of the Hertz criterion, m/s.
    pub(crate) v_impact: f64,
    /// Steps per check.
    pub(crate) chunk: u64,
    /// Fewest steps before the energy may end the run.
    pub(crate) min_steps: u64,
    /// Most steps before the deck gives up.
    pub(crate) max_steps: u64,
    /// Union volume of all bodies, m³.
    pub(crate) volume: f64,
    /// Floor height, m.
    pub(crate) floor: f64,
    /// Container cross-section, m².
    pub(crate) area: f64,
    /// Bed fraction of the packed specimen (module docs).
    pub(crate) packed_fraction: f64,
}

/// Hertz contact duration `2.87 (m*² / (R* E*² v))^(1/5)` of two bodies of effective mass
/// `m_star` meeting at speed `v` with effective radius `r_star` and modulus `e_star`
/// (Johnson 1985, Contact Mechanics, § 11.4).
pub(crate) fn hertz_contact_time(m_star: f64, r_star: f64, e_star: f64, v: f64) -> f64 {
    2.87 * (m_star * m_star / (r_star * e_star * e_star * v)).powf(0.2)
}

/// Rayleigh time of a sphere of radius `r`: `π r √(ρ/G) / (0.1631 ν + 0.8766)`.
pub(crate) fn rayleigh_time(r: f64, density: f64, shear: f64, nu: f64) -> f64 {
    PI * r * (density / shear).sqrt() / (0.1631 * nu + 0.8766)
}

/// Floor height, cross-section and the LAMMPS box of a walled container.
fn geometry(c: &Container) -> anyhow::Result<(f64, f64, [[f64; 2]; 3])> {
    match c {
        Container::Cylinder {
            base,
            radius,
            height,
        } => {
            let pad = 0.05 * height.max(*radius);
            Ok((
                base.z,
                PI * radius * radius,
                [
                    [base.x - radius - pad, base.x + radius + pad],
                    [base.y - radius - pad, base.y + radius + pad],
                    [base.z - pad, base.z + height + pad],
                ],
            ))
        }
        Container::Box { min, max, periodic } => {
            ensure!(
                !periodic[0] && !periodic[1],
                "the DEM decks need a walled container; periodic boxes are not written yet"
            );
            let pad = 0.05 * (max - min).max();
            Ok((
                min.z,
                (max.x - min.x) * (max.y - min.y),
                [
                    [min.x - pad, max.x + pad],
                    [min.y - pad, max.y + pad],
                    [min.z - pad, max.z + pad],
                ],
            ))
        }
        _ => bail!("the DEM decks need a cylinder or box container"),
    }
}

/// Height of the container (lid − floor).
fn height(c: &Container) -> f64 {
    match c {
        Container::Cylinder { height, .. } => *height,
        Container::Box { min, max, .. } => max.z - min.z,
        _ => f64::NAN,
    }
}

impl DemSpecimen<'_> {
    /// Checks the input and computes the shared numbers.
    ///
    /// # Errors
    /// No body, a body naming a missing template, a template without spheres or with a
    /// non-positive volume, a container without walls, bad material constants.
    pub(crate) fn plan(&self) -> anyhow::Result<Plan> {
        self.material.validate().context("material")?;
        ensure!(!self.bodies.is_empty(), "no body to write");
        for (k, t) in self.templates.iter().enumerate() {
            ensure!(!t.spheres.is_empty(), "template {k} has no sphere");
            ensure!(
                t.volume.is_finite() && t.volume > 0.0,
                "template {k}: union volume {} is not positive",
                t.volume
            );
            for (c, r) in &t.spheres {
                ensure!(
                    c.coords.iter().all(|v| v.is_finite()) && r.is_finite() && *r > 0.0,
                    "template {k}: bad sphere {c} r {r}"
                );
            }
        }
        for b in self.bodies {
            ensure!(
                b.template < self.templates.len(),
                "body {} names template {} of {}",
                b.id,
                b.template,
                self.templates.len()
            );
        }
        let (floor, area, _) = geometry(self.container)?;
        let m = self.material;
        let mut d: Vec<f64> = self
            .bodies
            .iter()
            .map(|b| (6.0 * self.templates[b.template].volume / PI).cbrt())
            .collect();
        d.sort_by(f64::total_cmp);
        let d50 = d[d.len() / 2];
        let d_max = d[d.len() - 1];
        let n = self.bodies.len();
        let volume: f64 = self
            .bodies
            .iter()
            .map(|b| self.templates[b.template].volume)
            .sum();
        let mean_mass = m.density * volume / n as f64;
        let m_min = m.density * PI / 6.0 * d[0].powi(3);
        let r_min = self
            .bodies
            .iter()
            .flat_map(|b| self.templates[b.template].spheres.iter().map(|s| s.1))
            .fold(f64::INFINITY, f64::min);
        let v_impact = (2.0 * m.gravity * d_max).sqrt();
        let t_hertz = hertz_contact_time(0.5 * m_min, 0.5 * r_min, m.effective_youngs(), v_impact);
        let dt = t_hertz / STEPS_PER_CONTACT;
        let fall = |h: f64| (2.0 * h / m.gravity).sqrt();
        let steps = |t: f64| ((t / dt / CHUNK_STEPS as f64).ceil() as u64).max(1) * CHUNK_STEPS;
        let atoms = self
            .bodies
            .iter()
            .map(|b| self.templates[b.template].spheres.len())
            .sum();
        let zbar = self
            .bodies
            .iter()
            .flat_map(|b| {
                self.templates[b.template]
                    .spheres
                    .iter()
                    .map(move |(c, _)| (b.pose * c).z)
            })
            .sum::<f64>()
            / atoms as f64;
        let packed_fraction = volume / (area * 2.0 * (zbar - floor));
        Ok(Plan {
            n,
            atoms,
            mean_mass,
            d50,
            d_max,
            ke_limit: KE_FACTOR * n as f64 * mean_mass * m.gravity * d50,
            t_hertz,
            t_rayleigh: rayleigh_time(r_min, m.density, m.shear(), m.poisson_ratio),
            dt,
            m_min,
            r_min,
            v_impact,
            chunk: CHUNK_STEPS,
            min_steps: steps(2.0 * fall(d_max)),
            max_steps: steps(5.0 * fall(height(self.container).max(d_max))),
            volume,
            floor,
            area,
            packed_fraction,
        })
    }

    /// World spheres of body `b`.
    fn world<'b>(&'b self, b: &'b Body) -> impl Iterator<Item = (Point3<f64>, f64)> + 'b {
        self.templates[b.template]
            .spheres
            .iter()
            .map(move |(c, r)| (b.pose * c, *r))
    }

    /// Union mass (kg), world centre of mass and world inertia tensor (kg m²) of `b`.
    fn mass(&self, b: &Body) -> (f64, Point3<f64>, Matrix3<f64>) {
        let t = &self.templates[b.template];
        let r = b.pose.rotation.to_rotation_matrix();
        let rho = self.material.density;
        (
            t.volume * rho,
            b.pose * t.centroid,
            r.matrix() * t.inertia * r.matrix().transpose() * rho,
        )
    }

    /// The provenance lines as comments.
    fn header(&self, comment: &str) -> String {
        let mut s = String::new();
        for l in self.provenance {
            let _ = writeln!(s, "{comment} {l}");
        }
        s
    }

    /// The deck's comment block on constants, time step and criteria.
    fn preamble(&self, p: &Plan, comment: &str, code: &str, run: &str) -> String {
        let m = self.material;
        let text = format!(
            "{code} deck of grainforge: settle the specimen under gravity and check it. Run from this folder:\n\
             \x20 {run}\n\
             Units SI (m, kg, s). {n} bodies, {atoms} spheres.\n\
             Hertz-Mindlin contacts: E = {e:e} Pa / stiffness scale {scale} = {es:e} Pa, nu = {nu}, density {rho} kg/m^3,\n\
             \x20 friction {mu} (grains and walls), restitution {rest}; no global or viscous damping; gravity {g} m/s^2 along -z.\n\
             Bodies: mass, centre of mass and inertia of the union of each clump's spheres (not their sum).\n\
             Time step (Hertz criterion, smallest clump): t_H = 2.87 (m*^2 / (R* E*^2 v))^(1/5) with m* = m_min/2 = {ms:e} kg,\n\
             \x20 R* = r_min/2 = {rs:e} m (smallest sphere), E* = E/(2(1-nu^2)) = {estar:e} Pa, v = sqrt(2 g d_max) = {v:e} m/s:\n\
             \x20 t_H = {th:e} s, dt = t_H/{spc} = {dt:e} s (Rayleigh time of the smallest sphere, for comparison: {tr:e} s).\n\
             Settling: checked every {chunk} steps, at least {min} and at most {max} steps.\n\
             Checks at the end (the deck fails when one of the first three fails; the fourth is reported):\n\
             \x20 bodies = {n} (largest volume-equivalent diameter d_max = {dmax:e} m);\n\
             \x20 kinetic energy (translation + rotation) <= 1e-6 N m g d50 = {ke:e} J (m = mean body mass {mm:e} kg, d50 = {d50:e} m);\n\
             \x20 largest overlap of two spheres of different bodies <= {ov} d50 = {ovm:e} m;\n\
             \x20 bed fraction phi = V / (A 2 (zbar - z_floor)) within {ft} of the packed {pf:.5}: V = {vol:e} m^3 union volume,\n\
             \x20 A = {area:e} m^2 cross-section, zbar = mean height of the sphere centres, z_floor = {floor:e} m.",
            n = p.n,
            atoms = p.atoms,
            e = m.youngs_modulus,
            scale = m.stiffness_scale,
            es = m.youngs(),
            nu = m.poisson_ratio,
            rho = m.density,
            mu = m.friction,
            rest = m.restitution,
            g = m.gravity,
            ms = 0.5 * p.m_min,
            rs = 0.5 * p.r_min,
            estar = m.effective_youngs(),
            v = p.v_impact,
            th = p.t_hertz,
            spc = STEPS_PER_CONTACT,
            dt = p.dt,
            tr = p.t_rayleigh,
            chunk = p.chunk,
            min = p.min_steps,
            max = p.max_steps,
            ke = p.ke_limit,
            dmax = p.d_max,
            mm = p.mean_mass,
            d50 = p.d50,
            ov = OVERLAP_LIMIT,
            ovm = OVERLAP_LIMIT * p.d50,
            ft = FRACTION_TOLERANCE,
            pf = p.packed_fraction,
            vol = p.volume,
            area = p.area,
            floor = p.floor,
        );
        let mut s = self.header(comment);
        for l in text.lines() {
            let _ = writeln!(s, "{comment} {l}");
        }
        s
    }
}

/// LAMMPS: `lammps/clumps.data` (every sphere, plain `atom_style sphere`: LAMMPS' `read_data`
/// alone reads it), `lammps/clumps.body` (the body of each sphere, an atomfile variable),
/// `lammps/bodies.rigid` (the `fix rigid/small … infile` file: union mass,
/// centre and inertia tensor of each body) and `lammps/in.settle`.
///
/// # Errors
/// As [`DemSpecimen::plan`].
pub(crate) fn lammps_files(s: &DemSpecimen) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let p = s.plan()?;
    let (_, _, bounds) = geometry(s.container)?;
    let m = s.material;
    let mut data = String::from(
        "LAMMPS data file of grainforge (atom_style sphere, SI; the body of each atom: clumps.body)\n\n",
    );
    let _ = writeln!(data, "{} atoms\n1 atom types\n", p.atoms);
    for (b, axis) in bounds.iter().zip(["x", "y", "z"]) {
        let _ = writeln!(data, "{:e} {:e} {axis}lo {axis}hi", b[0], b[1]);
    }
    data.push_str("\nAtoms # sphere\n\n");
    let mut mols = s.header("#");
    let _ = writeln!(
        mols,
        "# body (molecule id) of every atom of clumps.data: atomfile-style variable of in.settle\n{}",
        p.atoms
    );
    let mut id = 0usize;
    for (k, b) in s.bodies.iter().enumerate() {
        for (c, r) in s.world(b) {
            id += 1;
            let _ = writeln!(
                data,
                "{id} 1 {:e} {:e} {:e} {:e} {:e}",
                2.0 * r,
                m.density,
                c.x,
                c.y,
                c.z
            );
            let _ = writeln!(mols, "{id} {}", k + 1);
        }
    }
    let mut rigid = s.header("#");
    rigid.push_str(
        "# fix rigid/small infile: per body (molecule id = body k + 1 = line k + 1 of ../poses.csv) the union's\n\
         # mass (kg), centre of mass (m) and inertia tensor about it (kg m^2, world frame), zero velocities:\n\
         # id masstotal xcm ycm zcm ixx iyy izz ixy ixz iyz vxcm vycm vzcm lx ly lz ixcm iycm izcm\n",
    );
    let _ = writeln!(rigid, "{}", s.bodies.len());
    for (k, b) in s.bodies.iter().enumerate() {
        let (mass, c, i) = s.mass(b);
        let _ = writeln!(
            rigid,
            "{} {mass:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} 0 0 0 0 0 0 0 0 0",
            k + 1,
            c.x,
            c.y,
            c.z,
            i[(0, 0)],
            i[(1, 1)],
            i[(2, 2)],
            i[(0, 1)],
            i[(0, 2)],
            i[(1, 2)]
        );
    }
    let walls = match s.container {
        Container::Cylinder {
            base,
            radius,
            height,
        } => format!(
            "region          walls cylinder z {:e} {:e} {:e} {:e} {:e} side in",
            base.x,
            base.y,
            radius,
            base.z,
            base.z + height
        ),
        Container::Box { min, max, .. } => format!(
            "region          walls block {:e} {:e} {:e} {:e} {:e} {:e} side in",
            min.x, max.x, min.y, max.y, min.z, max.z
        ),
        _ => bail!("the DEM decks need a cylinder or box container"),
    };
    let contact = format!(
        "hertz/material {:e} {} {} tangential mindlin NULL 1.0 {} damping coeff_restitution",
        m.youngs(),
        m.restitution,
        m.poisson_ratio,
        m.friction
    );
    let mut deck = s.preamble(
        &p,
        "#",
        "LAMMPS",
        "../shared/tools/lammps-run lammps/in.settle   (or: lmp -in in.settle)",
    );
    let _ = write!(
        deck,
        r#"# LAMMPS >= 2022 (pair granular, fix rigid/small infile, compute pair/local cutoff radius).
units           si
dimension       3
atom_style      sphere
atom_modify     map array
boundary        f f f
comm_modify     vel yes
newton          off
fix             mol all property/atom mol ghost yes
read_data       clumps.data
variable        body atomfile clumps.body
set             group all mol v_body
# the spheres of one body overlap: they never interact
neighbor        {skin:e} bin
neigh_modify    delay 0 every 1 check yes exclude molecule/intra all
pair_style      granular
pair_coeff      * * {contact}
{walls}
fix             walls all wall/gran/region granular {contact} region walls
# gravity on each body's union mass at its centre of mass (fix rigid/small's gravity keyword);
# the group of fix gravity is empty so that the atoms' (summed sphere) masses are not weighed
group           nobody empty
fix             grav nobody gravity {g} vector 0 0 -1
fix             bodies all rigid/small molecule infile bodies.rigid gravity grav
compute         ket all ke/rigid bodies
compute         ker all erotate/rigid bodies
variable        ke equal c_ket+c_ker
compute         zs all reduce ave z
variable        phi equal {vol:e}/({area:e}*2*(c_zs-({floor:e})))
timestep        {dt:e}
thermo_style    custom step time atoms v_ke v_phi
thermo          {chunk}
thermo_modify   lost error norm no
run             0
# initial.dump and final.dump (id body x y z radius): for cargo xtask specimen-check
write_dump      all custom initial.dump id mol x y z radius modify sort id format float %.12g
variable        phi0 equal {pf:.10}
variable        phistart equal $(v_phi:%.10f)
print           "grainforge settle: bed fraction at the start ${{phistart}} (packed {pf:.6})"
variable        limit equal {ke:e}
run             {min}
variable        chunk loop {chunks}
label           settle
run             {chunk}
if              "${{ke}} <= ${{limit}}" then "jump SELF settled"
next            chunk
jump            SELF settle
label           settled
variable        kefinal equal $(v_ke:%.6e)
variable        phiend equal $(v_phi:%.10f)
write_restart   settled.restart
write_dump      all custom final.dump id mol x y z radius modify sort id format float %.12g
# largest overlap of two spheres of different bodies, by bisection: shrink every radius by s/2
# (pairs of one body stay excluded) and see whether any pair still touches
uncompute       ket
uncompute       ker
unfix           bodies
unfix           walls
fix             r0 all store/state 0 radius
compute         touch all pair/local dist cutoff radius
compute         ntouch all reduce sum c_touch inputs local
thermo_style    custom step c_ntouch
thermo          0
variable        lo equal 0
variable        hi equal {ovhi:e}
variable        bis loop 14
label           bisect
variable        s equal 0.5*(${{lo}}+${{hi}})
variable        dshrunk atom 2*f_r0-v_s
set             group all diameter v_dshrunk
run             0 post no
if              "$(c_ntouch) > 0" then "variable lo equal $(v_s)" else "variable hi equal $(v_s)"
next            bis
jump            SELF bisect
variable        overlap equal ${{hi}}
print           "grainforge settle: atoms $(atoms) of {atoms} ({n} bodies), kinetic energy ${{kefinal}} J (limit ${{limit}} J) at step $(step), t = $(time) s"
print           "grainforge settle: largest overlap ${{overlap}} m = $(v_overlap/{d50:e}) d50 (limit {ovl})"
print           "grainforge settle: bed fraction ${{phistart}} -> ${{phiend}} (packed {pf:.6}, tolerance {ft})"
if              "$(atoms) != {atoms}" then "print 'grainforge settle: FAILED, atoms lost'" "quit 1"
if              "${{kefinal}} > ${{limit}}" then "print 'grainforge settle: FAILED, not at rest after {max} steps'" "quit 1"
if              "${{overlap}} > {ovm:e}" then "print 'grainforge settle: FAILED, overlap above {ovl} d50'" "quit 1"
variable        dphi equal abs(${{phiend}}-${{phi0}})
if              "${{dphi}} > {ft}" then "print 'grainforge settle: NOT MET, bed fraction moved more than {ft} (reported, not fatal: the packed specimen was not at rest)'" else "print 'grainforge settle: bed fraction within {ft}'"
print           "grainforge settle: OK (bodies, energy, overlap)"
"#,
        skin = 0.1 * p.d50,
        g = m.gravity,
        vol = p.volume,
        area = p.area,
        floor = p.floor,
        dt = p.dt,
        chunk = p.chunk,
        pf = p.packed_fraction,
        ke = p.ke_limit,
        min = p.min_steps,
        chunks = (p.max_steps - p.min_steps).div_ceil(p.chunk).max(1),
        max = p.max_steps,
        ovhi = 0.05 * p.d50,
        atoms = p.atoms,
        n = p.n,
        d50 = p.d50,
        ovl = OVERLAP_LIMIT,
        ovm = OVERLAP_LIMIT * p.d50,
        ft = FRACTION_TOLERANCE,
    );
    Ok(vec![
        ("lammps/clumps.data".into(), data.into_bytes()),
        ("lammps/clumps.body".into(), mols.into_bytes()),
        ("lammps/bodies.rigid".into(), rigid.into_bytes()),
        ("lammps/in.settle".into(), deck.into_bytes()),
    ])
}

/// Yade: `yade/clumps.txt` (`x y z r body`, world frame, metres; body k + 1 = line k + 1 of
/// `../poses.csv`), `yade/masses.txt` (the union's mass of each body, for comparison) and
/// `yade/settle.py` (run from this folder: `yade -n -x settle.py`).
///
/// # Errors
/// As [`DemSpecimen::plan`].
pub(crate) fn yade_files(s: &DemSpecimen) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let p = s.plan()?;
    let m = s.material;
    let mut spheres = s.header("#");
    spheres.push_str(
        "# x y z r body (world frame, metres); body k + 1 = line k + 1 of ../poses.csv\n",
    );
    let mut masses = s.header("#");
    masses.push_str("# body union_mass_kg\n");
    for (k, b) in s.bodies.iter().enumerate() {
        for (c, r) in s.world(b) {
            let _ = writeln!(spheres, "{:e} {:e} {:e} {:e} {}", c.x, c.y, c.z, r, k + 1);
        }
        let _ = writeln!(masses, "{} {:e}", k + 1, s.mass(b).0);
    }
    let walls = match s.container {
        Container::Cylinder {
            base,
            radius,
            height,
        } => format!(
            "# the cylinder as a 72-sided prism whose faces touch the circle, with floor and lid\n\
             n_seg = 72\n\
             walls = geom.facetCylinder(center=({:e}, {:e}, {:e}), radius={:e} / math.cos(math.pi / n_seg), height={:e}, segmentsNumber=n_seg, wallMask=7, material=quartz)",
            base.x,
            base.y,
            base.z + 0.5 * height,
            radius,
            height
        ),
        Container::Box { min, max, .. } => {
            let c = nalgebra::center(min, max);
            let e = (max - min) * 0.5;
            format!(
                "walls = geom.facetBox(center=({:e}, {:e}, {:e}), extents=({:e}, {:e}, {:e}), wallMask=63, material=quartz)",
                c.x, c.y, c.z, e.x, e.y, e.z
            )
        }
        _ => bail!("the DEM decks need a cylinder or box container"),
    };
    // the grid of appendClumped's integration: cells across the smallest sphere's diameter
    let mut deck = s.preamble(
        &p,
        "#",
        "Yade",
        "../shared/tools/yade-run yade/settle.py   (or: yade -n -x settle.py)",
    );
    let _ = write!(
        deck,
        r#"# Clumps: O.bodies.appendClumped(..., discretization=DISCRETIZATION) integrates the union of each
# clump's spheres on a grid (without it Yade sums the members' masses and inertias: ~1.9x too heavy);
# a one-sphere body is a plain sphere. Files are read from the current folder (yade-run and
# `yade -x` run the script where it is; __file__ is not the script inside Yade).
import math
from yade import geom, utils

DISCRETIZATION = 20
quartz = O.materials.append(FrictMat(young={es:e}, poisson={nu}, frictionAngle=math.atan({mu}), density={rho:e}, label='quartz'))
{walls}
O.bodies.append(walls)
spheres = {{}}
with open('clumps.txt') as f:
    for line in f:
        if line.startswith('#') or not line.strip():
            continue
        x, y, z, r, b = line.split()
        spheres.setdefault(int(b), []).append(((float(x), float(y), float(z)), float(r)))
union = {{}}
with open('masses.txt') as f:
    for line in f:
        if not line.startswith('#') and line.strip():
            b, mass = line.split()
            union[int(b)] = float(mass)
bodies = {{}}
members = []
for b in sorted(spheres):
    ss = [utils.sphere(c, r, material=quartz) for c, r in spheres[b]]
    if len(ss) == 1:
        bodies[b] = O.bodies.append(ss[0])
        members.append((b, bodies[b]))
    else:
        cid, mids = O.bodies.appendClumped(ss, discretization=DISCRETIZATION)
        bodies[b] = cid
        members.extend((b, i) for i in mids)
ratio = [O.bodies[bodies[b]].state.mass / union[b] for b in bodies]
print('grainforge settle: %d bodies; Yade mass / union mass: mean %.4f, min %.4f, max %.4f' % (len(ratio), sum(ratio) / len(ratio), min(ratio), max(ratio)))
body_of = dict((i, b) for b, i in members)

def bed_fraction():
    zbar = sum(O.bodies[i].state.pos[2] for _, i in members) / len(members)
    return {vol:e} / ({area:e} * 2 * (zbar - ({floor:e})))

def dump(name):
    # id body x y z radius, for cargo xtask specimen-check
    with open(name, 'w') as f:
        f.write('# id body x y z radius\n')
        for b, i in members:
            p = O.bodies[i].state.pos
            f.write('%d %d %.12g %.12g %.12g %.12g\n' % (i, b, p[0], p[1], p[2], O.bodies[i].shape.radius))

def largest_overlap():
    worst = 0.0
    for i in O.interactions:
        if not i.isReal or i.id1 not in body_of or i.id2 not in body_of:
            continue
        if body_of[i.id1] == body_of[i.id2]:
            continue
        worst = max(worst, i.geom.penetrationDepth)
    return worst

O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()], verletDist={skin:e}),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom()],
        [Ip2_FrictMat_FrictMat_MindlinPhys(en={rest}, es={rest})],
        [Law2_ScGeom_MindlinPhys_Mindlin()],
    ),
    NewtonIntegrator(damping=0.0, gravity=(0, 0, -{g})),
]
O.dt = {dt:e}
phi0 = {pf:.10}
phi_start = bed_fraction()
dump('initial.dump')
print('grainforge settle: bed fraction at the start %.6f (packed %.6f)' % (phi_start, phi0))
limit = {ke:e}
O.run({min}, True)
while True:
    ke = utils.kineticEnergy()
    print('step %d t %.6g s kinetic energy %.4e J' % (O.iter, O.time, ke))
    if ke <= limit or O.iter >= {max}:
        break
    O.run({chunk}, True)
O.save('settled.yade.gz')
dump('final.dump')
n = sum(1 for b in bodies if O.bodies[bodies[b]] is not None)
overlap = largest_overlap()
phi_end = bed_fraction()
print('grainforge settle: bodies %d of {n}, kinetic energy %.4e J (limit %.4e J) at step %d, t = %.6g s' % (n, ke, limit, O.iter, O.time))
print('grainforge settle: largest overlap %.4e m = %.5f d50 (limit {ovl})' % (overlap, overlap / {d50:e}))
print('grainforge settle: bed fraction %.6f -> %.6f (packed %.6f, tolerance {ft})' % (phi_start, phi_end, phi0))
failed = []
if n != {n}:
    failed.append('bodies lost')
if ke > limit:
    failed.append('not at rest after {max} steps')
if overlap > {ovm:e}:
    failed.append('overlap above {ovl} d50')
if abs(phi_end - phi0) > {ft}:
    print('grainforge settle: NOT MET, bed fraction moved more than {ft} (reported, not fatal: the packed specimen was not at rest)')
else:
    print('grainforge settle: bed fraction within {ft}')
if failed:
    print('grainforge settle: FAILED, ' + ', '.join(failed))
    raise SystemExit(1)
print('grainforge settle: OK (bodies, energy, overlap)')
"#,
        es = m.youngs(),
        nu = m.poisson_ratio,
        mu = m.friction,
        rho = m.density,
        rest = m.restitution,
        g = m.gravity,
        dt = p.dt,
        vol = p.volume,
        area = p.area,
        floor = p.floor,
        skin = 0.1 * p.d50,
        pf = p.packed_fraction,
        ke = p.ke_limit,
        min = p.min_steps,
        max = p.max_steps,
        chunk = p.chunk,
        n = p.n,
        d50 = p.d50,
        ovl = OVERLAP_LIMIT,
        ovm = OVERLAP_LIMIT * p.d50,
        ft = FRACTION_TOLERANCE,
    );
    Ok(vec![
        ("yade/clumps.txt".into(), spheres.into_bytes()),
        ("yade/masses.txt".into(), masses.into_bytes()),
        ("yade/settle.py".into(), deck.into_bytes()),
    ])
}

/// The first `n` primes above 10⁵ (LIGGGHTS wants prime seeds above 10⁴).
fn primes(n: usize) -> Vec<u64> {
    let mut out = Vec::with_capacity(n);
    let mut k = 100_003u64;
    while out.len() < n {
        if (2..)
            .take_while(|d| d * d <= k)
            .all(|d| !k.is_multiple_of(d))
        {
            out.push(k);
        }
        k += 2;
    }
    out
}

/// LIGGGHTS: one `liggghts/template-T.txt` per template used (`x y z r` relative to the
/// union's centroid, template frame, metres) and `liggghts/in.settle`: one
/// `particletemplate/multisphere` per template (several bodies share one) with the union's
/// mass, volume and inertia tensor, one `particledistribution/discrete/numberbased` of it,
/// and per body an `insert/pack` of one particle in a tiny sphere around its centre of mass
/// with `orientation constant` its pose's quaternion, so every body starts at its packed
/// pose. A one-sphere template is a `particletemplate/sphere` (multisphere templates need
/// two spheres) integrated by `nve/sphere`.
///
/// # Errors
/// As [`DemSpecimen::plan`].
pub(crate) fn liggghts_files(s: &DemSpecimen) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let p = s.plan()?;
    let m = s.material;
    let mut used = vec![0usize; s.templates.len()];
    for b in s.bodies {
        used[b.template] += 1;
    }
    let seeds = primes(3 * s.templates.len() + s.bodies.len() + 1);
    let mut seed = seeds.into_iter();
    let mut next_seed = || seed.next().unwrap_or(100_003);
    let mut files = Vec::new();
    let mut tpl = String::new();
    let singles = s
        .templates
        .iter()
        .zip(&used)
        .any(|(t, u)| *u > 0 && t.spheres.len() == 1);
    let multi = s
        .templates
        .iter()
        .zip(&used)
        .any(|(t, u)| *u > 0 && t.spheres.len() > 1);
    let mut ms_type = 0usize;
    for (k, t) in s.templates.iter().enumerate() {
        if used[k] == 0 {
            continue;
        }
        let k1 = k + 1;
        if t.spheres.len() == 1 {
            let _ = writeln!(
                tpl,
                "fix             pts{k1} all particletemplate/sphere {} atom_type 1 volume_limit 1e-30 density constant {:e} radius constant {:e}",
                next_seed(),
                m.density,
                t.spheres[0].1
            );
        } else {
            let name = format!("template-{k1:06}.txt");
            let mut text = String::new();
            for (c, r) in &t.spheres {
                let d = c - t.centroid;
                let _ = writeln!(text, "{:e} {:e} {:e} {:e}", d.x, d.y, d.z, r);
            }
            files.push((format!("liggghts/{name}"), text.into_bytes()));
            // multisphere types are consecutive from 1
            ms_type += 1;
            let i = t.inertia * m.density;
            let _ = writeln!(
                tpl,
                "fix             pts{k1} all particletemplate/multisphere {} atom_type 1 volume_limit 1e-30 density constant {:e} nspheres {} ntry 100000 spheres file {name} scale 1.0 type {ms_type} mass {:e} use_density inertia_tensor {:e} {:e} {:e} {:e} {:e} {:e}",
                next_seed(),
                m.density,
                t.spheres.len(),
                t.volume * m.density,
                i[(0, 0)],
                i[(0, 1)],
                i[(0, 2)],
                i[(1, 1)],
                i[(1, 2)],
                i[(2, 2)],
            );
        }
        let _ = writeln!(
            tpl,
            "fix             pdd{k1} all particledistribution/discrete/numberbased {} 1 pts{k1} 1.0",
            next_seed()
        );
    }
    let mut ins = String::new();
    let mut unfix = String::new();
    let tiny = 1e-6 * p.d50;
    for (k, b) in s.bodies.iter().enumerate() {
        let t = &s.templates[b.template];
        let k1 = k + 1;
        let c = b.pose * t.centroid;
        let q = b.pose.rotation.quaternion();
        let group = if t.spheres.len() == 1 {
            "singles"
        } else {
            "all"
        };
        let _ = writeln!(
            ins,
            "region          r{k1} sphere {:e} {:e} {:e} {tiny:e} units box volume_limit 1e-30\n\
             fix             ins{k1} {group} insert/pack seed {} distributiontemplate pdd{} insert_every once overlapcheck no orientation constant {:.15} {:.15} {:.15} {:.15} region r{k1} particles_in_region 1",
            c.x,
            c.y,
            c.z,
            next_seed(),
            b.template + 1,
            q.w,
            q.i,
            q.j,
            q.k
        );
        let _ = writeln!(unfix, "unfix           ins{k1}");
    }
    let walls = match s.container {
        Container::Cylinder {
            base,
            radius,
            height,
        } => format!(
            "fix             side all wall/gran model hertz tangential history primitive type 1 zcylinder {radius:e} {:e} {:e}\n\
             fix             floor all wall/gran model hertz tangential history primitive type 1 zplane {:e}\n\
             fix             lid all wall/gran model hertz tangential history primitive type 1 zplane {:e}",
            base.x,
            base.y,
            base.z,
            base.z + height
        ),
        Container::Box { min, max, .. } => {
            let mut w = String::new();
            for (k, (axis, lo, hi)) in [
                ("x", min.x, max.x),
                ("y", min.y, max.y),
                ("z", min.z, max.z),
            ]
            .into_iter()
            .enumerate()
            {
                let _ = writeln!(
                    w,
                    "fix             wlo{k} all wall/gran model hertz tangential history primitive type 1 {axis}plane {lo:e}\n\
                     fix             whi{k} all wall/gran model hertz tangential history primitive type 1 {axis}plane {hi:e}"
                );
            }
            w.trim_end().to_owned()
        }
        _ => bail!("the DEM decks need a cylinder or box container"),
    };
    let (_, _, bounds) = geometry(s.container)?;
    let mut deck = s.preamble(
        &p,
        "#",
        "LIGGGHTS 3.8",
        "../shared/tools/liggghts-run liggghts/in.settle   (or: liggghts -in in.settle)",
    );
    let _ = write!(
        deck,
        r#"# Bodies start at their packed poses: insert/pack of one particle in a sphere of radius {tiny:e} m
# around each centre of mass, orientation constant = the pose's quaternion (w x y z); templates
# shared by several bodies are defined once; distributions are numberbased. A failed check jumps
# to a label that does not exist: LIGGGHTS stops with an ERROR (its `quit` exits 0).
atom_style      granular
atom_modify     map array
boundary        f f f
newton          off
communicate     single vel yes
units           si
region          domain block {:e} {:e} {:e} {:e} {:e} {:e} units box
create_box      1 domain
neighbor        {skin:e} bin
neigh_modify    delay 0
fix             m1 all property/global youngsModulus peratomtype {es:e}
fix             m2 all property/global poissonsRatio peratomtype {nu}
fix             m3 all property/global coefficientRestitution peratomtypepair 1 {rest}
fix             m4 all property/global coefficientFriction peratomtypepair 1 {mu}
pair_style      gran model hertz tangential history
pair_coeff      * *
timestep        {dt:e}
{walls}
fix             gravi all gravity {g} vector 0.0 0.0 -1.0
group           singles type 1
compute         pgl all pair/gran/local delta
{tpl}{ms}{nve}{ins}run             1
{unfix}compute         zs all reduce ave z
variable        phi equal {vol:e}/({area:e}*2*(c_zs-({floor:e})))
{ke_computes}compute         ovl all reduce max c_pgl[1]
thermo_style    custom step time atoms v_ke v_phi
thermo          {chunk}
thermo_modify   lost error norm no
run             0
variable        phi0 equal {pf:.10}
variable        phistart equal $(v_phi)
print           "grainforge settle: bed fraction at the start ${{phistart}} (packed {pf:.6})"
variable        limit equal {ke:e}
run             {min}
variable        chunk loop {chunks}
label           settle
run             {chunk}
if              "${{ke}} <= ${{limit}}" then "jump SELF settled"
next            chunk
jump            SELF settle
label           settled
# computes are current only on output steps: one more step that outputs them all
thermo_style    custom step atoms v_ke v_phi c_ovl
run             0
variable        kefinal equal $(v_ke)
variable        phiend equal $(v_phi)
variable        overlap equal $(c_ovl)
write_restart   settled.restart
print           "grainforge settle: atoms $(atoms) of {atoms} ({n} bodies), kinetic energy ${{kefinal}} J (limit ${{limit}} J)"
print           "grainforge settle: largest overlap ${{overlap}} m (limit {ovm:e} m = {ovl} d50)"
print           "grainforge settle: bed fraction ${{phistart}} -> ${{phiend}} (packed {pf:.6}, tolerance {ft})"
variable        nat equal atoms
if              "${{nat}} != {atoms}" then "print 'grainforge settle: FAILED, atoms lost'" "jump SELF grainforge_settle_failed"
if              "${{kefinal}} > ${{limit}}" then "print 'grainforge settle: FAILED, not at rest after {max} steps'" "jump SELF grainforge_settle_failed"
if              "${{overlap}} > {ovm:e}" then "print 'grainforge settle: FAILED, overlap above {ovl} d50'" "jump SELF grainforge_settle_failed"
variable        dphi equal abs(${{phiend}}-${{phi0}})
if              "${{dphi}} > {ft}" then "print 'grainforge settle: NOT MET, bed fraction moved more than {ft} (reported, not fatal: the packed specimen was not at rest)'" else "print 'grainforge settle: bed fraction within {ft}'"
print           "grainforge settle: OK (bodies, energy, overlap)"
"#,
        bounds[0][0],
        bounds[0][1],
        bounds[1][0],
        bounds[1][1],
        bounds[2][0],
        bounds[2][1],
        skin = 0.1 * p.d50,
        es = m.youngs(),
        nu = m.poisson_ratio,
        rest = m.restitution,
        mu = m.friction,
        dt = p.dt,
        g = m.gravity,
        ms = if multi {
            "fix             ms all multisphere\n"
        } else {
            ""
        },
        nve = if singles {
            "fix             integr singles nve/sphere\n"
        } else {
            ""
        },
        ke_computes = match (multi, singles) {
            (true, false) =>
                "compute         ket all ke/multisphere\ncompute         ker all erotate/multisphere\nvariable        ke equal c_ket+c_ker\n",
            (true, true) =>
                "compute         ket all ke/multisphere\ncompute         ker all erotate/multisphere\ncompute         kes singles ke\ncompute         kers singles erotate/sphere\nvariable        ke equal c_ket+c_ker+c_kes+c_kers\n",
            _ =>
                "compute         ket all ke\ncompute         ker all erotate/sphere\nvariable        ke equal c_ket+c_ker\n",
        },
        vol = p.volume,
        area = p.area,
        floor = p.floor,
        chunk = p.chunk,
        pf = p.packed_fraction,
        ke = p.ke_limit,
        min = p.min_steps,
        chunks = (p.max_steps - p.min_steps).div_ceil(p.chunk).max(1),
        atoms = p.atoms,
        n = p.n,
        max = p.max_steps,
        ovl = OVERLAP_LIMIT,
        ovm = OVERLAP_LIMIT * p.d50,
        ft = FRACTION_TOLERANCE,
    );
    files.push(("liggghts/in.settle".into(), deck.into_bytes()));
    Ok(files)
}

/// Sum of the spheres' own volumes (what a code that adds the members' masses weighs).
#[cfg(test)]
fn summed_volume(t: &Template) -> f64 {
    t.spheres
        .iter()
        .map(|(_, r)| 4.0 / 3.0 * PI * r.powi(3))
        .sum()
}

/// A template's centroid as a vector (tests).
#[cfg(test)]
fn centroid_offset(t: &Template) -> nalgebra::Vector3<f64> {
    t.centroid.coords
}

#[cfg(test)]
mod tests;
