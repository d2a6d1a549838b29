//! Label image formats: round trips, axis conventions, malformed input, no-panic properties.

use super::super::*;
use crate::error::Error;
use crate::labels::{LabelImage, MAX_VOXELS};
use proptest::prelude::*;
use std::io::Cursor;
use tiff::encoder::{Compression, DeflateLevel, TiffEncoder, colortype};

/// A 5 × 4 × 3 image whose label encodes its position (x + 10 y + 100 z), plus `extra`.
fn coded(extra: u32) -> LabelImage {
    let dims = [5, 4, 3];
    let mut labels = Vec::new();
    for z in 0..3u32 {
        for y in 0..4u32 {
            for x in 0..5u32 {
                labels.push(x + 10 * y + 100 * z + extra);
            }
        }
    }
    LabelImage::new(dims, 0.5, labels).expect("image")
}

/// A hand-written npy: header dict text and raw data.
fn npy(version: u8, dict: &str, data: &[u8]) -> Vec<u8> {
    let mut h = dict.to_string();
    let pre = if version == 1 { 10 } else { 12 };
    while !(pre + h.len() + 1).is_multiple_of(64) {
        h.push(' ');
    }
    h.push('\n');
    let mut out = b"\x93NUMPY".to_vec();
    out.extend_from_slice(&[version, 0]);
    if version == 1 {
        out.extend_from_slice(&(h.len() as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&(h.len() as u32).to_le_bytes());
    }
    out.extend_from_slice(h.as_bytes());
    out.extend_from_slice(data);
    out
}

#[test]
fn dtype_names() {
    for (s, d) in [
        ("u8", Dtype::U8),
        ("uint8", Dtype::U8),
        ("UINT16", Dtype::U16),
        ("u32", Dtype::U32),
        ("int32", Dtype::I32),
        ("i64", Dtype::I64),
    ] {
        assert_eq!(s.parse::<Dtype>().expect("dtype"), d);
        assert_eq!(d.to_string().parse::<Dtype>().expect("round trip"), d);
    }
    assert!(matches!(
        "f64".parse::<Dtype>(),
        Err(Error::UnsupportedDtype { .. })
    ));
    assert_eq!(Dtype::smallest_for(255), Dtype::U8);
    assert_eq!(Dtype::smallest_for(256), Dtype::U16);
    assert_eq!(Dtype::smallest_for(70_000), Dtype::U32);
}

#[test]
fn npy_round_trips_every_dtype() {
    let img = coded(0);
    for d in [Dtype::U8, Dtype::U16, Dtype::U32, Dtype::I32, Dtype::I64] {
        let mut buf = Vec::new();
        write_npy(&mut buf, &img, d).expect("write");
        assert_eq!(buf.len(), 128 + img.len() * d.size(), "header padded to 64");
        let back = read_npy(buf.as_slice(), 0.5).expect("read");
        assert_eq!(back, img, "{d}");
    }
    let big = coded(70_000);
    let mut buf = Vec::new();
    assert!(matches!(
        write_npy(&mut buf, &big, Dtype::U16),
        Err(Error::LabelDoesNotFit {
            label: 70_000,
            index: 0,
            dtype: Dtype::U16
        })
    ));
    assert!(buf.is_empty(), "nothing written before the check");
}

#[test]
fn npy_orders_versions_and_byte_orders_agree() {
    let img = coded(0);
    let [nx, ny, nz] = img.dims;
    // C order [z, y, x] = the image's own layout; Fortran order: z fastest.
    let c: Vec<u8> = img
        .labels
        .iter()
        .flat_map(|&l| (l as u16).to_le_bytes())
        .collect();
    let mut f = Vec::new();
    for x in 0..nx {
        for y in 0..ny {
            for z in 0..nz {
                f.extend_from_slice(&(img.labels[img.index(x, y, z)] as u16).to_le_bytes());
            }
        }
    }
    let shape = format!("({nz}, {ny}, {nx})");
    for v in [1, 2, 3] {
        let cf = npy(
            v,
            &format!("{{'descr': '<u2', 'fortran_order': False, 'shape': {shape}, }}"),
            &c,
        );
        let ff = npy(
            v,
            &format!("{{\"descr\": \"<u2\", \"fortran_order\": True, \"shape\": {shape}}}"),
            &f,
        );
        assert_eq!(read_npy(cf.as_slice(), 0.5).expect("c"), img);
        assert_eq!(read_npy(ff.as_slice(), 0.5).expect("f"), img);
    }
    // Big-endian i8 and u4.
    let be8: Vec<u8> = img
        .labels
        .iter()
        .flat_map(|&l| i64::from(l).to_be_bytes())
        .collect();
    let b = npy(
        1,
        &format!("{{'descr': '>i8', 'fortran_order': False, 'shape': {shape}, }}"),
        &be8,
    );
    assert_eq!(read_npy(b.as_slice(), 0.5).expect("be"), img);
    let be4: Vec<u8> = img.labels.iter().flat_map(|&l| l.to_be_bytes()).collect();
    let b = npy(
        1,
        &format!("{{'descr': '>u4', 'fortran_order': False, 'shape': {shape}, }}"),
        &be4,
    );
    assert_eq!(read_npy(b.as_slice(), 0.5).expect("be"), img);
    // 2-D: one slice.
    let b = npy(
        1,
        "{'descr': '|u1', 'fortran_order': False, 'shape': (2, 3), }",
        &[1, 2, 3, 4, 5, 6],
    );
    let s = read_npy(b.as_slice(), 1.0).expect("2d");
    assert_eq!((s.dims, s.labels[s.index(2, 1, 0)]), ([3, 2, 1], 6));
    let b = npy(
        1,
        "{'descr': '|u1', 'fortran_order': True, 'shape': (2, 3), }",
        &[1, 4, 2, 5, 3, 6],
    );
    assert_eq!(read_npy(b.as_slice(), 1.0).expect("2d f"), s);
}

#[test]
fn npy_bad_input() {
    let img = coded(0);
    let mut good = Vec::new();
    write_npy(&mut good, &img, Dtype::U16).expect("write");
    // Truncated data, trailing data.
    assert!(matches!(
        read_npy(&good[..good.len() - 1], 1.0),
        Err(Error::DataSizeMismatch {
            format: "npy",
            expected: 120,
            found: 119
        })
    ));
    let mut long = good.clone();
    long.extend_from_slice(&[0, 0, 0]);
    assert!(matches!(
        read_npy(long.as_slice(), 1.0),
        Err(Error::DataSizeMismatch {
            expected: 120,
            found: 123,
            ..
        })
    ));
    // Truncated header, bad magic.
    for cut in [0, 5, 9, 60] {
        assert!(
            matches!(read_npy(&good[..cut], 1.0), Err(Error::Parse { .. })),
            "cut {cut}"
        );
    }
    assert!(matches!(
        read_npy(&b"PK\x03\x04 zip"[..], 1.0),
        Err(Error::Parse { .. })
    ));
    // Wrong dtype.
    let f8 = npy(
        1,
        "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1, 1), }",
        &[0; 8],
    );
    match read_npy(f8.as_slice(), 1.0) {
        Err(Error::UnsupportedDtype { name }) => assert_eq!(name, "<f8"),
        other => panic!("expected UnsupportedDtype, got {other:?}"),
    }
    // Negative label: error names the byte offset (128-byte header + 2 elements · 4 bytes).
    let mut data = Vec::new();
    for v in [1i32, 2, -5, 4] {
        data.extend_from_slice(&v.to_le_bytes());
    }
    let neg = npy(
        1,
        "{'descr': '<i4', 'fortran_order': False, 'shape': (1, 2, 2), }",
        &data,
    );
    assert!(matches!(
        read_npy(neg.as_slice(), 1.0),
        Err(Error::LabelOutOfRange {
            format: "npy",
            offset: 136,
            value: -5
        })
    ));
    let mut data = Vec::new();
    for v in [1i64, 1 << 40] {
        data.extend_from_slice(&v.to_le_bytes());
    }
    let big = npy(
        1,
        "{'descr': '<i8', 'fortran_order': False, 'shape': (1, 1, 2), }",
        &data,
    );
    assert!(matches!(
        read_npy(big.as_slice(), 1.0),
        Err(Error::LabelOutOfRange {
            offset: 136,
            value: 1_099_511_627_776,
            ..
        })
    ));
    // Absurd shapes: rejected before any allocation.
    for shape in [
        "(100000, 100000, 100000)",
        "(99999999999999999999, 1, 1)",
        "(0, 3, 3)",
        "(2, 2, 2, 2)",
        "(5,)",
    ] {
        let h = npy(
            1,
            &format!("{{'descr': '<u2', 'fortran_order': False, 'shape': {shape}, }}"),
            &[],
        );
        let e = read_npy(h.as_slice(), 1.0).expect_err(shape);
        assert!(
            matches!(
                e,
                Error::ImageTooLarge { .. } | Error::EmptyAxis { .. } | Error::Parse { .. }
            ),
            "{shape}: {e}"
        );
    }
    // Missing key, unknown key, wrong type, garbage after the dict.
    for dict in [
        "{'descr': '<u2', 'shape': (1, 1, 1), }",
        "{'descr': '<u2', 'fortran_order': False, 'shape': (1, 1, 1), 'x': 1}",
        "{'descr': '<u2', 'fortran_order': 0, 'shape': (1, 1, 1), }",
        "{'descr': '<u2', 'fortran_order': False, 'shape': (1, 1, 1), } x",
        "{'descr': '<u2 , 'fortran_order': False, 'shape': (1, 1, 1), }",
    ] {
        assert!(
            matches!(
                read_npy(npy(1, dict, &[0, 0]).as_slice(), 1.0),
                Err(Error::Parse { .. })
            ),
            "{dict}"
        );
    }
    for s in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            read_npy(good.as_slice(), s),
            Err(Error::NonPositiveSpacing { .. })
        ));
    }
}

#[test]
fn raw_round_trips_and_size_errors() {
    let img = coded(0);
    for d in [Dtype::U8, Dtype::U16, Dtype::U32, Dtype::I32, Dtype::I64] {
        for little_endian in [true, false] {
            let mut buf = Vec::new();
            write_raw(&mut buf, &img, d, little_endian).expect("write");
            let layout = RawLayout {
                dims: img.dims,
                dtype: d,
                little_endian,
            };
            assert_eq!(read_raw(buf.as_slice(), &layout, 0.5).expect("read"), img);
            assert!(matches!(
                read_raw(&buf[..buf.len() - 1], &layout, 0.5),
                Err(Error::DataSizeMismatch { format: "raw", expected, found })
                    if expected == buf.len() as u64 && found == expected - 1
            ));
            buf.push(0);
            assert!(matches!(
                read_raw(buf.as_slice(), &layout, 0.5),
                Err(Error::DataSizeMismatch { expected, found, .. }) if found == expected + 1
            ));
        }
    }
    let layout = RawLayout {
        dims: [1 << 20, 1 << 20, 1 << 20],
        dtype: Dtype::U8,
        little_endian: true,
    };
    assert!(matches!(
        read_raw(&[0u8; 4][..], &layout, 1.0),
        Err(Error::ImageTooLarge {
            max_voxels: MAX_VOXELS,
            ..
        })
    ));
}

#[test]
fn tiff_round_trips_u16_u32_and_compressions() {
    for extra in [0, 70_000] {
        let img = coded(extra);
        let mut buf = Cursor::new(Vec::new());
        write_tiff(&mut buf, &img).expect("write");
        buf.set_position(0);
        assert_eq!(read_tiff(&mut buf, 0.5).expect("read"), img);
    }
    // Files written by other tools: 8-bit pages, LZW, Deflate, PackBits, signed 32-bit.
    let img = coded(0);
    let compressions = [
        Compression::Uncompressed,
        Compression::Lzw,
        Compression::Deflate(DeflateLevel::Balanced),
        Compression::Packbits,
    ];
    for comp in compressions {
        let mut buf = Cursor::new(Vec::new());
        {
            let mut enc = TiffEncoder::new(&mut buf)
                .expect("enc")
                .with_compression(comp);
            for page in img.labels.chunks(20) {
                let p: Vec<u8> = page.iter().map(|&l| l as u8).collect();
                enc.write_image::<colortype::Gray8>(5, 4, &p).expect("page");
            }
        }
        buf.set_position(0);
        assert_eq!(read_tiff(&mut buf, 0.5).expect("read"), img);
    }
    let mut buf = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut buf).expect("enc");
        for page in img.labels.chunks(20) {
            let p: Vec<i32> = page.iter().map(|&l| l as i32).collect();
            enc.write_image::<colortype::GrayI32>(5, 4, &p)
                .expect("page");
        }
        enc.write_image::<colortype::GrayI32>(5, 4, &[-1; 20])
            .expect("page");
    }
    buf.set_position(0);
    match read_tiff(&mut buf, 0.5) {
        Err(Error::Tiff { page: 3, reason }) => assert!(reason.contains("negative"), "{reason}"),
        other => panic!("expected a negative-label error on page 3, got {other:?}"),
    }
}

#[test]
fn tiff_unsupported_layouts_name_the_page() {
    // RGB page.
    let mut buf = Cursor::new(Vec::new());
    TiffEncoder::new(&mut buf)
        .expect("enc")
        .write_image::<colortype::RGB8>(2, 2, &[0; 12])
        .expect("rgb");
    buf.set_position(0);
    match read_tiff(&mut buf, 1.0) {
        Err(Error::Tiff { page: 0, reason }) => assert!(reason.contains("RGB"), "{reason}"),
        other => panic!("expected an RGB layout error, got {other:?}"),
    }
    // Float page after a good one; pages of different sizes.
    let mut buf = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut buf).expect("enc");
        enc.write_image::<colortype::Gray16>(2, 2, &[1; 4])
            .expect("p0");
        enc.write_image::<colortype::Gray32Float>(2, 2, &[1.0; 4])
            .expect("p1");
    }
    buf.set_position(0);
    match read_tiff(&mut buf, 1.0) {
        Err(Error::Tiff { page: 1, reason }) => assert!(reason.contains("float"), "{reason}"),
        other => panic!("expected a float error on page 1, got {other:?}"),
    }
    let mut buf = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut buf).expect("enc");
        enc.write_image::<colortype::Gray16>(2, 2, &[1; 4])
            .expect("p0");
        enc.write_image::<colortype::Gray16>(3, 2, &[1; 6])
            .expect("p1");
    }
    buf.set_position(0);
    match read_tiff(&mut buf, 1.0) {
        Err(Error::Tiff { page: 1, reason }) => assert!(reason.contains("3 × 2"), "{reason}"),
        other => panic!("expected a size error on page 1, got {other:?}"),
    }
    assert!(matches!(
        read_tiff(Cursor::new(b"not a tiff".to_vec()), 1.0),
        Err(Error::Tiff { page: 0, .. })
    ));
}

fn valid_files() -> Vec<Vec<u8>> {
    let img = coded(0);
    let mut n = Vec::new();
    write_npy(&mut n, &img, Dtype::U16).expect("npy");
    let mut i = Vec::new();
    write_npy(&mut i, &img, Dtype::I32).expect("npy");
    let mut t = Cursor::new(Vec::new());
    write_tiff(&mut t, &img).expect("tiff");
    let mut l = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut l)
            .expect("enc")
            .with_compression(Compression::Lzw);
        for page in img.labels.chunks(20) {
            let p: Vec<u16> = page.iter().map(|&v| v as u16).collect();
            enc.write_image::<colortype::Gray16>(5, 4, &p)
                .expect("page");
        }
    }
    vec![n, i, t.into_inner(), l.into_inner()]
}

fn read_all(data: &[u8]) {
    let _ = read_npy(data, 1.0);
    let _ = read_tiff(Cursor::new(data), 1.0);
    let layout = RawLayout {
        dims: [5, 4, 3],
        dtype: Dtype::I64,
        little_endian: false,
    };
    let _ = read_raw(data, &layout, 1.0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(data in proptest::collection::vec(any::<u8>(), 0..600)) {
        read_all(&data);
        // Also behind a valid magic.
        let mut n = b"\x93NUMPY\x01\x00".to_vec();
        n.extend_from_slice(&data);
        let _ = read_npy(n.as_slice(), 1.0);
        let mut t = b"II*\x00\x08\x00\x00\x00".to_vec();
        t.extend_from_slice(&data);
        let _ = read_tiff(Cursor::new(t), 1.0);
    }

    #[test]
    fn mutated_and_truncated_label_files_never_panic(
        which in 0usize..4,
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..4),
        cut in any::<usize>(),
    ) {
        let mut f = valid_files().swap_remove(which);
        for (pos, byte) in edits {
            let p = pos % f.len();
            f[p] = byte;
        }
        read_all(&f);
        let c = cut % (f.len() + 1);
        read_all(&f[..c]);
    }
}
