//! Unit tests of the DEM decks: file contents, the time step, one-sphere templates, union mass.
use super::*;
use approx::assert_relative_eq;
use nalgebra::Vector3;

/// A template of `spheres` with its union properties from `levelset`.
fn template(spheres: Vec<(Point3<f64>, f64)>) -> Template {
    let h = spheres.iter().map(|s| s.1).fold(f64::INFINITY, f64::min) / 20.0;
    let u = levelset::union_mass_properties(&spheres, h).expect("union");
    Template {
        spheres,
        volume: u.volume,
        centroid: u.centroid,
        inertia: u.inertia,
    }
}

fn pair() -> Template {
    let r = 1e-4;
    template(vec![
        (Point3::new(-0.5 * r, 0.0, 0.0), r),
        (Point3::new(0.5 * r, 0.0, 0.0), r),
    ])
}

fn one() -> Template {
    template(vec![(Point3::new(1e-5, 0.0, 0.0), 1e-4)])
}

fn cylinder() -> Container {
    Container::Cylinder {
        base: Point3::origin(),
        radius: 1e-3,
        height: 2e-3,
    }
}

fn bodies(templates: usize, n: usize) -> Vec<Body> {
    (0..n)
        .map(|k| Body {
            id: k as u64,
            template: k % templates,
            pose: Isometry3::new(
                Vector3::new(0.0, 0.0, 2e-4 + 3e-4 * k as f64),
                Vector3::new(0.1 * k as f64, 0.2, 0.0),
            ),
        })
        .collect()
}

type Writer = fn(&DemSpecimen) -> crate::Result<Vec<(String, Vec<u8>)>>;

fn files(f: Writer, templates: &[Template], container: &Container) -> Vec<(String, String)> {
    let b = bodies(templates.len(), 4);
    let material = Material::default();
    let prov = vec!["grainforge test".to_owned()];
    let s = DemSpecimen {
        templates,
        bodies: &b,
        container,
        material: &material,
        provenance: &prov,
    };
    f(&s)
        .expect("files")
        .into_iter()
        .map(|(p, b)| (p, String::from_utf8(b).expect("utf-8")))
        .collect()
}

fn get<'a>(files: &'a [(String, String)], name: &str) -> &'a str {
    &files
        .iter()
        .find(|f| f.0 == name)
        .unwrap_or_else(|| panic!("no {name}"))
        .1
}

#[test]
fn union_of_two_overlapping_spheres_is_less_than_their_sum() {
    // two unit-ish spheres at half a radius apart: union = 2 V − lens
    let t = pair();
    let r: f64 = 1e-4;
    let d = r; // centre distance
    let lens = PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
    assert_relative_eq!(
        t.volume,
        2.0 * 4.0 / 3.0 * PI * r.powi(3) - lens,
        max_relative = 3e-3
    );
    // the lens is 15.6 % of a sphere: the sum over-counts by 18 %
    assert!(summed_volume(&t) / t.volume > 1.15);
    assert_relative_eq!(centroid_offset(&t).norm(), 0.0, epsilon = 1e-3 * r);
    // the body mass the decks give is the union's
    let b = bodies(1, 1);
    let mat = Material::default();
    let s = DemSpecimen {
        templates: std::slice::from_ref(&t),
        bodies: &b,
        container: &cylinder(),
        material: &mat,
        provenance: &[],
    };
    assert_relative_eq!(
        s.mass(&b[0]).0,
        t.volume * mat.density,
        max_relative = 1e-12
    );
}

#[test]
fn hertz_time_step_matches_the_closed_form() {
    // m* = 1 kg, R* = 1 m, E* = 1 Pa, v = 1 m/s: t = 2.87
    assert_relative_eq!(
        hertz_contact_time(1.0, 1.0, 1.0, 1.0),
        2.87,
        max_relative = 1e-12
    );
    // scaling: t ∝ m*^0.4 R*^-0.2 E*^-0.4 v^-0.2
    let t = hertz_contact_time(32.0, 1.0, 1.0, 1.0);
    assert_relative_eq!(t, 2.87 * 4.0, max_relative = 1e-12);
    let t = hertz_contact_time(1.0, 32.0, 1.0, 32.0);
    assert_relative_eq!(t, 2.87 / 4.0, max_relative = 1e-12);
    // the plan's step is t_H / STEPS_PER_CONTACT of the lightest clump at the smallest sphere
    let t = [pair()];
    let b = bodies(1, 3);
    let mat = Material::default();
    let s = DemSpecimen {
        templates: &t,
        bodies: &b,
        container: &cylinder(),
        material: &mat,
        provenance: &[],
    };
    let p = s.plan().expect("plan");
    let d = (6.0 * t[0].volume / PI).cbrt();
    let m = mat.density * PI / 6.0 * d.powi(3);
    let e = mat.youngs() / (2.0 * (1.0 - 0.04));
    let th = hertz_contact_time(0.5 * m, 0.5e-4, e, (2.0 * 9.81 * d).sqrt());
    assert_relative_eq!(p.dt, th / STEPS_PER_CONTACT, max_relative = 1e-12);
    assert_relative_eq!(p.ke_limit, 1e-6 * 3.0 * m * 9.81 * d, max_relative = 1e-9);
    assert!(p.min_steps >= p.chunk && p.max_steps > p.min_steps);
    // quartz at E/100: a few 1e-7 s for 0.2 mm sand (Rayleigh of the sphere is shorter)
    assert!(p.dt > 1e-8 && p.dt < 1e-5, "dt {}", p.dt);
}

#[test]
fn packed_fraction_of_a_uniform_bed() {
    // one sphere per body stacked in a column: zbar = mean height
    let t = [one()];
    let b = bodies(1, 4);
    let mat = Material::default();
    let c = cylinder();
    let s = DemSpecimen {
        templates: &t,
        bodies: &b,
        container: &c,
        material: &mat,
        provenance: &[],
    };
    let p = s.plan().expect("plan");
    let zbar = b
        .iter()
        .map(|b| (b.pose * t[0].spheres[0].0).z)
        .sum::<f64>()
        / 4.0;
    assert_relative_eq!(
        p.packed_fraction,
        4.0 * t[0].volume / (PI * 1e-6 * 2.0 * zbar),
        max_relative = 1e-12
    );
}

#[test]
fn lammps_files_parse() {
    let f = files(lammps_files, &[pair(), one()], &cylinder());
    let data = get(&f, "lammps/clumps.data");
    assert!(data.contains("6 atoms"));
    let atoms: Vec<&str> = data
        .split("Atoms # sphere\n\n")
        .nth(1)
        .expect("atoms")
        .lines()
        .filter(|l| !l.trim().is_empty())
        .collect();
    assert_eq!(atoms.len(), 6);
    for l in &atoms {
        assert_eq!(l.split_whitespace().count(), 7, "{l}");
    }
    assert!(!data.contains("Molecules"));
    // clumps.body: the atom count, then `atom-id body` for every atom
    let body = get(&f, "lammps/clumps.body");
    let mols: Vec<&str> = body.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(mols[0], "6");
    assert_eq!(mols.len(), 7);
    assert_eq!(mols[1], "1 1");
    let rigid = get(&f, "lammps/bodies.rigid");
    let rows: Vec<Vec<f64>> = rigid
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            l.split_whitespace()
                .map(|v| v.parse().expect("number"))
                .collect()
        })
        .collect();
    assert_eq!(rigid.lines().find(|l| !l.starts_with('#')), Some("4"));
    assert_eq!(rows.len(), 4);
    for r in &rows {
        assert_eq!(r.len(), 20);
        // the union's mass, not the spheres' sum
        assert!(r[1] > 0.0);
    }
    let deck = get(&f, "lammps/in.settle");
    for key in [
        "read_data       clumps.data\nvariable        body atomfile clumps.body",
        "exclude molecule/intra all",
        "rigid/small molecule infile bodies.rigid gravity grav",
        "wall/gran/region granular hertz/material",
        "region          walls cylinder z",
        "write_restart",
        "quit 1",
        "grainforge test",
    ] {
        assert!(deck.contains(key), "no `{key}`");
    }
    // every line is a comment, blank or a command word followed by arguments
    for l in deck.lines() {
        assert!(
            l.is_empty()
                || l.starts_with('#')
                || l.chars().next().is_some_and(|c| c.is_ascii_lowercase()),
            "{l}"
        );
    }
    // braces of the Rust format are all substituted
    assert!(!deck.contains("{{") && !deck.contains("}}"));
}

/// `write_lammps_clump_data` writes the very bytes of `lammps/clumps.data` (box and cylinder,
/// one-sphere and multisphere bodies), to a `Vec<u8>` or through a `&mut` writer.
#[test]
fn clump_data_writer_matches_lammps_files() {
    let bx = Container::Box {
        min: Point3::new(-1e-3, -1e-3, 0.0),
        max: Point3::new(1e-3, 1e-3, 2e-3),
        periodic: [false, false],
    };
    for container in [cylinder(), bx] {
        let t = [pair(), one()];
        let b = bodies(t.len(), 5);
        let material = Material::default();
        let prov = vec!["grainforge test".to_owned()];
        let s = DemSpecimen {
            templates: &t,
            bodies: &b,
            container: &container,
            material: &material,
            provenance: &prov,
        };
        let files = lammps_files(&s).expect("files");
        let expected = &files
            .iter()
            .find(|f| f.0 == "lammps/clumps.data")
            .expect("clumps.data")
            .1;
        let mut data = Vec::new();
        write_lammps_clump_data(&s, &mut data).expect("write");
        assert_eq!(&data, expected);
        let mut cursor = std::io::Cursor::new(Vec::new());
        write_lammps_clump_data(&s, &mut cursor).expect("write");
        assert_eq!(&cursor.into_inner(), expected);
    }
    // refused like lammps_files
    let s = DemSpecimen {
        templates: &[pair()],
        bodies: &[],
        container: &cylinder(),
        material: &Material::default(),
        provenance: &[],
    };
    assert!(write_lammps_clump_data(&s, Vec::new()).is_err());
}

#[test]
fn yade_files_parse() {
    let f = files(yade_files, &[pair(), one()], &cylinder());
    let spheres = get(&f, "yade/clumps.txt");
    let rows: Vec<&str> = spheres.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows.len(), 6);
    assert!(rows.iter().all(|l| l.split_whitespace().count() == 5));
    let deck = get(&f, "yade/settle.py");
    assert!(deck.contains("discretization=DISCRETIZATION"));
    assert!(deck.contains("raise SystemExit(1)"));
    assert!(deck.contains("O.save('settled.yade.gz')"));
    // the files are read from the current folder, never through __file__
    assert!(
        deck.lines()
            .all(|l| l.starts_with('#') || !l.contains("__file__"))
    );
    assert!(deck.contains("open('clumps.txt')"));
    // a one-sphere body is a plain sphere
    assert!(deck.contains("if len(ss) == 1:"));
}

#[test]
fn liggghts_reuses_templates_and_takes_one_sphere_templates() {
    let f = files(liggghts_files, &[pair(), one()], &cylinder());
    let deck = get(&f, "liggghts/in.settle");
    // 2 templates for 4 bodies: one multisphere, one sphere
    assert_eq!(deck.matches("particletemplate/multisphere").count(), 1);
    assert_eq!(deck.matches("particletemplate/sphere").count(), 1);
    assert_eq!(
        deck.matches("particledistribution/discrete/numberbased")
            .count(),
        2
    );
    assert_eq!(deck.matches(" insert/pack seed").count(), 4);
    assert_eq!(
        deck.matches("overlapcheck no orientation constant").count(),
        4
    );
    assert!(deck.contains("fix             integr singles nve/sphere"));
    assert!(deck.contains("fix             ms all multisphere"));
    // template spheres relative to the union centroid
    let t = pair();
    let text = get(&f, "liggghts/template-000001.txt");
    let first: Vec<f64> = text
        .lines()
        .next()
        .expect("line")
        .split_whitespace()
        .map(|v| v.parse().expect("number"))
        .collect();
    assert_relative_eq!(
        first[0],
        t.spheres[0].0.x - t.centroid.x,
        max_relative = 1e-12
    );
    // seeds (the word after these keywords) are distinct primes above 1e4
    let mut seeds = Vec::new();
    for l in deck.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        for (k, word) in w.iter().enumerate() {
            if matches!(
                *word,
                "particletemplate/multisphere"
                    | "particletemplate/sphere"
                    | "particledistribution/discrete/numberbased"
                    | "seed"
            ) {
                seeds.push(w[k + 1].parse::<u64>().expect("seed"));
            }
        }
    }
    assert_eq!(seeds.len(), 2 + 2 + 4);
    for v in &seeds {
        assert!(
            *v > 10_000
                && (2..)
                    .take_while(|d| d * d <= *v)
                    .all(|d| !v.is_multiple_of(d)),
            "{v}"
        );
    }
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), 8);
    assert!(!deck.contains("{{") && !deck.contains("}}"));
}

#[test]
fn refuses_bad_input() {
    let t = [pair()];
    let mat = Material::default();
    let periodic = Container::Box {
        min: Point3::origin(),
        max: Point3::new(1e-3, 1e-3, 1e-3),
        periodic: [true, false],
    };
    let b = bodies(1, 2);
    let s = DemSpecimen {
        templates: &t,
        bodies: &b,
        container: &periodic,
        material: &mat,
        provenance: &[],
    };
    assert!(lammps_files(&s).is_err());
    let s = DemSpecimen {
        templates: &t,
        bodies: &[],
        container: &cylinder(),
        material: &mat,
        provenance: &[],
    };
    assert!(yade_files(&s).is_err());
    let soft = Material {
        stiffness_scale: 1000.0,
        ..Material::default()
    };
    let s = DemSpecimen {
        templates: &t,
        bodies: &b,
        container: &cylinder(),
        material: &soft,
        provenance: &[],
    };
    assert!(liggghts_files(&s).is_err());
}

/// Walks a LIGGGHTS deck's fixes: every `unfix` names a fix alive, every insertion's
/// distribution is alive, and the multisphere templates alive at each `run` have types
/// 1..n (LIGGGHTS' check) with n ≤ the batch size. Returns the number of insertion
/// steps and the bodies inserted.
fn walk_liggghts_deck(deck: &str) -> (usize, usize) {
    use std::collections::BTreeMap;
    let mut alive: BTreeMap<String, Option<usize>> = BTreeMap::new();
    let (mut steps, mut inserted) = (0, 0);
    for l in deck.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.first() {
            Some(&"fix") => {
                let ms_type = w
                    .iter()
                    .position(|x| *x == "type")
                    .filter(|_| l.contains("particletemplate/multisphere"))
                    .map(|i| w[i + 1].parse::<usize>().expect("type"));
                if let Some(i) = w.iter().position(|x| *x == "distributiontemplate") {
                    assert!(alive.contains_key(w[i + 1]), "{l}: distribution not alive");
                    inserted += 1;
                }
                assert!(
                    alive.insert(w[1].to_owned(), ms_type).is_none(),
                    "{l}: twice"
                );
            }
            Some(&"unfix") => {
                assert!(alive.remove(w[1]).is_some(), "{l}: not alive");
            }
            Some(&"run") if w[1] == "1" => {
                steps += 1;
                let mut types: Vec<usize> = alive.values().flatten().copied().collect();
                types.sort_unstable();
                assert!(
                    types.len() <= LIGGGHTS_BATCH,
                    "{} templates alive",
                    types.len()
                );
                assert_eq!(types, (1..=types.len()).collect::<Vec<_>>());
            }
            _ => {}
        }
    }
    assert!(
        alive
            .keys()
            .all(|k| !k.starts_with("pts") && !k.starts_with("pdd") && !k.starts_with("ins")),
        "template, distribution or insertion fixes left: {alive:?}"
    );
    (steps, inserted)
}

#[test]
fn liggghts_defines_templates_in_batches() {
    // 250 distinct two-sphere templates and a one-sphere one, 260 bodies
    let mut templates: Vec<Template> = (0..250)
        .map(|k| {
            let r = 1e-4 * (1.0 + 1e-3 * k as f64);
            template(vec![
                (Point3::new(-0.5 * r, 0.0, 0.0), r),
                (Point3::new(0.5 * r, 0.0, 0.0), r),
            ])
        })
        .collect();
    templates.push(one());
    let b = bodies(templates.len(), 260);
    let material = Material::default();
    let prov = vec!["grainforge test".to_owned()];
    let container = Container::Cylinder {
        base: Point3::origin(),
        radius: 5e-3,
        height: 0.1,
    };
    let s = DemSpecimen {
        templates: &templates,
        bodies: &b,
        container: &container,
        material: &material,
        provenance: &prov,
    };
    let f: Vec<(String, String)> = liggghts_files(&s)
        .expect("files")
        .into_iter()
        .map(|(p, b)| (p, String::from_utf8(b).expect("utf-8")))
        .collect();
    let deck = get(&f, "liggghts/in.settle");
    let (steps, inserted) = walk_liggghts_deck(deck);
    assert_eq!(steps, 3, "251 templates in batches of {LIGGGHTS_BATCH}");
    assert_eq!(liggghts_batches(&s), steps);
    assert_eq!(inserted, 260);
    assert_eq!(deck.matches("particletemplate/multisphere").count(), 250);
    // one batch: the bodies inserted in the body order, one step
    let small = files(liggghts_files, &[pair(), one()], &cylinder());
    assert_eq!(
        walk_liggghts_deck(get(&small, "liggghts/in.settle")),
        (1, 4)
    );
}
