//! Function and file lengths of non-test code (house style, "Library
//! first": a function over ≈ 150 lines is several functions, a source file
//! over ≈ 1,200 lines is several modules). A small lexer blanks comments,
//! strings and character literals, then braces are matched: a function runs
//! from its `fn` line to its closing brace; `#[cfg(test)]` items and
//! `tests.rs` files are test code and not counted.

use std::path::Path;

/// Longest non-test function, in lines from `fn` to its closing brace.
pub(super) const MAX_FN_LINES: usize = 150;
/// Longest non-test source file, in lines outside `#[cfg(test)]` items.
pub(super) const MAX_FILE_LINES: usize = 1200;

/// Source text with comments, string and character literals replaced by
/// spaces (newlines kept, so line numbers stay).
pub(super) fn blank(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    let ident = |ch: char| ch.is_alphanumeric() || ch == '_';
    let keep_lines = |out: &mut String, s: &[char]| {
        for &ch in s {
            out.push(if ch == '\n' { '\n' } else { ' ' });
        }
    };
    while i < c.len() {
        let prev_ident = i > 0 && ident(c[i - 1]);
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            let end = c[i..]
                .iter()
                .position(|&x| x == '\n')
                .map_or(c.len(), |p| i + p);
            keep_lines(&mut out, &c[i..end]);
            i = end;
        } else if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let (mut depth, mut j) = (1, i + 2);
            while j < c.len() && depth > 0 {
                if c[j] == '/' && c.get(j + 1) == Some(&'*') {
                    depth += 1;
                    j += 2;
                } else if c[j] == '*' && c.get(j + 1) == Some(&'/') {
                    depth -= 1;
                    j += 2;
                } else {
                    j += 1;
                }
            }
            keep_lines(&mut out, &c[i..j]);
            i = j;
        } else if (c[i] == 'r'
            && (!prev_ident || (i > 0 && c[i - 1] == 'b' && (i < 2 || !ident(c[i - 2])))))
            && matches!(c.get(i + 1), Some('#') | Some('"'))
        {
            // raw string r"…", r#"…"#, br#"…"#
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= c.len() {
                    break;
                }
                if c[j] == '"' && (0..hashes).all(|h| c.get(j + 1 + h) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            out.push('r');
            keep_lines(&mut out, &c[i + 1..j]);
            i = j;
        } else if c[i] == '"' {
            let mut j = i + 1;
            while j < c.len() && c[j] != '"' {
                j += if c[j] == '\\' { 2 } else { 1 };
            }
            let j = (j + 1).min(c.len());
            keep_lines(&mut out, &c[i..j]);
            i = j;
        } else if c[i] == '\'' && !prev_ident {
            // a character literal ('x', '\n', '\u{1F}') or a lifetime ('a)
            let end = if c.get(i + 1) == Some(&'\\') {
                c[i + 2..]
                    .iter()
                    .position(|&x| x == '\'')
                    .map(|p| i + 2 + p + 1)
            } else if c.get(i + 2) == Some(&'\'') {
                Some(i + 3)
            } else {
                None
            };
            match end {
                Some(j) => {
                    keep_lines(&mut out, &c[i..j]);
                    i = j;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// The byte offset of the brace closing the one at `open`, in blanked code.
fn matching_brace(code: &[u8], open: usize) -> usize {
    let mut depth = 0usize;
    for (k, &b) in code.iter().enumerate().skip(open) {
        match b {
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return k;
                }
            }
            _ => {}
        }
    }
    code.len().saturating_sub(1)
}

fn line_of(code: &[u8], offset: usize) -> usize {
    code[..offset].iter().filter(|&&b| b == b'\n').count() + 1
}

/// The end of the item starting at `from` (its closing brace or `;`).
fn item_end(code: &[u8], from: usize) -> usize {
    for (k, &b) in code.iter().enumerate().skip(from) {
        match b {
            b'{' => return matching_brace(code, k),
            b';' => return k,
            _ => {}
        }
    }
    code.len().saturating_sub(1)
}

/// Line ranges (1-based, inclusive) of `#[cfg(test)]` items.
fn test_ranges(code: &str) -> Vec<(usize, usize)> {
    let bytes = code.as_bytes();
    let mut ranges = Vec::new();
    let mut from = 0;
    while let Some(p) = code[from..].find("#[cfg(test)]") {
        let start = from + p;
        let after = start + "#[cfg(test)]".len();
        let end = item_end(bytes, after);
        ranges.push((line_of(bytes, start), line_of(bytes, end)));
        from = end.max(after);
    }
    ranges
}

/// A function longer than allowed: (name, first line, lines).
#[derive(Debug, PartialEq)]
pub(super) struct LongFn {
    pub(super) name: String,
    pub(super) line: usize,
    pub(super) lines: usize,
}

/// Every non-test function of a source text with its length, and the
/// file's non-test line count.
pub(super) fn measure(src: &str) -> (Vec<LongFn>, usize) {
    let code = blank(src);
    let bytes = code.as_bytes();
    let tests = test_ranges(&code);
    let in_test = |line: usize| tests.iter().any(|&(a, b)| a <= line && line <= b);
    let total = code.lines().count();
    let test_lines: usize = tests.iter().map(|&(a, b)| b - a + 1).sum();
    let mut fns = Vec::new();
    let mut k = 0;
    while k + 2 < bytes.len() {
        let is_fn = &bytes[k..k + 2] == b"fn"
            && (k == 0 || !(bytes[k - 1].is_ascii_alphanumeric() || bytes[k - 1] == b'_'))
            && bytes[k + 2].is_ascii_whitespace();
        if !is_fn {
            k += 1;
            continue;
        }
        let name_start = k
            + 2
            + bytes[k + 2..]
                .iter()
                .take_while(|b| b.is_ascii_whitespace())
                .count();
        let name: String = bytes[name_start..]
            .iter()
            .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_')
            .map(|&b| b as char)
            .collect();
        let line = line_of(bytes, k);
        if name.is_empty() || in_test(line) {
            k += 2;
            continue;
        }
        let end = item_end(bytes, name_start);
        if bytes[end] == b'}' {
            fns.push(LongFn {
                name,
                line,
                lines: line_of(bytes, end) - line + 1,
            });
        }
        k = name_start;
    }
    (fns, total - test_lines)
}

/// Is this source file test code as a whole?
pub(super) fn is_test_file(path: &Path) -> bool {
    path.file_name().is_some_and(|f| f == "tests.rs")
        || path.components().any(|c| {
            matches!(
                c.as_os_str().to_str(),
                Some("tests" | "benches" | "examples")
            )
        })
}
