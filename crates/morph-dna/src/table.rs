//! Plain-data DNA tables: one row per grain, one column per [`Descriptor`].
//!
//! The per-grain descriptor code fills a [`DnaTable`]; every population
//! statistic of this crate reads one. The table is validated at construction
//! (at least one descriptor, no duplicate, rectangular, every value finite), so
//! downstream code never meets NaN.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

pub use crate::descriptor::Descriptor;

/// The serialised shape of a [`DnaTable`]; validated on the way in.
#[derive(Serialize, Deserialize)]
struct DnaTableRaw {
    descriptors: Vec<Descriptor>,
    columns: Vec<Vec<f64>>,
}

impl TryFrom<DnaTableRaw> for DnaTable {
    type Error = Error;
    fn try_from(raw: DnaTableRaw) -> Result<Self> {
        Self::from_columns(raw.descriptors, raw.columns)
    }
}

impl From<DnaTable> for DnaTableRaw {
    fn from(t: DnaTable) -> Self {
        Self {
            descriptors: t.descriptors,
            columns: t.columns,
        }
    }
}

/// A validated table of descriptors: one column per [`Descriptor`], one row per
/// grain, every value finite.
///
/// Stored column-major (populations statistics work on columns). A table may
/// hold zero grains; statistics that need a population check its size
/// themselves and return [`Error::TooFewSamples`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DnaTableRaw", into = "DnaTableRaw")]
pub struct DnaTable {
    descriptors: Vec<Descriptor>,
    columns: Vec<Vec<f64>>,
}

impl DnaTable {
    /// An empty table (zero grains) with the given columns.
    ///
    /// # Errors
    /// [`Error::NoDescriptors`] or [`Error::DuplicateDescriptor`].
    pub fn new(descriptors: Vec<Descriptor>) -> Result<Self> {
        let n = descriptors.len();
        Self::from_columns(descriptors, vec![Vec::new(); n])
    }

    /// A table from its columns (`columns[k]` holds `descriptors[k]` of every grain).
    ///
    /// # Errors
    /// [`Error::NoDescriptors`], [`Error::DuplicateDescriptor`],
    /// [`Error::RaggedTable`] or [`Error::NonFiniteValue`].
    pub fn from_columns(descriptors: Vec<Descriptor>, columns: Vec<Vec<f64>>) -> Result<Self> {
        check_descriptors(&descriptors)?;
        if columns.len() != descriptors.len() {
            return Err(Error::RaggedTable {
                what: "table",
                index: 0,
                expected: descriptors.len(),
                found: columns.len(),
            });
        }
        let n = columns.first().map_or(0, Vec::len);
        for (k, (d, col)) in descriptors.iter().zip(&columns).enumerate() {
            if col.len() != n {
                return Err(Error::RaggedTable {
                    what: "column",
                    index: k,
                    expected: n,
                    found: col.len(),
                });
            }
            check_finite(*d, col, 0)?;
        }
        Ok(Self {
            descriptors,
            columns,
        })
    }

    /// A table from its rows (`rows[g][k]` is `descriptors[k]` of grain `g`).
    ///
    /// # Errors
    /// As [`DnaTable::from_columns`].
    pub fn from_rows(descriptors: Vec<Descriptor>, rows: &[Vec<f64>]) -> Result<Self> {
        let mut t = Self::new(descriptors)?;
        for row in rows {
            t.push_row(row)?;
        }
        Ok(t)
    }

    /// Appends one grain. On error the table is unchanged.
    ///
    /// # Errors
    /// [`Error::RaggedTable`] if `row` does not have one value per descriptor,
    /// [`Error::NonFiniteValue`] if a value is NaN or infinite.
    pub fn push_row(&mut self, row: &[f64]) -> Result<()> {
        if row.len() != self.descriptors.len() {
            return Err(Error::RaggedTable {
                what: "row",
                index: self.n_grains(),
                expected: self.descriptors.len(),
                found: row.len(),
            });
        }
        for (d, v) in self.descriptors.iter().zip(row) {
            if !v.is_finite() {
                return Err(Error::NonFiniteValue {
                    descriptor: *d,
                    grain: self.n_grains(),
                    value: *v,
                });
            }
        }
        for (col, v) in self.columns.iter_mut().zip(row) {
            col.push(*v);
        }
        Ok(())
    }

    /// The descriptors, in column order.
    pub fn descriptors(&self) -> &[Descriptor] {
        &self.descriptors
    }

    /// All columns, in the order of [`DnaTable::descriptors`].
    pub fn columns(&self) -> &[Vec<f64>] {
        &self.columns
    }

    /// Number of grains (rows).
    pub fn n_grains(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// Position of a descriptor among the columns.
    pub fn position(&self, descriptor: Descriptor) -> Option<usize> {
        self.descriptors.iter().position(|d| *d == descriptor)
    }

    /// The values of one descriptor for every grain.
    ///
    /// # Errors
    /// [`Error::MissingDescriptor`].
    pub fn column(&self, descriptor: Descriptor) -> Result<&[f64]> {
        self.position(descriptor)
            .map(|k| self.columns[k].as_slice())
            .ok_or(Error::MissingDescriptor { descriptor })
    }

    /// The descriptors of grain `grain`, or `None` past the end.
    pub fn row(&self, grain: usize) -> Option<Vec<f64>> {
        (grain < self.n_grains()).then(|| self.columns.iter().map(|c| c[grain]).collect())
    }

    /// A new table with only the given descriptors, in the given order.
    ///
    /// # Errors
    /// [`Error::MissingDescriptor`], [`Error::NoDescriptors`] or
    /// [`Error::DuplicateDescriptor`].
    pub fn select(&self, descriptors: &[Descriptor]) -> Result<Self> {
        let columns = descriptors
            .iter()
            .map(|d| self.column(*d).map(<[f64]>::to_vec))
            .collect::<Result<Vec<_>>>()?;
        Self::from_columns(descriptors.to_vec(), columns)
    }

    /// Fails with [`Error::TooFewSamples`] unless the table has at least `needed` grains.
    ///
    /// # Errors
    /// [`Error::TooFewSamples`].
    pub fn require_grains(&self, needed: usize) -> Result<()> {
        if self.n_grains() < needed {
            return Err(Error::TooFewSamples {
                needed,
                found: self.n_grains(),
            });
        }
        Ok(())
    }

    /// Serialises the table as RON (pretty-printed) to `w`.
    ///
    /// # Errors
    /// [`Error::Ron`] or [`Error::Io`].
    pub fn write_ron(&self, mut w: impl std::io::Write) -> Result<()> {
        let s =
            ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).map_err(|e| {
                Error::Ron {
                    message: e.to_string(),
                }
            })?;
        w.write_all(s.as_bytes())?;
        w.write_all(b"\n")?;
        Ok(())
    }

    /// Reads a table written by [`DnaTable::write_ron`]; the result is validated
    /// like [`DnaTable::from_columns`].
    ///
    /// # Errors
    /// [`Error::Io`], or [`Error::Ron`] carrying the position and the
    /// validation message.
    pub fn read_ron(mut r: impl std::io::BufRead) -> Result<Self> {
        let mut s = String::new();
        r.read_to_string(&mut s)?;
        ron::from_str(&s).map_err(|e| Error::Ron {
            message: e.to_string(),
        })
    }
}

fn check_descriptors(descriptors: &[Descriptor]) -> Result<()> {
    if descriptors.is_empty() {
        return Err(Error::NoDescriptors);
    }
    let mut sorted = descriptors.to_vec();
    sorted.sort();
    for w in sorted.windows(2) {
        if w[0] == w[1] {
            return Err(Error::DuplicateDescriptor { descriptor: w[0] });
        }
    }
    Ok(())
}

fn check_finite(descriptor: Descriptor, col: &[f64], offset: usize) -> Result<()> {
    match col.iter().position(|v| !v.is_finite()) {
        Some(g) => Err(Error::NonFiniteValue {
            descriptor,
            grain: offset + g,
            value: col[g],
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_unique() {
        for d in Descriptor::ALL {
            assert_eq!(Descriptor::from_name(d.name()), Some(d));
        }
        let mut names: Vec<_> = Descriptor::ALL.iter().map(|d| d.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Descriptor::ALL.len());
    }

    #[test]
    fn validation_rejects_bad_tables() {
        use Descriptor::*;
        assert_eq!(DnaTable::new(vec![]), Err(Error::NoDescriptors));
        assert_eq!(
            DnaTable::new(vec![Volume, Roundness, Volume]),
            Err(Error::DuplicateDescriptor { descriptor: Volume })
        );
        assert!(matches!(
            DnaTable::from_columns(vec![Volume, Roundness], vec![vec![1.0, 2.0], vec![1.0]]),
            Err(Error::RaggedTable { index: 1, .. })
        ));
        assert!(matches!(
            DnaTable::from_columns(vec![Volume], vec![vec![1.0, f64::NAN]]),
            Err(Error::NonFiniteValue { grain: 1, .. })
        ));
        let mut t = DnaTable::new(vec![Volume, Roundness]).expect("valid");
        assert!(t.push_row(&[1.0]).is_err());
        assert!(t.push_row(&[1.0, f64::INFINITY]).is_err());
        assert_eq!(t.n_grains(), 0);
        t.push_row(&[1.0, 0.5]).expect("valid row");
        assert_eq!(t.row(0), Some(vec![1.0, 0.5]));
        assert_eq!(t.row(1), None);
        assert_eq!(
            t.require_grains(2),
            Err(Error::TooFewSamples {
                needed: 2,
                found: 1
            })
        );
        assert_eq!(
            t.column(Sphericity),
            Err(Error::MissingDescriptor {
                descriptor: Sphericity
            })
        );
        let s = t.select(&[Roundness]).expect("present");
        assert_eq!(s.columns(), &[vec![0.5]]);
    }

    #[test]
    fn ron_round_trip_is_exact_and_validated() {
        use Descriptor::*;
        let t = DnaTable::from_rows(
            vec![AspectRatio, EquivalentDiameter],
            &[vec![0.1 + 0.2, 1e-300], vec![-0.0, 123_456_789.125]],
        )
        .expect("valid");
        let mut buf = Vec::new();
        t.write_ron(&mut buf).expect("write");
        let back = DnaTable::read_ron(buf.as_slice()).expect("read");
        assert_eq!(back, t);
        let bad = "(descriptors: [Volume, Volume], columns: [[1.0], [2.0]])";
        assert!(matches!(
            DnaTable::read_ron(bad.as_bytes()),
            Err(Error::Ron { .. })
        ));
        let ragged = "(descriptors: [Volume, Roundness], columns: [[1.0], []])";
        assert!(matches!(
            DnaTable::read_ron(ragged.as_bytes()),
            Err(Error::Ron { .. })
        ));
    }
}
