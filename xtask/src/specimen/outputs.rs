//! The files of a specimen: a staging folder that makes the whole output
//! atomic, and the writers of every format (LS-DEM poses, clump files for
//! LAMMPS, LIGGGHTS and Yade, the VTU of the whole specimen).
//!
//! Every file is written into a hidden staging folder beside `out_dir`;
//! only when every stage has succeeded are the files renamed into
//! `out_dir`. On an error the staging folder is removed and `out_dir` is
//! left as it was (not even created).

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::Context;
use nalgebra::{Isometry3, Point3};
use packer_quadtree::{Container, Sphere};

/// A hidden folder beside `out_dir` collecting the run's files.
pub(crate) struct Staging {
    dir: PathBuf,
    files: Mutex<Vec<PathBuf>>,
    committed: bool,
}

static STAGING_COUNTER: AtomicU64 = AtomicU64::new(0);

impl Staging {
    /// A fresh staging folder for `out_dir`.
    pub(crate) fn new(out_dir: &Path) -> anyhow::Result<Self> {
        let name = out_dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "specimen".into());
        let parent = out_dir
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let dir = parent.join(format!(
            ".{name}.staging-{}-{}",
            std::process::id(),
            STAGING_COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self {
            dir,
            files: Mutex::new(Vec::new()),
            committed: false,
        })
    }

    /// The staged path of `rel` (its folder created).
    pub(crate) fn path(&self, rel: &str) -> anyhow::Result<PathBuf> {
        let p = self.dir.join(rel);
        if let Some(d) = p.parent() {
            std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
        }
        if let Ok(mut f) = self.files.lock() {
            f.push(PathBuf::from(rel));
        }
        Ok(p)
    }

    /// Stages `bytes` as `rel` (a path relative to `out_dir`).
    pub(crate) fn write(&self, rel: &str, bytes: &[u8]) -> anyhow::Result<()> {
        let p = self.path(rel)?;
        std::fs::write(&p, bytes).with_context(|| format!("writing {}", p.display()))
    }

    /// Moves every staged file into `out_dir` (renames within one file
    /// system; a staged folder such as `lsdem/` replaces the one already
    /// there) and returns their paths relative to `out_dir`, sorted.
    pub(crate) fn commit(mut self, out_dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
        let mut files = self.files.lock().map(|f| f.clone()).unwrap_or_default();
        files.sort();
        files.dedup();
        // an output folder of this run replaces the one of an earlier run
        // (no stale grain files beside the new ones)
        let mut folders: Vec<PathBuf> = files
            .iter()
            .filter(|f| f.components().count() > 1)
            .filter_map(|f| f.components().next().map(|c| PathBuf::from(c.as_os_str())))
            .collect();
        folders.dedup();
        for d in folders {
            let old = out_dir.join(d);
            if old.is_dir() {
                std::fs::remove_dir_all(&old)
                    .with_context(|| format!("replacing {}", old.display()))?;
            }
        }
        for rel in &files {
            let to = out_dir.join(rel);
            if let Some(d) = to.parent() {
                std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
            }
            std::fs::rename(self.dir.join(rel), &to)
                .with_context(|| format!("moving {} into place", to.display()))?;
        }
        self.committed = true;
        let _ = std::fs::remove_dir_all(&self.dir);
        Ok(files)
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

/// One placed grain's LS-DEM pose: the morph file it uses, its centre of
/// mass in the world, its rotation and the length of one grid unit.
pub(crate) struct LsdemPose {
    pub(crate) index: u64,
    pub(crate) file: String,
    pub(crate) centre: Point3<f64>,
    pub(crate) pose: Isometry3<f64>,
    pub(crate) spacing: f64,
}

/// `lsdem/poses.txt`: one line per grain.
pub(crate) fn lsdem_poses(poses: &[LsdemPose]) -> String {
    let mut s = String::from(
        "# grainforge specimen: LS-DEM poses, one line per grain\n\
         # id morph_file x y z q0 q1 q2 q3 spacing\n\
         # x y z: the grain's centre of mass in the world (scene length unit);\n\
         # q0 q1 q2 q3: unit quaternion (scalar first) rotating the morph file's axes to the world;\n\
         # spacing: world length of one grid unit (the same for every morph file: they use spacing 1),\n\
         # so a morph point p (relative to the centre of mass, grid units) is at x + R(q) * spacing * p.\n\
         # positions.dat holds x y z / spacing (grid units), one grain per line, morphID.dat the file numbers.\n",
    );
    for p in poses {
        let q = p.pose.rotation.quaternion();
        let _ = writeln!(
            s,
            "{} {} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
            p.index, p.file, p.centre.x, p.centre.y, p.centre.z, q.w, q.i, q.j, q.k, p.spacing
        );
    }
    s
}

/// `lsdem/positions.dat`: `x y z` of every centre of mass in grid units
/// (world / spacing), one grain per line, no header (what LS-DEM codes read
/// with their position-file readers).
pub(crate) fn lsdem_positions(poses: &[LsdemPose]) -> String {
    let mut s = String::new();
    for p in poses {
        let c = p.centre.coords / p.spacing;
        let _ = writeln!(s, "{:e} {:e} {:e}", c.x, c.y, c.z);
    }
    s
}

/// `lsdem/morphID.dat`: the morph file number (`grain-NNNNNN.dat`) of every
/// line of `positions.dat`.
pub(crate) fn lsdem_morph_ids(poses: &[LsdemPose]) -> String {
    let mut s = String::new();
    for p in poses {
        let _ = writeln!(s, "{}", p.index);
    }
    s
}

/// A clump of one placed grain: its spheres in the clone frame (scaled).
pub(crate) struct PlacedClump {
    pub(crate) index: u64,
    pub(crate) pose: Isometry3<f64>,
    pub(crate) spheres: Vec<(Point3<f64>, f64)>,
}

impl PlacedClump {
    fn world(&self) -> impl Iterator<Item = Sphere> + '_ {
        self.spheres.iter().map(|(c, r)| Sphere {
            center: self.pose * c,
            radius: *r,
        })
    }
}

/// `lammps/clumps.data` (every clump sphere, `atom_style sphere`) and
/// `lammps/clumps.body` (an atomfile-style variable: atom id → body id).
pub(crate) fn lammps_clumps(
    clumps: &[PlacedClump],
    container: &Container,
    density: f64,
) -> anyhow::Result<(Vec<u8>, String)> {
    let spheres: Vec<Sphere> = clumps.iter().flat_map(PlacedClump::world).collect();
    let mut data = Vec::new();
    packer_quadtree::write_lammps_data3(&spheres, container, density, &mut data)?;
    let mut body = String::from(
        "# grainforge specimen: body id of every atom of clumps.data (atomfile-style variable)\n\
         # LAMMPS (see in.clumps): atom_modify map array; read_data clumps.data;\n\
         #   variable body atomfile clumps.body; fix clumps all rigid/small custom v_body\n",
    );
    let _ = writeln!(body, "{}", spheres.len());
    let mut id = 0usize;
    for (b, c) in clumps.iter().enumerate() {
        for _ in &c.spheres {
            id += 1;
            let _ = writeln!(body, "{id} {}", b + 1);
        }
    }
    Ok((data, body))
}

/// `yade/clumps.txt`: `x y z r clump_id` per sphere (world frame).
pub(crate) fn yade_clumps(clumps: &[PlacedClump]) -> String {
    let mut s = String::from("# grainforge specimen: x y z r clump_id (world frame)\n");
    for (b, c) in clumps.iter().enumerate() {
        for sp in c.world() {
            let _ = writeln!(
                s,
                "{:e} {:e} {:e} {:e} {b}",
                sp.center.x, sp.center.y, sp.center.z, sp.radius
            );
        }
    }
    s
}

/// `yade/load_clumps.py`: reads `clumps.txt` into clumps.
pub(crate) const YADE_SCRIPT: &str = r#"# grainforge specimen: load the clumps of clumps.txt into Yade.
# Run inside Yade (e.g. `yade load_clumps.py`, or exec(open('load_clumps.py').read())
# from your own script, after defining materials).
import os
from yade import utils

here = os.path.dirname(os.path.abspath(__file__)) if '__file__' in globals() else '.'
clumps = {}
with open(os.path.join(here, 'clumps.txt')) as f:
    for line in f:
        if line.startswith('#') or not line.strip():
            continue
        x, y, z, r, c = line.split()
        clumps.setdefault(int(c), []).append(((float(x), float(y), float(z)), float(r)))
for c in sorted(clumps):
    O.bodies.appendClumped([utils.sphere(centre, radius) for centre, radius in clumps[c]])
print('grainforge: %d clumps loaded' % len(clumps))
"#;

/// LIGGGHTS templates: one `liggghts/clump-NNNNNN.txt` per clone (`x y z r`
/// per sphere, clone frame) and `liggghts/templates.in` with the
/// `particletemplate/multisphere` fixes and a discrete distribution of
/// them (equal weights).
pub(crate) fn liggghts_templates(
    clumps: &[PlacedClump],
    density: f64,
) -> (Vec<(String, String)>, String) {
    let mut files = Vec::new();
    let mut script = String::from(
        "# grainforge specimen: LIGGGHTS multisphere templates, one per clone.\n\
         # include this file from the LIGGGHTS input (paths are relative to out_dir/liggghts);\n\
         # density = the scene's `outputs.density`; one multisphere type per template.\n\
         # The placed poses are in ../poses.csv.\n",
    );
    let n = clumps.len();
    for (k, c) in clumps.iter().enumerate() {
        let name = format!("clump-{:06}.txt", c.index);
        let mut t = String::new();
        for (p, r) in &c.spheres {
            let _ = writeln!(t, "{:e} {:e} {:e} {:e}", p.x, p.y, p.z, r);
        }
        let _ = writeln!(
            script,
            "fix pts{} all particletemplate/multisphere 15485863 atom_type 1 density constant {density} nspheres {} ntry 1000000 spheres file {name} scale 1.0 type {}",
            k + 1,
            c.spheres.len(),
            k + 1
        );
        files.push((name, t));
    }
    let _ = write!(
        script,
        "fix pdd all particledistribution/discrete 32452843 {n}"
    );
    for k in 0..n {
        let _ = write!(script, " &\n    pts{} {:.12}", k + 1, 1.0 / n as f64);
    }
    script.push('\n');
    (files, script)
}

/// A streaming VTU (UnstructuredGrid, ASCII) of grain surfaces: one
/// `<Piece>` per call of [`VtuWriter::piece`], triangles with a `grain_id`
/// cell field.
pub(crate) struct VtuWriter<W: Write> {
    w: W,
}

/// Triangles of several grains in the world frame, with their grain ids.
#[derive(Default)]
pub(crate) struct Surfaces {
    pub(crate) points: Vec<Point3<f64>>,
    pub(crate) triangles: Vec<[usize; 3]>,
    pub(crate) grain_ids: Vec<u64>,
}

impl Surfaces {
    /// Appends a grain's mesh, moved by `pose`.
    pub(crate) fn push(&mut self, id: u64, mesh: &levelset::TriMesh, pose: &Isometry3<f64>) {
        let base = self.points.len();
        self.points.extend(mesh.vertices().iter().map(|p| pose * p));
        for t in mesh.triangles() {
            self.triangles.push([t[0] + base, t[1] + base, t[2] + base]);
            self.grain_ids.push(id);
        }
    }
}

impl<W: Write> VtuWriter<W> {
    pub(crate) fn new(mut w: W) -> std::io::Result<Self> {
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(
            w,
            r#"<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">"#
        )?;
        writeln!(w, "<UnstructuredGrid>")?;
        Ok(Self { w })
    }

    pub(crate) fn piece(&mut self, s: &Surfaces) -> std::io::Result<()> {
        let w = &mut self.w;
        writeln!(
            w,
            r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
            s.points.len(),
            s.triangles.len()
        )?;
        writeln!(w, "<Points>")?;
        writeln!(
            w,
            r#"<DataArray type="Float64" NumberOfComponents="3" format="ascii">"#
        )?;
        for p in &s.points {
            writeln!(w, "{:.7e} {:.7e} {:.7e}", p.x, p.y, p.z)?;
        }
        writeln!(w, "</DataArray>\n</Points>\n<Cells>")?;
        writeln!(
            w,
            r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#
        )?;
        for t in &s.triangles {
            writeln!(w, "{} {} {}", t[0], t[1], t[2])?;
        }
        writeln!(w, "</DataArray>")?;
        writeln!(
            w,
            r#"<DataArray type="Int64" Name="offsets" format="ascii">"#
        )?;
        for k in 0..s.triangles.len() {
            writeln!(w, "{}", 3 * (k + 1))?;
        }
        writeln!(w, "</DataArray>")?;
        writeln!(w, r#"<DataArray type="UInt8" Name="types" format="ascii">"#)?;
        for _ in &s.triangles {
            writeln!(w, "5")?;
        }
        writeln!(w, "</DataArray>\n</Cells>")?;
        writeln!(w, r#"<CellData Scalars="grain_id">"#)?;
        writeln!(
            w,
            r#"<DataArray type="Int64" Name="grain_id" format="ascii">"#
        )?;
        for id in &s.grain_ids {
            writeln!(w, "{id}")?;
        }
        writeln!(w, "</DataArray>\n</CellData>\n</Piece>")?;
        Ok(())
    }

    pub(crate) fn finish(mut self) -> std::io::Result<W> {
        writeln!(self.w, "</UnstructuredGrid>\n</VTKFile>")?;
        Ok(self.w)
    }
}

/// `poses.csv`: every placed grain's pose (always written).
pub(crate) fn poses_csv(
    indices: &[u64],
    poses: &[Isometry3<f64>],
    bounding: &[f64],
    scales: &[f64],
) -> String {
    let mut s = String::from(
        "# grainforge specimen: clone frame -> world. x,y,z: the clone frame's origin; q0..q3: unit quaternion (scalar first); bounding_radius: the placed bounding sphere; scale: factor applied to the clone's radii (1 unless the scene grades the sizes)\nid,x,y,z,q0,q1,q2,q3,bounding_radius,scale\n",
    );
    for (((i, p), b), sc) in indices.iter().zip(poses).zip(bounding).zip(scales) {
        let q = p.rotation.quaternion();
        let t = p.translation.vector;
        let _ = writeln!(
            s,
            "{i},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            t.x, t.y, t.z, q.w, q.i, q.j, q.k, b, sc
        );
    }
    s
}
