//! Readers and writers over `BufRead` / `Write`: LS-DEM morph files, LAMMPS LSDEM grid
//! files, VTK legacy structured points (ParaView), surface meshes as STL (binary and ASCII) and
//! Wavefront OBJ; labelled 3D
//! images ([`crate::LabelImage`]) as NumPy `.npy` ([`read_npy`]), multi-page TIFF stacks
//! ([`read_tiff`], over `Read + Seek`) and raw binary ([`read_raw`]).
//!
//! Label readers stream: elements are converted to `u32` in 1 MiB chunks (TIFF: page by
//! page), declared sizes are checked against [`crate::labels::MAX_VOXELS`] before anything
//! is allocated, and at most 2²⁴ labels are reserved from a header before the data arrive.
//! They never panic on any byte string (proptests in `io/tests.rs`).
//!
//! Writers print floats with Rust's shortest round-trip representation (switching to
//! exponent notation outside 1e-4 ≤ |x| < 1e15), so every text writer round-trips exactly.
//! Readers never trust declared counts for allocation, and report the 1-based line of the
//! first problem ([`crate::Error::Parse`]); binary STL errors report line 0 and a byte
//! offset in the reason.
//!
//! Mesh readers return the mesh as the file has it (STL welded, since it has no shared
//! vertices; degenerate facets kept). A user's grain goes through
//! [`crate::TriMesh::prepare_closed`] next, which repairs or refuses orientation and
//! names what is wrong with an open or non-manifold mesh; the caller adds the file name.

pub(crate) mod dtype;
mod lammps;
pub mod lsdem;
mod morph;
mod npy;
mod obj;
mod raw;
mod stl;
mod tiff_stack;
mod vtk;

pub use dtype::Dtype;
pub use lammps::{read_lammps, write_lammps};
pub use lsdem::{PrincipalMorph, principal_morph};
pub use morph::{MorphFile, read_morph, write_morph, write_morph_decimals};
pub use npy::{read_npy, write_npy};
pub use obj::{read_obj, write_obj};
pub use raw::{RawLayout, read_raw, write_raw};
pub use stl::{read_stl, write_stl_ascii, write_stl_binary};
pub use tiff_stack::{read_tiff, write_tiff};
pub use vtk::{read_vtk, write_vtk};

use std::fmt::Write as _;
use std::io::BufRead;

use crate::error::{Error, Result};

/// Largest capacity reserved up front from a declared count.
const MAX_PREALLOC: usize = 1 << 20;

/// Shortest round-trip text of a float.
pub(crate) fn fmt_f64(out: &mut String, x: f64) {
    let a = x.abs();
    if x == 0.0 || (1e-4..1e15).contains(&a) {
        let _ = write!(out, "{x}");
    } else {
        let _ = write!(out, "{x:e}");
    }
}

/// Whitespace-separated tokens with their 1-based line numbers.
pub(crate) struct Tokens<R> {
    reader: R,
    format: &'static str,
    line: usize,
    buf: Vec<u8>,
    tokens: Vec<String>,
    pos: usize,
    lossy: bool,
}

impl<R: BufRead> Tokens<R> {
    pub(crate) fn new(reader: R, format: &'static str) -> Self {
        Self {
            reader,
            format,
            line: 0,
            buf: Vec::new(),
            tokens: Vec::new(),
            pos: 0,
            lossy: false,
        }
    }

    /// Accepts lines that are not UTF-8, replacing invalid bytes by U+FFFD (for formats
    /// whose free-text fields, such as an STL solid name, may be in another encoding; a
    /// replaced byte inside a number still fails to parse).
    pub(crate) fn lossy(mut self) -> Self {
        self.lossy = true;
        self
    }

    pub(crate) fn err(&self, reason: impl Into<String>) -> Error {
        Error::Parse {
            format: self.format,
            line: self.line.max(1),
            reason: reason.into(),
        }
    }

    /// Reads the next raw line (without the line break); `None` at end of input.
    pub(crate) fn next_line(&mut self) -> Result<Option<String>> {
        self.buf.clear();
        let n = self.reader.read_until(b'\n', &mut self.buf)?;
        if n == 0 {
            return Ok(None);
        }
        self.line += 1;
        let s = match std::str::from_utf8(&self.buf) {
            Ok(s) => std::borrow::Cow::Borrowed(s),
            Err(_) if self.lossy => String::from_utf8_lossy(&self.buf),
            Err(_) => return Err(self.err("line is not valid UTF-8")),
        };
        Ok(Some(s.trim_end_matches(['\n', '\r']).to_string()))
    }

    /// Next token, crossing line breaks; `None` at end of input.
    pub(crate) fn next_token(&mut self) -> Result<Option<String>> {
        loop {
            if self.pos < self.tokens.len() {
                self.pos += 1;
                return Ok(Some(std::mem::take(&mut self.tokens[self.pos - 1])));
            }
            match self.next_line()? {
                None => return Ok(None),
                Some(l) => {
                    self.tokens = l.split_ascii_whitespace().map(str::to_string).collect();
                    self.pos = 0;
                }
            }
        }
    }

    /// Drops the tokens left on the current line.
    pub(crate) fn skip_rest_of_line(&mut self) {
        self.pos = self.tokens.len();
    }

    /// Next token or an error naming what was expected.
    pub(crate) fn expect(&mut self, what: &str) -> Result<String> {
        match self.next_token()? {
            Some(t) => Ok(t),
            None => Err(self.err(format!("unexpected end of input, expected {what}"))),
        }
    }

    pub(crate) fn f64(&mut self, what: &str) -> Result<f64> {
        let t = self.expect(what)?;
        let v: f64 = t
            .parse()
            .map_err(|_| self.err(format!("expected {what}, found {t:?}")))?;
        if !v.is_finite() {
            return Err(self.err(format!("{what} is not finite: {t:?}")));
        }
        Ok(v)
    }

    pub(crate) fn usize(&mut self, what: &str) -> Result<usize> {
        let t = self.expect(what)?;
        t.parse().map_err(|_| {
            self.err(format!(
                "expected {what} (a non-negative integer), found {t:?}"
            ))
        })
    }

    /// Errors if any token is left.
    pub(crate) fn finish(&mut self) -> Result<()> {
        match self.next_token()? {
            None => Ok(()),
            Some(t) => Err(self.err(format!("unexpected trailing data {t:?}"))),
        }
    }

    pub(crate) fn line(&self) -> usize {
        self.line
    }
}

/// Reads grid dimensions and checks them the way [`crate::GridSpec::validate`] does, as a parse
/// error with the line number.
pub(crate) fn read_dims<R: BufRead>(t: &mut Tokens<R>) -> Result<[usize; 3]> {
    let dims = [t.usize("nx")?, t.usize("ny")?, t.usize("nz")?];
    for (axis, &n) in dims.iter().enumerate() {
        if n < 3 {
            return Err(t.err(format!(
                "axis {axis} has {n} nodes; at least 3 are required"
            )));
        }
    }
    let total = dims[0]
        .checked_mul(dims[1])
        .and_then(|v| v.checked_mul(dims[2]));
    if total.is_none_or(|v| v > (1usize << 31)) {
        return Err(t.err(format!("grid of {dims:?} nodes is too large")));
    }
    Ok(dims)
}

/// Reads `n` finite values.
pub(crate) fn read_values<R: BufRead>(t: &mut Tokens<R>, n: usize) -> Result<Vec<f64>> {
    let mut v = Vec::with_capacity(n.min(MAX_PREALLOC));
    for _ in 0..n {
        v.push(t.f64("level-set value")?);
    }
    Ok(v)
}

#[cfg(test)]
mod tests;
