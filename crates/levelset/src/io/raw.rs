//! Raw binary label volumes (x fastest, no header) and the element codec shared with the
//! NumPy reader: streaming conversion to `u32` labels in chunks, so reading never holds the
//! file's bytes and the labels at once.

use std::io::{ErrorKind, Read, Write};
use std::str::FromStr;

use super::Dtype;
use crate::error::{Error, Result};
use crate::labels::{LabelImage, check_spacing, checked_len};

impl FromStr for Dtype {
    type Err = Error;

    /// Accepts `u8`/`uint8`, `u16`/`uint16`, `u32`/`uint32`, `i32`/`int32`, `i64`/`int64`
    /// (ASCII case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "u8" | "uint8" => Self::U8,
            "u16" | "uint16" => Self::U16,
            "u32" | "uint32" => Self::U32,
            "i32" | "int32" => Self::I32,
            "i64" | "int64" => Self::I64,
            _ => {
                return Err(Error::UnsupportedDtype {
                    name: s.to_string(),
                });
            }
        })
    }
}

/// Layout of a raw label file: `dims = [nx, ny, nz]`, x fastest, no header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RawLayout {
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Element type.
    pub dtype: Dtype,
    /// Byte order of multi-byte elements.
    pub little_endian: bool,
}

/// Bytes converted per chunk.
const CHUNK: usize = 1 << 20;
/// Labels reserved up front from a declared count (the rest grows with the data read).
const PREALLOC_LABELS: usize = 1 << 24;

/// Reads into `buf` until it is full or the stream ends; returns the bytes read.
pub(crate) fn fill(r: &mut impl Read, buf: &mut [u8]) -> Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e.into()),
        }
    }
    Ok(got)
}

/// Bytes left in the stream (read and discarded).
fn count_rest(r: &mut impl Read) -> Result<u64> {
    Ok(std::io::copy(r, &mut std::io::sink())?)
}

/// Converts one chunk of whole elements, appending to `out`.
fn convert(
    bytes: &[u8],
    dtype: Dtype,
    little: bool,
    format: &'static str,
    base: u64,
    out: &mut Vec<u32>,
) -> Result<()> {
    let bad = |pos: usize, value: i64| Error::LabelOutOfRange {
        format,
        offset: base + pos as u64,
        value,
    };
    match dtype {
        Dtype::U8 => out.extend(bytes.iter().map(|&b| u32::from(b))),
        Dtype::U16 => out.extend(bytes.chunks_exact(2).map(|c| {
            let b = [c[0], c[1]];
            u32::from(if little {
                u16::from_le_bytes(b)
            } else {
                u16::from_be_bytes(b)
            })
        })),
        Dtype::U32 => out.extend(bytes.chunks_exact(4).map(|c| {
            let b = [c[0], c[1], c[2], c[3]];
            if little {
                u32::from_le_bytes(b)
            } else {
                u32::from_be_bytes(b)
            }
        })),
        Dtype::I32 => {
            for (e, c) in bytes.chunks_exact(4).enumerate() {
                let b = [c[0], c[1], c[2], c[3]];
                let v = if little {
                    i32::from_le_bytes(b)
                } else {
                    i32::from_be_bytes(b)
                };
                out.push(u32::try_from(v).map_err(|_| bad(4 * e, v.into()))?);
            }
        }
        Dtype::I64 => {
            for (e, c) in bytes.chunks_exact(8).enumerate() {
                let b = [c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]];
                let v = if little {
                    i64::from_le_bytes(b)
                } else {
                    i64::from_be_bytes(b)
                };
                out.push(u32::try_from(v).map_err(|_| bad(8 * e, v))?);
            }
        }
    }
    Ok(())
}

/// Reads exactly `n` elements (then requires the end of the stream), converting chunk by
/// chunk. `base` is the byte offset of the first element in the stream (for errors).
pub(crate) fn read_elements(
    mut r: impl Read,
    n: usize,
    dtype: Dtype,
    little: bool,
    format: &'static str,
    base: u64,
) -> Result<Vec<u32>> {
    let size = dtype.size();
    let expected = n as u64 * size as u64;
    let mut out = Vec::with_capacity(n.min(PREALLOC_LABELS));
    let mut buf = vec![0u8; CHUNK.min(n.saturating_mul(size)).max(1)];
    let mut done: u64 = 0;
    while done < expected {
        let want = (expected - done).min(buf.len() as u64) as usize;
        let got = fill(&mut r, &mut buf[..want])?;
        if got < want {
            return Err(Error::DataSizeMismatch {
                format,
                expected,
                found: done + got as u64,
            });
        }
        convert(&buf[..got], dtype, little, format, base + done, &mut out)?;
        done += got as u64;
    }
    let rest = count_rest(&mut r)?;
    if rest > 0 {
        return Err(Error::DataSizeMismatch {
            format,
            expected,
            found: expected + rest,
        });
    }
    Ok(out)
}

/// Writes labels as `dtype` in the given byte order, in chunks.
pub(crate) fn write_elements(
    mut w: impl Write,
    labels: &[u32],
    dtype: Dtype,
    little: bool,
) -> Result<()> {
    let max = dtype.max_label();
    if let Some((index, &label)) = labels.iter().enumerate().find(|&(_, &l)| l > max) {
        return Err(Error::LabelDoesNotFit {
            label,
            index,
            dtype,
        });
    }
    let mut buf = Vec::with_capacity(CHUNK);
    for chunk in labels.chunks(CHUNK / 8) {
        buf.clear();
        for &l in chunk {
            // Fits: checked above.
            match (dtype, little) {
                (Dtype::U8, _) => buf.push(l as u8),
                (Dtype::U16, true) => buf.extend_from_slice(&(l as u16).to_le_bytes()),
                (Dtype::U16, false) => buf.extend_from_slice(&(l as u16).to_be_bytes()),
                (Dtype::U32, true) => buf.extend_from_slice(&l.to_le_bytes()),
                (Dtype::U32, false) => buf.extend_from_slice(&l.to_be_bytes()),
                (Dtype::I32, true) => buf.extend_from_slice(&(l as i32).to_le_bytes()),
                (Dtype::I32, false) => buf.extend_from_slice(&(l as i32).to_be_bytes()),
                (Dtype::I64, true) => buf.extend_from_slice(&i64::from(l).to_le_bytes()),
                (Dtype::I64, false) => buf.extend_from_slice(&i64::from(l).to_be_bytes()),
            }
        }
        w.write_all(&buf)?;
    }
    Ok(())
}

/// Reads a raw label volume (x fastest, no header) of the given layout; origin (0, 0, 0).
///
/// # Errors
/// [`Error::EmptyAxis`] / [`Error::ImageTooLarge`] for the layout (checked before reading),
/// [`Error::NonPositiveSpacing`], [`Error::DataSizeMismatch`] for a short or long stream
/// (expected and found bytes), [`Error::LabelOutOfRange`] for a negative or too large
/// signed label (with its byte offset), [`Error::Io`].
pub fn read_raw(r: impl Read, layout: &RawLayout, spacing: f64) -> Result<LabelImage> {
    let n = checked_len(layout.dims)?;
    check_spacing(spacing)?;
    let labels = read_elements(r, n, layout.dtype, layout.little_endian, "raw", 0)?;
    LabelImage::new(layout.dims, spacing, labels)
}

/// Writes the labels raw (x fastest, no header) as `dtype` in the given byte order.
///
/// # Errors
/// Invalid image; [`Error::LabelDoesNotFit`] (checked before writing anything);
/// [`Error::Io`].
pub fn write_raw(w: impl Write, img: &LabelImage, dtype: Dtype, little_endian: bool) -> Result<()> {
    img.validate()?;
    write_elements(w, &img.labels, dtype, little_endian)
}
