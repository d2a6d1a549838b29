//! CSV form of a [`DnaTable`], hand-written over `impl Write` / `impl BufRead`.
//!
//! Format: a header line of snake-case descriptor names
//! ([`Descriptor::name`]) separated by commas, then one line per grain with
//! one number per descriptor. Numbers are written in Rust's shortest
//! round-trip form, so write → read is bit-exact. The reader trims ASCII
//! whitespace around fields, accepts `\r\n` line ends, skips blank lines and
//! lines starting with `#`, and rejects non-finite numbers. Errors carry the
//! 1-based line number. No quoting: no field ever needs it.

use std::io::{BufRead, Write};

use crate::error::{CsvErrorKind, Error, Result};
use crate::table::{Descriptor, DnaTable};

fn csv_err(line: usize, kind: CsvErrorKind) -> Error {
    Error::Csv { line, kind }
}

impl DnaTable {
    /// Writes the table as CSV.
    ///
    /// # Errors
    /// [`Error::Io`].
    pub fn write_csv(&self, mut w: impl Write) -> Result<()> {
        let header: Vec<&str> = self.descriptors().iter().map(|d| d.name()).collect();
        writeln!(w, "{}", header.join(","))?;
        let mut line = String::new();
        for g in 0..self.n_grains() {
            line.clear();
            for (k, col) in self.columns().iter().enumerate() {
                if k > 0 {
                    line.push(',');
                }
                line.push_str(&format!("{:?}", col[g]));
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        Ok(())
    }

    /// Reads a table written by [`DnaTable::write_csv`] (see the module docs
    /// for the accepted format).
    ///
    /// # Errors
    /// [`Error::Csv`] with the line number and a [`CsvErrorKind`].
    pub fn read_csv(r: impl BufRead) -> Result<Self> {
        let mut table: Option<Self> = None;
        for (k, line) in r.lines().enumerate() {
            let n = k + 1;
            let line = line.map_err(|e| {
                csv_err(
                    n,
                    CsvErrorKind::Read {
                        message: e.to_string(),
                    },
                )
            })?;
            let text = line.trim();
            if text.is_empty() || text.starts_with('#') {
                continue;
            }
            match &mut table {
                None => table = Some(parse_header(text, n)?),
                Some(t) => {
                    let expected = t.descriptors().len();
                    let mut row = Vec::with_capacity(expected);
                    for (c, field) in text.split(',').enumerate() {
                        let f = field.trim();
                        match f.parse::<f64>() {
                            Ok(v) if v.is_finite() => row.push(v),
                            _ => {
                                return Err(csv_err(
                                    n,
                                    CsvErrorKind::InvalidNumber {
                                        column: c + 1,
                                        text: f.to_owned(),
                                    },
                                ));
                            }
                        }
                    }
                    if row.len() != expected {
                        return Err(csv_err(
                            n,
                            CsvErrorKind::FieldCount {
                                expected,
                                found: row.len(),
                            },
                        ));
                    }
                    // Values are finite and the length matches: cannot fail.
                    t.push_row(&row)?;
                }
            }
        }
        table.ok_or(csv_err(1, CsvErrorKind::MissingHeader))
    }
}

fn parse_header(text: &str, line: usize) -> Result<DnaTable> {
    let mut descriptors = Vec::new();
    for field in text.split(',') {
        let name = field.trim();
        let d = Descriptor::from_name(name).ok_or_else(|| {
            csv_err(
                line,
                CsvErrorKind::UnknownDescriptor {
                    name: name.to_owned(),
                },
            )
        })?;
        if descriptors.contains(&d) {
            return Err(csv_err(
                line,
                CsvErrorKind::DuplicateDescriptor { descriptor: d },
            ));
        }
        descriptors.push(d);
    }
    DnaTable::new(descriptors)
}

#[cfg(test)]
mod tests {
    use super::*;
    use Descriptor::*;
    use proptest::prelude::*;

    fn read(s: &str) -> Result<DnaTable> {
        DnaTable::read_csv(s.as_bytes())
    }

    #[test]
    fn reads_tolerant_whitespace_comments_and_crlf() {
        let t = read("# parents\r\n aspect_ratio , roundness\r\n\r\n0.5,0.25\r\n1e-3, -2\n")
            .expect("ok");
        assert_eq!(t.descriptors(), &[AspectRatio, Roundness]);
        assert_eq!(t.columns(), &[vec![0.5, 1e-3], vec![0.25, -2.0]]);
        let empty = read("volume\n").expect("header only");
        assert_eq!(empty.n_grains(), 0);
    }

    #[test]
    fn errors_carry_line_numbers() {
        let e = |s: &str| match read(s) {
            Err(Error::Csv { line, kind }) => (line, kind),
            other => panic!("expected a csv error, got {other:?}"),
        };
        assert_eq!(e(""), (1, CsvErrorKind::MissingHeader));
        assert_eq!(
            e("volume,bogus\n"),
            (
                1,
                CsvErrorKind::UnknownDescriptor {
                    name: "bogus".into()
                }
            )
        );
        assert_eq!(
            e("volume,volume\n"),
            (1, CsvErrorKind::DuplicateDescriptor { descriptor: Volume })
        );
        assert_eq!(
            e("volume,roundness\n1,2\n\n3\n"),
            (
                4,
                CsvErrorKind::FieldCount {
                    expected: 2,
                    found: 1
                }
            )
        );
        assert_eq!(
            e("volume\n1\nNaN\n"),
            (
                3,
                CsvErrorKind::InvalidNumber {
                    column: 1,
                    text: "NaN".into()
                }
            )
        );
        assert_eq!(
            e("volume,roundness\n1,inf\n"),
            (
                2,
                CsvErrorKind::InvalidNumber {
                    column: 2,
                    text: "inf".into()
                }
            )
        );
        let bad_utf8: &[u8] = b"volume\n\xff\n";
        assert!(matches!(
            DnaTable::read_csv(bad_utf8),
            Err(Error::Csv {
                line: 2,
                kind: CsvErrorKind::Read { .. }
            })
        ));
    }

    fn arb_table() -> impl Strategy<Value = DnaTable> {
        (1usize..=Descriptor::ALL.len(), 0usize..20).prop_flat_map(|(k, n)| {
            let descriptors = Just(Descriptor::ALL[..k].to_vec()).prop_shuffle();
            let values = prop::collection::vec(
                prop::num::f64::NORMAL | prop::num::f64::ZERO | prop::num::f64::SUBNORMAL,
                k * n,
            );
            (descriptors, values).prop_map(move |(d, v)| {
                let rows: Vec<Vec<f64>> = v.chunks(k.max(1)).map(<[f64]>::to_vec).collect();
                let rows = if n == 0 { Vec::new() } else { rows };
                DnaTable::from_rows(d, &rows)
                    .unwrap_or_else(|e| panic!("generated table invalid: {e}"))
            })
        })
    }

    proptest! {
        #[test]
        fn csv_round_trip_is_exact(t in arb_table()) {
            let mut buf = Vec::new();
            t.write_csv(&mut buf).expect("write");
            let back = DnaTable::read_csv(buf.as_slice()).expect("read back");
            prop_assert_eq!(back, t);
        }

        #[test]
        fn ron_round_trip_is_exact(t in arb_table()) {
            let mut buf = Vec::new();
            t.write_ron(&mut buf).expect("write");
            let back = DnaTable::read_ron(buf.as_slice()).expect("read back");
            prop_assert_eq!(back, t);
        }

        #[test]
        fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
            let n_lines = bytes.iter().filter(|b| **b == b'\n').count() + 1;
            match DnaTable::read_csv(bytes.as_slice()) {
                Ok(t) => prop_assert!(t.columns().iter().flatten().all(|v| v.is_finite())),
                Err(Error::Csv { line, .. }) => prop_assert!(line >= 1 && line <= n_lines),
                Err(other) => prop_assert!(false, "unexpected error {other:?}"),
            }
        }

        #[test]
        fn near_valid_text_never_panics(s in "(volume|roundness|aspect_ratio|,| |x|\n|[0-9.eE+-]{1,6}|nan|inf|#)*") {
            let n_lines = s.matches('\n').count() + 1;
            match read(&s) {
                Ok(t) => prop_assert!(t.columns().iter().flatten().all(|v| v.is_finite())),
                Err(Error::Csv { line, .. }) => prop_assert!(line >= 1 && line <= n_lines),
                Err(other) => prop_assert!(false, "unexpected error {other:?}"),
            }
        }
    }
}
