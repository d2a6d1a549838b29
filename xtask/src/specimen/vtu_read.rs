//! Reads back the specimen VTU (tests): the inverse of `specimen::outputs::VtuWriter`.

/// A VTU of `VtuWriter` read back: per piece, the point, triangle and
/// grain-id arrays (tests only).
pub(crate) struct VtuPiece {
    pub(crate) points: Vec<[f32; 3]>,
    pub(crate) connectivity: Vec<i32>,
    pub(crate) offsets: Vec<i32>,
    pub(crate) types: Vec<u8>,
    pub(crate) grain_ids: Vec<i32>,
}

/// Reads back a VTU written by `VtuWriter` (tests only): checks the
/// header counts of every array and the piece's declared sizes.
pub(crate) fn read_vtu(text: &str) -> anyhow::Result<Vec<VtuPiece>> {
    use anyhow::{bail, ensure};
    // the header (its own base64 stream: 3 + blocks UInt64), then the blocks
    let decode = |body: &str| -> anyhow::Result<Vec<u8>> {
        use std::io::Read as _;
        let body = body.trim();
        let first = specimen::outputs::base64_decode(body.get(..16).unwrap_or(""))
            .ok_or_else(|| anyhow::anyhow!("bad base64"))?;
        ensure!(first.len() >= 8, "no header");
        let blocks = u64::from_le_bytes(first[..8].try_into()?) as usize;
        let header_chars = (8 * (3 + blocks)).div_ceil(3) * 4;
        ensure!(body.len() >= header_chars, "truncated header");
        let header = specimen::outputs::base64_decode(&body[..header_chars])
            .ok_or_else(|| anyhow::anyhow!("bad base64 header"))?;
        let h: Vec<usize> = header
            .chunks_exact(8)
            .map(|x| u64::from_le_bytes(x.try_into().unwrap_or([0; 8])) as usize)
            .collect();
        ensure!(h.len() == 3 + blocks, "header of {} values", h.len());
        let z = specimen::outputs::base64_decode(&body[header_chars..])
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
