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

use anyhow::{Context, bail};
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
         # positions.dat holds x y z / spacing (grid units), one grain per line, morphID.dat the file numbers,\n\
         # rotations.dat the same rotations in LS-DEM's own quaternion convention (q0 q1 q2 q3 = y -x -z w).\n",
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

/// The LS-DEM quaternion `[q0, q1, q2, q3]` of a body → world rotation.
///
/// LS-DEM (Kawamoto et al. 2016, 2018; `Grain3d::updateRotationMatrix` of
/// the Kawamoto/Andrade code and its descendants) stores `(X, Y, Z, W)` but
/// builds its rotation matrix with a sign and axis convention of its own:
/// for a Hamilton unit quaternion `w + x i + y j + z k` whose matrix is the
/// body → world rotation `R` (world point = `R · morph point + position`,
/// the convention of its `_pointList = _rotMatrix * _refPointList +
/// _position`), LS-DEM's matrix equals `R` when the file holds
/// `q0 = y, q1 = −x, q2 = −z, q3 = w`. `lsdem_matrix` is that matrix,
/// written out as LS-DEM does; the tests check the round trip.
pub(crate) fn lsdem_quaternion(rotation: &nalgebra::UnitQuaternion<f64>) -> [f64; 4] {
    let q = rotation.quaternion();
    // one sign for q and −q (the same rotation): W ≥ 0
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.j, -s * q.i, -s * q.k, s * q.w]
}

/// LS-DEM's rotation matrix of a file quaternion `[q0, q1, q2, q3]`
/// (`Grain3d::updateRotationMatrix`, term by term): the body → world
/// rotation the simulation will apply.
#[cfg(test)]
pub(crate) fn lsdem_matrix(q: [f64; 4]) -> nalgebra::Matrix3<f64> {
    let [a, b, c, d] = q;
    nalgebra::Matrix3::new(
        -a * a + b * b - c * c + d * d,
        -2.0 * (a * b - c * d),
        2.0 * (b * c + a * d),
        -2.0 * (a * b + c * d),
        a * a - b * b - c * c + d * d,
        -2.0 * (a * c - b * d),
        2.0 * (b * c - a * d),
        -2.0 * (a * c + b * d),
        -a * a - b * b + c * c + d * d,
    )
}

/// `lsdem/rotations.dat`: one LS-DEM quaternion `q0 q1 q2 q3` per line of
/// `positions.dat` (single spaces, no header: LS-DEM's
/// `readQuaternionFile`), see [`lsdem_quaternion`] for the convention.
pub(crate) fn lsdem_rotations(poses: &[LsdemPose]) -> String {
    let mut s = String::new();
    for p in poses {
        let [a, b, c, d] = lsdem_quaternion(&p.pose.rotation);
        let _ = writeln!(s, "{a:e} {b:e} {c:e} {d:e}");
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

/// A streaming VTU (UnstructuredGrid, VTK XML with inline binary data) of
/// grain surfaces: one `<Piece>` per call of [`VtuWriter::piece`],
/// triangles with a `grain_id` cell field.
///
/// Every `DataArray` is `format="binary"` with `compressor=
/// "vtkZLibDataCompressor"` and `header_type="UInt64"` (VTK file formats,
/// "XML File Formats", binary data): the UInt64 header `[blocks,
/// block size, last partial block size (0 when full), compressed size of
/// each block]` base64-encoded on its own, then the zlib blocks
/// base64-encoded as one stream — what `vtkXMLWriter` writes. Points are
/// Float32 (a relative precision of 6·10⁻⁸ is far below a surface cell),
/// connectivity and offsets Int32 (piece-local), types UInt8, `grain_id`
/// Int32. ParaView and VTK ≥ 6 read it.
pub(crate) struct VtuWriter<W: Write> {
    w: W,
}

/// Uncompressed bytes per zlib block of a VTU array (VTK's default 32 KiB
/// is too small to compress the long regular arrays well).
const VTU_BLOCK: usize = 1 << 20;

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

/// Base64 (RFC 4648, with padding) of `bytes`, appended to `out`.
pub(crate) fn base64_into(bytes: &[u8], out: &mut String) {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    out.reserve(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= c.len() {
                out.push(char::from(ALPHABET[(n >> (18 - 6 * k)) as usize & 63]));
            } else {
                out.push('=');
            }
        }
    }
}

/// Decodes base64 (the inverse of [`base64_into`]); `None` on a bad byte.
#[cfg(test)]
pub(crate) fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let val = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let t: Vec<u8> = text.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    let mut out = Vec::with_capacity(t.len() / 4 * 3);
    for q in t.chunks(4) {
        let pad = q.iter().filter(|c| **c == b'=').count();
        let mut n = 0u32;
        for (k, c) in q.iter().enumerate() {
            n |= if *c == b'=' { 0 } else { val(*c)? } << (18 - 6 * k);
        }
        let b = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&b[..3 - pad]);
    }
    Some(out)
}

impl<W: Write> VtuWriter<W> {
    pub(crate) fn new(mut w: W) -> std::io::Result<Self> {
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(
            w,
            r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64" compressor="vtkZLibDataCompressor">"#
        )?;
        writeln!(w, "<UnstructuredGrid>")?;
        Ok(Self { w })
    }

    /// One binary `DataArray`: zlib blocks of [`VTU_BLOCK`] bytes behind
    /// the UInt64 compression header, each base64-encoded.
    fn array(
        &mut self,
        kind: &str,
        name: &str,
        components: usize,
        data: &[u8],
    ) -> std::io::Result<()> {
        let name = if name.is_empty() {
            String::new()
        } else {
            format!(r#" Name="{name}""#)
        };
        let blocks: Vec<Vec<u8>> = data
            .chunks(VTU_BLOCK)
            .map(|b| {
                let mut z = flate2::write::ZlibEncoder::new(
                    Vec::with_capacity(b.len() / 2),
                    flate2::Compression::fast(),
                );
                z.write_all(b)?;
                z.finish()
            })
            .collect::<std::io::Result<_>>()?;
        let mut header: Vec<u64> = vec![
            blocks.len() as u64,
            VTU_BLOCK as u64,
            (data.len() % VTU_BLOCK) as u64,
        ];
        header.extend(blocks.iter().map(|b| b.len() as u64));
        let header: Vec<u8> = header.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut text = String::new();
        base64_into(&header, &mut text);
        base64_into(&blocks.concat(), &mut text);
        writeln!(
            self.w,
            r#"<DataArray type="{kind}"{name} NumberOfComponents="{components}" format="binary">"#
        )?;
        self.w.write_all(text.as_bytes())?;
        writeln!(self.w, "\n</DataArray>")
    }

    pub(crate) fn piece(&mut self, s: &Surfaces) -> std::io::Result<()> {
        let too_big = |what: &str| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("a VTU piece has more {what} than Int32 indexes"),
            )
        };
        if s.points.len() > i32::MAX as usize {
            return Err(too_big("points"));
        }
        if 3 * s.triangles.len() > i32::MAX as usize {
            return Err(too_big("triangles"));
        }
        writeln!(
            self.w,
            r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
            s.points.len(),
            s.triangles.len()
        )?;
        writeln!(self.w, "<Points>")?;
        let mut b = Vec::with_capacity(12 * s.points.len());
        for p in &s.points {
            for v in [p.x, p.y, p.z] {
                b.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
        self.array("Float32", "", 3, &b)?;
        writeln!(self.w, "</Points>\n<Cells>")?;
        b.clear();
        for t in &s.triangles {
            for v in t {
                b.extend_from_slice(&(*v as i32).to_le_bytes());
            }
        }
        self.array("Int32", "connectivity", 1, &b)?;
        b.clear();
        for k in 0..s.triangles.len() {
            b.extend_from_slice(&(3 * (k as i32 + 1)).to_le_bytes());
        }
        self.array("Int32", "offsets", 1, &b)?;
        self.array("UInt8", "types", 1, &vec![5u8; s.triangles.len()])?;
        writeln!(self.w, "</Cells>")?;
        writeln!(self.w, r#"<CellData Scalars="grain_id">"#)?;
        b.clear();
        for id in &s.grain_ids {
            b.extend_from_slice(&(*id as i32).to_le_bytes());
        }
        self.array("Int32", "grain_id", 1, &b)?;
        writeln!(self.w, "</CellData>\n</Piece>")?;
        Ok(())
    }

    pub(crate) fn finish(mut self) -> std::io::Result<W> {
        writeln!(self.w, "</UnstructuredGrid>\n</VTKFile>")?;
        Ok(self.w)
    }
}

/// A VTU of [`VtuWriter`] read back: per piece, the point, triangle and
/// grain-id arrays (tests only).
#[cfg(test)]
pub(crate) struct VtuPiece {
    pub(crate) points: Vec<[f32; 3]>,
    pub(crate) connectivity: Vec<i32>,
    pub(crate) offsets: Vec<i32>,
    pub(crate) types: Vec<u8>,
    pub(crate) grain_ids: Vec<i32>,
}

/// Reads back a VTU written by [`VtuWriter`] (tests only): checks the
/// header counts of every array and the piece's declared sizes.
#[cfg(test)]
pub(crate) fn read_vtu(text: &str) -> anyhow::Result<Vec<VtuPiece>> {
    use anyhow::{bail, ensure};
    // the header (its own base64 stream: 3 + blocks UInt64), then the blocks
    let decode = |body: &str| -> anyhow::Result<Vec<u8>> {
        use std::io::Read as _;
        let body = body.trim();
        let first = base64_decode(body.get(..16).unwrap_or(""))
            .ok_or_else(|| anyhow::anyhow!("bad base64"))?;
        ensure!(first.len() >= 8, "no header");
        let blocks = u64::from_le_bytes(first[..8].try_into()?) as usize;
        let header_chars = (8 * (3 + blocks)).div_ceil(3) * 4;
        ensure!(body.len() >= header_chars, "truncated header");
        let header = base64_decode(&body[..header_chars])
            .ok_or_else(|| anyhow::anyhow!("bad base64 header"))?;
        let h: Vec<usize> = header
            .chunks_exact(8)
            .map(|x| u64::from_le_bytes(x.try_into().unwrap_or([0; 8])) as usize)
            .collect();
        ensure!(h.len() == 3 + blocks, "header of {} values", h.len());
        let z = base64_decode(&body[header_chars..])
            .ok_or_else(|| anyhow::anyhow!("bad base64 data"))?;
        ensure!(
            z.len() == h[3..].iter().sum::<usize>(),
            "compressed sizes disagree"
        );
        let mut out = Vec::new();
        let mut at = 0;
        for (k, c) in h[3..].iter().enumerate() {
            let mut block = Vec::new();
            flate2::read::ZlibDecoder::new(&z[at..at + c]).read_to_end(&mut block)?;
            let want = if k + 1 == blocks && h[2] > 0 {
                h[2]
            } else {
                h[1]
            };
            ensure!(
                block.len() == want,
                "block {k}: {} bytes, not {want}",
                block.len()
            );
            out.extend_from_slice(&block);
            at += c;
        }
        Ok(out)
    };
    let attr = |tag: &str, key: &str| -> anyhow::Result<usize> {
        let k = format!("{key}=\"");
        let at = tag.find(&k).ok_or_else(|| anyhow::anyhow!("no {key}"))? + k.len();
        let end = tag[at..]
            .find('"')
            .ok_or_else(|| anyhow::anyhow!("bad {key}"))?;
        Ok(tag[at..at + end].parse()?)
    };
    let mut pieces = Vec::new();
    for chunk in text.split("<Piece ").skip(1) {
        let head = &chunk[..chunk.find('>').unwrap_or(0)];
        let (np, nc) = (attr(head, "NumberOfPoints")?, attr(head, "NumberOfCells")?);
        let mut arrays = Vec::new();
        for a in chunk.split("<DataArray ").skip(1) {
            let open = a
                .find('>')
                .ok_or_else(|| anyhow::anyhow!("bad DataArray"))?;
            let close = a
                .find("</DataArray>")
                .ok_or_else(|| anyhow::anyhow!("unclosed"))?;
            ensure!(a[..open].contains(r#"format="binary""#), "not binary");
            arrays.push(decode(&a[open + 1..close])?);
        }
        let [p, c, o, t, g] = <[Vec<u8>; 5]>::try_from(arrays)
            .map_err(|a| anyhow::anyhow!("{} arrays in a piece, not 5", a.len()))?;
        let i32s = |b: &[u8]| -> Vec<i32> {
            b.chunks_exact(4)
                .map(|x| i32::from_le_bytes([x[0], x[1], x[2], x[3]]))
                .collect()
        };
        let f: Vec<f32> = p
            .chunks_exact(4)
            .map(|x| f32::from_le_bytes([x[0], x[1], x[2], x[3]]))
            .collect();
        let piece = VtuPiece {
            points: f.chunks_exact(3).map(|v| [v[0], v[1], v[2]]).collect(),
            connectivity: i32s(&c),
            offsets: i32s(&o),
            types: t,
            grain_ids: i32s(&g),
        };
        if piece.points.len() != np
            || piece.offsets.len() != nc
            || piece.types.len() != nc
            || piece.grain_ids.len() != nc
            || piece.connectivity.len() != 3 * nc
        {
            bail!("a piece's arrays disagree with NumberOfPoints={np} NumberOfCells={nc}");
        }
        pieces.push(piece);
    }
    Ok(pieces)
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

/// Radius trimming of [`separate_clumps`].
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Trim {
    /// Sphere pairs of different clumps that overlapped.
    pub(crate) pairs: usize,
    /// Worst of those overlaps over the smaller sphere's diameter.
    pub(crate) worst: f64,
    /// Spheres that crossed a wall.
    pub(crate) walls: usize,
    /// Spheres whose radius was trimmed.
    pub(crate) trimmed: usize,
    /// Largest relative radius reduction.
    pub(crate) max_cut: f64,
    /// Relative change of the summed sphere volumes.
    pub(crate) volume_change: f64,
}

/// Makes the clumps of a grain packing a valid DEM start: the clumps
/// approximate the level sets (their radii are offset to match each
/// grain's volume), so their spheres may reach past a grain's surface,
/// across the margin the packer leaves and into a neighbour's spheres or a
/// wall. Every sphere of a pair of different clumps that overlaps by `δ`
/// loses `δ/2` (plus 1e-9 of its radius) of radius — the largest cut any of
/// its pairs asks, so one pass leaves no overlap — and a sphere crossing a
/// wall is cut to its clearance. Spheres of one clump keep overlapping each
/// other (they are one rigid body). A uniform cell grid of sphere centres
/// (cell = the largest diameter): O(spheres).
///
/// # Errors
/// A sphere that would lose more than 90 % of its radius (the packing is
/// not one a clump of this size can follow).
pub(crate) fn separate_clumps(
    clumps: &mut [PlacedClump],
    container: &Container,
) -> anyhow::Result<Trim> {
    let index: Vec<(usize, usize)> = clumps
        .iter()
        .enumerate()
        .flat_map(|(k, c)| (0..c.spheres.len()).map(move |m| (k, m)))
        .collect();
    let spheres: Vec<(Point3<f64>, f64, usize)> = clumps
        .iter()
        .enumerate()
        .flat_map(|(k, c)| c.world().map(move |s| (s.center, s.radius, k)))
        .collect();
    let mut trim = Trim::default();
    let Some(r_max) = spheres.iter().map(|s| s.1).reduce(f64::max) else {
        return Ok(trim);
    };
    let cell = 2.0 * r_max;
    let key = |p: &Point3<f64>| {
        [
            (p.x / cell).floor() as i64,
            (p.y / cell).floor() as i64,
            (p.z / cell).floor() as i64,
        ]
    };
    let mut grid: std::collections::BTreeMap<[i64; 3], Vec<usize>> =
        std::collections::BTreeMap::new();
    for (i, s) in spheres.iter().enumerate() {
        grid.entry(key(&s.0)).or_default().push(i);
    }
    let mut cut = vec![0.0_f64; spheres.len()];
    for (i, a) in spheres.iter().enumerate() {
        let clear = container.clearance(&a.0);
        if clear < a.1 {
            trim.walls += 1;
            cut[i] = cut[i].max(a.1 - clear + 1e-9 * a.1);
        }
        let k = key(&a.0);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                        continue;
                    };
                    for &j in list {
                        let b = &spheres[j];
                        if j <= i || b.2 == a.2 {
                            continue;
                        }
                        let overlap = a.1 + b.1 - (a.0 - b.0).norm();
                        if overlap > 0.0 {
                            trim.pairs += 1;
                            trim.worst = trim.worst.max(overlap / (2.0 * a.1.min(b.1)));
                            cut[i] = cut[i].max(0.5 * overlap + 1e-9 * a.1);
                            cut[j] = cut[j].max(0.5 * overlap + 1e-9 * b.1);
                        }
                    }
                }
            }
        }
    }
    let (mut before, mut after) = (0.0, 0.0);
    for (i, &(k, m)) in index.iter().enumerate() {
        let r = &mut clumps[k].spheres[m].1;
        before += r.powi(3);
        if cut[i] > 0.0 {
            let rel = cut[i] / *r;
            if rel > 0.9 {
                bail!(
                    "clump of clone {}: a sphere of radius {:.4} would lose {:.0} % of it to its neighbours; use more spheres per clump",
                    clumps[k].index,
                    *r,
                    100.0 * rel
                );
            }
            trim.trimmed += 1;
            trim.max_cut = trim.max_cut.max(rel);
            *r -= cut[i];
        }
        after += r.powi(3);
    }
    trim.volume_change = after / before - 1.0;
    Ok(trim)
}
