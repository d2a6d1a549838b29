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

    /// Stages a relative symbolic link `rel → target` (`target` relative to `rel`'s folder).
    pub(crate) fn link(&self, rel: &str, target: &str) -> anyhow::Result<()> {
        let p = self.path(rel)?;
        std::os::unix::fs::symlink(target, &p)
            .with_context(|| format!("linking {} to {target}", p.display()))
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

/// Where a distinct shape's principal-frame morph file sits in its clone frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LsdemFrame {
    /// Morph frame → clone frame (scene units; translation = centre of mass).
    pub(crate) frame: Isometry3<f64>,
    /// Scene length of one morph grid unit.
    pub(crate) spacing: f64,
    /// Largest `|I_ij| / I_max` of the morph file's level set.
    pub(crate) off_diagonal: f64,
}

/// The LS-DEM files beside the morph files: text files and links (relative to `lsdem/`).
pub(crate) struct LsdemFiles {
    pub(crate) text: Vec<(String, Vec<u8>)>,
    /// `Morphologies/morph_<k>.dat` → `morph_<t>.dat` for grains that reuse a shape.
    pub(crate) links: Vec<(String, String)>,
    pub(crate) worst_off_diagonal: f64,
    /// Metres per grid unit.
    pub(crate) spacing_m: f64,
}

/// The LS-DEM layout (`levelset::io::lsdem`): `InitState/positions_<NAME>.dat` (centres of
/// mass in grid units), `InitState/rotations_<NAME>.dat` (LS-DEM's quaternion convention),
/// links for reused morphs, `poses.txt` (SI) and `PROVENANCE.txt`.
///
/// Grain `k` (line `k + 1`) is a copy of shape `template_of(k)`; its morph frame → world
/// is `poses[k] · frames[t].frame`.
pub(crate) fn lsdem_files(
    frames: &[Option<LsdemFrame>],
    poses: &[Isometry3<f64>],
    template_of: &dyn Fn(usize) -> usize,
    metres: f64,
    name: &str,
    provenance: &[String],
) -> anyhow::Result<LsdemFiles> {
    use levelset::io::lsdem;
    let mut grains = Vec::with_capacity(poses.len());
    let mut worst = 0.0f64;
    let mut h = f64::NAN;
    let mut table = String::new();
    for (k, pose) in poses.iter().enumerate() {
        let t = template_of(k);
        let f = frames
            .get(t)
            .copied()
            .flatten()
            .ok_or_else(|| anyhow::anyhow!("no morph file for shape {t}"))?;
        h = f.spacing;
        worst = worst.max(f.off_diagonal);
        let world = pose * f.frame;
        // LS-DEM works in grid units: the morph frame → world in grid units
        grains.push((
            t,
            Isometry3::from_parts(
                nalgebra::Translation3::from(world.translation.vector / f.spacing),
                world.rotation,
            ),
        ));
        let q = world.rotation.quaternion();
        let c = world.translation.vector * metres;
        let _ = writeln!(
            table,
            "{} {} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
            k + 1,
            lsdem::morph_path(t + 1),
            c.x,
            c.y,
            c.z,
            q.w,
            q.i,
            q.j,
            q.k,
            f.spacing * metres
        );
    }
    let mut text = Vec::new();
    let mut links = Vec::new();
    for e in lsdem::layout(name, &grains)? {
        match e {
            lsdem::LayoutEntry::File { path, bytes } => text.push((path, bytes)),
            lsdem::LayoutEntry::Link { path, target } => links.push((path, target)),
        }
    }
    let mut header = String::new();
    for l in provenance {
        let _ = writeln!(header, "# {l}");
    }
    header.push_str(
        "# LS-DEM poses, one line per grain (line k of InitState/positions_NAME.dat and rotations_NAME.dat)\n\
         # k morph_file x y z q0 q1 q2 q3 grid_unit\n\
         # x y z: the grain's centre of mass in the world, metres; q0..q3: unit quaternion (scalar first)\n\
         # rotating the morph file's (principal) axes to the world; grid_unit: metres per morph grid unit.\n\
         # A morph point p (grid units, relative to the centre of mass) is at x + R(q) * grid_unit * p.\n\
         # The morph files are in grid units (spacing 1) with density 1: mass in kg = density * grid_unit^3 * morph mass,\n\
         # moments in kg m^2 = density * grid_unit^5 * morph moments. positions_NAME.dat is x y z / grid_unit,\n\
         # rotations_NAME.dat the same rotations in LS-DEM's convention (q0 q1 q2 q3 = y -x -z w of the quaternion above).\n",
    );
    header.push_str(&table);
    let mut prov = String::new();
    for l in provenance {
        prov.push_str(l);
        prov.push('\n');
    }
    let _ = writeln!(
        prov,
        "LS-DEM input folder: Morphologies/morph_<k>.dat for line k of InitState/positions_{name}.dat and rotations_{name}.dat; \
         lengths in grid units, 1 grid unit = {:e} m; morph files in their principal-axis frames.",
        h * metres
    );
    text.push(("poses.txt".into(), header.into_bytes()));
    text.push(("PROVENANCE.txt".into(), prov.into_bytes()));
    Ok(LsdemFiles {
        text,
        links,
        worst_off_diagonal: worst,
        spacing_m: h * metres,
    })
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
    /// Appends a grain's mesh, moved by `pose` and scaled by `metres` (scene unit → m).
    pub(crate) fn push(
        &mut self,
        id: u64,
        mesh: &levelset::TriMesh,
        pose: &Isometry3<f64>,
        metres: f64,
    ) {
        let base = self.points.len();
        self.points
            .extend(mesh.vertices().iter().map(|p| (pose * p) * metres));
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

/// One line of `poses.csv` (metres).
pub(crate) struct PoseRow {
    pub(crate) grain: u64,
    pub(crate) clone: u64,
    pub(crate) pose: Isometry3<f64>,
    pub(crate) bounding_radius: f64,
    pub(crate) scale: f64,
}

/// `poses.csv`: every placed grain's pose (always written), in metres.
pub(crate) fn poses_csv(rows: &[PoseRow], provenance: &[String]) -> String {
    let mut s = String::new();
    for l in provenance {
        let _ = writeln!(s, "# {l}");
    }
    s.push_str(
        "# clone frame -> world, metres. grain: grain number; clone: the clone whose shape it has (grains share a clone when the scene sets distinct_shapes); x,y,z: the clone frame's origin (m); q0..q3: unit quaternion (scalar first); bounding_radius: of the grain about x,y,z (m); scale: factor applied to the clone's radii (1 unless the scene grades the sizes)\ngrain,clone,x,y,z,q0,q1,q2,q3,bounding_radius,scale\n",
    );
    for r in rows {
        let q = r.pose.rotation.quaternion();
        let t = r.pose.translation.vector;
        let _ = writeln!(
            s,
            "{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            r.grain, r.clone, t.x, t.y, t.z, q.w, q.i, q.j, q.k, r.bounding_radius, r.scale
        );
    }
    s
}
