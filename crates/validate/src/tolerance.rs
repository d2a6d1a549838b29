//! Tolerance semantics: how "ours" is compared with "reference" per metric.

use std::fmt;

/// How a computed value is judged against a reference value.
///
/// Every comparison with a NaN or infinite operand fails: a case that
/// produces a non-finite number never passes by accident.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// `|ours − reference| ≤ x` ("within ±x").
    Within(f64),
    /// `ours ≤ reference + x` ("at most reference + x"), e.g. a porosity that
    /// must not exceed the published one by more than `x`.
    AtMost(f64),
    /// `ours ≥ reference − x` ("at least reference − x"); `AtLeast(0.0)` is a
    /// plain "at least".
    AtLeast(f64),
    /// `|ours − reference| ≤ r·|reference|` ("relative ≤ r").
    Relative(f64),
}

impl Tolerance {
    /// Whether `ours` is acceptable against `reference`.
    #[must_use]
    pub fn holds(&self, reference: f64, ours: f64) -> bool {
        if !reference.is_finite() || !ours.is_finite() {
            return false;
        }
        match *self {
            Self::Within(x) => (ours - reference).abs() <= x,
            Self::AtMost(x) => ours <= reference + x,
            Self::AtLeast(x) => ours >= reference - x,
            Self::Relative(r) => (ours - reference).abs() <= r * reference.abs(),
        }
    }
}

impl fmt::Display for Tolerance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Within(x) => write!(f, "within ±{x}"),
            Self::AtMost(x) => write!(f, "at most ref + {x}"),
            Self::AtLeast(0.0) => write!(f, "at least ref"),
            Self::AtLeast(x) => write!(f, "at least ref − {x}"),
            Self::Relative(r) => write!(f, "relative ≤ {r}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Tolerance;

    #[test]
    fn within_is_symmetric_and_inclusive() {
        let t = Tolerance::Within(0.5);
        assert!(t.holds(1.0, 1.5));
        assert!(t.holds(1.0, 0.5));
        assert!(!t.holds(1.0, 1.51));
        assert!(!t.holds(1.0, 0.49));
    }

    #[test]
    fn at_most_is_one_sided_upper() {
        let t = Tolerance::AtMost(0.005);
        assert!(t.holds(0.18, 0.0)); // far below is fine
        assert!(t.holds(0.18, 0.185));
        assert!(!t.holds(0.18, 0.1851));
    }

    #[test]
    fn at_least_is_one_sided_lower() {
        let t = Tolerance::AtLeast(0.0);
        assert!(t.holds(100.0, 1e9));
        assert!(t.holds(100.0, 100.0));
        assert!(!t.holds(100.0, 99.999));
        assert!(Tolerance::AtLeast(1.0).holds(100.0, 99.0));
    }

    #[test]
    fn relative_scales_with_reference() {
        let t = Tolerance::Relative(0.01);
        assert!(t.holds(200.0, 201.9));
        assert!(!t.holds(200.0, 202.1));
        assert!(t.holds(-200.0, -198.5));
        // a zero reference admits only an exact zero
        assert!(t.holds(0.0, 0.0));
        assert!(!t.holds(0.0, 1e-300));
    }

    #[test]
    fn non_finite_never_passes() {
        for t in [
            Tolerance::Within(f64::INFINITY),
            Tolerance::AtMost(1.0),
            Tolerance::AtLeast(1.0),
            Tolerance::Relative(1.0),
        ] {
            assert!(!t.holds(1.0, f64::NAN), "{t}");
            assert!(!t.holds(f64::NAN, 1.0), "{t}");
            assert!(!t.holds(1.0, f64::INFINITY), "{t}");
        }
    }

    #[test]
    fn display_names_the_semantics() {
        assert_eq!(Tolerance::Within(0.01).to_string(), "within ±0.01");
        assert_eq!(Tolerance::AtMost(0.005).to_string(), "at most ref + 0.005");
        assert_eq!(Tolerance::AtLeast(0.0).to_string(), "at least ref");
        assert_eq!(Tolerance::Relative(0.001).to_string(), "relative ≤ 0.001");
    }
}
