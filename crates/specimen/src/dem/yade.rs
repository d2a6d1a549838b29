//! The Yade deck: the clump spheres and the bodies' union masses as text tables, and the
//! settle script `settle.py`.

use std::fmt::Write as _;

use packer_spheres::Container;

use super::{DemSpecimen, FRACTION_TOLERANCE, OVERLAP_LIMIT, Plan, not_walled};
use crate::error::Result;

/// Yade: `yade/clumps.txt` (`x y z r body`, world frame, metres; body k + 1 = line k + 1 of
/// `../poses.csv`), `yade/masses.txt` (the union's mass of each body, for comparison) and
/// `yade/settle.py` (run from this folder: `yade -n -x settle.py`).
///
/// # Errors
/// As [`DemSpecimen::plan`].
pub fn yade_files(s: &DemSpecimen) -> Result<Vec<(String, Vec<u8>)>> {
    let p = s.plan()?;
    let (spheres, masses) = tables(s);
    let deck = settle_deck(s, &p)?;
    Ok(vec![
        ("yade/clumps.txt".into(), spheres.into_bytes()),
        ("yade/masses.txt".into(), masses.into_bytes()),
        ("yade/settle.py".into(), deck.into_bytes()),
    ])
}

/// `clumps.txt` (every sphere with its body) and `masses.txt` (each body's union mass).
fn tables(s: &DemSpecimen) -> (String, String) {
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
    (spheres, masses)
}

/// The facets of the container's walls (`walls = geom.facet…`).
fn walls_facets(c: &Container) -> Result<String> {
    Ok(match c {
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
        _ => return Err(not_walled()),
    })
}

/// `settle.py`: the preamble, then the bodies, the helper functions and engines, and the
/// settling with its checks.
fn settle_deck(s: &DemSpecimen, p: &Plan) -> Result<String> {
    let walls = walls_facets(s.container)?;
    let mut deck = s.preamble(
        p,
        "#",
        "Yade",
        "../shared/tools/yade-run yade/settle.py   (or: yade -n -x settle.py)",
    );
    deck_bodies(&mut deck, s, &walls);
    deck_engines(&mut deck, s, p);
    deck_settle(&mut deck, p);
    Ok(deck)
}

/// The script's material, walls and bodies: the clumps read from `clumps.txt` and made by
/// `appendClumped` (the grid of its integration: cells across the smallest sphere's
/// diameter), their masses against the union's of `masses.txt`.
fn deck_bodies(deck: &mut String, s: &DemSpecimen, walls: &str) {
    let m = s.material;
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
"#,
        es = m.youngs(),
        nu = m.poisson_ratio,
        mu = m.friction,
        rho = m.density,
    );
}

/// The script's functions (bed fraction, dumps, largest overlap), engines and step.
fn deck_engines(deck: &mut String, s: &DemSpecimen, p: &Plan) {
    let m = s.material;
    let _ = write!(
        deck,
        r#"
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
"#,
        vol = p.volume,
        area = p.area,
        floor = p.floor,
        skin = 0.1 * p.d50,
        rest = m.restitution,
        g = m.gravity,
        dt = p.dt,
    );
}

/// The settling in runs of [`Plan::chunk`] steps until the energy is down, the dumps, the
/// report lines and `SystemExit(1)` on a failure.
fn deck_settle(deck: &mut String, p: &Plan) {
    let _ = write!(
        deck,
        r#"phi0 = {pf:.10}
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
}
