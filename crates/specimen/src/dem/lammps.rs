//! The LAMMPS deck: the clump data file (every sphere, `atom_style sphere`), the body of
//! each sphere, the `fix rigid/small` infile of the bodies' union mass properties and the
//! settle deck `in.settle`.

use std::fmt::Write as _;
use std::io::Write as _;

use packer_spheres::Container;

use super::{DemSpecimen, FRACTION_TOLERANCE, OVERLAP_LIMIT, Plan, geometry, not_walled};
use crate::error::Result;

/// LAMMPS: `lammps/clumps.data` (every sphere, plain `atom_style sphere`: LAMMPS' `read_data`
/// alone reads it; [`write_lammps_clump_data`]), `lammps/clumps.body` (the body of each
/// sphere, an atomfile variable), `lammps/bodies.rigid` (the `fix rigid/small … infile` file:
/// union mass, centre and inertia tensor of each body) and `lammps/in.settle`.
///
/// # Errors
/// As [`DemSpecimen::plan`].
pub fn lammps_files(s: &DemSpecimen) -> Result<Vec<(String, Vec<u8>)>> {
    let p = s.plan()?;
    let mut data = Vec::new();
    clump_data(s, &p, &mut data)?;
    let body = body_file(s, &p);
    let rigid = rigid_file(s);
    let deck = settle_deck(s, &p)?;
    Ok(vec![
        ("lammps/clumps.data".into(), data),
        ("lammps/clumps.body".into(), body.into_bytes()),
        ("lammps/bodies.rigid".into(), rigid.into_bytes()),
        ("lammps/in.settle".into(), deck.into_bytes()),
    ])
}

/// Writes the LAMMPS clump data file of `s` to `w`, byte for byte the `lammps/clumps.data`
/// of [`lammps_files`]: every clump sphere as an atom of `atom_style sphere` (id, type 1,
/// diameter, density, world position; SI), in body order, in a box 5 % larger than the
/// container. LAMMPS' `read_data` reads it alone; which body each atom belongs to, and the
/// bodies' union mass properties, are the other files of [`lammps_files`].
///
/// # Errors
/// As [`DemSpecimen::plan`]; [`crate::Error::Io`] when `w` fails.
pub fn write_lammps_clump_data(s: &DemSpecimen, w: impl std::io::Write) -> Result<()> {
    clump_data(s, &s.plan()?, w)
}

/// [`write_lammps_clump_data`] with the specimen's plan already made (and validated).
fn clump_data(s: &DemSpecimen, p: &Plan, w: impl std::io::Write) -> Result<()> {
    let (_, _, bounds) = geometry(s.container)?;
    let mut w = std::io::BufWriter::new(w);
    w.write_all(
        b"LAMMPS data file of grainforge (atom_style sphere, SI; the body of each atom: clumps.body)\n\n",
    )?;
    writeln!(w, "{} atoms\n1 atom types\n", p.atoms)?;
    for (b, axis) in bounds.iter().zip(["x", "y", "z"]) {
        writeln!(w, "{:e} {:e} {axis}lo {axis}hi", b[0], b[1])?;
    }
    w.write_all(b"\nAtoms # sphere\n\n")?;
    let density = s.material.density;
    let mut id = 0usize;
    for b in s.bodies {
        for (c, r) in s.world(b) {
            id += 1;
            writeln!(
                w,
                "{id} 1 {:e} {:e} {:e} {:e} {:e}",
                2.0 * r,
                density,
                c.x,
                c.y,
                c.z
            )?;
        }
    }
    w.flush()?;
    Ok(())
}

/// `clumps.body`: the body (molecule id k + 1) of every atom of `clumps.data`, read by an
/// atomfile-style variable of the deck.
fn body_file(s: &DemSpecimen, p: &Plan) -> String {
    let mut body = s.header("#");
    let _ = writeln!(
        body,
        "# body (molecule id) of every atom of clumps.data: atomfile-style variable of in.settle\n{}",
        p.atoms
    );
    let mut id = 0usize;
    for (k, b) in s.bodies.iter().enumerate() {
        for _ in s.world(b) {
            id += 1;
            let _ = writeln!(body, "{id} {}", k + 1);
        }
    }
    body
}

/// `bodies.rigid`, the `fix rigid/small` infile: each body's union mass, centre of mass and
/// inertia tensor (world frame), zero velocities.
fn rigid_file(s: &DemSpecimen) -> String {
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
    rigid
}

/// The `region` of the container's walls.
fn walls_region(c: &Container) -> Result<String> {
    Ok(match c {
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
        _ => return Err(not_walled()),
    })
}

/// `in.settle`: the preamble, then the set-up, the settling and the checks.
fn settle_deck(s: &DemSpecimen, p: &Plan) -> Result<String> {
    let walls = walls_region(s.container)?;
    let m = s.material;
    let contact = format!(
        "hertz/material {:e} {} {} tangential mindlin NULL 1.0 {} damping coeff_restitution",
        m.youngs(),
        m.restitution,
        m.poisson_ratio,
        m.friction
    );
    let mut deck = s.preamble(
        p,
        "#",
        "LAMMPS",
        "../shared/tools/lammps-run lammps/in.settle   (or: lmp -in in.settle)",
    );
    deck_setup(&mut deck, s, p, &walls, &contact);
    deck_settle(&mut deck, p);
    deck_checks(&mut deck, p);
    Ok(deck)
}

/// The deck's set-up: atoms, bodies, contacts, walls, gravity, the energy and bed-fraction
/// variables, the step.
fn deck_setup(deck: &mut String, s: &DemSpecimen, p: &Plan, walls: &str, contact: &str) {
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
"#,
        skin = 0.1 * p.d50,
        g = s.material.gravity,
        vol = p.volume,
        area = p.area,
        floor = p.floor,
        dt = p.dt,
        chunk = p.chunk,
    );
}

/// The settling: the initial dump and bed fraction, runs of [`Plan::chunk`] steps until the
/// energy is down, the restart and the final dump.
fn deck_settle(deck: &mut String, p: &Plan) {
    let _ = write!(
        deck,
        r#"run             0
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
"#,
        pf = p.packed_fraction,
        ke = p.ke_limit,
        min = p.min_steps,
        chunks = p.chunks(),
        chunk = p.chunk,
    );
}

/// The checks: the largest overlap by bisection, the report lines, `quit 1` on a failure.
fn deck_checks(deck: &mut String, p: &Plan) {
    let _ = write!(
        deck,
        r#"# largest overlap of two spheres of different bodies, by bisection: shrink every radius by s/2
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
        ovhi = 0.05 * p.d50,
        atoms = p.atoms,
        n = p.n,
        d50 = p.d50,
        pf = p.packed_fraction,
        max = p.max_steps,
        ovl = OVERLAP_LIMIT,
        ovm = OVERLAP_LIMIT * p.d50,
        ft = FRACTION_TOLERANCE,
    );
}
