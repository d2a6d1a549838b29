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
//! Pure functions: [`lammps_files`], [`liggghts_files`] and [`yade_files`] return
//! `(path relative to the output folder, bytes)` and the caller stores them
//! ([`write_lammps_clump_data`] writes the LAMMPS clump data alone to any `impl Write`); one
//! submodule per code (`lammps.rs`, `liggghts.rs`, `yade.rs`). LAMMPS and Yade also write
//! `initial.dump` and `final.dump` (`id body x y z radius`) that `cargo xtask specimen-check`
//! measures again (`cargo xtask specimen` adds `settle.txt` beside each deck).
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

use nalgebra::{Isometry3, Matrix3, Point3};
use packer_spheres::Container;
use serde::Deserialize;

use crate::error::{Context as _, Error, Result, invalid};

mod lammps;
mod liggghts;
mod yade;

pub use lammps::{lammps_files, write_lammps_clump_data};
pub use liggghts::{LIGGGHTS_BATCH, liggghts_batches, liggghts_files};
pub use yade::yade_files;

/// Steps between two kinetic-energy checks.
const CHUNK_STEPS: u64 = 2000;
/// Time-step divisions of the Hertz contact duration.
pub const STEPS_PER_CONTACT: f64 = 10.0;
/// Largest overlap allowed at the end, as a fraction of d50.
const OVERLAP_LIMIT: f64 = 0.01;
/// Largest change of the bed fraction.
const FRACTION_TOLERANCE: f64 = 0.01;
/// Kinetic-energy limit per `N · m̄ · g · d50`.
const KE_FACTOR: f64 = 1e-6;
/// What the decks say of a container they cannot write.
const NOT_WALLED: &str = "the DEM decks need a cylinder or box container";

/// Material and contact constants of the decks (SI units).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Material {
    /// Particle density, kg/m³ (quartz 2650).
    pub density: f64,
    /// Young's modulus, Pa (quartz 70 GPa), before the stiffness scaling.
    pub youngs_modulus: f64,
    /// Poisson's ratio (quartz 0.2).
    pub poisson_ratio: f64,
    /// Coulomb friction coefficient, grain–grain and grain–wall.
    pub friction: f64,
    /// Normal coefficient of restitution, grain–grain and grain–wall.
    pub restitution: f64,
    /// The decks use `youngs_modulus / stiffness_scale`, in [1, 100].
    pub stiffness_scale: f64,
    /// Gravitational acceleration, m/s², along −z.
    pub gravity: f64,
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
    /// [`Error::Invalid`] naming the value out of range.
    pub fn validate(&self) -> Result<()> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !pos(self.density) {
            invalid!("density", "must be positive, got {}", self.density);
        }
        if !pos(self.youngs_modulus) {
            invalid!(
                "youngs_modulus",
                "must be positive, got {}",
                self.youngs_modulus
            );
        }
        if !(0.0..0.5).contains(&self.poisson_ratio) {
            invalid!(
                "poisson_ratio",
                "must be in [0, 0.5), got {}",
                self.poisson_ratio
            );
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            invalid!("friction", "must be non-negative, got {}", self.friction);
        }
        if !(self.restitution > 0.0 && self.restitution <= 1.0) {
            invalid!("restitution", "must be in (0, 1], got {}", self.restitution);
        }
        if !(1.0..=100.0).contains(&self.stiffness_scale) {
            invalid!(
                "stiffness_scale",
                "must be in [1, 100] (at most 100× softer than the material), got {}",
                self.stiffness_scale
            );
        }
        if !pos(self.gravity) {
            invalid!("gravity", "must be positive, got {}", self.gravity);
        }
        Ok(())
    }

    /// The Young's modulus the decks use, `youngs_modulus / stiffness_scale`, Pa.
    pub fn youngs(&self) -> f64 {
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
pub struct Template {
    /// Sphere centres and radii.
    pub spheres: Vec<(Point3<f64>, f64)>,
    /// Union volume, m³.
    pub volume: f64,
    /// Union centroid, template frame.
    pub centroid: Point3<f64>,
    /// Union inertia per unit density about the centroid, template frame, m⁵.
    pub inertia: Matrix3<f64>,
}

/// A placed body: template frame → world (metres).
#[derive(Debug, Clone)]
pub struct Body {
    /// The grain's number (line of `poses.csv`); body `k` of the decks is `bodies[k]`.
    pub id: u64,
    /// Index into the templates.
    pub template: usize,
    /// Template frame → world.
    pub pose: Isometry3<f64>,
}

/// Everything a deck needs.
#[derive(Debug, Clone, Copy)]
pub struct DemSpecimen<'a> {
    /// The distinct clump shapes.
    pub templates: &'a [Template],
    /// The placed bodies.
    pub bodies: &'a [Body],
    /// The container, metres.
    pub container: &'a Container,
    /// Constants.
    pub material: &'a Material,
    /// Header lines to put in every file as comments.
    pub provenance: &'a [String],
}

/// The numbers the three decks share, computed once in Rust ([`DemSpecimen::plan`]).
#[derive(Debug, Clone, Copy)]
pub struct Plan {
    /// Bodies.
    pub n: usize,
    /// Spheres.
    pub atoms: usize,
    /// Mean body mass, kg.
    pub mean_mass: f64,
    /// Median volume-equivalent diameter, m.
    pub d50: f64,
    /// Largest volume-equivalent diameter, m.
    pub d_max: f64,
    /// Kinetic-energy limit `1e-6 · N · m̄ · g · d50`, J.
    pub ke_limit: f64,
    /// Hertz contact duration of the smallest clump, s.
    pub t_hertz: f64,
    /// Rayleigh time of the smallest sphere (for comparison), s.
    pub t_rayleigh: f64,
    /// Time step, s.
    pub dt: f64,
    /// Lightest body's mass, kg.
    pub m_min: f64,
    /// Smallest sphere radius, m.
    pub r_min: f64,
    /// Impact speed of the Hertz criterion, m/s.
    pub v_impact: f64,
    /// Steps per check.
    pub chunk: u64,
    /// Fewest steps before the energy may end the run.
    pub min_steps: u64,
    /// Most steps before the deck gives up.
    pub max_steps: u64,
    /// Union volume of all bodies, m³.
    pub volume: f64,
    /// Floor height, m.
    pub floor: f64,
    /// Container cross-section, m².
    pub area: f64,
    /// Bed fraction of the packed specimen (module docs).
    pub packed_fraction: f64,
}

impl Plan {
    /// Checks of [`Plan::chunk`] steps after the first [`Plan::min_steps`] (at least one).
    fn chunks(&self) -> u64 {
        (self.max_steps - self.min_steps)
            .div_ceil(self.chunk)
            .max(1)
    }
}

/// Hertz contact duration `2.87 (m*² / (R* E*² v))^(1/5)` of two bodies of effective mass
/// `m_star` meeting at speed `v` with effective radius `r_star` and modulus `e_star`
/// (Johnson 1985, Contact Mechanics, § 11.4).
pub fn hertz_contact_time(m_star: f64, r_star: f64, e_star: f64, v: f64) -> f64 {
    2.87 * (m_star * m_star / (r_star * e_star * e_star * v)).powf(0.2)
}

/// Rayleigh time of a sphere of radius `r`: `π r √(ρ/G) / (0.1631 ν + 0.8766)`.
pub fn rayleigh_time(r: f64, density: f64, shear: f64, nu: f64) -> f64 {
    PI * r * (density / shear).sqrt() / (0.1631 * nu + 0.8766)
}

/// Floor height, cross-section and the LAMMPS box of a walled container.
fn geometry(c: &Container) -> Result<(f64, f64, [[f64; 2]; 3])> {
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
            if periodic[0] || periodic[1] {
                return Err(Error::Rejected(
                    "the DEM decks need a walled container; periodic boxes are not written yet"
                        .to_owned(),
                ));
            }
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
        _ => Err(not_walled()),
    }
}

/// The error of a container the decks cannot write.
fn not_walled() -> Error {
    Error::Rejected(NOT_WALLED.to_owned())
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
    /// non-positive volume ([`Error::Invalid`]); bad material constants (the
    /// [`Material::validate`] error in [`Error::Context`] "material"); a container without
    /// walls ([`Error::Rejected`]).
    pub fn plan(&self) -> Result<Plan> {
        self.material
            .validate()
            .context_with(|| "material".to_owned())?;
        self.check_bodies()?;
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

    /// At least one body, every template with spheres and a positive volume, every body
    /// naming a template.
    fn check_bodies(&self) -> Result<()> {
        if self.bodies.is_empty() {
            invalid!("bodies", "no body to write");
        }
        for (k, t) in self.templates.iter().enumerate() {
            if t.spheres.is_empty() {
                invalid!(format!("template {k}"), "has no sphere");
            }
            if !(t.volume.is_finite() && t.volume > 0.0) {
                invalid!(
                    format!("template {k}"),
                    "union volume {} is not positive",
                    t.volume
                );
            }
            for (c, r) in &t.spheres {
                if !(c.coords.iter().all(|v| v.is_finite()) && r.is_finite() && *r > 0.0) {
                    invalid!(format!("template {k}"), "bad sphere {c} r {r}");
                }
            }
        }
        for b in self.bodies {
            if b.template >= self.templates.len() {
                invalid!(
                    format!("body {}", b.id),
                    "names template {} of {}",
                    b.template,
                    self.templates.len()
                );
            }
        }
        Ok(())
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
