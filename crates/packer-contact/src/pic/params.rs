//! Parameters of a particle-in-contact packing: the contact solver
//! ([`ContactMethod`]), [`PicParams`] with its validation and the presets
//! of Pérez Morales et al. 2016.

use crate::error::{Error, Result};
use crate::shapes::GrainShape;

/// How the contact positions are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactMethod {
    /// Closed-form wrapper intersections (seed §3.1): exact for disks,
    /// spheres and their clusters (every element combination, as the
    /// seed); other shapes fall back to [`ContactMethod::Newton`].
    Wrappers,
    /// Closed form for single disks/spheres, otherwise Newton's method on
    /// exact gaps from closed-form first guesses (the fast method).
    #[default]
    Newton,
    /// The seed's Nelder–Mead minimisation of the gaps (§3.2), from the
    /// same first guesses, for comparison.
    NelderMead,
    /// The seed's "approximate wrappers method" (P5) for disks/spheres and
    /// their clusters of equal elements: one element of the new cluster is
    /// placed tangent to one element of the front grain and one (2D) or two
    /// (3D) elements or walls among the nearest placed elements (closed
    /// form), the cluster follows rigidly in its drawn orientation (each of
    /// its elements is tried as the contact one), and candidates, lowest
    /// first, are rejected by element–element overlap tests on a cell grid
    /// of all placed elements. Approximate: the cluster touches one set of
    /// elements, not the lowest exact contact of the whole cluster, so
    /// packings are looser than [`ContactMethod::Newton`]'s, but two
    /// orders of magnitude faster. Other shapes fall back to
    /// [`ContactMethod::Newton`].
    ApproxWrappers,
}

/// Parameters of a particle-in-contact packing.
#[derive(Debug, Clone, PartialEq)]
pub struct PicParams {
    /// Side of the square or cube domain `[0, side]^D`.
    pub side: f64,
    /// Smallest circumscribed radius.
    pub radius_min: f64,
    /// Largest circumscribed radius.
    pub radius_max: f64,
    /// Grain family.
    pub shape: GrainShape,
    /// Contact solver.
    pub method: ContactMethod,
    /// Stop after this many placed grains.
    pub max_grains: usize,
    /// How many grains nearest to the front grain may be contact partners
    /// (with the walls); more is slower and slightly denser.
    pub neighbours: usize,
    /// Orientations tried per grain (the drawn one first; the lowest
    /// placement wins). 1 keeps every grain's random orientation, as the
    /// seed's "without making rotations".
    pub orientations: usize,
}

impl Default for PicParams {
    /// The seed's Fig. 6 setting in 2D: side 20, `R ~ U[1, 2]`, capsules of
    /// aspect ratio 0.5.
    fn default() -> Self {
        Self {
            side: 20.0,
            radius_min: 1.0,
            radius_max: 2.0,
            shape: GrainShape::Capsule { aspect: 0.5 },
            method: ContactMethod::Newton,
            max_grains: 1_000_000,
            neighbours: 16,
            orientations: 1,
        }
    }
}

impl PicParams {
    /// Checks every field for dimension `dim`.
    ///
    /// # Errors
    /// [`Error::NonPositive`], [`Error::NonFinite`], [`Error::InvertedRange`],
    /// [`Error::DomainTooSmall`] when the side is below the largest
    /// circumscribed diameter, and the shape's [`GrainShape::validate`].
    pub fn validate(&self, dim: usize) -> Result<()> {
        crate::error::positive("side", self.side)?;
        crate::error::positive("radius_min", self.radius_min)?;
        crate::error::positive("radius_max", self.radius_max)?;
        if self.radius_min > self.radius_max {
            return Err(Error::InvertedRange {
                min: self.radius_min,
                max: self.radius_max,
            });
        }
        if self.side < 2.0 * self.radius_max {
            return Err(Error::DomainTooSmall {
                domain: self.side,
                particle: 2.0 * self.radius_max,
            });
        }
        self.shape.validate(dim)
    }
}

impl PicParams {
    /// The configuration we use for a row of Pérez Morales et al. 2016
    /// (`fixtures/reference/perezmorales2016_packings.csv`), with its
    /// dimension: side 20 (2D) or 40 (3D), `R ~ U[1, 2]`, aspect ratio
    /// `r/R = 0.5` (see [`crate::GrainShape`]). Our choices where the seed
    /// is silent: P1 half disks, half regular 4–8-gons, Newton on parry
    /// contacts; P2 4-disk clusters by the seed's wrappers, 8 orientations
    /// tried per grain; P3 exact capsules by Newton, 64 orientations; P4
    /// exact capsules by Newton, the drawn orientation only, 10 partners;
    /// P5 4-sphere clusters by the seed's approximate wrappers
    /// ([`ContactMethod::ApproxWrappers`], 6 nearest elements per element
    /// of the front grain; Newton with 10 partners packs 0.54 at ~220
    /// grains/s, the approximate method ~0.38 at ~15 000 grains/s).
    ///
    /// # Errors
    /// [`Error::Parameter`] for an unknown row id.
    pub fn perezmorales2016(row: &str) -> Result<(usize, Self)> {
        let base = Self::default();
        let capsule = GrainShape::Capsule { aspect: 0.5 };
        let cluster = GrainShape::Cluster {
            aspect: 0.5,
            spheres: 4,
        };
        Ok(match row {
            "P1" => (
                2,
                Self {
                    shape: GrainShape::Mix {
                        polygon_share: 0.5,
                        sides_min: 4,
                        sides_max: 8,
                    },
                    ..base
                },
            ),
            "P2" => (
                2,
                Self {
                    shape: cluster,
                    method: ContactMethod::Wrappers,
                    orientations: 8,
                    ..base
                },
            ),
            "P3" => (
                2,
                Self {
                    shape: capsule,
                    orientations: 64,
                    ..base
                },
            ),
            "P4" => (
                3,
                Self {
                    side: 40.0,
                    shape: capsule,
                    neighbours: 10,
                    ..base
                },
            ),
            "P5" => (
                3,
                Self {
                    side: 40.0,
                    shape: cluster,
                    method: ContactMethod::ApproxWrappers,
                    neighbours: 6,
                    ..base
                },
            ),
            _ => {
                return Err(Error::Parameter {
                    what: "perezmorales2016 row (P1..P5)",
                    value: f64::NAN,
                    range: "P1, P2, P3, P4, P5",
                });
            }
        })
    }
}
