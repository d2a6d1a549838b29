//! Interval arithmetic over printed numbers, to tell a source's rounding
//! from a real inconsistency.
//!
//! A number printed with `k` decimals stands for the interval
//! `value ± 0.5·10⁻ᵏ`. Recomputing a printed result from printed inputs gives
//! two checks: *strict* (the midpoint recomputation, rounded as printed,
//! equals the printed result) and *rounding* (some choice of inputs inside
//! their print intervals reproduces the printed result).

use crate::{Check, Error, Tolerance, fixtures::Table};

/// A closed interval `[lo, hi]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Iv {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
}

impl Iv {
    /// An exact number (a definition, not a printed value).
    pub(crate) fn exact(v: f64) -> Self {
        Self { lo: v, hi: v }
    }

    /// A printed number: its decimals fix the half-unit of rounding.
    pub(crate) fn printed(text: &str) -> Option<Self> {
        let t = text.trim();
        let v: f64 = t.parse().ok()?;
        if !v.is_finite() {
            return None;
        }
        let half = 0.5 * 10f64.powi(-(decimals(t) as i32));
        Some(Self {
            lo: v - half,
            hi: v + half,
        })
    }

    pub(crate) fn mid(self) -> f64 {
        0.5 * (self.lo + self.hi)
    }

    pub(crate) fn half_width(self) -> f64 {
        0.5 * (self.hi - self.lo)
    }

    pub(crate) fn add(self, o: Self) -> Self {
        Self {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
    }

    pub(crate) fn sub(self, o: Self) -> Self {
        Self {
            lo: self.lo - o.hi,
            hi: self.hi - o.lo,
        }
    }

    pub(crate) fn mul(self, o: Self) -> Self {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Self {
            lo: p.iter().copied().fold(f64::INFINITY, f64::min),
            hi: p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// Division by an interval that excludes zero.
    pub(crate) fn div(self, o: Self) -> Self {
        debug_assert!(
            o.lo > 0.0 || o.hi < 0.0,
            "division by an interval containing 0"
        );
        self.mul(Self {
            lo: 1.0 / o.hi,
            hi: 1.0 / o.lo,
        })
    }

    pub(crate) fn scale(self, k: f64) -> Self {
        if k >= 0.0 {
            Self {
                lo: self.lo * k,
                hi: self.hi * k,
            }
        } else {
            Self {
                lo: self.hi * k,
                hi: self.lo * k,
            }
        }
    }

    pub(crate) fn abs(self) -> Self {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            Self {
                lo: -self.hi,
                hi: -self.lo,
            }
        } else {
            Self {
                lo: 0.0,
                hi: self.hi.max(-self.lo),
            }
        }
    }

    pub(crate) fn sqrt(self) -> Self {
        Self {
            lo: self.lo.max(0.0).sqrt(),
            hi: self.hi.max(0.0).sqrt(),
        }
    }

    pub(crate) fn square(self) -> Self {
        self.mul(self)
    }
}

/// Number of decimals as printed (`"2.90"` → 2, `"674027"` → 0).
pub(crate) fn decimals(text: &str) -> usize {
    let t = text.trim();
    let mantissa = t.split(['e', 'E']).next().unwrap_or(t);
    mantissa.split_once('.').map_or(0, |(_, d)| d.len())
}

/// A printed cell of a table as an interval.
pub(crate) fn cell(t: &Table, row: usize, column: &str) -> Result<Iv, Error> {
    let text = t.text(row, column)?;
    Iv::printed(text).ok_or_else(|| Error::NotANumber {
        table: t.name.clone(),
        line: t.lines.get(row).copied().unwrap_or(0),
        column: column.to_owned(),
        value: text.to_owned(),
    })
}

/// The strict and the rounding check of a printed result against its
/// recomputation from printed inputs (`computed` is the interval image of
/// the inputs' print intervals; its midpoint is "ours").
pub(crate) fn recompute(metric: &str, printed: Iv, computed: Iv) -> [Check; 2] {
    let slack = 1e-9 * printed.mid().abs().max(1.0);
    let ours = computed.mid();
    [
        Check::new(
            metric,
            printed.mid(),
            ours,
            Tolerance::Within(printed.half_width() + slack),
        ),
        Check::new(
            format!("{metric} (rounding)"),
            printed.mid(),
            ours,
            Tolerance::Within(printed.half_width() + computed.half_width() + slack),
        ),
    ]
}

/// Only the rounding check, under the plain metric name: for tables whose
/// results were computed from unrounded internal values, where a strict
/// recomputation from the rounded inputs says nothing about consistency.
pub(crate) fn consistent(metric: &str, printed: Iv, computed: Iv) -> Check {
    let slack = 1e-9 * printed.mid().abs().max(1.0);
    Check::new(
        metric,
        printed.mid(),
        computed.mid(),
        Tolerance::Within(printed.half_width() + computed.half_width() + slack),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printed_intervals() {
        let v = Iv::printed("2.90").expect("number");
        assert!((v.lo - 2.895).abs() < 1e-12 && (v.hi - 2.905).abs() < 1e-12);
        assert_eq!(decimals("674027"), 0);
        assert_eq!(decimals("0.0009857"), 7);
        assert_eq!(decimals("1.5e-3"), 1);
        assert!(Iv::printed("x").is_none());
    }

    #[test]
    fn interval_ops_contain_every_pointwise_result() {
        let a = Iv { lo: -1.0, hi: 2.0 };
        let b = Iv { lo: 0.5, hi: 3.0 };
        for &x in &[-1.0, 0.0, 1.3, 2.0] {
            for &y in &[0.5, 1.0, 3.0] {
                let inside = |iv: Iv, v: f64| iv.lo - 1e-12 <= v && v <= iv.hi + 1e-12;
                assert!(inside(a.add(b), x + y));
                assert!(inside(a.sub(b), x - y));
                assert!(inside(a.mul(b), x * y));
                assert!(inside(a.div(b), x / y));
                assert!(inside(a.abs(), f64::abs(x)));
                assert!(inside(a.scale(-2.0), -2.0 * x));
                assert!(inside(b.sqrt(), f64::sqrt(y)));
            }
        }
    }

    #[test]
    fn strict_fails_where_only_rounding_explains() {
        // GSC 2018 Cu: |1.15 − 1.26| / 1.26 = 8.73 %, printed 8.29 %
        let p = Iv::printed("1.26").expect("n");
        let c = Iv::printed("1.15").expect("n");
        let e = c.sub(p).abs().div(p).scale(100.0);
        let [strict, rounding] = recompute("Cu", Iv::printed("8.29").expect("n"), e);
        assert!(!strict.passes());
        assert!(rounding.passes());
    }
}
