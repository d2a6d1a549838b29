//! The provenance of a specimen's files (grainforge version and commit, seed, units, the
//! scene, the parents' licence) and the embedded Ottawa parents.

use std::path::Path;

use super::scene::{ParentsSpec, Scene};

/// The provenance lines of every output: grainforge version and commit, seed, the scene,
/// and for clones of the embedded NIST/VCCTL grains their licence and citation.
pub(crate) fn provenance_lines(
    scene: &Scene,
    scene_text: &str,
    root: &Path,
    seed: u64,
) -> Vec<String> {
    let commit = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_else(|| "unknown".into());
    let dirty = std::process::Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .current_dir(root)
        .output()
        .ok()
        .is_some_and(|o| o.status.success() && !o.stdout.is_empty());
    let mut lines = vec![
        format!(
            "grainforge {} (commit {commit}{}), cargo xtask specimen",
            env!("CARGO_PKG_VERSION"),
            if dirty {
                ", with uncommitted changes"
            } else {
                ""
            }
        ),
        format!(
            "seed {seed}; units: SI (lengths m, masses kg, density {} kg/m^3); 1 parents' length unit = {:e} m",
            scene.outputs.density,
            scene.metres()
        ),
    ];
    match &scene.parents {
        ParentsSpec::Ottawa => lines.extend(
            [
                "parents: 71 Ottawa-sand grains of the NIST/VCCTL aggregate shape database (X-ray CT, spherical harmonics),",
                "  Garboczi (2002), Cem. Concr. Res. 32:1621; VCCTL (Bentz, Garboczi, Bullard; github.com/jwbullard/VCCTL),",
                "  Copyright (c) 2020-present Jeffrey W. Bullard, MIT licence (notice in full in PROVENANCE.txt).",
                "  The clones are new grains statistically like these parents (grainforge GSC 2.0), not copies.",
            ]
            .iter()
            .map(|s| (*s).to_owned()),
        ),
        ParentsSpec::Files { path, .. } => lines.push(format!("parents: {}", path.display())),
    }
    lines.push("scene:".into());
    lines.extend(scene_text.lines().map(|l| format!("  {l}")));
    lines
}

/// The licence notice of the embedded NIST/VCCTL grains.
const VCCTL_NOTICE: &str = include_str!("../../../fixtures/grains/vcctl/NOTICE.txt");

/// `PROVENANCE.txt`: the provenance lines, and the VCCTL licence notice in full when the
/// parents are the embedded grains.
pub(crate) fn provenance_text(lines: &[String], scene: &Scene) -> String {
    let mut s = String::new();
    for l in lines {
        s.push_str(l);
        s.push('\n');
    }
    if matches!(scene.parents, ParentsSpec::Ottawa) {
        s.push('\n');
        s.push_str(VCCTL_NOTICE);
    }
    s
}

/// The embedded Ottawa parents, built once per process (the tests run
/// several scenes).
pub(crate) fn ottawa() -> anyhow::Result<&'static cloner::Parents> {
    static OTTAWA: std::sync::OnceLock<cloner::Parents> = std::sync::OnceLock::new();
    if let Some(p) = OTTAWA.get() {
        return Ok(p);
    }
    let p = validate::grains::ottawa_parents()?;
    Ok(OTTAWA.get_or_init(|| p))
}
