//! The embedded `fixtures/` tree and a small CSV table loader.
//!
//! Plain data, no internal dependencies: `build.rs` compiles every file of
//! `fixtures/reference/`, `fixtures/grains/` and `fixtures/calibrated/` into
//! the crate, so cases and `xtask` work from a fresh clone without paths and
//! without run-time file access. Names are paths relative to their folder
//! with `/` separators (e.g. `vcctl/ottawa/Ottawa-sand-anm-20001.dat`).

mod index {
    include!(concat!(env!("OUT_DIR"), "/fixtures_index.rs"));
}

use crate::Error;

/// Every file of `fixtures/reference/` as `(name, contents)`, sorted by name.
#[must_use]
pub fn reference_files() -> &'static [(&'static str, &'static str)] {
    index::REFERENCE
}

/// Every file of `fixtures/grains/` as `(name, contents)`, sorted by name.
#[must_use]
pub fn grain_files() -> &'static [(&'static str, &'static str)] {
    index::GRAINS
}

/// Every file of `fixtures/calibrated/` as `(name, contents)`, sorted by name.
#[must_use]
pub fn calibrated_files() -> &'static [(&'static str, &'static str)] {
    index::CALIBRATED
}

fn find(files: &'static [(&'static str, &'static str)], name: &str) -> Result<&'static str, Error> {
    files
        .binary_search_by(|(n, _)| (*n).cmp(name))
        .map(|i| files[i].1)
        .map_err(|_| Error::MissingFixture {
            name: name.to_owned(),
        })
}

/// The contents of `fixtures/reference/<name>`.
///
/// # Errors
/// [`Error::MissingFixture`] if there is no such file.
pub fn reference(name: &str) -> Result<&'static str, Error> {
    find(index::REFERENCE, name)
}

/// The contents of `fixtures/grains/<name>`.
///
/// # Errors
/// [`Error::MissingFixture`] if there is no such file.
pub fn grain(name: &str) -> Result<&'static str, Error> {
    find(index::GRAINS, name)
}

/// Contents of `fixtures/calibrated/<name>` (e.g. `gsc2-ottawa.ron`).
///
/// # Errors
/// [`Error::MissingFixture`] if no such file is embedded.
pub fn calibrated(name: &str) -> Result<&'static str, Error> {
    find(index::CALIBRATED, name).map_err(|_| Error::MissingFixture {
        name: format!("calibrated/{name}"),
    })
}

/// The grain files under `fixtures/grains/<folder>/` whose name ends with
/// `suffix` (e.g. `grains_in("vcctl/ottawa", ".dat")`), sorted by name.
#[must_use]
pub fn grains_in(folder: &str, suffix: &str) -> Vec<(&'static str, &'static str)> {
    let prefix = format!("{}/", folder.trim_end_matches('/'));
    index::GRAINS
        .iter()
        .filter(|(n, _)| {
            n.starts_with(&prefix) && !n[prefix.len()..].contains('/') && n.ends_with(suffix)
        })
        .copied()
        .collect()
}

/// A parsed CSV table: header and string cells, exactly as written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Table {
    /// File name (for error messages).
    pub name: String,
    /// Header row.
    pub columns: Vec<String>,
    /// Data rows; every row has `columns.len()` cells.
    pub rows: Vec<Vec<String>>,
    /// 1-based file line on which each data row starts.
    pub lines: Vec<usize>,
}

impl Table {
    /// Loads and parses `fixtures/reference/<name>`.
    ///
    /// # Errors
    /// [`Error::MissingFixture`] or any [`Table::parse`] error.
    pub fn reference(name: &str) -> Result<Self, Error> {
        Self::parse(name, reference(name)?)
    }

    /// Parses RFC 4180 CSV: comma separated, `"` quoting with `""` escapes,
    /// `\n` or `\r\n` line ends, one header row, every row as wide as the
    /// header.
    ///
    /// # Errors
    /// [`Error::Csv`] with the line number for an unterminated quote, text
    /// after a closing quote, an empty file or a row of the wrong width.
    pub fn parse(name: &str, text: &str) -> Result<Self, Error> {
        let csv_err = |line: usize, message: String| Error::Csv {
            table: name.to_owned(),
            line,
            message,
        };
        let mut records: Vec<(usize, Vec<String>)> = Vec::new();
        let mut field = String::new();
        let mut record: Vec<String> = Vec::new();
        let mut line = 1usize;
        let mut start_line = 1usize;
        let mut chars = text.chars().peekable();
        let mut in_quotes = false;
        let mut quoted_field = false;
        let mut any = false;
        while let Some(c) = chars.next() {
            any = true;
            if in_quotes {
                match c {
                    '"' if chars.peek() == Some(&'"') => {
                        chars.next();
                        field.push('"');
                    }
                    '"' => in_quotes = false,
                    '\n' => {
                        line += 1;
                        field.push('\n');
                    }
                    _ => field.push(c),
                }
                continue;
            }
            match c {
                '"' if field.is_empty() && !quoted_field => {
                    in_quotes = true;
                    quoted_field = true;
                }
                '"' => return Err(csv_err(line, "stray quote inside an unquoted field".into())),
                ',' => {
                    record.push(std::mem::take(&mut field));
                    quoted_field = false;
                }
                '\r' if chars.peek() == Some(&'\n') => {}
                '\n' => {
                    record.push(std::mem::take(&mut field));
                    quoted_field = false;
                    records.push((start_line, std::mem::take(&mut record)));
                    line += 1;
                    start_line = line;
                    any = false;
                }
                _ if quoted_field => {
                    return Err(csv_err(line, format!("text {c:?} after a closing quote")));
                }
                _ => field.push(c),
            }
        }
        if in_quotes {
            return Err(csv_err(start_line, "unterminated quoted field".into()));
        }
        if any {
            record.push(field);
            records.push((start_line, record));
        }
        let mut iter = records.into_iter();
        let (_, columns) = iter
            .next()
            .ok_or_else(|| csv_err(1, "empty file: no header row".into()))?;
        if columns.iter().any(String::is_empty) {
            return Err(csv_err(1, "empty column name in the header".into()));
        }
        let mut rows = Vec::new();
        let mut lines = Vec::new();
        for (l, r) in iter {
            if r.len() == 1 && r[0].is_empty() {
                continue; // blank line
            }
            if r.len() != columns.len() {
                return Err(csv_err(
                    l,
                    format!("{} cells, header has {}", r.len(), columns.len()),
                ));
            }
            rows.push(r);
            lines.push(l);
        }
        Ok(Self {
            name: name.to_owned(),
            columns,
            rows,
            lines,
        })
    }

    /// Index of a column.
    ///
    /// # Errors
    /// [`Error::MissingColumn`].
    pub fn column(&self, column: &str) -> Result<usize, Error> {
        self.columns
            .iter()
            .position(|c| c == column)
            .ok_or_else(|| Error::MissingColumn {
                table: self.name.clone(),
                column: column.to_owned(),
            })
    }

    /// The cell of row `row` in `column`, as written.
    ///
    /// # Errors
    /// [`Error::MissingColumn`].
    pub fn text(&self, row: usize, column: &str) -> Result<&str, Error> {
        let c = self.column(column)?;
        Ok(self.rows.get(row).map_or("", |r| r[c].as_str()))
    }

    /// The cell of row `row` in `column` as a number; `None` for an empty
    /// cell (the source gives no value).
    ///
    /// # Errors
    /// [`Error::MissingColumn`], or [`Error::NotANumber`] for a non-empty
    /// cell that does not parse as a finite `f64`.
    pub fn number_opt(&self, row: usize, column: &str) -> Result<Option<f64>, Error> {
        let cell = self.text(row, column)?.trim();
        if cell.is_empty() {
            return Ok(None);
        }
        match cell.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(Error::NotANumber {
                table: self.name.clone(),
                line: self.lines.get(row).copied().unwrap_or(0),
                column: column.to_owned(),
                value: cell.to_owned(),
            }),
        }
    }

    /// The cell of row `row` in `column` as a number that must be present.
    ///
    /// # Errors
    /// As [`Table::number_opt`], and [`Error::NotANumber`] for an empty cell.
    pub fn number(&self, row: usize, column: &str) -> Result<f64, Error> {
        self.number_opt(row, column)?
            .ok_or_else(|| Error::NotANumber {
                table: self.name.clone(),
                line: self.lines.get(row).copied().unwrap_or(0),
                column: column.to_owned(),
                value: String::new(),
            })
    }

    /// Index of the first row whose `column` equals `value`.
    ///
    /// # Errors
    /// [`Error::MissingColumn`] or [`Error::MissingRow`].
    pub fn row_where(&self, column: &str, value: &str) -> Result<usize, Error> {
        let c = self.column(column)?;
        self.rows
            .iter()
            .position(|r| r[c] == value)
            .ok_or_else(|| Error::MissingRow {
                table: self.name.clone(),
                column: column.to_owned(),
                value: value.to_owned(),
            })
    }

    /// Indices of all rows whose `column` equals `value`.
    ///
    /// # Errors
    /// [`Error::MissingColumn`].
    pub fn rows_where(&self, column: &str, value: &str) -> Result<Vec<usize>, Error> {
        let c = self.column(column)?;
        Ok((0..self.rows.len())
            .filter(|&i| self.rows[i][c] == value)
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_quotes_crlf_and_blank_lines() {
        let t = Table::parse("t.csv", "a,b\r\n1,\"x, \"\"y\"\"\"\n\n2,\n").expect("valid csv");
        assert_eq!(t.columns, ["a", "b"]);
        assert_eq!(t.rows, [vec!["1", "x, \"y\""], vec!["2", ""]]);
        assert_eq!(t.lines, [2, 4]);
        assert_eq!(t.number_opt(1, "b"), Ok(None));
        assert_eq!(t.number(0, "a"), Ok(1.0));
    }

    #[test]
    fn reports_line_numbers() {
        let err = Table::parse("t.csv", "a,b\n1,2\n3\n").expect_err("short row");
        assert_eq!(
            err,
            Error::Csv {
                table: "t.csv".into(),
                line: 3,
                message: "1 cells, header has 2".into()
            }
        );
        let err = Table::parse("t.csv", "a\n\"open\n").expect_err("unterminated");
        assert!(matches!(err, Error::Csv { line: 2, .. }), "{err}");
        assert!(matches!(
            Table::parse("t.csv", ""),
            Err(Error::Csv { line: 1, .. })
        ));
        let t = Table::parse("t.csv", "a\nx\n").expect("valid");
        assert!(matches!(
            t.number(0, "a"),
            Err(Error::NotANumber { line: 2, .. })
        ));
        assert!(matches!(
            t.number(0, "zz"),
            Err(Error::MissingColumn { .. })
        ));
    }

    #[test]
    fn never_panics_on_arbitrary_text() {
        // a deterministic sweep over short strings of CSV-significant bytes
        let alphabet = ['a', '1', ',', '"', '\n', '\r', ' '];
        let mut s = String::new();
        for n in 0..7u32.pow(5) {
            s.clear();
            let mut k = n;
            for _ in 0..5 {
                s.push(alphabet[(k % 7) as usize]);
                k /= 7;
            }
            if let Ok(t) = Table::parse("fuzz", &s) {
                assert!(t.rows.iter().all(|r| r.len() == t.columns.len()));
            }
        }
    }

    #[test]
    fn every_reference_csv_is_embedded_and_parses() {
        let csvs: Vec<_> = reference_files()
            .iter()
            .filter(|(n, _)| n.ends_with(".csv"))
            .collect();
        assert!(
            csvs.len() >= 40,
            "only {} reference tables embedded",
            csvs.len()
        );
        for (name, text) in csvs {
            Table::parse(name, text).unwrap_or_else(|e| panic!("{e}"));
        }
        assert!(reference("NOTES.md").is_ok());
        assert!(matches!(
            reference("nope.csv"),
            Err(Error::MissingFixture { .. })
        ));
    }

    #[test]
    fn real_grains_are_embedded() {
        assert_eq!(grains_in("vcctl/ottawa", ".dat").len(), 100);
        assert_eq!(grains_in("vcctl/ottawa-full", ".dat").len(), 10);
        assert_eq!(grains_in("vcctl/MA106A-1-fine", ".dat").len(), 60);
        assert_eq!(grains_in("vcctl/MA107-6-fine", ".dat").len(), 60);
        assert!(grain("vcctl/Ottawa-sand-geom-shipped.txt").is_ok());
        assert!(grain("vcctl/NOTICE.txt").is_ok());
    }
}
