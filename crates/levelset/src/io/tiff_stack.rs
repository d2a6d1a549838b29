//! Multi-page TIFF label stacks (ImageJ/Fiji, tifffile, Avizo), through the `tiff` crate
//! (image-rs).
//!
//! One page per z slice, page 0 first; every page must have the size of page 0. Pages are
//! single-sample grayscale (BlackIsZero) or palette images (Fiji writes label images with a
//! colour LUT as palette TIFFs: the indices are the labels) of 8, 16 or 32 unsigned bits, or
//! 32-bit signed with non-negative values; strips or tiles; uncompressed, PackBits, LZW or
//! Deflate. Everything else (RGB, float, WhiteIsZero, other bit depths, extra samples,
//! JPEG…) is an [`Error::Tiff`] naming the page and the layout found. Pages are decoded one
//! at a time, so memory stays at the labels plus one page.
//!
//! The writer stores unsigned 16-bit pages when the largest label fits, else 32-bit,
//! uncompressed, one strip per page; Fiji opens the file as a z stack.

use std::io::{Read, Seek, Write};

use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult};
use tiff::encoder::{TiffEncoder, colortype};
use tiff::tags::Tag;

use crate::error::{Error, Result};
use crate::labels::{LabelImage, MAX_VOXELS, check_spacing};

fn terr(page: usize, reason: impl Into<String>) -> Error {
    Error::Tiff {
        page,
        reason: reason.into(),
    }
}

/// Appends one decoded page, checking the sample type.
fn append(page: usize, data: DecodingResult, layout: &str, out: &mut Vec<u32>) -> Result<()> {
    match data {
        DecodingResult::U8(v) => out.extend(v.iter().map(|&x| u32::from(x))),
        DecodingResult::U16(v) => out.extend(v.iter().map(|&x| u32::from(x))),
        DecodingResult::U32(v) => out.extend_from_slice(&v),
        DecodingResult::I32(v) => {
            for (i, &x) in v.iter().enumerate() {
                out.push(u32::try_from(x).map_err(|_| {
                    terr(page, format!("negative label {x} at pixel {i} ({layout})"))
                })?);
            }
        }
        other => {
            let kind = match other {
                DecodingResult::U64(_) => "unsigned 64-bit",
                DecodingResult::F16(_) | DecodingResult::F32(_) | DecodingResult::F64(_) => {
                    "floating-point"
                }
                DecodingResult::I8(_) | DecodingResult::I16(_) => "signed 8/16-bit",
                _ => "signed 64-bit",
            };
            return Err(terr(
                page,
                format!(
                    "unsupported {kind} samples ({layout}); labels need 8, 16 or 32-bit unsigned or 32-bit signed integers"
                ),
            ));
        }
    }
    Ok(())
}

/// Reads a multi-page TIFF label stack (page = z slice); origin (0, 0, 0). Wrap files in a
/// `BufReader`.
///
/// # Errors
/// [`Error::NonPositiveSpacing`]; [`Error::Tiff`] (page and layout) for an unreadable file,
/// an unsupported layout, a page of another size, a negative label;
/// [`Error::ImageTooLarge`] beyond [`MAX_VOXELS`].
pub fn read_tiff(r: impl Read + Seek, spacing: f64) -> Result<LabelImage> {
    check_spacing(spacing)?;
    let mut dec = Decoder::new(r).map_err(|e| terr(0, format!("not a readable TIFF: {e}")))?;
    let mut labels = Vec::new();
    let (mut nx, mut ny) = (0usize, 0usize);
    let mut page = 0usize;
    loop {
        let (w, h) = dec
            .dimensions()
            .map_err(|e| terr(page, format!("no dimensions: {e}")))?;
        let (w, h) = (w as usize, h as usize);
        if page == 0 {
            (nx, ny) = (w, h);
        } else if (w, h) != (nx, ny) {
            return Err(terr(
                page,
                format!("page is {w} × {h} pixels but page 0 is {nx} × {ny}"),
            ));
        }
        if w == 0 || h == 0 {
            return Err(terr(page, format!("page has {w} × {h} pixels")));
        }
        let voxels = (w as u64) * (h as u64) * (page as u64 + 1);
        if voxels > MAX_VOXELS {
            return Err(Error::ImageTooLarge {
                dims: [w, h, page + 1],
                max_voxels: MAX_VOXELS,
            });
        }
        let ct = dec
            .colortype()
            .map_err(|e| terr(page, format!("unsupported layout: {e}")))?;
        let photometric: Option<u16> = dec
            .find_tag_unsigned(Tag::PhotometricInterpretation)
            .map_err(|e| terr(page, format!("bad PhotometricInterpretation: {e}")))?;
        let layout = format!("{ct:?}, photometric {photometric:?}, {w} × {h}");
        let ok_ct = matches!(
            ct,
            ColorType::Gray(8 | 16 | 32) | ColorType::Palette(8 | 16)
        );
        if !ok_ct || photometric == Some(0) {
            return Err(terr(
                page,
                format!(
                    "unsupported layout {layout}; labels need one grayscale (BlackIsZero) or palette sample of 8, 16 or 32 bits"
                ),
            ));
        }
        let data = dec
            .read_image()
            .map_err(|e| terr(page, format!("cannot decode ({layout}): {e}")))?;
        let before = labels.len();
        append(page, data, &layout, &mut labels)?;
        if labels.len() - before != w * h {
            return Err(terr(
                page,
                format!(
                    "decoded {} samples, expected {w} × {h} ({layout})",
                    labels.len() - before
                ),
            ));
        }
        page += 1;
        if !dec.more_images() {
            break;
        }
        dec.next_image()
            .map_err(|e| terr(page, format!("cannot read the directory: {e}")))?;
    }
    LabelImage::new([nx, ny, page], spacing, labels)
}

/// Writes a multi-page TIFF (page = z slice), unsigned 16-bit when the largest label fits,
/// else 32-bit, uncompressed.
///
/// # Errors
/// Invalid image; [`Error::InvalidParameter`] if nx or ny exceeds `u32`; [`Error::Tiff`]
/// when encoding fails (page given).
pub fn write_tiff(w: impl Write + Seek, img: &LabelImage) -> Result<()> {
    img.validate()?;
    let [nx, ny, nz] = img.dims;
    let side = |n: usize| {
        u32::try_from(n).map_err(|_| Error::InvalidParameter {
            name: "tiff page side",
            value: n as f64,
            requirement: "at most 2^32 − 1 pixels",
        })
    };
    let (w32, h32) = (side(nx)?, side(ny)?);
    let wide = img.max_label() > u32::from(u16::MAX);
    let mut enc = TiffEncoder::new(w).map_err(|e| terr(0, format!("cannot start: {e}")))?;
    let slice = nx * ny;
    for (z, page) in img.labels.chunks_exact(slice).enumerate().take(nz) {
        let res = if wide {
            enc.write_image::<colortype::Gray32>(w32, h32, page)
        } else {
            // Fits: the largest label is at most u16::MAX.
            let buf: Vec<u16> = page.iter().map(|&l| l as u16).collect();
            enc.write_image::<colortype::Gray16>(w32, h32, &buf)
        };
        res.map_err(|e| terr(z, format!("cannot encode: {e}")))?;
    }
    Ok(())
}
