//! Tests of `cargo xtask specimen`: each output flag changes only its own
//! files, a clumps-only scene skips the level-set output stage, and bad
//! input is an error naming the key or file with nothing left in `out_dir`.
//!
//! Small and fast: 20 clones of a cheap configuration (the calibrated
//! Ottawa one with a 25³ level set, 16 pilot clones and no level-set
//! roundness check) at a 21³ output resolution.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use super::scene::Scene;
use super::{StageReport, run_scene};

fn root() -> PathBuf {
    crate::workspace_root()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grainforge-specimen-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// A cheap calibrated configuration in `dir` (test speed only).
fn cheap_config(dir: &Path) -> PathBuf {
    let path = root().join("fixtures/calibrated/gsc2-ottawa.ron");
    let text = std::fs::read_to_string(path).expect("calibrated fixture");
    let mut cal = cloner::Calibrated::from_ron(&text).expect("parses");
    cal.params.level_set_resolution = 25;
    cal.params.pilot_clones = 16;
    cal.params.roundness_tolerance = None;
    cal.params.roundness_repairs = 0;
    cal.params.roundness_predictions = 0;
    let p = dir.join("cheap.ron");
    std::fs::write(&p, cal.to_ron().expect("ron")).expect("write config");
    p
}

/// A scene of 20 cheap clones with the given outputs (RON fragment).
fn scene_text(config: &Path, out_dir: &Path, container: &str, outputs: &str) -> String {
    format!(
        r#"Scene(
    calibrated: Some("{}"),
    clones: Count(20),
    seed: Some(3),
    container: {container},
    allow_narrow_container: true,
    level_set_resolution: 21,
    outputs: ({outputs}),
    out_dir: "{}",
)"#,
        config.display(),
        out_dir.display()
    )
}

fn run(text: &str) -> anyhow::Result<StageReport> {
    let scene = Scene::parse(text, Path::new("test.ron"))?;
    run_scene(&scene, &root(), true)
}

fn files_under(dir: &Path) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if let Ok(rel) = p.strip_prefix(dir) {
                out.insert(rel.to_string_lossy().into_owned());
            }
        }
    }
    out
}

const AUTO: &str = "AutoCylinder(solid_fraction: 0.3)";

#[test]
fn each_output_flag_changes_only_its_own_files() {
    let dir = tmp("flags");
    let config = cheap_config(&dir);
    let base_dir = dir.join("base");
    let base = run(&scene_text(&config, &base_dir, AUTO, "")).expect("base scene");
    let base_files = files_under(&base_dir);
    assert_eq!(
        base_files,
        ["PROVENANCE.txt", "poses.csv", "report.txt"]
            .map(String::from)
            .into(),
        "{base_files:?}"
    );
    assert_eq!(base.files.len(), 3);
    let prov = std::fs::read_to_string(base_dir.join("PROVENANCE.txt")).expect("provenance");
    assert!(
        prov.contains("grainforge")
            && prov.contains("seed 3")
            && prov.contains("clones: Count(20)")
    );
    // flag → the files it must add (every other file unchanged)
    type Owns = fn(&str) -> bool;
    let cases: [(&str, Owns); 6] = [
        ("lsdem: true", |f| f.starts_with("lsdem/")),
        ("lammps_clumps: true", |f| f.starts_with("lammps/")),
        ("liggghts_templates: true", |f| f.starts_with("liggghts/")),
        ("yade_clumps: true", |f| f.starts_with("yade/")),
        ("vtu: true", |f| f == "specimen.vtu"),
        ("report: true", |f| {
            f == "report.md" || f.starts_with("plots/")
        }),
    ];
    let base_poses = std::fs::read_to_string(base_dir.join("poses.csv")).expect("poses");
    for (k, (flag, own)) in cases.iter().enumerate() {
        let d = dir.join(format!("flag-{k}"));
        run(&scene_text(&config, &d, AUTO, flag)).unwrap_or_else(|e| panic!("{flag}: {e:#}"));
        let files = files_under(&d);
        let added: BTreeSet<&String> = files.difference(&base_files).collect();
        let removed: Vec<&String> = base_files.difference(&files).collect();
        assert!(removed.is_empty(), "{flag} removed {removed:?}");
        assert!(!added.is_empty(), "{flag} added nothing");
        for f in &added {
            assert!(own(f), "{flag} wrote {f}, not its own file");
        }
        // the placement does not depend on the outputs
        let poses = std::fs::read_to_string(d.join("poses.csv")).expect("poses");
        let rows = |t: &str| -> Vec<String> {
            t.lines()
                .filter(|l| !l.starts_with('#'))
                .map(String::from)
                .collect()
        };
        assert_eq!(rows(&poses), rows(&base_poses), "{flag} changed poses.csv");
    }
    // specific contents
    let lsdem = files_under(&dir.join("flag-0"));
    assert_eq!(
        lsdem
            .iter()
            .filter(|f| f.starts_with("lsdem/Morphologies/morph_"))
            .count(),
        20,
        "one morph file per grain"
    );
    // one grid unit for every morph file
    let poses = std::fs::read_to_string(dir.join("flag-0/lsdem/poses.txt")).expect("poses");
    let spacings: BTreeSet<String> = poses
        .lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| l.split_whitespace().last().map(String::from))
        .collect();
    assert_eq!(spacings.len(), 1, "{spacings:?}");
    // LAMMPS: one rigid-body line per grain (the union's mass > 0), a body file
    // naming a body for every atom, and the deck
    let rigid = std::fs::read_to_string(dir.join("flag-1/lammps/bodies.rigid")).expect("rigid");
    let lines: Vec<&str> = rigid.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(lines[0].trim(), "20");
    assert_eq!(lines.len(), 21);
    for l in &lines[1..] {
        let v: Vec<f64> = l
            .split_whitespace()
            .map(|x| x.parse().expect("number"))
            .collect();
        assert_eq!(v.len(), 20);
        assert!(v[1] > 0.0 && v[5] > 0.0 && v[6] > 0.0 && v[7] > 0.0, "{l}");
    }
    let data = std::fs::read_to_string(dir.join("flag-1/lammps/clumps.data")).expect("data");
    let atoms: usize = data
        .lines()
        .find(|l| l.ends_with(" atoms"))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .expect("atom count");
    let body = std::fs::read_to_string(dir.join("flag-1/lammps/clumps.body")).expect("body");
    let rows: Vec<&str> = body.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows[0].trim().parse::<usize>().expect("count"), atoms);
    assert_eq!(rows.len(), atoms + 1);
    let deck = std::fs::read_to_string(dir.join("flag-1/lammps/in.settle")).expect("deck");
    assert!(deck.contains("set             group all mol v_body"));
    let vtu = std::fs::read_to_string(dir.join("flag-4/specimen.vtu")).expect("vtu");
    assert!(vtu.contains("grain_id") && vtu.trim_end().ends_with("</VTKFile>"));
    assert!(vtu.contains(r#"header_type="UInt64""#) && !vtu.contains(r#"format="ascii""#));
    vtu_reads_back(&vtu, 20);
    lsdem_folder_reads_as_lsdem(&dir.join("flag-0/lsdem"), 20);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_clumps_only_scene_skips_the_level_set_outputs() {
    let dir = tmp("clumps");
    let config = cheap_config(&dir);
    let out = dir.join("out");
    let r = run(&scene_text(
        &config,
        &out,
        AUTO,
        "lammps_clumps: true, clump: (spheres_per_clump: 10)",
    ))
    .expect("clumps scene");
    let lsdem = r.stage("lsdem").expect("lsdem stage listed");
    assert!(lsdem.skipped.is_some(), "{lsdem:?}");
    assert!(lsdem.seconds == 0.0, "{lsdem:?}");
    for s in ["report", "vtu", "liggghts", "yade"] {
        let st = r.stage(s).expect("listed");
        assert!(st.skipped.is_some() && st.seconds == 0.0, "{st:?}");
    }
    assert!(r.stage("level sets").expect("listed").skipped.is_none());
    assert!(r.stage("clumps").expect("listed").skipped.is_none());
    let files = files_under(&out);
    assert!(
        files
            .iter()
            .all(|f| !f.ends_with(".dat") && !f.ends_with(".vtk") && !f.ends_with(".vtu")),
        "{files:?}"
    );
    let text = std::fs::read_to_string(out.join("report.txt")).expect("report");
    assert!(
        text.contains("lsdem") && text.contains("skipped (no LS-DEM asked)"),
        "{text}"
    );
    // a rerun into the same out_dir replaces its output folders (no stale files)
    std::fs::write(out.join("lammps/stale.data"), "old").expect("plant a stale file");
    run(&scene_text(
        &config,
        &out,
        AUTO,
        "lammps_clumps: true, clump: (spheres_per_clump: 10)",
    ))
    .expect("rerun");
    assert!(!out.join("lammps/stale.data").exists());
    assert!(out.join("lammps/clumps.data").exists());
    // nothing is rasterised when no output needs it
    let none = run(&scene_text(&config, &dir.join("none"), AUTO, "")).expect("no outputs");
    assert!(none.stage("level sets").expect("listed").skipped.is_some());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs a bad scene: returns the error text and checks that `out_dir`
/// (and no staging folder) exists afterwards.
fn bad(dir: &Path, text: &str) -> String {
    let e = match run(text) {
        Ok(_) => panic!("expected an error:\n{text}"),
        Err(e) => format!("{e:#}"),
    };
    assert!(!dir.join("out").exists(), "out_dir left after: {e}");
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .expect("dir")
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains("staging"))
        .collect();
    assert!(leftovers.is_empty(), "staging left after: {e}");
    e
}

#[test]
fn bad_scenes_name_the_key_or_file_and_write_nothing() {
    let dir = tmp("bad");
    let config = cheap_config(&dir);
    let out = dir.join("out");
    // unknown key, at top level and inside outputs
    let e = bad(
        &dir,
        &scene_text(&config, &out, AUTO, "").replace("seed:", "sead:"),
    );
    assert!(e.contains("sead") && e.contains("test.ron:"), "{e}");
    let e = bad(&dir, &scene_text(&config, &out, AUTO, "lsdm: true"));
    assert!(e.contains("lsdm"), "{e}");
    let e = bad(
        &dir,
        &scene_text(&config, &out, "Cylinder(diameter: 5.0, hieght: 3.0)", ""),
    );
    assert!(e.contains("hieght"), "{e}");
    // count 0
    let e = bad(
        &dir,
        &scene_text(&config, &out, AUTO, "").replace("Count(20)", "Count(0)"),
    );
    assert!(e.contains("`clones`") && e.contains("at least 1"), "{e}");
    // missing files: calibrated configuration and parents
    let missing = dir.join("no-such-config.ron");
    let e = bad(&dir, &scene_text(&missing, &out, AUTO, ""));
    assert!(
        e.contains("`calibrated`") && e.contains("no-such-config.ron"),
        "{e}"
    );
    let text = scene_text(&config, &out, AUTO, "").replace(
        "Scene(",
        "Scene(\n    parents: Files(path: \"/no/such/grains\"),\n    length_unit: Some(1e-6),",
    );
    let e = bad(&dir, &text);
    assert!(
        e.contains("`parents.path`") && e.contains("/no/such/grains"),
        "{e}"
    );
    // a container too small for the largest clone (Ottawa clones: bounding diameters ≈ 300-650)
    let e = bad(
        &dir,
        &scene_text(&config, &out, "Cylinder(diameter: 5.0)", "lsdem: true"),
    );
    assert!(
        e.contains("`container` is too small for the largest clone"),
        "{e}"
    );
    // a container that cannot take every clone
    let e = bad(
        &dir,
        &scene_text(
            &config,
            &out,
            "Box(x: 700.0, y: 700.0, z: 700.0)",
            "vtu: true",
        ),
    );
    assert!(e.contains("cannot take all 20 clones"), "{e}");
    // a settling of bounding spheres
    let text = scene_text(&config, &out, AUTO, "").replace(
        "Scene(",
        "Scene(\n    settle: true,\n    placement: BoundingSpheres,",
    );
    let e = bad(&dir, &text);
    assert!(
        e.contains("`settle: true`") && e.contains("placement: Grains"),
        "{e}"
    );
    // Files parents without their length unit
    let text = scene_text(&config, &out, AUTO, "").replace(
        "Scene(",
        "Scene(\n    parents: Files(path: \"fixtures/grains/vcctl/MA107-6-fine\"),",
    );
    let e = bad(&dir, &text);
    assert!(e.contains("`length_unit`"), "{e}");
    // one-sphere clumps, a bad LS-DEM name, too many distinct shapes
    let e = bad(
        &dir,
        &scene_text(
            &config,
            &out,
            AUTO,
            "lammps_clumps: true, clump: (spheres_per_clump: 1)",
        ),
    );
    assert!(
        e.contains("spheres_per_clump") && e.contains("at least 2"),
        "{e}"
    );
    let e = bad(
        &dir,
        &scene_text(&config, &out, AUTO, "lsdem: true, lsdem_name: \"a/b\""),
    );
    assert!(e.contains("lsdem_name"), "{e}");
    let e = bad(
        &dir,
        &scene_text(&config, &out, AUTO, "")
            .replace("Scene(", "Scene(\n    distinct_shapes: Some(21),"),
    );
    assert!(e.contains("distinct_shapes"), "{e}");
    // more grains than the machine's memory, refused before any work
    let e = bad(
        &dir,
        &scene_text(&config, &out, AUTO, "").replace("Count(20)", "Count(100000000)"),
    );
    assert!(e.contains("memory") && e.contains("estimate"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_example_scenes_parse() {
    for name in [
        "specimen-clumps.ron",
        "specimen-lsdem.ron",
        "specimen-10k.ron",
        "specimen-dense.ron",
        "specimen-settled-2000.ron",
    ] {
        let p = root().join("examples").join(name);
        let s = Scene::read(&p).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert!(s.clones.count() >= 1);
    }
}

/// Non-overlap by construction needs every grain inside its bounding
/// sphere: the rasterised surface (interpolated between mesh nodes) stays
/// within `BOUNDING_MARGIN` × the largest node radius.
#[test]
fn grains_stay_inside_their_bounding_spheres() {
    let dir = tmp("bounding");
    let config = cheap_config(&dir);
    let text = std::fs::read_to_string(config).expect("config");
    let cal = cloner::Calibrated::from_ron(&text).expect("parses");
    let parents = super::ottawa().expect("parents");
    let mut params = cal.params;
    params.outputs = cloner::Outputs {
        level_set: false,
        dna: false,
    };
    let model = cloner::CloneModel::fit(parents, &params).expect("fit");
    let run = model.run(0..20, cloner::Hooks::default()).expect("run");
    let mut worst = 0.0_f64;
    for c in &run.clones {
        let g = model.rasterise_at(&c.radii, 31).expect("grid");
        let far = g
            .marching_cubes()
            .vertices()
            .iter()
            .map(|p| p.coords.norm())
            .fold(0.0, f64::max);
        worst = worst.max(far / c.surface.r_max);
    }
    assert!(
        worst <= ::specimen::place::BOUNDING_MARGIN,
        "a surface reaches {worst:.4} × the largest node radius"
    );
    println!("farthest surface point / largest node radius: {worst:.4}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The binary VTU read back: every array's byte count matches its piece's
/// counts, triangles index their own piece, every grain has a surface.
fn vtu_reads_back(vtu: &str, grains: usize) {
    let pieces = super::vtu_read::read_vtu(vtu).expect("the VTU reads back");
    assert!(!pieces.is_empty());
    let mut ids = BTreeSet::new();
    for p in &pieces {
        assert!(p.types.iter().all(|t| *t == 5), "triangles only");
        for (k, o) in p.offsets.iter().enumerate() {
            assert_eq!(*o as usize, 3 * (k + 1));
        }
        assert!(
            p.connectivity
                .iter()
                .all(|v| *v >= 0 && (*v as usize) < p.points.len())
        );
        assert!(p.points.iter().flatten().all(|v| v.is_finite()));
        ids.extend(p.grain_ids.iter().copied());
    }
    assert_eq!(ids.len(), grains, "one surface per grain: {ids:?}");
}

/// The LS-DEM folder as LS-DEM reads it: `Morphologies/morph_<k>.dat` for every line `k` of
/// `InitState/positions_specimen.dat` and `rotations_specimen.dat`, each morph file's level
/// set principal (|I_ij| ≤ 1e-9 I_max by its own inertia), and LS-DEM's pose of each line
/// (position × grid unit, its rotation matrix) equal to `poses.txt`'s (metres).
fn lsdem_folder_reads_as_lsdem(dir: &Path, grains: usize) {
    use levelset::io::lsdem;
    let open = |rel: &str| {
        std::io::BufReader::new(
            std::fs::File::open(dir.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}")),
        )
    };
    let pos = lsdem::read_rows::<3>(open(&lsdem::positions_path("specimen")), "positions")
        .expect("positions");
    let rot = lsdem::read_rows::<4>(open(&lsdem::rotations_path("specimen")), "rotations")
        .expect("rotations");
    assert_eq!(pos.len(), grains);
    assert_eq!(rot.len(), grains);
    let txt = std::fs::read_to_string(dir.join("poses.txt")).expect("poses.txt");
    let rows: Vec<Vec<f64>> = txt
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            l.split_whitespace()
                .skip(2)
                .map(|x| x.parse().expect("number"))
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), grains);
    for k in 0..grains {
        let m = levelset::io::read_morph(open(&lsdem::morph_path(k + 1))).expect("morph");
        assert!(m.mass > 0.0 && m.points.len() == 1000);
        let mp = m.grid.mass_properties_linear().expect("mass");
        assert!(
            lsdem::off_diagonal(&mp.inertia) <= 1e-9,
            "morph {}: {:e}",
            k + 1,
            lsdem::off_diagonal(&mp.inertia)
        );
        // moments in the file = the diagonal of the level set's inertia (unit density)
        for a in 0..3 {
            approx::assert_relative_eq!(
                m.principal_moments[a],
                mp.inertia[(a, a)],
                max_relative = 1e-9
            );
        }
        let q = rot[k];
        approx::assert_relative_eq!(q.iter().map(|v| v * v).sum::<f64>(), 1.0, epsilon = 1e-12);
        let r = &rows[k];
        let h = r[7];
        let world = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            r[3], r[4], r[5], r[6],
        ));
        approx::assert_relative_eq!(
            lsdem::lsdem_matrix(q),
            *world.to_rotation_matrix().matrix(),
            epsilon = 1e-12
        );
        for a in 0..3 {
            approx::assert_relative_eq!(pos[k][a] * h, r[a], max_relative = 1e-12);
        }
    }
}

#[test]
fn lsdem_quaternions_give_lsdem_the_pose_rotation() {
    use rand::{Rng, SeedableRng};
    let seed = 11;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut rotations = vec![
        nalgebra::UnitQuaternion::identity(),
        nalgebra::UnitQuaternion::from_euler_angles(0.3, 0.0, 0.0),
        nalgebra::UnitQuaternion::from_euler_angles(0.0, -1.2, 0.0),
        nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, 2.9),
    ];
    for _ in 0..200 {
        let q = nalgebra::Quaternion::new(
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
        );
        rotations.push(nalgebra::UnitQuaternion::from_quaternion(q));
    }
    for r in rotations {
        let q = levelset::io::lsdem::lsdem_quaternion(&r);
        assert!(q[3] >= 0.0, "W ≥ 0");
        let m = levelset::io::lsdem::lsdem_matrix(q);
        approx::assert_relative_eq!(m, *r.to_rotation_matrix().matrix(), epsilon = 1e-12);
        // body → world: a body point lands where the pose puts it
        let p = nalgebra::Point3::new(0.3, -1.7, 2.2);
        approx::assert_relative_eq!(m * p.coords, (r * p).coords, epsilon = 1e-12);
    }
}

#[test]
fn base64_matches_rfc_4648_and_round_trips() {
    let enc = |b: &[u8]| {
        let mut s = String::new();
        ::specimen::outputs::base64_into(b, &mut s);
        s
    };
    // RFC 4648 § 10 test vectors
    for (plain, coded) in [
        ("", ""),
        ("f", "Zg=="),
        ("fo", "Zm8="),
        ("foo", "Zm9v"),
        ("foob", "Zm9vYg=="),
        ("fooba", "Zm9vYmE="),
        ("foobar", "Zm9vYmFy"),
    ] {
        assert_eq!(enc(plain.as_bytes()), coded);
        assert_eq!(
            ::specimen::outputs::base64_decode(coded).expect("decodes"),
            plain.as_bytes()
        );
    }
    let bytes: Vec<u8> = (0..=255u8).cycle().take(1000).collect();
    assert_eq!(
        ::specimen::outputs::base64_decode(&enc(&bytes)),
        Some(bytes)
    );
}

/// Spheres of different grains that overlap, or cross a wall, are trimmed
/// until none does; spheres of one clump keep their overlap; grains that copy
/// one shape share its trimmed clump.
#[test]
fn separate_clumps_leaves_no_overlap_between_clumps_or_with_walls() {
    use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};
    use packer_grains::separate_clumps;
    let at =
        |x: f64| Isometry3::from_parts(Translation3::new(x, 5.0, 5.0), UnitQuaternion::identity());
    let mut shapes = vec![
        vec![(Point3::origin(), 1.0), (Point3::new(0.5, 0.0, 0.0), 1.0)],
        vec![(Point3::origin(), 1.0)],
        vec![(Point3::origin(), 1.0)],
    ];
    let poses = [at(4.0), at(6.2), at(0.5)];
    let c = packer_spheres::Container::walled_box(nalgebra::Vector3::new(10.0, 10.0, 10.0));
    let t = separate_clumps(&mut shapes, &poses, |k| k, &c).expect("trims");
    assert_eq!(t.walls, 1);
    assert!(t.pairs == 1 && t.trimmed == 3, "{t:?}");
    assert!(t.volume_change < 0.0);
    let check = |shapes: &[Vec<(Point3<f64>, f64)>],
                 poses: &[Isometry3<f64>],
                 of: &dyn Fn(usize) -> usize| {
        let world: Vec<(Point3<f64>, f64, usize)> = poses
            .iter()
            .enumerate()
            .flat_map(|(g, p)| shapes[of(g)].iter().map(move |(c, r)| (p * c, *r, g)))
            .collect();
        for (i, a) in world.iter().enumerate() {
            assert!(c.clearance(&a.0) >= a.1, "sphere {i} crosses a wall");
            for b in &world[i + 1..] {
                if a.2 != b.2 {
                    assert!((a.0 - b.0).norm() >= a.1 + b.1, "{a:?} {b:?}");
                }
            }
        }
    };
    check(&shapes, &poses, &|k| k);
    // the two spheres of clump 0 still overlap each other
    let s = &shapes[0];
    assert!((s[0].0 - s[1].0).norm() < s[0].1 + s[1].1);
    // three copies of one shape: one template, cut for the worst copy
    let mut one = vec![vec![(Point3::origin(), 1.0)]];
    let copies = [at(2.0), at(3.9), at(8.5)];
    let t = separate_clumps(&mut one, &copies, |_| 0, &c).expect("trims");
    assert_eq!(t.trimmed, 1);
    check(&one, &copies, &|_| 0);
    approx::assert_relative_eq!(one[0][0].1, 0.95, max_relative = 1e-6);
    // a sphere that would lose nearly all of its radius is an error
    let mut deep = vec![vec![(Point3::origin(), 1.0)], vec![(Point3::origin(), 1.0)]];
    let e = separate_clumps(&mut deep, &[at(5.0), at(5.05)], |k| k, &c)
        .expect_err("too deep")
        .to_string();
    assert!(e.contains("spheres per clump"), "{e}");
}

#[test]
fn a_narrow_container_is_refused_unless_allowed() {
    let dir = tmp("narrow");
    let config = cheap_config(&dir);
    let text = scene_text(&config, &dir.join("out"), AUTO, "")
        .replace("    allow_narrow_container: true,\n", "");
    let e = run(&text)
        .expect_err("20 clones make a narrow cylinder")
        .to_string();
    assert!(
        e.contains("narrower than 8 d_max") && e.contains("allow_narrow_container"),
        "{e}"
    );
    assert!(!dir.join("out").exists(), "nothing written");
    // allowed: the stage report states the width and the walls' share
    let r = run(&scene_text(&config, &dir.join("ok"), AUTO, "")).expect("allowed");
    let place = r.text();
    assert!(
        place.contains("d_max wide") && place.contains("within one d_max of a wall"),
        "{place}"
    );
}

#[test]
fn a_sieve_curve_by_mass_sizes_the_intermediate_dimension() {
    use super::scene::SizeMeasure;
    // the measure's scale gives the grain the drawn size
    let dims = [3.0, 2.0, 1.0];
    let v = std::f64::consts::PI / 6.0 * 8.0; // d_eq = 2
    assert!((SizeMeasure::Intermediate.scale(5.0, v, dims) * dims[1] - 5.0).abs() < 1e-12);
    assert!((SizeMeasure::Equivalent.scale(5.0, v, dims) * 2.0 - 5.0).abs() < 1e-12);
    // a scene with a lab's curve by mass runs, every grain's scale from its own I
    let dir = tmp("sieve-mass");
    let config = cheap_config(&dir);
    let text = scene_text(&config, &dir.join("out"), AUTO, "").replace(
        "clones: Count(20),",
        "clones: Graded(count: 20, grading: \"sieve-mass:150:0,250:40,425:100\", size: Intermediate),",
    );
    run(&text).expect("sieve-mass scene");
    let bad = text.replace("425:100", "425:90");
    let e = run(&bad).expect_err("passing must end at 100").to_string();
    assert!(e.contains("grading"), "{e}");
}
