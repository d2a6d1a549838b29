//! Writers and readers of 3D sphere packings for DEM codes and viewers:
//! LAMMPS/LIGGGHTS `read_data` (`atom_style sphere`), Yade `ymport.text`,
//! CSV and VTK XML unstructured grids (`.vtu`, ParaView).
//!
//! Everything goes through `impl Write` / `impl BufRead`; the library
//! touches no files. Every writer validates all of its input before the
//! first byte is written, so an `Err` leaves the sink untouched. Numbers are
//! written with Rust's shortest round-trip formatting (`{:e}`), which every
//! correctly rounding parser (Rust, C `strtod`, Python `float`) reads back
//! to the same `f64`: writing and reading back gives bit-identical spheres
//! (diameters are `2 r`, exact in binary floating point).
//!
//! Readers report malformed input as [`Error::Parse`] with the 1-based line
//! number; they never panic, whatever the bytes.

use std::io::{BufRead, Write};

use nalgebra::Point3;

use super::{Container, Sphere};
use crate::error::{Error, Result, finite, positive};

/// Every centre coordinate finite, every radius positive and finite.
fn check(spheres: &[Sphere]) -> Result<()> {
    for s in spheres {
        finite("sphere centre x", s.center.x)?;
        finite("sphere centre y", s.center.y)?;
        finite("sphere centre z", s.center.z)?;
        positive("sphere radius", s.radius)?;
    }
    Ok(())
}

/// As [`check`], plus finite diameters (`2 r` overflows above `f64::MAX / 2`).
fn check_with_diameters(spheres: &[Sphere]) -> Result<()> {
    check(spheres)?;
    for s in spheres {
        positive("sphere diameter", 2.0 * s.radius)?;
    }
    Ok(())
}

// ---------------------------------------------------------------- LAMMPS --

/// The `boundary` command matching a container's periodicity: `p` for the
/// periodic x/y directions of a box, `f` (fixed, non-periodic) otherwise.
fn boundary_command(periodic: [bool; 2]) -> &'static str {
    match periodic {
        [true, true] => "boundary p p f",
        [true, false] => "boundary p f f",
        [false, true] => "boundary f p f",
        [false, false] => "boundary f f f",
    }
}

/// The simulation box of [`write_lammps_data3`]: the container's bounding
/// box, exactly in the periodic directions and widened in the others until
/// every sphere (centre ± radius) is inside and every centre strictly inside.
fn lammps_box(spheres: &[Sphere], container: &Container) -> Result<[[f64; 2]; 3]> {
    let (lo, hi) = container.bbox();
    let periodic = container.periodic();
    let mut bounds = [[lo.x, hi.x], [lo.y, hi.y], [lo.z, hi.z]];
    for (k, b) in bounds.iter_mut().enumerate() {
        if k < 2 && periodic[k] {
            continue;
        }
        for s in spheres {
            let c = s.center[k];
            // `c ± r` rounds back to `c` when `r` is below half an ulp of `c`.
            let below = c - s.radius;
            let above = c + s.radius;
            b[0] = b[0].min(if below < c { below } else { c.next_down() });
            b[1] = b[1].max(if above > c { above } else { c.next_up() });
        }
        finite("LAMMPS box lower bound", b[0])?;
        finite("LAMMPS box upper bound", b[1])?;
    }
    Ok(bounds)
}

/// LAMMPS/LIGGGHTS `read_data` file, `atom_style sphere`, one atom type.
///
/// Layout (every number in shortest round-trip `{:e}` form):
///
/// ```text
/// LAMMPS data file written by grainforge packer-quadtree (atom_style sphere; boundary p p f)
///
/// 500 atoms
/// 1 atom types
///
/// 0e0 1e1 xlo xhi
/// 0e0 1e1 ylo yhi
/// 0e0 5e0 zlo zhi
///
/// Atoms # sphere
///
/// 1 1 9e-1 2.65e3 5e-1 5e-1 5e-1
/// ...
/// ```
///
/// * line 1, the title (LAMMPS skips it): names the `boundary` command
///   that matches the container;
/// * `N atoms`: the number of spheres;
/// * `1 atom types`: every sphere is type 1;
/// * `xlo xhi`, `ylo yhi`, `zlo zhi`: the simulation box. In the periodic
///   directions of a [`Container::Box`] it is exactly the box, so that the
///   periodic images LAMMPS builds are those of the packing (centres
///   outside a periodic direction are written as they are: LAMMPS remaps
///   them into the box). In every other direction it is the container's
///   bounding box, widened where needed so that every sphere lies inside
///   and every centre strictly inside (LAMMPS drops atoms outside a
///   non-periodic box);
/// * `Atoms # sphere`: the section, one line per sphere with the columns
///   of `atom_style sphere`: `atom-ID atom-type diameter density x y z`,
///   ids from 1 in slice order, type 1, diameter `2 r`, the given
///   `density` (mass per volume: LAMMPS sets the mass to
///   `density · π d³ / 6`), the centre. No image flags (all zero).
///
/// Use it with `atom_style sphere`, `dimension 3` and the boundary named on
/// the title line: `boundary p p f` for a box periodic in x and y (`p f f`
/// / `f p f` when only one is), `boundary f f f` for walled boxes,
/// cylinders and meshes. The walls themselves are the user's (e.g. `fix
/// wall/gran`): the data file carries only the box.
///
/// # Errors
/// [`Error::NonFinite`] / [`Error::NonPositive`] for a bad centre, radius,
/// diameter, density, container or box bound; [`Error::Empty`] for no
/// spheres (no box can be derived); [`Error::Io`]. Nothing is written on
/// a validation error.
pub fn write_lammps_data3(
    spheres: &[Sphere],
    container: &Container,
    density: f64,
    mut w: impl Write,
) -> Result<()> {
    check_with_diameters(spheres)?;
    positive("density", density)?;
    if spheres.is_empty() {
        return Err(Error::Empty {
            what: "sphere list",
        });
    }
    container.validate()?;
    let bounds = lammps_box(spheres, container)?;
    writeln!(
        w,
        "LAMMPS data file written by grainforge packer-quadtree (atom_style sphere; {})",
        boundary_command(container.periodic())
    )?;
    writeln!(w)?;
    writeln!(w, "{} atoms", spheres.len())?;
    writeln!(w, "1 atom types")?;
    writeln!(w)?;
    for (b, axis) in bounds.iter().zip(["x", "y", "z"]) {
        writeln!(w, "{:e} {:e} {axis}lo {axis}hi", b[0], b[1])?;
    }
    writeln!(w)?;
    writeln!(w, "Atoms # sphere")?;
    writeln!(w)?;
    for (i, s) in spheres.iter().enumerate() {
        writeln!(
            w,
            "{} 1 {:e} {:e} {:e} {:e} {:e}",
            i + 1,
            2.0 * s.radius,
            density,
            s.center.x,
            s.center.y,
            s.center.z
        )?;
    }
    Ok(())
}

/// A LAMMPS `atom_style sphere` data file as [`read_lammps_data3`] reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct LammpsData3 {
    /// Atom ids, increasing.
    pub ids: Vec<u64>,
    /// The spheres (radius = diameter / 2), in the order of `ids`.
    pub spheres: Vec<Sphere>,
    /// Per-atom density column, in the order of `ids`.
    pub densities: Vec<f64>,
    /// Box bounds `[[xlo, xhi], [ylo, yhi], [zlo, zhi]]` (LAMMPS's default
    /// `[-0.5, 0.5]` for a direction the header leaves out).
    pub bounds: [[f64; 2]; 3],
}

/// Reads a LAMMPS/LIGGGHTS data file with `atom_style sphere` atoms: what
/// [`write_lammps_data3`] writes, and any orthogonal-box data file of that
/// style.
///
/// Accepted: the title line (skipped); header lines `N atoms`,
/// `N atom types`, `lo hi xlo xhi` (and `y`, `z`), any other `N keyword…`
/// count (ignored); comments after `#`; blank lines; CRLF line ends; the
/// `Atoms` section, with no style comment, `# sphere` or `# granular`
/// (LIGGGHTS's name of the same style), holding lines
/// `atom-ID atom-type diameter density x y z`, optionally followed by three
/// integer image flags (parsed and ignored: positions are returned as
/// written), in any id order (the result is sorted by id); any other
/// section (`Velocities`, `Masses`, …), skipped. A section keyword is a
/// line starting with an upper-case letter.
///
/// # Errors
/// [`Error::Parse`] with the line number for: invalid UTF-8, an unknown
/// header line, a triclinic box (`xy xz yz`), box bounds not finite or not
/// increasing, a second `Atoms` section or another atom style, an atom line
/// without 7 or 10 fields, a non-integer or zero id or type, a type above
/// the `atom types` count, a non-finite value, a non-positive diameter or
/// density, a repeated id, an atom count different from the header's (or
/// atoms without one), a missing `Atoms` section when atoms are declared;
/// [`Error::Io`] from the reader.
pub fn read_lammps_data3(r: impl BufRead) -> Result<LammpsData3> {
    const F: &str = "lammps data";
    let mut lines = Lines::new(r, F);
    if lines.next_line()?.is_none() {
        return Err(parse_error(F, 1, "empty input"));
    }
    let mut natoms: Option<usize> = None;
    let mut ntypes: Option<u64> = None;
    let mut bounds = [[-0.5, 0.5]; 3];

    // Header: everything up to the first section keyword.
    let mut section: Option<(String, String, usize)> = None;
    while let Some((no, raw)) = lines.next_line()? {
        let (data, comment) = split_comment(&raw);
        let toks: Vec<&str> = data.split_whitespace().collect();
        let Some(first) = toks.first() else { continue };
        if first.starts_with(|c: char| c.is_ascii_uppercase()) {
            section = Some((toks.join(" "), comment.trim().to_owned(), no));
            break;
        }
        match toks.as_slice() {
            [n, "atoms"] => natoms = Some(parse_count(F, no, "atom count", n)?),
            [n, "atom", "types"] => ntypes = Some(parse_count(F, no, "atom type count", n)?),
            [lo, hi, "xlo", "xhi"] => bounds[0] = parse_bounds(no, lo, hi)?,
            [lo, hi, "ylo", "yhi"] => bounds[1] = parse_bounds(no, lo, hi)?,
            [lo, hi, "zlo", "zhi"] => bounds[2] = parse_bounds(no, lo, hi)?,
            [_, _, _, "xy", "xz", "yz"] => {
                return Err(parse_error(F, no, "triclinic boxes are not supported"));
            }
            [n, rest @ ..]
                if !rest.is_empty()
                    && n.parse::<u64>().is_ok()
                    && rest
                        .iter()
                        .all(|t| t.chars().all(|c| c.is_ascii_alphabetic() || c == '/')) => {}
            _ => {
                return Err(parse_error(
                    F,
                    no,
                    format!("unrecognised header line `{}`", data.trim()),
                ));
            }
        }
    }

    // Sections.
    let mut atoms: Vec<(u64, usize, Sphere, f64)> = Vec::new();
    let mut atoms_line: Option<usize> = None;
    while let Some((keyword, style, kw_line)) = section.take() {
        let is_atoms = keyword == "Atoms";
        if is_atoms {
            if atoms_line.is_some() {
                return Err(parse_error(F, kw_line, "second Atoms section"));
            }
            let style = style.split_whitespace().next().unwrap_or("sphere");
            if style != "sphere" && style != "granular" {
                return Err(parse_error(
                    F,
                    kw_line,
                    format!("atom style `{style}` is not supported (only `sphere`)"),
                ));
            }
            if natoms.is_none() {
                return Err(parse_error(
                    F,
                    kw_line,
                    "Atoms section without an `atoms` count in the header",
                ));
            }
            atoms_line = Some(kw_line);
        }
        while let Some((no, raw)) = lines.next_line()? {
            let (data, comment) = split_comment(&raw);
            let toks: Vec<&str> = data.split_whitespace().collect();
            let Some(first) = toks.first() else { continue };
            if first.starts_with(|c: char| c.is_ascii_uppercase()) {
                section = Some((toks.join(" "), comment.trim().to_owned(), no));
                break;
            }
            if is_atoms {
                if let Some(n) = natoms
                    && atoms.len() >= n
                {
                    return Err(parse_error(
                        F,
                        no,
                        format!("more atoms than the {n} declared in the header"),
                    ));
                }
                let (id, sphere, density) = parse_atom(no, &toks, ntypes)?;
                atoms.push((id, no, sphere, density));
            }
        }
    }
    let declared = natoms.unwrap_or(0);
    match atoms_line {
        None if declared > 0 => {
            return Err(parse_error(
                F,
                lines.line + 1,
                format!("the header declares {declared} atoms but there is no Atoms section"),
            ));
        }
        Some(line) if atoms.len() != declared => {
            return Err(parse_error(
                F,
                line,
                format!(
                    "the header declares {declared} atoms, the Atoms section has {}",
                    atoms.len()
                ),
            ));
        }
        _ => {}
    }
    let atoms = sort_by_id(F, atoms)?;
    let mut out = LammpsData3 {
        ids: Vec::with_capacity(atoms.len()),
        spheres: Vec::with_capacity(atoms.len()),
        densities: Vec::with_capacity(atoms.len()),
        bounds,
    };
    for (id, _, s, d) in atoms {
        out.ids.push(id);
        out.spheres.push(s);
        out.densities.push(d);
    }
    Ok(out)
}

/// The two numbers of a `lo hi xlo xhi` header line: finite, increasing.
fn parse_bounds(no: usize, lo: &str, hi: &str) -> Result<[f64; 2]> {
    const F: &str = "lammps data";
    let lo = parse_finite(F, no, "box lower bound", lo)?;
    let hi = parse_finite(F, no, "box upper bound", hi)?;
    if lo < hi {
        Ok([lo, hi])
    } else {
        Err(parse_error(F, no, format!("box bounds {lo} >= {hi}")))
    }
}

/// One `atom_style sphere` line: `id type diameter density x y z [ix iy iz]`.
fn parse_atom(no: usize, toks: &[&str], ntypes: Option<u64>) -> Result<(u64, Sphere, f64)> {
    const F: &str = "lammps data";
    if toks.len() != 7 && toks.len() != 10 {
        return Err(parse_error(
            F,
            no,
            format!(
                "atom line has {} fields, expected 7 (id type diameter density x y z) or 10 (with image flags)",
                toks.len()
            ),
        ));
    }
    let id = parse_id(F, no, "atom id", toks[0])?;
    let ty = parse_id(F, no, "atom type", toks[1])?;
    if let Some(n) = ntypes
        && ty > n
    {
        return Err(parse_error(
            F,
            no,
            format!("atom type {ty} above the {n} atom types of the header"),
        ));
    }
    let diameter = parse_positive(F, no, "diameter", toks[2])?;
    let density = parse_positive(F, no, "density", toks[3])?;
    let x = parse_finite(F, no, "x", toks[4])?;
    let y = parse_finite(F, no, "y", toks[5])?;
    let z = parse_finite(F, no, "z", toks[6])?;
    for t in &toks[7..] {
        t.parse::<i64>()
            .map_err(|_| parse_error(F, no, format!("image flag `{t}` is not an integer")))?;
    }
    Ok((
        id,
        Sphere {
            center: Point3::new(x, y, z),
            radius: 0.5 * diameter,
        },
        density,
    ))
}

// ------------------------------------------------------------------ Yade --

/// Yade text for `ymport.text` (format `x_y_z_r`): a `# x y z r` comment
/// line (ymport skips lines starting with `#`), then one `x y z r` line per
/// sphere. No blank lines (ymport fails on them).
///
/// # Errors
/// [`Error::NonFinite`] / [`Error::NonPositive`] for a bad sphere;
/// [`Error::Io`]. Nothing is written on a validation error.
pub fn write_yade3(spheres: &[Sphere], mut w: impl Write) -> Result<()> {
    check(spheres)?;
    writeln!(w, "# x y z r")?;
    for s in spheres {
        writeln!(
            w,
            "{:e} {:e} {:e} {:e}",
            s.center.x, s.center.y, s.center.z, s.radius
        )?;
    }
    Ok(())
}

/// Reads Yade `x_y_z_r` text (what [`write_yade3`] and Yade's
/// `export.text` write): lines starting with `#` are comments, except
/// `#format x_y_z_r` (any other `#format` is an error); blank lines are
/// skipped; every other line is exactly `x y z r`.
///
/// # Errors
/// [`Error::Parse`] with the line number for invalid UTF-8, another
/// `#format`, a line without 4 fields, a non-finite value or a
/// non-positive radius; [`Error::Io`] from the reader.
pub fn read_yade3(r: impl BufRead) -> Result<Vec<Sphere>> {
    const F: &str = "yade text";
    let mut lines = Lines::new(r, F);
    let mut out = Vec::new();
    while let Some((no, raw)) = lines.next_line()? {
        let toks: Vec<&str> = raw.split_whitespace().collect();
        let Some(first) = toks.first() else { continue };
        if *first == "#format" {
            match toks.get(1) {
                Some(&"x_y_z_r") if toks.len() == 2 => continue,
                _ => {
                    return Err(parse_error(
                        F,
                        no,
                        format!("unsupported `{}` (only `#format x_y_z_r`)", raw.trim()),
                    ));
                }
            }
        }
        if first.starts_with('#') {
            continue;
        }
        let [x, y, z, r] = toks.as_slice() else {
            return Err(parse_error(
                F,
                no,
                format!("{} fields, expected 4 (x y z r)", toks.len()),
            ));
        };
        out.push(Sphere {
            center: Point3::new(
                parse_finite(F, no, "x", x)?,
                parse_finite(F, no, "y", y)?,
                parse_finite(F, no, "z", z)?,
            ),
            radius: parse_positive(F, no, "radius", r)?,
        });
    }
    Ok(out)
}

// ------------------------------------------------------------------- CSV --

/// The CSV header of [`write_csv3`].
const CSV_HEADER: [&str; 5] = ["id", "x", "y", "z", "radius"];

/// CSV with header `id,x,y,z,radius`, ids from 1 in slice order.
///
/// # Errors
/// [`Error::NonFinite`] / [`Error::NonPositive`] for a bad sphere;
/// [`Error::Io`]. Nothing is written on a validation error.
pub fn write_csv3(spheres: &[Sphere], mut w: impl Write) -> Result<()> {
    check(spheres)?;
    writeln!(w, "{}", CSV_HEADER.join(","))?;
    for (i, s) in spheres.iter().enumerate() {
        writeln!(
            w,
            "{},{:e},{:e},{:e},{:e}",
            i + 1,
            s.center.x,
            s.center.y,
            s.center.z,
            s.radius
        )?;
    }
    Ok(())
}

/// Reads the CSV of [`write_csv3`]: the header `id,x,y,z,radius` (spaces
/// around fields allowed) on the first non-blank line, then `id,x,y,z,radius`
/// rows in any id order (the result is sorted by id); blank lines skipped.
///
/// # Errors
/// [`Error::Parse`] with the line number for invalid UTF-8, a missing or
/// different header, a row without 5 fields, a non-integer or zero id, a
/// repeated id, a non-finite value or a non-positive radius; [`Error::Io`]
/// from the reader.
pub fn read_csv3(r: impl BufRead) -> Result<Vec<Sphere>> {
    const F: &str = "csv";
    let mut lines = Lines::new(r, F);
    let mut header = false;
    let mut rows = Vec::new();
    while let Some((no, raw)) = lines.next_line()? {
        if raw.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = raw.split(',').map(str::trim).collect();
        if !header {
            if fields != CSV_HEADER {
                return Err(parse_error(
                    F,
                    no,
                    format!("header `{}`, expected `id,x,y,z,radius`", raw.trim()),
                ));
            }
            header = true;
            continue;
        }
        let [id, x, y, z, r] = fields.as_slice() else {
            return Err(parse_error(
                F,
                no,
                format!("{} fields, expected 5 (id,x,y,z,radius)", fields.len()),
            ));
        };
        let sphere = Sphere {
            center: Point3::new(
                parse_finite(F, no, "x", x)?,
                parse_finite(F, no, "y", y)?,
                parse_finite(F, no, "z", z)?,
            ),
            radius: parse_positive(F, no, "radius", r)?,
        };
        rows.push((parse_id(F, no, "id", id)?, no, sphere, ()));
    }
    if !header {
        return Err(parse_error(
            F,
            lines.line + 1,
            "missing header `id,x,y,z,radius`",
        ));
    }
    Ok(sort_by_id(F, rows)?
        .into_iter()
        .map(|(_, _, s, ())| s)
        .collect())
}

// ------------------------------------------------------------------- VTU --

/// VTK XML unstructured grid (`.vtu`, ASCII): one vertex cell per sphere,
/// point arrays `radius` and `diameter` (Float64).
///
/// In ParaView: open the file, add a Glyph filter with Glyph Type
/// *Sphere*, Scale Array *diameter* and Scale Factor 1 (the glyph source
/// has diameter 1), Glyph Mode *All Points*.
///
/// # Errors
/// [`Error::NonFinite`] / [`Error::NonPositive`] for a bad sphere or
/// diameter; [`Error::Io`]. Nothing is written on a validation error.
pub fn write_vtu3(spheres: &[Sphere], mut w: impl Write) -> Result<()> {
    check_with_diameters(spheres)?;
    packer_quadtree::write_vtu_glyphs(
        spheres.len(),
        |i| spheres[i].radius,
        |i, w| {
            let c = spheres[i].center;
            writeln!(w, "{:e} {:e} {:e}", c.x, c.y, c.z)
        },
        &mut w,
    )?;
    Ok(())
}

/// Reads back points and the `radius` point array of an ASCII VTK XML
/// unstructured grid such as [`write_vtu3`] writes.
///
/// A small parser, not a general XML one: one `VTKFile` of type
/// `UnstructuredGrid` with one `Piece`; every `DataArray` in `ascii`
/// format; the `Points` array Float32/Float64 with 3 components; a
/// Float32/Float64 `radius` array in `PointData`. Other arrays
/// (`diameter`, the cells) are skipped; XML declarations and comments are
/// ignored.
///
/// # Errors
/// [`Error::Parse`] with the line number for invalid UTF-8, malformed or
/// unbalanced tags, another file type, a second piece, binary or appended
/// data, a missing or mis-sized points or radius array, a non-finite value
/// or a non-positive radius; [`Error::Io`] from the reader.
pub fn read_vtu3(mut r: impl BufRead) -> Result<Vec<Sphere>> {
    let mut bytes = Vec::new();
    r.read_to_end(&mut bytes)?;
    let text = vtu_text(&bytes)?;
    let mut reader = VtuReader {
        stack: Vec::new(),
        seen_file: false,
        npoints: None,
        array: None,
        points: None,
        radii: None,
        values: Vec::new(),
        line: 1,
    };
    let mut pos = 0;
    while pos < text.len() {
        let rest = &text[pos..];
        pos += if let Some(body) = rest.strip_prefix("<!--") {
            reader.comment(rest, body)?
        } else if rest.starts_with('<') {
            reader.tag(rest)?
        } else {
            reader.text(rest)?
        };
    }
    reader.finish(text)
}

/// Format name of the VTU reader's errors.
const VTU: &str = "vtu";

/// The input as UTF-8, or the line of the first invalid byte.
fn vtu_text(bytes: &[u8]) -> Result<&str> {
    match std::str::from_utf8(bytes) {
        Ok(t) => Ok(t),
        Err(e) => {
            let line = 1 + bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            Err(parse_error(VTU, line, "not valid UTF-8"))
        }
    }
}

/// A `(value, line)` list and the line of its `DataArray` tag.
type VtuValues = (Vec<(f64, usize)>, usize);

/// The state of [`read_vtu3`]'s pass over the text.
struct VtuReader<'a> {
    /// Open elements and the lines of their tags.
    stack: Vec<(&'a str, usize)>,
    seen_file: bool,
    npoints: Option<usize>,
    /// The DataArray being read: what it is for and the line of its tag.
    array: Option<(VtuArray, usize)>,
    points: Option<VtuValues>,
    radii: Option<VtuValues>,
    /// Values of the array being read.
    values: Vec<(f64, usize)>,
    /// Line at the current position.
    line: usize,
}

/// The value of attribute `key`.
fn vtu_attr<'v>(attrs: &[(&str, &'v str)], key: &str) -> Option<&'v str> {
    attrs.iter().find(|(k, _)| *k == key).map(|(_, v)| *v)
}

impl<'a> VtuReader<'a> {
    /// Skips the comment at the start of `rest` (`body` after its `<!--`);
    /// returns its length.
    fn comment(&mut self, rest: &str, body: &str) -> Result<usize> {
        let Some(end) = body.find("-->") else {
            return Err(parse_error(VTU, self.line, "unterminated comment"));
        };
        let len = 4 + end + 3;
        self.line += count_newlines(&rest[..len]);
        Ok(len)
    }

    /// Reads the tag at the start of `rest` (declarations skipped); returns
    /// its length.
    fn tag(&mut self, rest: &'a str) -> Result<usize> {
        let Some(end) = rest.find('>') else {
            return Err(parse_error(VTU, self.line, "unterminated tag"));
        };
        let tag = &rest[1..end];
        let tag_line = self.line;
        self.line += count_newlines(&rest[..=end]);
        if tag.starts_with('?') {
            return Ok(end + 1);
        }
        if let Some(name) = tag.strip_prefix('/') {
            self.close(name.trim(), tag_line)?;
        } else {
            self.open(tag, tag_line)?;
        }
        Ok(end + 1)
    }

    /// A closing tag: it must close the innermost open element; a
    /// `DataArray` being read is stored.
    fn close(&mut self, name: &str, tag_line: usize) -> Result<()> {
        match self.stack.pop() {
            Some((open, _)) if open == name => {}
            Some((open, _)) => {
                return Err(parse_error(
                    VTU,
                    tag_line,
                    format!("`</{name}>` closes `<{open}>`"),
                ));
            }
            None => {
                return Err(parse_error(
                    VTU,
                    tag_line,
                    format!("`</{name}>` without an opening tag"),
                ));
            }
        }
        if name == "DataArray"
            && let Some((kind, array_line)) = self.array.take()
        {
            let vals = std::mem::take(&mut self.values);
            match kind {
                VtuArray::Points => self.points = Some((vals, array_line)),
                VtuArray::Radius => self.radii = Some((vals, array_line)),
                VtuArray::Skip => {}
            }
        }
        Ok(())
    }

    /// An opening (or self-closing) tag: checked against its parent.
    fn open(&mut self, tag: &'a str, tag_line: usize) -> Result<()> {
        let (tag, self_closing) = match tag.strip_suffix('/') {
            Some(t) => (t, true),
            None => (tag, false),
        };
        let (name, attrs) = parse_tag(VTU, tag_line, tag)?;
        let attr = |key: &str| vtu_attr(&attrs, key);
        let parent = self.stack.last().map(|(p, _)| *p);
        match (name, parent) {
            ("VTKFile", None) => {
                if self.seen_file {
                    return Err(parse_error(VTU, tag_line, "second VTKFile element"));
                }
                self.seen_file = true;
                if attr("type") != Some("UnstructuredGrid") {
                    return Err(parse_error(
                        VTU,
                        tag_line,
                        "not a VTK UnstructuredGrid file",
                    ));
                }
                if attr("compressor").is_some() {
                    return Err(parse_error(
                        VTU,
                        tag_line,
                        "compressed files are not supported",
                    ));
                }
            }
            ("UnstructuredGrid", Some("VTKFile")) => {}
            ("Piece", Some("UnstructuredGrid")) => {
                if self.npoints.is_some() {
                    return Err(parse_error(
                        VTU,
                        tag_line,
                        "more than one Piece is not supported",
                    ));
                }
                let n = attr("NumberOfPoints")
                    .ok_or_else(|| parse_error(VTU, tag_line, "Piece without NumberOfPoints"))?;
                self.npoints = Some(parse_count(VTU, tag_line, "NumberOfPoints", n)?);
            }
            ("PointData" | "CellData" | "Points" | "Cells", Some("Piece")) => {}
            ("DataArray", Some(p @ ("PointData" | "CellData" | "Points" | "Cells"))) => {
                self.data_array(p, &attrs, self_closing, tag_line)?;
            }
            _ => {
                return Err(parse_error(
                    VTU,
                    tag_line,
                    format!(
                        "unexpected element `<{name}>` in `{}`",
                        parent.unwrap_or("the document")
                    ),
                ));
            }
        }
        if !self_closing {
            self.stack.push((name, tag_line));
        }
        Ok(())
    }

    /// A `DataArray` in `parent`: ascii only; the points (3 components) and
    /// the `radius` point array (Float32/Float64, one of each) are read,
    /// others skipped.
    fn data_array(
        &mut self,
        parent: &str,
        attrs: &[(&str, &str)],
        self_closing: bool,
        tag_line: usize,
    ) -> Result<()> {
        let attr = |key: &str| vtu_attr(attrs, key);
        if attr("format") != Some("ascii") {
            return Err(parse_error(
                VTU,
                tag_line,
                "only format=\"ascii\" data arrays are supported",
            ));
        }
        let float = matches!(attr("type"), Some("Float32" | "Float64"));
        let kind = match (parent, attr("Name")) {
            ("Points", _) => {
                if attr("NumberOfComponents") != Some("3") {
                    return Err(parse_error(
                        VTU,
                        tag_line,
                        "points need NumberOfComponents=\"3\"",
                    ));
                }
                if self.points.is_some() {
                    return Err(parse_error(VTU, tag_line, "second points array"));
                }
                VtuArray::Points
            }
            ("PointData", Some("radius")) => {
                if self.radii.is_some() {
                    return Err(parse_error(VTU, tag_line, "second radius array"));
                }
                if attr("NumberOfComponents").is_some_and(|c| c != "1") {
                    return Err(parse_error(
                        VTU,
                        tag_line,
                        "the radius array needs 1 component",
                    ));
                }
                VtuArray::Radius
            }
            _ => VtuArray::Skip,
        };
        if kind != VtuArray::Skip && !float {
            return Err(parse_error(
                VTU,
                tag_line,
                "points and radius must be Float32 or Float64",
            ));
        }
        if !self_closing {
            self.array = Some((kind, tag_line));
        } else if kind == VtuArray::Points {
            self.points = Some((Vec::new(), tag_line));
        } else if kind == VtuArray::Radius {
            self.radii = Some((Vec::new(), tag_line));
        }
        Ok(())
    }

    /// Text up to the next tag: values of the array being read; returns
    /// its length.
    fn text(&mut self, rest: &str) -> Result<usize> {
        let end = rest.find('<').unwrap_or(rest.len());
        let chunk = &rest[..end];
        for (l, text_line) in (self.line..).zip(chunk.split('\n')) {
            for tok in text_line.split_whitespace() {
                match &self.array {
                    Some((VtuArray::Points | VtuArray::Radius, _)) => {
                        self.values.push((parse_finite(VTU, l, "value", tok)?, l));
                    }
                    Some((VtuArray::Skip, _)) => {}
                    None => return Err(parse_error(VTU, l, format!("unexpected text `{tok}`"))),
                }
            }
        }
        self.line += count_newlines(chunk);
        Ok(end)
    }

    /// At the end of `text`: every element closed, one piece, points and
    /// radii of the right sizes, positive radii.
    fn finish(self, text: &str) -> Result<Vec<Sphere>> {
        if let Some((open, open_line)) = self.stack.last() {
            return Err(parse_error(
                VTU,
                *open_line,
                format!("`<{open}>` is never closed"),
            ));
        }
        let eof = self.line + usize::from(!text.ends_with('\n'));
        let Some(n) = self.npoints else {
            return Err(parse_error(VTU, eof, "no Piece with NumberOfPoints"));
        };
        let Some((points, points_line)) = self.points else {
            return Err(parse_error(VTU, eof, "no Points array"));
        };
        let Some((radii, radii_line)) = self.radii else {
            return Err(parse_error(VTU, eof, "no `radius` point array"));
        };
        if n.checked_mul(3) != Some(points.len()) {
            return Err(parse_error(
                VTU,
                points_line,
                format!("{} point coordinates for {n} points", points.len()),
            ));
        }
        if radii.len() != n {
            return Err(parse_error(
                VTU,
                radii_line,
                format!("{} radii for {n} points", radii.len()),
            ));
        }
        let mut out = Vec::with_capacity(n);
        for (p, &(radius, l)) in points.chunks_exact(3).zip(&radii) {
            if radius <= 0.0 {
                return Err(parse_error(
                    VTU,
                    l,
                    format!("radius {radius} is not positive"),
                ));
            }
            out.push(Sphere {
                center: Point3::new(p[0].0, p[1].0, p[2].0),
                radius,
            });
        }
        Ok(out)
    }
}

/// What the values of the `DataArray` being read are for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum VtuArray {
    Points,
    Radius,
    Skip,
}

fn count_newlines(s: &str) -> usize {
    s.bytes().filter(|&b| b == b'\n').count()
}

/// Splits `Name key="value" key='value'` into the name and the attributes.
fn parse_tag<'a>(
    format: &'static str,
    line: usize,
    tag: &'a str,
) -> Result<(&'a str, Vec<(&'a str, &'a str)>)> {
    let tag = tag.trim();
    let name_end = tag.find(char::is_whitespace).unwrap_or(tag.len());
    let name = &tag[..name_end];
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(parse_error(
            format,
            line,
            format!("malformed tag `<{tag}>`"),
        ));
    }
    let mut attrs = Vec::new();
    let mut rest = tag[name_end..].trim_start();
    while !rest.is_empty() {
        let bad = || parse_error(format, line, format!("malformed attributes in `<{tag}>`"));
        let eq = rest.find('=').ok_or_else(bad)?;
        let key = rest[..eq].trim();
        if key.is_empty() || key.contains(char::is_whitespace) {
            return Err(bad());
        }
        let after = rest[eq + 1..].trim_start();
        let quote = after
            .chars()
            .next()
            .filter(|c| *c == '"' || *c == '\'')
            .ok_or_else(bad)?;
        let body = &after[1..];
        let close = body.find(quote).ok_or_else(bad)?;
        attrs.push((key, &body[..close]));
        rest = body[close + 1..].trim_start();
    }
    Ok((name, attrs))
}

// --------------------------------------------------------------- helpers --

fn parse_error(format: &'static str, line: usize, message: impl Into<String>) -> Error {
    Error::Parse {
        format,
        line,
        message: message.into(),
    }
}

/// Lines of a reader as UTF-8 strings without the line end (`\n` or
/// `\r\n`), numbered from 1.
struct Lines<R> {
    r: R,
    format: &'static str,
    /// Number of the last line returned (0 before the first).
    line: usize,
    buf: Vec<u8>,
}

impl<R: BufRead> Lines<R> {
    fn new(r: R, format: &'static str) -> Self {
        Self {
            r,
            format,
            line: 0,
            buf: Vec::new(),
        }
    }

    fn next_line(&mut self) -> Result<Option<(usize, String)>> {
        self.buf.clear();
        if self.r.read_until(b'\n', &mut self.buf)? == 0 {
            return Ok(None);
        }
        self.line += 1;
        if self.buf.last() == Some(&b'\n') {
            self.buf.pop();
            if self.buf.last() == Some(&b'\r') {
                self.buf.pop();
            }
        }
        match std::str::from_utf8(&self.buf) {
            Ok(s) => Ok(Some((self.line, s.to_owned()))),
            Err(_) => Err(parse_error(self.format, self.line, "not valid UTF-8")),
        }
    }
}

/// `(data, comment)`: the text before and after the first `#`.
fn split_comment(line: &str) -> (&str, &str) {
    match line.split_once('#') {
        Some((d, c)) => (d, c),
        None => (line, ""),
    }
}

fn parse_finite(format: &'static str, line: usize, what: &str, tok: &str) -> Result<f64> {
    match tok.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(parse_error(
            format,
            line,
            format!("{what} {v} is not finite"),
        )),
        Err(_) => Err(parse_error(
            format,
            line,
            format!("{what} `{tok}` is not a number"),
        )),
    }
}

fn parse_positive(format: &'static str, line: usize, what: &str, tok: &str) -> Result<f64> {
    let v = parse_finite(format, line, what, tok)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(parse_error(
            format,
            line,
            format!("{what} {v} is not positive"),
        ))
    }
}

fn parse_count<T: std::str::FromStr>(
    format: &'static str,
    line: usize,
    what: &str,
    tok: &str,
) -> Result<T> {
    tok.parse::<T>().map_err(|_| {
        parse_error(
            format,
            line,
            format!("{what} `{tok}` is not a non-negative integer"),
        )
    })
}

/// A positive integer id (LAMMPS atom ids and types start at 1).
fn parse_id(format: &'static str, line: usize, what: &str, tok: &str) -> Result<u64> {
    match tok.parse::<u64>() {
        Ok(0) => Err(parse_error(
            format,
            line,
            format!("{what} 0: ids start at 1"),
        )),
        Ok(v) => Ok(v),
        Err(_) => Err(parse_error(
            format,
            line,
            format!("{what} `{tok}` is not a positive integer"),
        )),
    }
}

/// Sorts `(id, line, sphere, extra)` rows by id; a repeated id is an error
/// at the later of its lines.
fn sort_by_id<T>(
    format: &'static str,
    mut rows: Vec<(u64, usize, Sphere, T)>,
) -> Result<Vec<(u64, usize, Sphere, T)>> {
    rows.sort_by_key(|r| (r.0, r.1));
    for pair in rows.windows(2) {
        if pair[0].0 == pair[1].0 {
            return Err(parse_error(
                format,
                pair[1].1,
                format!("id {} repeated (first on line {})", pair[1].0, pair[0].1),
            ));
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests;
