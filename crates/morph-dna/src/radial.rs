//! Radial profiles on the principal-axis-aligned spherical mesh and the
//! node-neighbour radius correlations of Medina 2018, §2.3 and Table 2.
//!
//! # Mesh indexing
//!
//! A [`SphericalMesh`] `n_az × (n_pol + 2)` has `n_az` azimuthal divisions,
//! `n_pol` polar rings and the two poles (Medina 2018 writes 28 × (18 + 2)).
//! The polar index `j` runs from 0 (north pole, θ = 0, the minor principal
//! axis) to `n_pol + 1` (south pole, θ = π); ring `j ∈ 1..=n_pol` sits at
//! θ_j = j π / (n_pol + 1) (equal polar spacing, poles included). The
//! azimuthal index `i ∈ 0..n_az` gives φ_i = 2π i / n_az, with φ = 0 the
//! major principal axis; it wraps periodically, so `i − 1` of `i = 0` is
//! `n_az − 1`. Flat node order: north pole = 0, ring node `(i, j)` =
//! `1 + (j − 1) n_az + i`, south pole = `1 + n_pol n_az`.
//!
//! The seed's stencil `(i ± 1, j), (i, j ± 1)` is defined for ring nodes; at
//! the first and last rings `j ∓ 1` is the pole itself (one node shared by
//! every azimuth).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::stats::{constant_value, pearson_unchecked};

/// An `n_az × (n_pol + 2)` spherical mesh; see the module docs for indexing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SphericalMesh {
    /// Azimuthal divisions (≥ 3).
    pub n_az: usize,
    /// Polar rings, poles excluded (≥ 1).
    pub n_pol: usize,
}

impl Default for SphericalMesh {
    /// The GSC 2.0 mesh 28 × (18 + 2) (Medina 2018, §3 and §4.1, trial 4).
    fn default() -> Self {
        Self {
            n_az: 28,
            n_pol: 18,
        }
    }
}

impl SphericalMesh {
    /// Checks `n_az ≥ 3` and `n_pol ≥ 1`.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`].
    pub fn validate(&self) -> Result<()> {
        if self.n_az < 3 || self.n_pol < 1 {
            return Err(Error::InvalidMesh {
                n_az: self.n_az,
                n_pol: self.n_pol,
            });
        }
        Ok(())
    }

    /// Number of nodes `n_az n_pol + 2`.
    pub fn n_nodes(&self) -> usize {
        self.n_az * self.n_pol + 2
    }

    /// Flat index of node `(i, j)`; `i` is ignored at the poles (`j = 0` or
    /// `j = n_pol + 1`) and wraps modulo `n_az` elsewhere. `None` if
    /// `j > n_pol + 1`.
    pub fn index(&self, i: usize, j: usize) -> Option<usize> {
        if j == 0 {
            Some(0)
        } else if j <= self.n_pol {
            Some(1 + (j - 1) * self.n_az + i % self.n_az)
        } else if j == self.n_pol + 1 {
            Some(1 + self.n_pol * self.n_az)
        } else {
            None
        }
    }

    /// Polar and azimuthal angles `(θ, φ)` of node `(i, j)` in radians (φ = 0
    /// at the poles). `None` if `j > n_pol + 1`.
    pub fn angles(&self, i: usize, j: usize) -> Option<(f64, f64)> {
        if j > self.n_pol + 1 {
            return None;
        }
        let theta = j as f64 * std::f64::consts::PI / (self.n_pol + 1) as f64;
        let phi = if j == 0 || j == self.n_pol + 1 {
            0.0
        } else {
            std::f64::consts::TAU * (i % self.n_az) as f64 / self.n_az as f64
        };
        Some((theta, phi))
    }

    /// Angles of every node in flat order.
    pub fn node_angles(&self) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(self.n_nodes());
        for j in 0..=self.n_pol + 1 {
            let count = if j == 0 || j == self.n_pol + 1 {
                1
            } else {
                self.n_az
            };
            for i in 0..count {
                out.extend(self.angles(i, j));
            }
        }
        out
    }
}

/// Radii of a population of grains at the nodes of one [`SphericalMesh`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RadialProfiles {
    /// The mesh.
    pub mesh: SphericalMesh,
    /// `radii[g][node]`: radius of grain `g` at flat node index `node`.
    pub radii: Vec<Vec<f64>>,
}

impl RadialProfiles {
    /// Checks the mesh, the profile lengths and that every radius is finite
    /// and positive.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`], [`Error::RaggedTable`], [`Error::NonPositive`]
    /// (also for NaN).
    pub fn validate(&self) -> Result<()> {
        self.mesh.validate()?;
        let n = self.mesh.n_nodes();
        for (g, r) in self.radii.iter().enumerate() {
            if r.len() != n {
                return Err(Error::RaggedTable {
                    what: "radial profile",
                    index: g,
                    expected: n,
                    found: r.len(),
                });
            }
            if let Some(k) = r.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(Error::NonPositive {
                    what: "radius",
                    index: g * n + k,
                    value: r[k],
                });
            }
        }
        Ok(())
    }

    /// Radii of every grain at flat node `node`.
    fn node_column(&self, node: usize) -> Vec<f64> {
        self.radii.iter().map(|r| r[node]).collect()
    }
}

/// Pearson correlations, across the population, of the radius at a ring node
/// `(i, j)` with its four stencil neighbours (Medina 2018, Table 2).
///
/// A correlation is `None` when the radius at one of the two nodes is the same
/// for every grain (correlation undefined, e.g. a population of identical
/// spheres); it is never NaN.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NeighbourCorrelation {
    /// Azimuthal index of the node.
    pub i: usize,
    /// Polar index of the node (1..=n_pol).
    pub j: usize,
    /// With `(i, j − 1)` (the north pole when `j = 1`).
    pub j_minus: Option<f64>,
    /// With `(i − 1, j)` (periodic).
    pub i_minus: Option<f64>,
    /// With `(i, j + 1)` (the south pole when `j = n_pol`).
    pub j_plus: Option<f64>,
    /// With `(i + 1, j)` (periodic).
    pub i_plus: Option<f64>,
}

fn correlation_or_none(a: &[f64], b: &[f64]) -> Option<f64> {
    if constant_value(a).is_some() || constant_value(b).is_some() {
        None
    } else {
        Some(pearson_unchecked(a, b))
    }
}

/// Neighbour correlations of ring node `(i, j)`.
///
/// # Errors
/// Validation errors of [`RadialProfiles::validate`], [`Error::TooFewSamples`]
/// below 2 grains, [`Error::NotARingNode`] if `i ≥ n_az` or `j` is a pole or
/// beyond.
pub fn neighbour_correlation(
    profiles: &RadialProfiles,
    i: usize,
    j: usize,
) -> Result<NeighbourCorrelation> {
    profiles.validate()?;
    if profiles.radii.len() < 2 {
        return Err(Error::TooFewSamples {
            needed: 2,
            found: profiles.radii.len(),
        });
    }
    neighbour_correlation_unchecked(profiles, i, j)
}

fn neighbour_correlation_unchecked(
    profiles: &RadialProfiles,
    i: usize,
    j: usize,
) -> Result<NeighbourCorrelation> {
    let m = profiles.mesh;
    if i >= m.n_az || j == 0 || j > m.n_pol {
        return Err(Error::NotARingNode {
            i,
            j,
            n_az: m.n_az,
            n_pol: m.n_pol,
        });
    }
    let col = |ii: usize, jj: usize| {
        // Indices are in range by construction (jj ≤ n_pol + 1).
        let idx = m.index(ii, jj).unwrap_or(0);
        profiles.node_column(idx)
    };
    let c = col(i, j);
    let im = (i + m.n_az - 1) % m.n_az;
    let ip = (i + 1) % m.n_az;
    Ok(NeighbourCorrelation {
        i,
        j,
        j_minus: correlation_or_none(&c, &col(i, j - 1)),
        i_minus: correlation_or_none(&c, &col(im, j)),
        j_plus: correlation_or_none(&c, &col(i, j + 1)),
        i_plus: correlation_or_none(&c, &col(ip, j)),
    })
}

/// Neighbour correlations of every ring node, ring by ring (`j = 1..=n_pol`,
/// then `i = 0..n_az`).
///
/// # Errors
/// As [`neighbour_correlation`].
pub fn all_neighbour_correlations(profiles: &RadialProfiles) -> Result<Vec<NeighbourCorrelation>> {
    profiles.validate()?;
    if profiles.radii.len() < 2 {
        return Err(Error::TooFewSamples {
            needed: 2,
            found: profiles.radii.len(),
        });
    }
    let m = profiles.mesh;
    let mut out = Vec::with_capacity(m.n_az * m.n_pol);
    for j in 1..=m.n_pol {
        for i in 0..m.n_az {
            out.push(neighbour_correlation_unchecked(profiles, i, j)?);
        }
    }
    Ok(out)
}

/// Mean of each stencil direction's correlation over a set of ring nodes
/// (undefined entries skipped), to set beside Medina 2018, Table 2, which
/// prints one node and states that "similar results are obtained for the
/// rest of the mesh points".
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NeighbourCorrelationSummary {
    /// Mean correlation with `(i, j − 1)`, `None` if undefined everywhere.
    pub j_minus: Option<f64>,
    /// Mean correlation with `(i − 1, j)`.
    pub i_minus: Option<f64>,
    /// Mean correlation with `(i, j + 1)`.
    pub j_plus: Option<f64>,
    /// Mean correlation with `(i + 1, j)`.
    pub i_plus: Option<f64>,
    /// Number of node pairs with an undefined correlation (constant radius).
    pub undefined: usize,
}

impl NeighbourCorrelationSummary {
    /// Summarises per-node correlations (for example
    /// [`all_neighbour_correlations`]).
    pub fn from_nodes(nodes: &[NeighbourCorrelation]) -> Self {
        let mut undefined = 0;
        let mut mean = |get: fn(&NeighbourCorrelation) -> Option<f64>| {
            let (mut sum, mut n) = (0.0, 0usize);
            for c in nodes {
                match get(c) {
                    Some(v) => {
                        sum += v;
                        n += 1;
                    }
                    None => undefined += 1,
                }
            }
            (n > 0).then(|| sum / n as f64)
        };
        Self {
            j_minus: mean(|c| c.j_minus),
            i_minus: mean(|c| c.i_minus),
            j_plus: mean(|c| c.j_plus),
            i_plus: mean(|c| c.i_plus),
            undefined,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn mesh_indexing_wraps_and_counts() {
        let m = SphericalMesh { n_az: 4, n_pol: 3 };
        assert_eq!(m.n_nodes(), 14);
        assert_eq!(m.index(7, 0), Some(0));
        assert_eq!(m.index(0, 1), Some(1));
        assert_eq!(m.index(3, 1), Some(4));
        assert_eq!(m.index(4, 1), Some(1));
        assert_eq!(m.index(2, 3), Some(11));
        assert_eq!(m.index(0, 4), Some(13));
        assert_eq!(m.index(0, 5), None);
        let a = m.node_angles();
        assert_eq!(a.len(), m.n_nodes());
        assert_relative_eq!(a[0].0, 0.0);
        assert_relative_eq!(a[13].0, std::f64::consts::PI);
        // Ring 2 of 3 is the equator; node (1, 2) at φ = π/2.
        let (t, p) = a[m.index(1, 2).expect("in mesh")];
        assert_relative_eq!(t, std::f64::consts::FRAC_PI_2);
        assert_relative_eq!(p, std::f64::consts::FRAC_PI_2);
        assert!(SphericalMesh { n_az: 2, n_pol: 3 }.validate().is_err());
        assert!(SphericalMesh { n_az: 3, n_pol: 0 }.validate().is_err());
        assert_eq!(SphericalMesh::default().n_nodes(), 28 * 18 + 2);
    }

    /// Builds profiles whose node values are known affine functions of a
    /// per-grain factor, so the neighbour correlations are known exactly.
    #[test]
    fn neighbour_correlations_oracle() {
        let m = SphericalMesh { n_az: 5, n_pol: 2 };
        let angles = m.node_angles();
        let s = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let t = [2.0, 1.0, 4.0, 3.0, 6.0, 5.0];
        // Node value = 10 + s (+ t at φ = 0 ring nodes only): nodes with φ = 0
        // correlate with their neighbours as pearson(s, s + t); the rest as 1.
        let radii: Vec<Vec<f64>> = (0..6)
            .map(|g| {
                angles
                    .iter()
                    .enumerate()
                    .map(|(k, (_, phi))| {
                        let ring = k != 0 && k != m.n_nodes() - 1;
                        10.0 + s[g] + if ring && *phi == 0.0 { t[g] } else { 0.0 }
                    })
                    .collect()
            })
            .collect();
        let p = RadialProfiles { mesh: m, radii };
        let st: Vec<f64> = s.iter().zip(&t).map(|(a, b)| a + b).collect();
        let r = crate::stats::pearson(&s, &st).expect("ok");
        let c = neighbour_correlation(&p, 0, 1).expect("ring node");
        assert_relative_eq!(c.i_minus.expect("defined"), r, epsilon = 1e-14);
        assert_relative_eq!(c.i_plus.expect("defined"), r, epsilon = 1e-14);
        assert_relative_eq!(c.j_minus.expect("defined"), r, epsilon = 1e-14);
        assert_relative_eq!(c.j_plus.expect("defined"), 1.0, epsilon = 1e-14);
        // Node (4, 1) has (0, 1) as its periodic i + 1 neighbour.
        let c = neighbour_correlation(&p, 4, 1).expect("ring node");
        assert_relative_eq!(c.i_plus.expect("defined"), r, epsilon = 1e-14);
        assert_relative_eq!(c.i_minus.expect("defined"), 1.0, epsilon = 1e-14);
        let all = all_neighbour_correlations(&p).expect("ok");
        assert_eq!(all.len(), 10);
        assert_eq!((all[7].i, all[7].j), (2, 2));
        // Azimuthal links touching a φ = 0 node: 2 per ring, 4 of 10 at r.
        // Polar links: only each φ = 0 node's pole link is at r (the two
        // φ = 0 ring nodes correlate with each other at 1).
        let s = NeighbourCorrelationSummary::from_nodes(&all);
        assert_eq!(s.undefined, 0);
        let azimuthal = (6.0 + 4.0 * r) / 10.0;
        let polar = (9.0 + r) / 10.0;
        assert_relative_eq!(s.i_minus.expect("defined"), azimuthal, epsilon = 1e-14);
        assert_relative_eq!(s.i_plus.expect("defined"), azimuthal, epsilon = 1e-14);
        assert_relative_eq!(s.j_minus.expect("defined"), polar, epsilon = 1e-14);
        assert_relative_eq!(s.j_plus.expect("defined"), polar, epsilon = 1e-14);
    }

    #[test]
    fn degenerate_profiles() {
        let m = SphericalMesh { n_az: 3, n_pol: 1 };
        let same = RadialProfiles {
            mesh: m,
            radii: vec![vec![1.0; 5]; 4],
        };
        let c = neighbour_correlation(&same, 0, 1).expect("valid");
        assert_eq!(c.i_plus, None);
        assert_eq!(c.j_minus, None);
        let s = NeighbourCorrelationSummary::from_nodes(&[c]);
        assert_eq!((s.i_plus, s.undefined), (None, 4));
        let one = RadialProfiles {
            mesh: m,
            radii: vec![vec![1.0; 5]],
        };
        assert!(matches!(
            neighbour_correlation(&one, 0, 1),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            neighbour_correlation(&same, 0, 0),
            Err(Error::NotARingNode { .. })
        ));
        assert!(matches!(
            neighbour_correlation(&same, 3, 1),
            Err(Error::NotARingNode { .. })
        ));
        let short = RadialProfiles {
            mesh: m,
            radii: vec![vec![1.0; 5], vec![1.0; 4]],
        };
        assert!(matches!(
            short.validate(),
            Err(Error::RaggedTable { index: 1, .. })
        ));
        let neg = RadialProfiles {
            mesh: m,
            radii: vec![vec![1.0; 5], vec![1.0, 1.0, -1.0, 1.0, 1.0]],
        };
        assert!(matches!(
            neg.validate(),
            Err(Error::NonPositive { index: 7, .. })
        ));
        let nan = RadialProfiles {
            mesh: m,
            radii: vec![vec![f64::NAN; 5], vec![1.0; 5]],
        };
        assert!(nan.validate().is_err());
    }
}
