//! Golden digests of what a scene writes: every file under `out_dir` (sorted
//! relative paths) but `report.txt` (the stage times) with the FNV-1a 64-bit
//! hash of its bytes, the commit in
//! provenance lines (`(commit 1a2b3c…)`) normalised to `(commit)` so the digest
//! is the same at every commit. The digests of the two example scenes
//! (`examples/specimen-clumps.ron`, `examples/specimen-lsdem.ron`) are committed
//! in `xtask/golden/` and checked by a test: the library move of issue 29 must
//! not change a byte of what they write. Re-mint after an intended change with
//! `GRAINFORGE_MINT_GOLDEN=1 cargo test -p xtask golden`.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;

/// FNV-1a, 64 bits.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// `bytes` with every `(commit X)` made `(commit)`.
fn normalise(bytes: &[u8]) -> Vec<u8> {
    const KEY: &[u8] = b"(commit ";
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(KEY)
            && let Some(end) = bytes[i + KEY.len()..].iter().position(|&b| b == b')')
            && end <= 64
        {
            out.extend_from_slice(b"(commit)");
            i += KEY.len() + end + 1;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    out
}

/// `path hash` lines of every file under `dir`, sorted by path.
pub(crate) fn listing(dir: &Path) -> anyhow::Result<String> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).with_context(|| format!("reading {}", d.display()))? {
            let p = e?.path();
            if p.is_dir() {
                stack.push(p);
            } else if p != dir.join("report.txt") {
                files.push(p);
            }
        }
    }
    let mut rows: Vec<(String, u64)> = files
        .iter()
        .map(|p| {
            let rel = p
                .strip_prefix(dir)
                .unwrap_or(p)
                .to_string_lossy()
                .replace('\\', "/");
            let bytes = std::fs::read(p).with_context(|| format!("reading {}", p.display()))?;
            Ok((rel, fnv1a(&normalise(&bytes))))
        })
        .collect::<anyhow::Result<_>>()?;
    rows.sort();
    let mut out = String::new();
    for (p, h) in rows {
        let _ = writeln!(out, "{p} {h:016x}");
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::specimen::{run_scene, scene::Scene};

    #[test]
    fn normalises_commits_and_hashes_bytes() {
        assert_eq!(
            normalise(b"# grainforge 0.0.0 (commit 1a2b3c4d5e6f), x (commit)"),
            b"# grainforge 0.0.0 (commit), x (commit)".to_vec()
        );
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
    }

    /// The files of the two example scenes, byte for byte (commit lines
    /// normalised), against `xtask/golden/<example>.digests`.
    #[test]
    fn example_scenes_write_their_golden_files() {
        let root = crate::workspace_root();
        let mint = std::env::var_os("GRAINFORGE_MINT_GOLDEN").is_some();
        for name in ["specimen-clumps", "specimen-lsdem"] {
            let path = root.join(format!("examples/{name}.ron"));
            let text = std::fs::read_to_string(&path).expect("example scene");
            let mut scene = Scene::parse(&text, &path).expect("parses");
            let out = std::env::temp_dir()
                .join(format!("grainforge-golden-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&out);
            scene.out_dir = out.clone();
            run_scene(&scene, &root, true).expect("the example runs");
            let got = listing(&out).expect("listing");
            let _ = std::fs::remove_dir_all(&out);
            let golden = root.join(format!("xtask/golden/{name}.digests"));
            if mint {
                std::fs::create_dir_all(golden.parent().expect("folder")).expect("mkdir");
                std::fs::write(&golden, &got).expect("mint");
                continue;
            }
            let want = std::fs::read_to_string(&golden).expect("golden digests");
            assert!(
                got == want,
                "{name}: the outputs changed (re-mint with GRAINFORGE_MINT_GOLDEN=1 if intended):\n--- golden\n{want}--- now\n{got}"
            );
        }
    }
}
