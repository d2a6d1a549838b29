//! Reader for NIST/VCCTL `*-anm-*.dat` spherical-harmonic coefficient files.
//!
//! Format: no header; one line per coefficient `n m Re(a_nm) Im(a_nm)`, n rising from 0 and,
//! within each n, m from n down to −n. The radius is `r = Σ a_nm Y_n^m` with the complex
//! orthonormal `Y_n^m` including the Condon–Shortley phase (SciPy `sph_harm_y`), θ polar
//! from +z, φ azimuth from +x. Blank lines are ignored; anything else is an error with its
//! line number. The last degree block must be complete.

use crate::basis::{coefficient_count, index};
use crate::error::Error;
use crate::model::ShModel;
use std::io::BufRead;

/// Complex coefficients read from a VCCTL file.
#[derive(Debug, Clone, PartialEq)]
pub struct VcctlCoefficients {
    /// Highest degree n in the file.
    pub degree: usize,
    /// `(Re a_nm, Im a_nm)` at index `n² + n + m`.
    pub complex: Vec<(f64, f64)>,
}

impl VcctlCoefficients {
    /// Largest violation of `a_{n,−m} = (−1)^m conj(a_nm)` (0 for a real surface).
    #[must_use]
    pub fn max_asymmetry(&self) -> f64 {
        let mut worst: f64 = 0.0;
        for n in 0..=self.degree {
            for m in 1..=n as i64 {
                let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
                let (ar, ai) = self.complex[index(n, m)];
                let (br, bi) = self.complex[index(n, -m)];
                worst = worst
                    .max((br - sign * ar).abs())
                    .max((bi + sign * ai).abs());
            }
            worst = worst.max(self.complex[index(n, 0)].1.abs());
        }
        worst
    }

    /// The real model truncated to `min(max_degree, degree)`; returns the degree used too.
    ///
    /// # Errors
    /// As [`ShModel::from_complex`].
    pub fn to_model(&self, max_degree: usize) -> Result<(ShModel, usize), Error> {
        let degree = max_degree.min(self.degree);
        let model = ShModel::from_complex(degree, &self.complex[..coefficient_count(degree)])?;
        Ok((model, degree))
    }
}

fn parse_err(line: usize, reason: impl Into<String>) -> Error {
    Error::Parse {
        line,
        reason: reason.into(),
    }
}

/// Reads a VCCTL `*-anm-*.dat` file.
///
/// # Errors
/// [`Error::Parse`] (with the 1-based line number) for a wrong field count, an unparsable or
/// non-finite number, an out-of-order (n, m), an empty file or an incomplete last degree;
/// [`Error::Io`] when reading fails; [`Error::DegreeOutOfRange`] above
/// [`crate::basis::MAX_DEGREE`].
pub fn read_anm(reader: impl BufRead) -> Result<VcctlCoefficients, Error> {
    let mut complex: Vec<(f64, f64)> = Vec::new();
    let mut last_line = 0;
    for (i, line) in reader.lines().enumerate() {
        let lineno = i + 1;
        last_line = lineno;
        let line = line.map_err(|e| Error::Io {
            line: lineno,
            message: e.to_string(),
        })?;
        let trimmed = line.trim();
        if trimmed.is_empty() {
            continue;
        }
        let fields: Vec<&str> = trimmed.split_whitespace().collect();
        if fields.len() != 4 {
            return Err(parse_err(
                lineno,
                format!("expected 4 fields `n m re im`, found {}", fields.len()),
            ));
        }
        let n: usize = fields[0].parse().map_err(|_| {
            parse_err(
                lineno,
                format!("degree n is not an integer: {:?}", fields[0]),
            )
        })?;
        let m: i64 = fields[1].parse().map_err(|_| {
            parse_err(
                lineno,
                format!("order m is not an integer: {:?}", fields[1]),
            )
        })?;
        let re: f64 = fields[2].parse().map_err(|_| {
            parse_err(
                lineno,
                format!("real part is not a number: {:?}", fields[2]),
            )
        })?;
        let im: f64 = fields[3].parse().map_err(|_| {
            parse_err(
                lineno,
                format!("imaginary part is not a number: {:?}", fields[3]),
            )
        })?;
        if !re.is_finite() || !im.is_finite() {
            return Err(parse_err(lineno, "coefficient is not finite"));
        }
        // Expected (n, m) of the k-th coefficient: k = n² + n − m (m from n down to −n).
        let k = complex.len();
        let en = (k as f64).sqrt() as usize;
        let en = if (en + 1) * (en + 1) <= k { en + 1 } else { en };
        let em = (en * en + en) as i64 - k as i64;
        if n != en || m != em {
            return Err(parse_err(
                lineno,
                format!("expected coefficient n={en} m={em}, found n={n} m={m}"),
            ));
        }
        if n > crate::basis::MAX_DEGREE {
            return Err(Error::DegreeOutOfRange {
                degree: n,
                max: crate::basis::MAX_DEGREE,
            });
        }
        complex.push((re, im));
    }
    if complex.is_empty() {
        return Err(parse_err(last_line.max(1), "file holds no coefficients"));
    }
    let k = complex.len();
    let degree = (k as f64).sqrt() as usize;
    let degree = if (degree + 1) * (degree + 1) <= k {
        degree + 1
    } else {
        degree
    };
    if degree * degree != k {
        return Err(parse_err(
            last_line,
            format!(
                "incomplete degree block: {k} coefficients, last complete degree {}",
                degree.saturating_sub(1)
            ),
        ));
    }
    let degree = degree - 1;
    // Stored order is m = n..−n; reorder to index n² + n + m.
    let mut out = vec![(0.0, 0.0); k];
    for (pos, v) in complex.into_iter().enumerate() {
        let n = (pos as f64).sqrt() as usize;
        let n = if (n + 1) * (n + 1) <= pos { n + 1 } else { n };
        let m = (n * n + n) as i64 - pos as i64;
        out[index(n, m)] = v;
    }
    Ok(VcctlCoefficients {
        degree,
        complex: out,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const SAMPLE: &str = "   0   0      449.6187622068        0.0000000000
   1   1       -4.8117368257       11.0779196368
   1   0       12.3128295797        0.0000000000
   1  -1        4.8117368257       11.0779196368
";

    #[test]
    fn reads_a_degree_one_file() {
        let c = read_anm(SAMPLE.as_bytes()).expect("parse");
        assert_eq!(c.degree, 1);
        assert!(c.max_asymmetry() < 1e-12);
        assert_eq!(c.complex[index(1, 1)], (-4.8117368257, 11.0779196368));
        let (model, used) = c.to_model(30).expect("model");
        assert_eq!(used, 1);
        assert_eq!(model.degree(), 1);
    }

    #[test]
    fn errors_carry_line_numbers() {
        let bad_order = "0 0 1 0\n1 0 1 0\n";
        assert_eq!(
            read_anm(bad_order.as_bytes()),
            Err(Error::Parse {
                line: 2,
                reason: "expected coefficient n=1 m=1, found n=1 m=0".into()
            })
        );
        let bad_number = "0 0 1 0\n1 1 x 0\n";
        assert!(matches!(
            read_anm(bad_number.as_bytes()),
            Err(Error::Parse { line: 2, .. })
        ));
        let truncated = "0 0 1 0\n1 1 0 0\n1 0 0 0\n";
        assert!(matches!(
            read_anm(truncated.as_bytes()),
            Err(Error::Parse { line: 3, .. })
        ));
        assert!(matches!(read_anm("".as_bytes()), Err(Error::Parse { .. })));
        assert!(matches!(
            read_anm("0 0 NaN 0\n".as_bytes()),
            Err(Error::Parse { line: 1, .. })
        ));
        assert!(matches!(
            read_anm("0 0 1\n".as_bytes()),
            Err(Error::Parse { line: 1, .. })
        ));
    }

    proptest! {
        #[test]
        fn never_panics_on_arbitrary_text(s in "\\PC*") {
            let _ = read_anm(s.as_bytes());
        }

        #[test]
        fn never_panics_on_numeric_noise(lines in prop::collection::vec(
            (0usize..4, -4i64..5, -1e3f64..1e3, -1e3f64..1e3), 0..20)) {
            let text: String = lines
                .iter()
                .map(|(n, m, a, b)| format!("{n} {m} {a} {b}\n"))
                .collect();
            let _ = read_anm(text.as_bytes());
        }

        #[test]
        fn round_trips_well_formed_files(degree in 0usize..6, seed in any::<u64>()) {
            let mut text = String::new();
            let mut x = seed;
            for n in 0..=degree {
                for m in (-(n as i64)..=n as i64).rev() {
                    x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    let v = (x >> 11) as f64 / (1u64 << 53) as f64;
                    text.push_str(&format!("{n} {m} {v} {}\n", -v));
                }
            }
            let c = read_anm(text.as_bytes()).expect("well-formed");
            prop_assert_eq!(c.degree, degree);
            prop_assert_eq!(c.complex.len(), (degree + 1) * (degree + 1));
        }
    }
}
