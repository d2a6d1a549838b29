//! NumPy `.npy` label arrays (format versions 1, 2 and 3).
//!
//! **Axis convention.** The array is indexed `[z, y, x]` (scikit-image, SPAM, tifffile,
//! `np.save` of a stack read slice by slice), whatever its memory order: shape
//! `(nz, ny, nx)` becomes `dims = [nx, ny, nz]`. A C-order array is therefore stored x
//! fastest, exactly the [`LabelImage`] layout; a Fortran-order array is stored z fastest
//! and is transposed after reading (it needs the labels twice in memory for a moment). A
//! 2-D array `(ny, nx)` is one slice (`nz = 1`).
//!
//! Element types: `|u1` (also `<u1`, `>u1`), `<u2`, `>u2`, `<u4`, `>u4`, `<i4`, `>i4`,
//! `<i8`, `>i8`; signed labels must lie in `0 ..= u32::MAX`. Anything else (`<f8`, `|b1`,
//! `<u8`, …) is [`Error::UnsupportedDtype`]. The header (at most 64 KiB, a Python dict
//! literal) is parsed strictly; the data must be exactly the declared size
//! ([`Error::DataSizeMismatch`]). Errors inside the header are [`Error::Parse`] with line 0
//! and the byte offset in the reason.

use std::io::{Read, Write};

use super::Dtype;
use super::raw::{fill, read_elements, write_elements};
use crate::error::{Error, Result};
use crate::labels::{LabelImage, check_spacing, checked_len};

const MAGIC: &[u8; 6] = b"\x93NUMPY";
/// Largest header accepted (NumPy's own default limit is 10,000 bytes).
const MAX_HEADER: usize = 1 << 16;

fn perr(offset: usize, reason: impl Into<String>) -> Error {
    Error::Parse {
        format: "npy",
        line: 0,
        reason: format!("byte {offset}: {}", reason.into()),
    }
}

/// A value of the header dict.
#[derive(Debug)]
enum Value {
    Str(String),
    Bool(bool),
    Tuple(Vec<usize>),
}

/// Minimal parser of the header's Python dict literal; `base` is the header's byte offset.
struct Header<'a> {
    s: &'a [u8],
    pos: usize,
    base: usize,
}

impl Header<'_> {
    fn err(&self, reason: impl Into<String>) -> Error {
        perr(self.base + self.pos, reason)
    }

    fn ws(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&self) -> Option<u8> {
        self.s.get(self.pos).copied()
    }

    fn expect(&mut self, c: u8) -> Result<()> {
        self.ws();
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.err(format!("expected {:?}", c as char)))
        }
    }

    fn string(&mut self) -> Result<String> {
        self.ws();
        let q = match self.peek() {
            Some(q @ (b'\'' | b'"')) => q,
            _ => return Err(self.err("expected a quoted string")),
        };
        self.pos += 1;
        let start = self.pos;
        while self.pos < self.s.len() && self.s[self.pos] != q {
            if self.s[self.pos] == b'\\' {
                return Err(self.err("escapes are not supported in header strings"));
            }
            self.pos += 1;
        }
        if self.pos >= self.s.len() {
            return Err(self.err("unterminated string"));
        }
        let text = std::str::from_utf8(&self.s[start..self.pos])
            .map_err(|_| self.err("string is not valid UTF-8"))?
            .to_string();
        self.pos += 1;
        Ok(text)
    }

    fn int(&mut self) -> Result<usize> {
        self.ws();
        let start = self.pos;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.err("expected a non-negative integer"));
        }
        let digits = std::str::from_utf8(&self.s[start..self.pos])
            .map_err(|_| self.err("invalid integer"))?;
        let v = digits
            .parse()
            .map_err(|_| self.err(format!("integer {digits} is too large")))?;
        // Python 2 long suffix.
        if self.peek() == Some(b'L') {
            self.pos += 1;
        }
        Ok(v)
    }

    fn value(&mut self) -> Result<Value> {
        self.ws();
        match self.peek() {
            Some(b'\'' | b'"') => Ok(Value::Str(self.string()?)),
            Some(b'(') => {
                self.pos += 1;
                let mut v = Vec::new();
                loop {
                    self.ws();
                    if self.peek() == Some(b')') {
                        self.pos += 1;
                        break;
                    }
                    if v.len() >= 32 {
                        return Err(self.err("shape has more than 32 axes"));
                    }
                    v.push(self.int()?);
                    self.ws();
                    match self.peek() {
                        Some(b',') => self.pos += 1,
                        Some(b')') => {}
                        _ => return Err(self.err("expected ',' or ')' in shape")),
                    }
                }
                Ok(Value::Tuple(v))
            }
            _ => {
                for (word, b) in [("True", true), ("False", false)] {
                    if self.s[self.pos..].starts_with(word.as_bytes()) {
                        self.pos += word.len();
                        return Ok(Value::Bool(b));
                    }
                }
                Err(self.err("expected a string, a tuple, True or False"))
            }
        }
    }

    fn dict(&mut self) -> Result<Vec<(String, Value)>> {
        self.expect(b'{')?;
        let mut out = Vec::new();
        loop {
            self.ws();
            if self.peek() == Some(b'}') {
                self.pos += 1;
                break;
            }
            let key = self.string()?;
            self.expect(b':')?;
            let v = self.value()?;
            out.push((key, v));
            self.ws();
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b'}') => {}
                _ => return Err(self.err("expected ',' or '}' in header dict")),
            }
        }
        self.ws();
        if self.pos != self.s.len() {
            return Err(self.err("unexpected data after the header dict"));
        }
        Ok(out)
    }
}

fn parse_descr(d: &str) -> Result<(Dtype, bool)> {
    Ok(match d {
        "|u1" | "<u1" | ">u1" | "u1" => (Dtype::U8, true),
        "<u2" => (Dtype::U16, true),
        ">u2" => (Dtype::U16, false),
        "<u4" => (Dtype::U32, true),
        ">u4" => (Dtype::U32, false),
        "<i4" => (Dtype::I32, true),
        ">i4" => (Dtype::I32, false),
        "<i8" => (Dtype::I64, true),
        ">i8" => (Dtype::I64, false),
        _ => {
            return Err(Error::UnsupportedDtype {
                name: d.to_string(),
            });
        }
    })
}

/// Reads a `.npy` label array (see the module doc for axes and types); origin (0, 0, 0).
///
/// # Errors
/// [`Error::Parse`] for a bad magic, version or header; [`Error::UnsupportedDtype`];
/// [`Error::EmptyAxis`] / [`Error::ImageTooLarge`] for the declared shape (checked before
/// any allocation); [`Error::NonPositiveSpacing`]; [`Error::DataSizeMismatch`] for
/// truncated or trailing data; [`Error::LabelOutOfRange`] (with the byte offset);
/// [`Error::Io`].
pub fn read_npy(mut r: impl Read, spacing: f64) -> Result<LabelImage> {
    check_spacing(spacing)?;
    let mut pre = [0u8; 8];
    let got = fill(&mut r, &mut pre)?;
    if got < 8 || &pre[..6] != MAGIC {
        return Err(perr(0, "not a .npy file (missing \\x93NUMPY magic)"));
    }
    let major = pre[6];
    let len_bytes = match major {
        1 => 2,
        2 | 3 => 4,
        _ => {
            return Err(perr(
                6,
                format!("unsupported .npy version {major}.{}", pre[7]),
            ));
        }
    };
    let mut lb = [0u8; 4];
    if fill(&mut r, &mut lb[..len_bytes])? < len_bytes {
        return Err(perr(8, "truncated header length"));
    }
    let hlen = u32::from_le_bytes(lb) as usize;
    if hlen > MAX_HEADER {
        return Err(perr(
            8,
            format!("header of {hlen} bytes exceeds {MAX_HEADER}"),
        ));
    }
    let base = 8 + len_bytes;
    let mut head = vec![0u8; hlen];
    let got = fill(&mut r, &mut head)?;
    if got < hlen {
        return Err(perr(
            base + got,
            format!("truncated header: {got} of {hlen} bytes"),
        ));
    }
    let entries = Header {
        s: &head,
        pos: 0,
        base,
    }
    .dict()?;
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    for (k, v) in entries {
        match (k.as_str(), v) {
            ("descr", Value::Str(s)) => descr = Some(s),
            ("fortran_order", Value::Bool(b)) => fortran = Some(b),
            ("shape", Value::Tuple(t)) => shape = Some(t),
            ("descr" | "fortran_order" | "shape", v) => {
                return Err(perr(
                    base,
                    format!("header key {k:?} has the wrong type: {v:?}"),
                ));
            }
            _ => return Err(perr(base, format!("unexpected header key {k:?}"))),
        }
    }
    let (Some(descr), Some(fortran), Some(shape)) = (descr, fortran, shape) else {
        return Err(perr(
            base,
            "header must give 'descr', 'fortran_order' and 'shape'",
        ));
    };
    let (dtype, little) = parse_descr(&descr)?;
    let dims = match shape[..] {
        [nz, ny, nx] => [nx, ny, nz],
        [ny, nx] => [nx, ny, 1],
        _ => {
            return Err(perr(
                base,
                format!(
                    "array of rank {} (shape {shape:?}); expected 3 (z, y, x) or 2 (y, x)",
                    shape.len()
                ),
            ));
        }
    };
    let n = checked_len(dims)?;
    let data_offset = (base + hlen) as u64;
    let stream = read_elements(r, n, dtype, little, "npy", data_offset)?;
    let labels = if fortran {
        transpose_fortran(&stream, dims)
    } else {
        stream
    };
    LabelImage::new(dims, spacing, labels)
}

/// Fortran-order `[z, y, x]` data (z fastest: element `(x, y, z)` at `z + nz·(y + ny·x)`)
/// into the x-fastest layout, in 32 × 32 tiles of (x, z) for each y.
fn transpose_fortran(src: &[u32], dims: [usize; 3]) -> Vec<u32> {
    let [nx, ny, nz] = dims;
    let mut dst = vec![0u32; src.len()];
    const T: usize = 32;
    for y in 0..ny {
        for x0 in (0..nx).step_by(T) {
            for z0 in (0..nz).step_by(T) {
                for x in x0..(x0 + T).min(nx) {
                    for z in z0..(z0 + T).min(nz) {
                        dst[x + nx * (y + ny * z)] = src[z + nz * (y + ny * x)];
                    }
                }
            }
        }
    }
    dst
}

/// Writes a `.npy` (version 1.0, C order, little-endian) of shape `(nz, ny, nx)`.
///
/// # Errors
/// Invalid image; [`Error::LabelDoesNotFit`] if a label exceeds `dtype` (checked before
/// writing anything); [`Error::Io`].
pub fn write_npy(mut w: impl Write, img: &LabelImage, dtype: Dtype) -> Result<()> {
    img.validate()?;
    let descr = match dtype {
        Dtype::U8 => "|u1",
        Dtype::U16 => "<u2",
        Dtype::U32 => "<u4",
        Dtype::I32 => "<i4",
        Dtype::I64 => "<i8",
    };
    let max = dtype.max_label();
    if let Some((index, &label)) = img.labels.iter().enumerate().find(|&(_, &l)| l > max) {
        return Err(Error::LabelDoesNotFit {
            label,
            index,
            dtype,
        });
    }
    let [nx, ny, nz] = img.dims;
    let mut h =
        format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': ({nz}, {ny}, {nx}), }}");
    // Magic + version + u16 length + header, padded with spaces to a multiple of 64, '\n'.
    let total = (10 + h.len() + 1).div_ceil(64) * 64;
    while 10 + h.len() + 1 < total {
        h.push(' ');
    }
    h.push('\n');
    let hlen = u16::try_from(h.len()).map_err(|_| Error::InvalidParameter {
        name: "npy header length",
        value: h.len() as f64,
        requirement: "below 65536 bytes",
    })?;
    let mut pre = Vec::with_capacity(10 + h.len());
    pre.extend_from_slice(MAGIC);
    pre.extend_from_slice(&[1, 0]);
    pre.extend_from_slice(&hlen.to_le_bytes());
    pre.extend_from_slice(h.as_bytes());
    w.write_all(&pre)?;
    write_elements(w, &img.labels, dtype, true)
}
