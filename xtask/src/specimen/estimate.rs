//! Memory and disk a scene will need, estimated before any work from its counts and
//! resolutions, and refused with a clear message when the machine does not have them
//! (`Count(100000000)` used to abort with "memory allocation of 43200000000 bytes failed").
//!
//! The per-item costs are measurements (README "Output cost"), rounded up:
//! - memory: [`BYTES_PER_GRAIN`] per placed grain plus [`BYTES_PER_SHAPE`] per distinct
//!   shape (the clone's mesh radii, DNA) and one chunk of level sets: 55 KB per grain of
//!   its own shape, the measured slope (peak RSS of `examples/specimen-dense.ron` at 0.60:
//!   595 MB at 10,000 clones, 2.67 GB at 50,000, 5.22 GB at 100,000, i.e. 51 KB per grain
//!   added) with a little to spare: the former 100 KB per grain (60 + 40, from the 10,000-
//!   grain total) refused 100,000 clones on a machine with 6–10 GB free, where they need
//!   5.2 GB;
//! - disk: an LS-DEM morph file holds `≈ (level_set_resolution + 4)³` level-set values
//!   (the median grain at the common spacing, larger grains more: × [`MORPH_SPREAD`]) of
//!   [`BYTES_PER_VALUE`] each, plus its nodes; a VTU surface 44 KB per grain at 16 cells
//!   across, growing with the square of the resolution; a clump sphere ≈ 120 bytes per
//!   clump format.

use std::path::Path;

use anyhow::bail;

use super::scene::Scene;

/// Memory per placed grain (star table, proxy spheres and neighbour lists, gap nodes,
/// pose, check nodes), bytes.
pub(crate) const BYTES_PER_GRAIN: f64 = 45e3;
/// Memory per distinct shape (the clone: mesh radii, DNA), bytes.
pub(crate) const BYTES_PER_SHAPE: f64 = 10e3;
/// Bytes per level-set value in a morph file (shortest round-trip float and a space).
pub(crate) const BYTES_PER_VALUE: f64 = 20.0;
/// Mean morph file size over the median grain's (larger grains have larger grids at the
/// common spacing: measured 2.8 MB mean against 2.2 MB for the median at 45³).
pub(crate) const MORPH_SPREAD: f64 = 1.3;

/// What a scene needs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Estimate {
    /// Peak memory, bytes.
    pub(crate) memory: f64,
    /// Disk written, bytes.
    pub(crate) disk: f64,
}

impl Estimate {
    /// The estimate of `scene`.
    pub(crate) fn of(scene: &Scene) -> Self {
        let grains = scene.clones.count() as f64;
        let shapes = scene.distinct() as f64;
        let out = &scene.outputs;
        let res = scene.level_set_resolution as f64;
        let chunk_grids = 64.0 * 2.0 * (res + 4.0).powi(3) * 8.0;
        let memory = grains * BYTES_PER_GRAIN + shapes * BYTES_PER_SHAPE + chunk_grids;
        let mut disk = grains * 200.0; // poses.csv and the LS-DEM pose lines
        if out.lsdem {
            let values = (res + 4.0).powi(3) * MORPH_SPREAD;
            disk += shapes * (values * BYTES_PER_VALUE + out.lsdem_nodes as f64 * 60.0);
        }
        if out.vtu {
            disk += grains * 44e3 * (out.vtu_resolution as f64 / 16.0).powi(2);
        }
        let formats = [out.lammps_clumps, out.liggghts_templates, out.yade_clumps]
            .iter()
            .filter(|f| **f)
            .count() as f64;
        disk += grains * out.clump.spheres_per_clump as f64 * 120.0 * formats;
        Self { memory, disk }
    }

    /// Refuses the scene when the estimate exceeds what the machine has (`available`
    /// memory and `free` disk, bytes; `None` when unknown).
    pub(crate) fn check(&self, available: Option<f64>, free: Option<f64>) -> anyhow::Result<()> {
        if let Some(m) = available
            && self.memory > m
        {
            bail!(
                "the scene needs about {} of memory by its estimate (45 KB per grain, 10 KB per distinct shape: measured 5.22 GB peak at 100,000 clones), more than the {} available: lower `clones` (or set `distinct_shapes`)",
                human(self.memory),
                human(m)
            );
        }
        if let Some(d) = free
            && self.disk > d
        {
            bail!(
                "the outputs need about {} of disk by their estimate, more than the {} free under `out_dir`: set `distinct_shapes` (LS-DEM morph reuse), a lower `level_set_resolution` or `vtu_resolution`, or fewer outputs",
                human(self.disk),
                human(d)
            );
        }
        Ok(())
    }
}

/// `MemAvailable` of `/proc/meminfo`, bytes (`None` where there is none).
pub(crate) fn available_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Free bytes on the file system of `dir` (its nearest existing ancestor), by `df -Pk`
/// (`None` when `df` is not there).
pub(crate) fn free_disk(dir: &Path) -> Option<f64> {
    let mut d = dir;
    while !d.exists() {
        d = d.parent()?;
    }
    let out = std::process::Command::new("df")
        .arg("-Pk")
        .arg(d)
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let kb: f64 = text
        .lines()
        .nth(1)?
        .split_whitespace()
        .nth(3)?
        .parse()
        .ok()?;
    Some(kb * 1024.0)
}

/// `1.2 GB`-style text.
pub(crate) fn human(bytes: f64) -> String {
    let units = ["B", "KB", "MB", "GB", "TB", "PB"];
    let mut v = bytes;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < units.len() {
        v /= 1000.0;
        u += 1;
    }
    format!("{v:.1} {}", units[u])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        Scene::parse(text, Path::new("t.ron")).expect("scene")
    }

    #[test]
    fn a_hundred_million_clones_are_refused_before_any_work() {
        let s =
            scene("Scene(clones: Count(100000000), container: AutoCylinder(solid_fraction: 0.5))");
        let e = Estimate::of(&s);
        assert!(e.memory > 5e12, "{e:?}");
        let msg = e
            .check(Some(24e9), Some(77e9))
            .expect_err("refused")
            .to_string();
        assert!(msg.contains("memory") && msg.contains("TB"), "{msg}");
        // 10,000 grains fit a 24 GB machine; 100,000 (measured peak 5.22 GB) a 6 GB one
        let s = scene("Scene(clones: Count(10000), container: AutoCylinder(solid_fraction: 0.5))");
        assert!(Estimate::of(&s).check(Some(24e9), Some(77e9)).is_ok());
        let s = scene("Scene(clones: Count(100000), container: AutoCylinder(solid_fraction: 0.6))");
        let e = Estimate::of(&s);
        assert!(e.memory > 5.22e9 && e.memory < 6e9, "{e:?}");
    }

    #[test]
    fn morph_reuse_caps_the_lsdem_disk() {
        let all = scene(
            "Scene(clones: Count(10000), container: AutoCylinder(solid_fraction: 0.5), outputs: (lsdem: true))",
        );
        let reuse = scene(
            "Scene(clones: Count(10000), distinct_shapes: Some(1000), container: AutoCylinder(solid_fraction: 0.5), outputs: (lsdem: true))",
        );
        let (a, r) = (Estimate::of(&all), Estimate::of(&reuse));
        assert!(a.disk > 20e9 && r.disk < 5e9, "{a:?} {r:?}");
        let msg = a
            .check(Some(24e9), Some(10e9))
            .expect_err("refused")
            .to_string();
        assert!(
            msg.contains("disk") && msg.contains("distinct_shapes"),
            "{msg}"
        );
        assert!(r.check(Some(24e9), Some(10e9)).is_ok());
        assert_eq!(human(1.5e9), "1.5 GB");
    }
}
