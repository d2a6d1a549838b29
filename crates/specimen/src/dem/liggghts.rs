//! The LIGGGHTS 3.8 deck: one sphere file per multisphere template and the settle deck
//! `in.settle` (particle templates, one insertion per body at its packed pose, walls,
//! settling and checks).

use std::fmt::Write as _;

use packer_spheres::Container;

use super::{DemSpecimen, FRACTION_TOLERANCE, OVERLAP_LIMIT, Plan, geometry, not_walled};
use crate::error::Result;

/// LIGGGHTS: one `liggghts/template-T.txt` per template used (`x y z r` relative to the
/// union's centroid, template frame, metres) and `liggghts/in.settle`: one
/// `particletemplate/multisphere` per template (several bodies share one) with the union's
/// mass, volume and inertia tensor, one `particledistribution/discrete/numberbased` of it,
/// and per body an `insert/pack` of one particle in a tiny sphere around its centre of mass
/// with `orientation constant` its pose's quaternion, so every body starts at its packed
/// pose. A one-sphere template is a `particletemplate/sphere` (multisphere templates need
/// two spheres) integrated by `nve/sphere`.
///
/// The templates are defined and their bodies inserted in batches of at most
/// [`LIGGGHTS_BATCH`] templates: each batch's fixes, one step that inserts its bodies,
/// then its insertion, distribution and template fixes removed (the bodies keep their
/// mass, inertia and spheres). LIGGGHTS 3.8's set-up of `particletemplate/multisphere`
/// (`FixTemplateMultisphere::init`, run for every template at every `run`) checks every
/// pair of templates for distinct types with a scan of all fixes per look-up: T³·F work
/// for T templates and F fixes, so 2,000 templates defined at once had not started after
/// 70 min; in batches of 100 they start in seconds. Multisphere types are consecutive from
/// 1 within a batch (LIGGGHTS requires it of the templates defined at one time). Bodies
/// are inserted batch by batch, so LIGGGHTS numbers them in that order (the body order
/// when every template fits one batch).
///
/// # Errors
/// As [`DemSpecimen::plan`].
pub fn liggghts_files(s: &DemSpecimen) -> Result<Vec<(String, Vec<u8>)>> {
    let p = s.plan()?;
    let mut used = vec![0usize; s.templates.len()];
    for b in s.bodies {
        used[b.template] += 1;
    }
    // batch of each used template: its rank among the used ones over the batch size
    let mut batch_of = vec![usize::MAX; s.templates.len()];
    for (rank, k) in (0..s.templates.len()).filter(|&k| used[k] > 0).enumerate() {
        batch_of[k] = rank / LIGGGHTS_BATCH;
    }
    let mut batches = vec![Batch::default(); liggghts_batches(s)];
    let mut seeds = Seeds(primes(3 * s.templates.len() + s.bodies.len() + 1).into_iter());
    let mut files = templates(s, &used, &batch_of, &mut batches, &mut seeds);
    inserts(s, &p, &batch_of, &mut batches, &mut seeds);
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
    let parts = Parts {
        batches,
        walls: wall_fixes(s.container)?,
        bounds: geometry(s.container)?.2,
        singles,
        multi,
    };
    let deck = settle_deck(s, &p, &parts);
    files.push(("liggghts/in.settle".into(), deck.into_bytes()));
    Ok(files)
}

/// Most templates the LIGGGHTS deck defines at one time (see [`liggghts_files`]).
pub const LIGGGHTS_BATCH: usize = 100;

/// The insertion batches of the LIGGGHTS deck of `s`: its templates used by a body, in
/// batches of [`LIGGGHTS_BATCH`].
pub fn liggghts_batches(s: &DemSpecimen) -> usize {
    let mut used = vec![false; s.templates.len()];
    for b in s.bodies {
        if let Some(u) = used.get_mut(b.template) {
            *u = true;
        }
    }
    used.iter().filter(|u| **u).count().div_ceil(LIGGGHTS_BATCH)
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

/// The seeds of the deck's fixes, handed out in the deck's order.
struct Seeds(std::vec::IntoIter<u64>);

impl Seeds {
    /// The next seed (the first prime above 10⁵ if they ran out).
    fn next(&mut self) -> u64 {
        self.0.next().unwrap_or(100_003)
    }
}

/// One insertion batch of the deck.
#[derive(Clone, Default)]
struct Batch {
    /// Its template and distribution fixes.
    define: String,
    /// Its insertion regions and fixes.
    insert: String,
    /// The `unfix` lines of its insertions.
    unfix_inserts: String,
    /// The `unfix` lines of its distributions and templates.
    unfix_templates: String,
}

/// The sphere files of the multisphere templates used (`liggghts/template-T.txt`) and the
/// deck's template and distribution fixes of every template used, per batch.
fn templates(
    s: &DemSpecimen,
    used: &[usize],
    batch_of: &[usize],
    batches: &mut [Batch],
    seeds: &mut Seeds,
) -> Vec<(String, Vec<u8>)> {
    let m = s.material;
    let mut files = Vec::new();
    let mut ms_types = vec![0usize; batches.len()];
    for (k, t) in s.templates.iter().enumerate() {
        if used[k] == 0 {
            continue;
        }
        let k1 = k + 1;
        let batch = batch_of[k];
        let _ = writeln!(
            batches[batch].unfix_templates,
            "unfix           pdd{k1}\nunfix           pts{k1}"
        );
        let tpl = &mut batches[batch].define;
        if t.spheres.len() == 1 {
            let _ = writeln!(
                tpl,
                "fix             pts{k1} all particletemplate/sphere {} atom_type 1 volume_limit 1e-30 density constant {:e} radius constant {:e}",
                seeds.next(),
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
            // multisphere types are consecutive from 1 within a batch
            ms_types[batch] += 1;
            let ms_type = ms_types[batch];
            let i = t.inertia * m.density;
            let _ = writeln!(
                tpl,
                "fix             pts{k1} all particletemplate/multisphere {} atom_type 1 volume_limit 1e-30 density constant {:e} nspheres {} ntry 100000 spheres file {name} scale 1.0 type {ms_type} mass {:e} use_density inertia_tensor {:e} {:e} {:e} {:e} {:e} {:e}",
                seeds.next(),
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
            seeds.next()
        );
    }
    files
}

/// One `insert/pack` per body of one particle in a tiny sphere around its centre of mass at
/// its packed orientation, and the `unfix` lines of the insertions, per batch of its
/// template.
fn inserts(
    s: &DemSpecimen,
    p: &Plan,
    batch_of: &[usize],
    batches: &mut [Batch],
    seeds: &mut Seeds,
) {
    let tiny = 1e-6 * p.d50;
    for (k, b) in s.bodies.iter().enumerate() {
        let t = &s.templates[b.template];
        let k1 = k + 1;
        let batch = &mut batches[batch_of[b.template]];
        let c = b.pose * t.centroid;
        let q = b.pose.rotation.quaternion();
        let group = if t.spheres.len() == 1 {
            "singles"
        } else {
            "all"
        };
        let _ = writeln!(
            batch.insert,
            "region          r{k1} sphere {:e} {:e} {:e} {tiny:e} units box volume_limit 1e-30\n\
             fix             ins{k1} {group} insert/pack seed {} distributiontemplate pdd{} insert_every once overlapcheck no orientation constant {:.15} {:.15} {:.15} {:.15} region r{k1} particles_in_region 1",
            c.x,
            c.y,
            c.z,
            seeds.next(),
            b.template + 1,
            q.w,
            q.i,
            q.j,
            q.k
        );
        let _ = writeln!(batch.unfix_inserts, "unfix           ins{k1}");
    }
}

/// The `wall/gran` fixes of the container's walls.
fn wall_fixes(c: &Container) -> Result<String> {
    Ok(match c {
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
        _ => return Err(not_walled()),
    })
}

/// The pieces of the deck made before it.
struct Parts {
    /// The insertion batches.
    batches: Vec<Batch>,
    /// Wall fixes.
    walls: String,
    /// The simulation box.
    bounds: [[f64; 2]; 3],
    /// A one-sphere template is used.
    singles: bool,
    /// A multisphere template is used.
    multi: bool,
}

/// `in.settle`: the preamble, then the set-up, the insertion, the settling and the checks.
fn settle_deck(s: &DemSpecimen, p: &Plan, parts: &Parts) -> String {
    let mut deck = s.preamble(
        p,
        "#",
        "LIGGGHTS 3.8",
        "../shared/tools/liggghts-run liggghts/in.settle   (or: liggghts -in in.settle)",
    );
    deck_setup(&mut deck, s, p, parts);
    deck_insert(&mut deck, parts);
    deck_settle(&mut deck, p, parts);
    deck_checks(&mut deck, p);
    deck
}

/// The deck's set-up: box, contacts, step, walls, gravity, the overlap compute.
fn deck_setup(deck: &mut String, s: &DemSpecimen, p: &Plan, parts: &Parts) {
    let m = s.material;
    let b = parts.bounds;
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
"#,
        b[0][0],
        b[0][1],
        b[1][0],
        b[1][1],
        b[2][0],
        b[2][1],
        tiny = 1e-6 * p.d50,
        skin = 0.1 * p.d50,
        es = m.youngs(),
        nu = m.poisson_ratio,
        rest = m.restitution,
        mu = m.friction,
        dt = p.dt,
        walls = parts.walls,
        g = m.gravity,
    );
}

/// The integrators, then per batch: the templates, the insertions, one step that inserts,
/// and the unfixes.
fn deck_insert(deck: &mut String, parts: &Parts) {
    let ms = if parts.multi {
        "fix             ms all multisphere\n"
    } else {
        ""
    };
    let nve = if parts.singles {
        "fix             integr singles nve/sphere\n"
    } else {
        ""
    };
    let n = parts.batches.len();
    let _ = write!(deck, "{ms}{nve}");
    for (b, batch) in parts.batches.iter().enumerate() {
        let _ = write!(
            deck,
            "# insertion batch {} of {n}\n{}{}run             1\n{}{}",
            b + 1,
            batch.define,
            batch.insert,
            batch.unfix_inserts,
            batch.unfix_templates,
        );
    }
}

/// The kinetic energy `ke` of the bodies: multisphere bodies, one-sphere bodies or both.
fn ke_computes(multi: bool, singles: bool) -> &'static str {
    match (multi, singles) {
        (true, false) => {
            "compute         ket all ke/multisphere\ncompute         ker all erotate/multisphere\nvariable        ke equal c_ket+c_ker\n"
        }
        (true, true) => {
            "compute         ket all ke/multisphere\ncompute         ker all erotate/multisphere\ncompute         kes singles ke\ncompute         kers singles erotate/sphere\nvariable        ke equal c_ket+c_ker+c_kes+c_kers\n"
        }
        _ => {
            "compute         ket all ke\ncompute         ker all erotate/sphere\nvariable        ke equal c_ket+c_ker\n"
        }
    }
}

/// The bed fraction and energy variables, the initial bed fraction and the settling in runs
/// of [`Plan::chunk`] steps until the energy is down.
fn deck_settle(deck: &mut String, p: &Plan, parts: &Parts) {
    let _ = write!(
        deck,
        r#"compute         zs all reduce ave z
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
"#,
        vol = p.volume,
        area = p.area,
        floor = p.floor,
        ke_computes = ke_computes(parts.multi, parts.singles),
        chunk = p.chunk,
        pf = p.packed_fraction,
        ke = p.ke_limit,
        min = p.min_steps,
        chunks = p.chunks(),
    );
}

/// The checks: one step that outputs the computes, the restart, the report lines and a jump
/// to a missing label (an `ERROR`) on a failure.
fn deck_checks(deck: &mut String, p: &Plan) {
    let _ = write!(
        deck,
        r#"# computes are current only on output steps: one more step that outputs them all
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
        atoms = p.atoms,
        n = p.n,
        pf = p.packed_fraction,
        max = p.max_steps,
        ovl = OVERLAP_LIMIT,
        ovm = OVERLAP_LIMIT * p.d50,
        ft = FRACTION_TOLERANCE,
    );
}
