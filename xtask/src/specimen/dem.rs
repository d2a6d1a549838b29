//! Complete DEM decks for the clumps of a specimen, in SI units: LAMMPS (`lammps/`), Yade
//! (`yade/`) and LIGGGHTS (`liggghts/`), each runnable as written from its own folder and
//! each settling the specimen under gravity to equilibrium, checking itself and writing a
//! restart and a final state (`final.dump`, columns `id body x y z radius`) that
//! `cargo xtask specimen-check` compares with the packed specimen.
//!
//! # Contact model and constants (the same in the three codes)
//! Hertz–Mindlin with quartz constants: E = 70 GPa, ν = 0.2, divided by
//! [`Material::stiffness_scale`] (default 100, the largest the issue allows: contacts 100×
//! softer make the time step 10× longer; overlaps stay far below 1 % of d50 under the
//! specimen's own weight), friction 0.5 grain–grain and grain–wall, restitution 0.5 (the
//! normal damping of each code's Hertz model set from it). No global or viscous damping:
//! the contacts dissipate.
//!
//! # Rigid bodies
//! Every grain is one rigid body whose mass, centre of mass and inertia tensor are those of
//! the **union** of its spheres ([`levelset::union_mass_properties`] in `mod.rs`), not the
//! sum of the spheres' own (which over-counts the overlaps ≈ 1.9× for 20-sphere clumps):
//! LAMMPS `fix rigid/small … infile` with gravity applied to each body at its centre of mass
//! through the fix's `gravity` keyword (a `fix gravity` on the atoms would weigh the
//! over-counted sphere masses); Yade `appendClumped(…, discretization=…)` with the clump's
//! mass and inertia then set to the union's; LIGGGHTS `particletemplate/multisphere` with
//! the union's `mass`, `volume_mc` and `inertia_tensor`.
//!
//! # Time step
//! Rayleigh's criterion on the smallest clump (its volume-equivalent radius `R`):
//! `Δt_R = π R √(ρ/G) / (0.1631 ν + 0.8766)`, `G = E / (2 (1 + ν))` with the scaled `E`,
//! and `Δt = 0.2 Δt_R`. A contact between two clumps is a contact of two of their spheres,
//! whose Hertz stiffness (∝ √(R_sphere δ)) is smaller than that of the whole clump's
//! equivalent sphere while the mass is the clump's: the contact period is longer than the
//! equivalent sphere's, so the clump-based step is the conservative one that still lets a
//! few hundred clumps settle in minutes.
//!
//! # Equilibrium
//! The deck runs in chunks of [`CHUNK_STEPS`] and stops when the kinetic energy of the
//! bodies (translation and rotation) is below `1e-6 · N · m̄ · g · d50` (the issue's
//! criterion; `m̄` the mean body mass, `d50` the median volume-equivalent diameter, both
//! written into the deck), or fails after [`MAX_CHUNKS`] chunks.

use std::fmt::Write as _;

use nalgebra::{Isometry3, Matrix3, Point3};
use packer_quadtree::Container;
use serde::Deserialize;

/// Steps per settling chunk.
pub(crate) const CHUNK_STEPS: u64 = 2000;
/// Chunks before a deck gives up.
pub(crate) const MAX_CHUNKS: u64 = 200;
/// Gravity, m/s².
pub(crate) const GRAVITY: f64 = 9.81;

/// Material and contact constants of the decks (SI units).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct Material {
    /// Young's modulus, Pa (quartz 70 GPa), before the stiffness scaling.
    pub(crate) youngs_modulus: f64,
    /// Poisson's ratio (quartz 0.2).
    pub(crate) poisson_ratio: f64,
    /// Friction coefficient, grain–grain and grain–wall.
    pub(crate) friction: f64,
    /// Coefficient of restitution.
    pub(crate) restitution: f64,
    /// The decks use `youngs_modulus / stiffness_scale` (1..=100).
    pub(crate) stiffness_scale: f64,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            youngs_modulus: 70e9,
            poisson_ratio: 0.2,
            friction: 0.5,
            restitution: 0.5,
            stiffness_scale: 100.0,
        }
    }
}

impl Material {
    /// Checks the ranges (the key is named by the caller).
    pub(crate) fn validate(&self) -> anyhow::Result<()> {
        let ok = |v: f64, lo: f64, hi: f64| v.is_finite() && v >= lo && v <= hi;
        if !(self.youngs_modulus.is_finite() && self.youngs_modulus > 0.0) {
            anyhow::bail!(
                "youngs_modulus must be positive, got {}",
                self.youngs_modulus
            );
        }
        if !ok(self.poisson_ratio, 0.0, 0.49) {
            anyhow::bail!(
                "poisson_ratio must be in [0, 0.49], got {}",
                self.poisson_ratio
            );
        }
        if !ok(self.friction, 0.0, 10.0) {
            anyhow::bail!("friction must be in [0, 10], got {}", self.friction);
        }
        if !(self.restitution > 0.0 && self.restitution <= 1.0) {
            anyhow::bail!("restitution must be in (0, 1], got {}", self.restitution);
        }
        if !ok(self.stiffness_scale, 1.0, 100.0) {
            anyhow::bail!(
                "stiffness_scale must be in [1, 100] (at most 100× softer than quartz), got {}",
                self.stiffness_scale
            );
        }
        Ok(())
    }

    /// The scaled Young's modulus.
    pub(crate) fn youngs(&self) -> f64 {
        self.youngs_modulus / self.stiffness_scale
    }

    /// Shear modulus of the scaled material.
    pub(crate) fn shear(&self) -> f64 {
        self.youngs() / (2.0 * (1.0 + self.poisson_ratio))
    }
}

/// A clump shape shared by one or more bodies; template frame, metres.
#[derive(Debug, Clone)]
pub(crate) struct Template {
    /// Spheres: centre and radius.
    pub(crate) spheres: Vec<(Point3<f64>, f64)>,
    /// Union volume, m³.
    pub(crate) volume: f64,
    /// Union centroid (template frame).
    pub(crate) centroid: Point3<f64>,
    /// Union inertia per unit density about the centroid (template frame), m⁵.
    pub(crate) inertia: Matrix3<f64>,
}

/// A placed body: template frame → world (metres).
#[derive(Debug, Clone)]
pub(crate) struct Body {
    /// The template it copies.
    pub(crate) template: usize,
    /// Template frame → world.
    pub(crate) pose: Isometry3<f64>,
}

/// Everything a deck needs.
pub(crate) struct DemSpecimen<'a> {
    pub(crate) templates: &'a [Template],
    pub(crate) bodies: &'a [Body],
    /// The container, metres.
    pub(crate) container: &'a Container,
    pub(crate) material: &'a Material,
    /// Particle density, kg/m³.
    pub(crate) density: f64,
    /// Header lines (provenance) for every file.
    pub(crate) provenance: &'a [String],
}

/// Numbers the decks and the checker share.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settle {
    /// Bodies.
    pub(crate) n: usize,
    /// Spheres.
    pub(crate) atoms: usize,
    /// Mean body mass, kg.
    pub(crate) mean_mass: f64,
    /// Median volume-equivalent diameter, m.
    pub(crate) d50: f64,
    /// Kinetic-energy limit, J.
    pub(crate) ke_limit: f64,
    /// Time step, s.
    pub(crate) dt: f64,
    /// Rayleigh time step of the smallest clump, s.
    pub(crate) dt_rayleigh: f64,
    /// Volume-equivalent radius of the smallest clump, m.
    pub(crate) r_min: f64,
}

impl DemSpecimen<'_> {
    /// The shared numbers.
    pub(crate) fn settle(&self) -> anyhow::Result<Settle> {
        if self.bodies.is_empty() {
            anyhow::bail!("no body to write");
        }
        let mut d: Vec<f64> = self
            .bodies
            .iter()
            .map(|b| (6.0 * self.templates[b.template].volume / std::f64::consts::PI).cbrt())
            .collect();
        d.sort_by(f64::total_cmp);
        let d50 = d[d.len() / 2];
        let r_min = 0.5 * d[0];
        let mean_mass = self
            .bodies
            .iter()
            .map(|b| self.density * self.templates[b.template].volume)
            .sum::<f64>()
            / self.bodies.len() as f64;
        let m = self.material;
        let dt_rayleigh = std::f64::consts::PI * r_min * (self.density / m.shear()).sqrt()
            / (0.1631 * m.poisson_ratio + 0.8766);
        let n = self.bodies.len();
        Ok(Settle {
            n,
            atoms: self
                .bodies
                .iter()
                .map(|b| self.templates[b.template].spheres.len())
                .sum(),
            mean_mass,
            d50,
            ke_limit: 1e-6 * n as f64 * mean_mass * GRAVITY * d50,
            dt: 0.2 * dt_rayleigh,
            dt_rayleigh,
            r_min,
        })
    }

    /// World spheres of body `b`.
    fn world(&self, b: &Body) -> impl Iterator<Item = (Point3<f64>, f64)> + '_ {
        let pose = b.pose;
        self.templates[b.template]
            .spheres
            .iter()
            .map(move |(c, r)| (pose * c, *r))
    }

    /// Union mass properties of body `b` in the world: mass, centre, inertia tensor.
    fn mass(&self, b: &Body) -> (f64, Point3<f64>, Matrix3<f64>) {
        let t = &self.templates[b.template];
        let r = b.pose.rotation.to_rotation_matrix();
        let inertia = r.matrix() * t.inertia * r.matrix().transpose() * self.density;
        (t.volume * self.density, b.pose * t.centroid, inertia)
    }

    fn header(&self, comment: &str) -> String {
        let mut s = String::new();
        for l in self.provenance {
            let _ = writeln!(s, "{comment} {l}");
        }
        s
    }
}

/// The container's walls as LAMMPS region arguments, and the simulation box.
fn lammps_region(c: &Container) -> anyhow::Result<(String, [[f64; 2]; 3])> {
    match c {
        Container::Cylinder {
            base,
            radius,
            height,
        } => {
            let pad = 0.05 * height.max(*radius);
            Ok((
                format!(
                    "cylinder z {:e} {:e} {:e} {:e} {:e} side in",
                    base.x,
                    base.y,
                    radius,
                    base.z,
                    base.z + height
                ),
                [
                    [base.x - radius - pad, base.x + radius + pad],
                    [base.y - radius - pad, base.y + radius + pad],
                    [base.z - pad, base.z + height + pad],
                ],
            ))
        }
        Container::Box { min, max, periodic } => {
            if periodic[0] || periodic[1] {
                anyhow::bail!("the DEM decks need a walled container (periodic boxes: not yet)");
            }
            let pad = 0.05 * (max - min).max();
            Ok((
                format!(
                    "block {:e} {:e} {:e} {:e} {:e} {:e} side in",
                    min.x, max.x, min.y, max.y, min.z, max.z
                ),
                [
                    [min.x - pad, max.x + pad],
                    [min.y - pad, max.y + pad],
                    [min.z - pad, max.z + pad],
                ],
            ))
        }
        _ => anyhow::bail!("the DEM decks need a box or cylinder container"),
    }
}

/// LAMMPS: `lammps/clumps.data` (every sphere, plain `atom_style sphere`: LAMMPS'
/// `read_data` alone reads it), `lammps/clumps.body` (the body of each sphere, an
/// atomfile variable), `lammps/bodies.rigid` (`fix rigid/small infile`: the union's mass, centre and
/// inertia tensor per body), `lammps/in.settle` (the deck).
pub(crate) fn lammps_files(s: &DemSpecimen) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let st = s.settle()?;
    let (region, bounds) = lammps_region(s.container)?;
    let mut data = String::new();
    let _ = writeln!(
        data,
        "LAMMPS data file of grainforge (atom_style sphere, SI; the body of each atom: clumps.body)\n"
    );
    let _ = writeln!(data, "{} atoms\n1 atom types\n", st.atoms);
    for (b, axis) in bounds.iter().zip(["x", "y", "z"]) {
        let _ = writeln!(data, "{:e} {:e} {axis}lo {axis}hi", b[0], b[1]);
    }
    let _ = writeln!(data, "\nAtoms # sphere\n");
    let mut id = 0usize;
    let mut mols = s.header("#");
    let _ = writeln!(
        mols,
        "# body (molecule id) of every atom of clumps.data: atomfile-style variable of in.settle\n{}",
        st.atoms
    );
    for (k, b) in s.bodies.iter().enumerate() {
        for (c, r) in s.world(b) {
            id += 1;
            let _ = writeln!(
                data,
                "{id} 1 {:e} {:e} {:e} {:e} {:e}",
                2.0 * r,
                s.density,
                c.x,
                c.y,
                c.z
            );
            let _ = writeln!(mols, "{id} {}", k + 1);
        }
    }

    let mut rigid = s.header("#");
    let _ = writeln!(
        rigid,
        "# fix rigid/small infile: body mass (kg), centre of mass (m), inertia tensor about it (kg m^2)\n\
         # of the union of each clump's spheres; id masstotal xcm ycm zcm ixx iyy izz ixy ixz iyz vxcm vycm vzcm lx ly lz ixcm iycm izcm\n{}",
        s.bodies.len()
    );
    for (k, b) in s.bodies.iter().enumerate() {
        let (m, c, i) = s.mass(b);
        let _ = writeln!(
            rigid,
            "{} {m:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} 0 0 0 0 0 0 0 0 0",
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
    let m = s.material;
    let contact = format!(
        "hertz/material {:e} {} {} tangential mindlin NULL 1.0 {} damping coeff_restitution",
        m.youngs(),
        m.restitution,
        m.poisson_ratio,
        m.friction
    );
    let mut deck = s.header("#");
    let _ = write!(
        deck,
        r#"# LAMMPS deck: settle the specimen under gravity to equilibrium (run from this folder:
#   ../shared/tools/lammps-run lammps/in.settle, or lmp -in in.settle).
# Units SI. Hertz-Mindlin (pair granular hertz/material, tangential mindlin), quartz E = {e:e} Pa
# scaled by 1/{scale} -> {es:e} Pa, nu = {nu}, friction {mu}, restitution {rest}; no global damping.
# Rigid bodies: fix rigid/small with the union's mass, centre and inertia (bodies.rigid); gravity on
# each body's total mass at its centre of mass (the gravity keyword; fix gravity's group is empty).
# Time step: Rayleigh on the smallest clump (R = {rmin:e} m): pi R sqrt(rho/G)/(0.1631 nu + 0.8766)
#   = {dtr:e} s, dt = 0.2 of it.
# Equilibrium: kinetic energy of the bodies <= 1e-6 N m g d50 = {ke:e} J (N = {n}, m = {mm:e} kg,
#   d50 = {d50:e} m), checked every {chunk} steps, at most {maxc} chunks.
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
neighbor        {skin:e} bin
neigh_modify    delay 0 every 1 check yes exclude molecule/intra all
pair_style      granular
pair_coeff      * * {contact}
region          walls {region}
fix             walls all wall/gran/region granular {contact} region walls
group           none empty
fix             grav none gravity {g} vector 0 0 -1
fix             bodies all rigid/small molecule infile bodies.rigid gravity grav
compute         ket all ke/rigid bodies
compute         ker all erotate/rigid bodies
variable        ke equal c_ket+c_ker
write_dump      all custom initial.dump id mol x y z radius modify sort id format float %.12g
timestep        {dt:e}
thermo_style    custom step time atoms v_ke
thermo          {chunk}
thermo_modify   lost error norm no
variable        limit equal {ke:e}
variable        chunk loop {maxc}
label           settle
run             {chunk}
if              "${{ke}} <= ${{limit}}" then "jump SELF settled"
next            chunk
jump            SELF settle
print           "grainforge settle: FAILED, kinetic energy ${{ke}} J above ${{limit}} J after {maxc} chunks"
quit            1
label           settled
print           "grainforge settle: bodies {n}, atoms $(atoms), kinetic energy ${{ke}} J <= ${{limit}} J at t = $(time) s"
write_restart   settled.restart
write_dump      all custom final.dump id mol x y z radius modify sort id format float %.12g
"#,
        e = m.youngs_modulus,
        scale = m.stiffness_scale,
        es = m.youngs(),
        nu = m.poisson_ratio,
        mu = m.friction,
        rest = m.restitution,
        rmin = st.r_min,
        dtr = st.dt_rayleigh,
        ke = st.ke_limit,
        n = st.n,
        mm = st.mean_mass,
        d50 = st.d50,
        chunk = CHUNK_STEPS,
        maxc = MAX_CHUNKS,
        skin = 0.1 * st.d50,
        g = GRAVITY,
        dt = st.dt,
    );
    Ok(vec![
        (
            "lammps/settle.txt".into(),
            super::check::settle_text(st.n, st.atoms, st.d50, s.container).into_bytes(),
        ),
        ("lammps/clumps.data".into(), data.into_bytes()),
        ("lammps/clumps.body".into(), mols.into_bytes()),
        ("lammps/bodies.rigid".into(), rigid.into_bytes()),
        ("lammps/in.settle".into(), deck.into_bytes()),
    ])
}

/// Yade: `yade/clumps.txt` (`x y z r body`, world frame, metres), `yade/settle.py` (the
/// deck: run from this folder, `yade -n -x settle.py`) and `yade/settle.txt`.
pub(crate) fn yade_files(s: &DemSpecimen) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let st = s.settle()?;
    let mut spheres = s.header("#");
    spheres.push_str("# x y z r body (world frame, metres); body = grain number + 1\n");
    let mut masses = String::from("masses = {\n");
    for (k, b) in s.bodies.iter().enumerate() {
        for (c, r) in s.world(b) {
            let _ = writeln!(spheres, "{:e} {:e} {:e} {:e} {}", c.x, c.y, c.z, r, k + 1);
        }
        let (m, _, _) = s.mass(b);
        let _ = writeln!(masses, "    {}: {m:e},", k + 1);
    }
    masses.push_str("}\n");
    let m = s.material;
    let walls = match s.container {
        Container::Cylinder {
            base,
            radius,
            height,
        } => format!(
            "# a 64-sided prism circumscribing the cylinder (its faces touch the circle), floor and lid\n\
             n_seg = 64\n\
             walls = geom.facetCylinder(center=({:e}, {:e}, {:e}), radius={:e} / math.cos(math.pi / n_seg), height={:e}, segmentsNumber=n_seg, wallMask=7, material=quartz, color=(0.5, 0.5, 0.5))",
            base.x,
            base.y,
            base.z + 0.5 * height,
            radius,
            height
        ),
        Container::Box { min, max, periodic } if !periodic[0] && !periodic[1] => {
            let c = nalgebra::center(min, max);
            let e = (max - min) * 0.5;
            format!(
                "walls = geom.facetBox(center=({:e}, {:e}, {:e}), extents=({:e}, {:e}, {:e}), wallMask=63, material=quartz)",
                c.x, c.y, c.z, e.x, e.y, e.z
            )
        }
        _ => anyhow::bail!("the DEM decks need a walled box or cylinder container"),
    };
    let mut deck = s.header("#");
    let _ = write!(
        deck,
        r#"# Yade deck: settle the specimen under gravity to equilibrium. Run from this folder:
#   yade -n -x settle.py        (or ../shared/tools/yade-run yade/settle.py)
# Units SI. Hertz-Mindlin (Ip2_FrictMat_FrictMat_MindlinPhys, Law2_ScGeom_MindlinPhys_Mindlin), quartz
# E = {e:e} Pa scaled by 1/{scale} -> {es:e} Pa, nu = {nu}, friction {mu}, restitution {rest} (en = es);
# no global damping (NewtonIntegrator damping 0).
# Clumps: O.bodies.appendClumped(..., discretization=20): Yade integrates the union of the overlapping
# spheres on a grid (its default sums the members' masses, ~1.9x too heavy for these clumps); the
# union's masses computed by grainforge are printed beside Yade's for comparison.
# Time step {dt:e} s = 0.2 Rayleigh of the smallest clump; equilibrium: kinetic energy <= {ke:e} J
# (1e-6 N m g d50, N = {n}, m = {mm:e} kg, d50 = {d50:e} m), checked every {chunk} steps.
import math, sys
from yade import geom, utils

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
{masses}clump_ids = {{}}
for b in sorted(spheres):
    cid, _ = O.bodies.appendClumped([utils.sphere(c, r, material=quartz) for c, r in spheres[b]], discretization=20)
    clump_ids[b] = cid
ratio = [O.bodies[clump_ids[b]].state.mass / masses[b] for b in clump_ids]
print('grainforge: %d clumps; Yade clump mass / union mass: mean %.4f, min %.4f, max %.4f' % (len(ratio), sum(ratio) / len(ratio), min(ratio), max(ratio)))

def dump(name):
    with open(name, 'w') as f:
        f.write('# id body x y z radius\n')
        for b in sorted(clump_ids):
            for mid in O.bodies[clump_ids[b]].shape.members.keys():
                m = O.bodies[mid]
                p = m.state.pos
                f.write('%d %d %.12g %.12g %.12g %.12g\n' % (mid, b, p[0], p[1], p[2], m.shape.radius))

O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()], verletDist={skin:e}),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom()],
        [Ip2_FrictMat_FrictMat_MindlinPhys(en=MatchMaker(algo='val', val={rest}), es=MatchMaker(algo='val', val={rest}))],
        [Law2_ScGeom_MindlinPhys_Mindlin()],
    ),
    NewtonIntegrator(damping=0.0, gravity=(0, 0, -{g})),
]
O.dt = {dt:e}
dump('initial.dump')
limit = {ke:e}
for chunk in range({maxc}):
    O.run({chunk}, True)
    ke = utils.kineticEnergy()
    print('step %d t %.6g s kinetic energy %.4e J' % (O.iter, O.time, ke))
    if ke <= limit:
        break
else:
    print('grainforge settle: FAILED, kinetic energy %.4e J above %.4e J' % (ke, limit))
    raise SystemExit(1)
print('grainforge settle: bodies %d, kinetic energy %.4e J <= %.4e J at t = %.6g s' % (len(clump_ids), ke, limit, O.time))
O.save('settled.yade.gz')
dump('final.dump')
"#,
        e = m.youngs_modulus,
        scale = m.stiffness_scale,
        es = m.youngs(),
        nu = m.poisson_ratio,
        mu = m.friction,
        rest = m.restitution,
        rho = s.density,
        dt = st.dt,
        ke = st.ke_limit,
        n = st.n,
        mm = st.mean_mass,
        d50 = st.d50,
        chunk = CHUNK_STEPS,
        maxc = MAX_CHUNKS,
        skin = 0.1 * st.d50,
        g = GRAVITY,
    );
    Ok(vec![
        (
            "yade/settle.txt".into(),
            super::check::settle_text(st.n, st.atoms, st.d50, s.container).into_bytes(),
        ),
        ("yade/clumps.txt".into(), spheres.into_bytes()),
        ("yade/settle.py".into(), deck.into_bytes()),
    ])
}

/// LIGGGHTS: one `liggghts/template-T.txt` per distinct shape (`x y z r` in the template
/// frame, metres) and `liggghts/templates.in`: a `fix particletemplate/multisphere` per
/// template with the union's `mass` and `inertia_tensor` (about its centre of mass, template
/// frame: `Ixx Ixy Ixz Iyy Iyz Izz`, kg m²) and `fix particledistribution/discrete/numberbased`
/// with each template weighted by the number of grains that use it (the mass-based default
/// would over-insert the small ones). A deck that starts the bodies at their packed poses is
/// not written yet (LIGGGHTS-PUBLIC inserts multisphere bodies only through its insertion
/// fixes); `../poses.csv` gives each grain's template and pose.
pub(crate) fn liggghts_files(s: &DemSpecimen) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    s.settle()?;
    let mut used = vec![0usize; s.templates.len()];
    for b in s.bodies {
        used[b.template] += 1;
    }
    let mut files = Vec::new();
    let mut script = s.header("#");
    let _ = writeln!(
        script,
        "# LIGGGHTS multisphere templates of the specimen's distinct shapes (SI: metres, kg, kg m^2).\n\
         # include this file from a LIGGGHTS input run in this folder; density {:e} kg/m^3.\n\
         # mass and inertia_tensor (Ixx Ixy Ixz Iyy Iyz Izz about the centre of mass) are the union's of each\n\
         # template's overlapping spheres; weights count the grains that use each template (numberbased).",
        s.density
    );
    let n_used = used.iter().filter(|u| **u > 0).count();
    // LIGGGHTS wants every random seed a prime above 10000: consecutive primes from 15485863
    let mut seed = 15_485_863u64;
    let mut weights = String::new();
    for (k, t) in s.templates.iter().enumerate() {
        if used[k] == 0 {
            continue;
        }
        let name = format!("template-{:06}.txt", k + 1);
        let mut text = String::new();
        for (c, r) in &t.spheres {
            let _ = writeln!(text, "{:e} {:e} {:e} {:e}", c.x, c.y, c.z, r);
        }
        let m = t.volume * s.density;
        let i = t.inertia * s.density;
        seed = next_prime(seed + 1);
        let _ = writeln!(
            script,
            "fix pts{k1} all particletemplate/multisphere {seed} atom_type 1 density constant {rho:e} volume_limit 1e-20 nspheres {ns} ntry 1000000 spheres file {name} scale 1.0 type {k1} use_density mass {m:e} inertia_tensor {:e} {:e} {:e} {:e} {:e} {:e}",
            i[(0, 0)],
            i[(0, 1)],
            i[(0, 2)],
            i[(1, 1)],
            i[(1, 2)],
            i[(2, 2)],
            k1 = k + 1,
            rho = s.density,
            ns = t.spheres.len(),
        );
        let _ = write!(
            weights,
            " &\n    pts{} {:.12}",
            k + 1,
            used[k] as f64 / s.bodies.len() as f64
        );
        files.push((format!("liggghts/{name}"), text.into_bytes()));
    }
    let _ = writeln!(
        script,
        "fix pdd all particledistribution/discrete/numberbased 32452843 {n_used}{weights}"
    );
    files.push(("liggghts/templates.in".into(), script.into_bytes()));
    let (_, b) = lammps_region(s.container)?;
    let st = s.settle()?;
    let m = s.material;
    let mut check = s.header("#");
    let _ = write!(
        check,
        r#"# LIGGGHTS: load the specimen's multisphere templates (run from this folder:
#   liggghts -in in.templates, or ../shared/tools/liggghts-run liggghts/in.templates).
# The contact constants of the other decks (Hertz, E = {es:e} Pa = quartz/{scale}, nu = {nu},
# restitution {rest}, friction {mu}); no settling deck yet: LIGGGHTS-PUBLIC 3.8 inserts multisphere
# bodies only at random positions of an insertion region (fix insert/pack into one tiny region per
# body stops with "Unable to calculate region volume"), so the packed poses (../poses.csv) cannot be
# given to it as they are.
atom_style      granular
atom_modify     map array
boundary        f f f
newton          off
communicate     single vel yes
units           si
region          domain block {x0:e} {x1:e} {y0:e} {y1:e} {z0:e} {z1:e} units box
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
include         templates.in
run             0
"#,
        es = m.youngs(),
        scale = m.stiffness_scale,
        nu = m.poisson_ratio,
        rest = m.restitution,
        mu = m.friction,
        x0 = b[0][0],
        x1 = b[0][1],
        y0 = b[1][0],
        y1 = b[1][1],
        z0 = b[2][0],
        z1 = b[2][1],
        skin = 0.1 * st.d50,
        dt = st.dt,
    );
    files.push(("liggghts/in.templates".into(), check.into_bytes()));
    Ok(files)
}

/// The smallest prime at least `n` (trial division; `n` is small).
fn next_prime(mut n: u64) -> u64 {
    let is_prime = |k: u64| {
        k > 1
            && (2..)
                .take_while(|d| d * d <= k)
                .all(|d| !k.is_multiple_of(d))
    };
    while !is_prime(n) {
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion, Vector3};

    fn specimen_parts() -> (Vec<Template>, Vec<Body>, Container) {
        let t = Template {
            spheres: vec![
                (Point3::new(-1e-4, 0.0, 0.0), 1e-4),
                (Point3::new(1e-4, 0.0, 0.0), 1e-4),
            ],
            volume: 8e-12,
            centroid: Point3::origin(),
            inertia: Matrix3::from_diagonal(&Vector3::new(1e-20, 3e-20, 3e-20)),
        };
        let bodies = (0..3)
            .map(|k| Body {
                template: 0,
                pose: Isometry3::from_parts(
                    Translation3::new(0.0, 0.0, 3e-4 + 5e-4 * k as f64),
                    UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3 * k as f64),
                ),
            })
            .collect();
        (vec![t], bodies, Container::triaxial(2e-3))
    }

    #[test]
    fn decks_carry_the_union_mass_and_the_rayleigh_step() {
        let (t, b, c) = specimen_parts();
        let m = Material::default();
        let s = DemSpecimen {
            templates: &t,
            bodies: &b,
            container: &c,
            material: &m,
            density: 2650.0,
            provenance: &["grainforge test".into()],
        };
        let st = s.settle().expect("settle");
        // Rayleigh: pi R sqrt(rho/G) / (0.1631 nu + 0.8766), R of the smallest clump
        let r = 0.5 * (6.0 * 8e-12 / std::f64::consts::PI).cbrt();
        let g: f64 = 7e8 / 2.4;
        let want = std::f64::consts::PI * r * (2650.0 / g).sqrt() / (0.1631 * 0.2 + 0.8766);
        approx::assert_relative_eq!(st.dt_rayleigh, want, max_relative = 1e-12);
        approx::assert_relative_eq!(st.dt, 0.2 * want, max_relative = 1e-12);
        let files = lammps_files(&s).expect("lammps");
        let rigid = String::from_utf8(files[3].1.clone()).expect("utf8");
        // one line per body with the union's mass 2650 * 8e-12
        let body: Vec<&str> = rigid.lines().filter(|l| l.starts_with("1 ")).collect();
        assert_eq!(body.len(), 1);
        let mass: f64 = body[0]
            .split_whitespace()
            .nth(1)
            .expect("mass")
            .parse()
            .expect("f64");
        approx::assert_relative_eq!(mass, 2650.0 * 8e-12, max_relative = 1e-12);
        let deck = String::from_utf8(files[4].1.clone()).expect("utf8");
        assert!(
            deck.contains("infile bodies.rigid gravity grav")
                && deck.contains("group           none empty")
        );
        let lig = liggghts_files(&s).expect("liggghts");
        let script = String::from_utf8(lig[1].1.clone()).expect("utf8");
        assert!(script.contains("numberbased") && script.contains("use_density mass"));
        assert_eq!(
            lig.len(),
            3,
            "one template for three bodies, templates.in, in.templates"
        );
        let yade = yade_files(&s).expect("yade");
        assert!(
            String::from_utf8(yade[2].1.clone())
                .expect("utf8")
                .contains("discretization=20")
        );
    }

    #[test]
    fn liggghts_seeds_are_primes_and_materials_are_checked() {
        assert_eq!(next_prime(15_485_863), 15_485_863);
        assert_eq!(next_prime(15_485_864), 15_485_867);
        let mut m = Material::default();
        assert!(m.validate().is_ok());
        m.stiffness_scale = 1000.0;
        assert!(m.validate().is_err());
        m.stiffness_scale = 10.0;
        m.restitution = 0.0;
        assert!(m.validate().is_err());
    }
}
