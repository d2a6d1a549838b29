//! The writers of a specimen's files that are not DEM decks: the LS-DEM
//! layout beside the morph files ([`lsdem_files`]), the streaming VTU of the
//! grains' surfaces ([`VtuWriter`]) and the poses
//! table ([`poses_csv`]). Pure: bytes or `impl Write`, no paths.

use std::fmt::Write as _;
use std::io::Write;

use nalgebra::{Isometry3, Point3};

use crate::error::{Error, Result};

/// Where a distinct shape's principal-frame morph file sits in its clone frame.
#[derive(Debug, Clone, Copy)]
pub struct LsdemFrame {
    /// Morph frame → clone frame (scene units; translation = centre of mass).
    pub frame: Isometry3<f64>,
    /// Scene length of one morph grid unit.
    pub spacing: f64,
    /// Largest `|I_ij| / I_max` of the morph file's level set.
    pub off_diagonal: f64,
}

/// The LS-DEM files beside the morph files: text files and links (relative to `lsdem/`).
pub struct LsdemFiles {
    /// `(path relative to lsdem/, bytes)` of the text files.
    pub text: Vec<(String, Vec<u8>)>,
    /// `Morphologies/morph_<k>.dat` → `morph_<t>.dat` for grains that reuse a shape.
    pub links: Vec<(String, String)>,
    /// Largest `|I_ij| / I_max` over the morph files.
    pub worst_off_diagonal: f64,
    /// Metres per grid unit.
    pub spacing_m: f64,
}

/// The LS-DEM layout (`levelset::io::lsdem`): `InitState/positions_<NAME>.dat` (centres of
/// mass in grid units), `InitState/rotations_<NAME>.dat` (LS-DEM's quaternion convention),
/// links for reused morphs, `poses.txt` (SI) and `PROVENANCE.txt`.
///
/// Grain `k` (line `k + 1`) is a copy of shape `template_of(k)`; its morph frame → world
/// is `poses[k] · frames[t].frame`.
///
/// # Errors
/// A shape without its frame; the layout's errors.
pub fn lsdem_files(
    frames: &[Option<LsdemFrame>],
    poses: &[Isometry3<f64>],
    template_of: &dyn Fn(usize) -> usize,
    metres: f64,
    name: &str,
    provenance: &[String],
) -> Result<LsdemFiles> {
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
            .ok_or_else(|| Error::Invalid {
                what: "LS-DEM frames".into(),
                message: format!("no morph file for shape {t}"),
            })?;
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
pub struct VtuWriter<W: Write> {
    w: W,
}

/// Uncompressed bytes per zlib block of a VTU array (VTK's default 32 KiB
/// is too small to compress the long regular arrays well).
const VTU_BLOCK: usize = 1 << 20;

/// Triangles of several grains in the world frame, with their grain ids.
#[derive(Default)]
pub struct Surfaces {
    /// Vertices, world frame, metres.
    pub points: Vec<Point3<f64>>,
    /// Triangles (indices into `points`).
    pub triangles: Vec<[usize; 3]>,
    /// The grain of each triangle.
    pub grain_ids: Vec<u64>,
}

impl Surfaces {
    /// Appends a grain's mesh, moved by `pose` and scaled by `metres` (scene unit → m).
    pub fn push(&mut self, id: u64, mesh: &levelset::TriMesh, pose: &Isometry3<f64>, metres: f64) {
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
pub fn base64_into(bytes: &[u8], out: &mut String) {
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
pub fn base64_decode(text: &str) -> Option<Vec<u8>> {
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
    /// Starts the file (header of the unstructured grid).
    ///
    /// # Errors
    /// The writer's I/O error.
    pub fn new(mut w: W) -> std::io::Result<Self> {
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

    /// Writes one `<Piece>` of surfaces.
    ///
    /// # Errors
    /// The writer's I/O error.
    pub fn piece(&mut self, s: &Surfaces) -> std::io::Result<()> {
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

    /// Closes the file and returns the writer.
    ///
    /// # Errors
    /// The writer's I/O error.
    pub fn finish(mut self) -> std::io::Result<W> {
        writeln!(self.w, "</UnstructuredGrid>\n</VTKFile>")?;
        Ok(self.w)
    }
}

/// One line of `poses.csv` (metres).
pub struct PoseRow {
    /// Grain number.
    pub grain: u64,
    /// The clone whose shape it has.
    pub clone: u64,
    /// Clone frame → world, metres.
    pub pose: Isometry3<f64>,
    /// Radius about the clone frame's origin that holds the grain, metres.
    pub bounding_radius: f64,
    /// Factor applied to the clone's radii.
    pub scale: f64,
}

/// `poses.csv`: every placed grain's pose (always written), in metres.
pub fn poses_csv(rows: &[PoseRow], provenance: &[String]) -> String {
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
