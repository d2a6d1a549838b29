//! The morphological descriptors, the columns of a DNA table (in their own
//! module: the error type names them and the tables hold them).

use serde::{Deserialize, Serialize};

/// A morphological descriptor of one grain (a column of a [`DnaTable`](crate::DnaTable)).
///
/// Lengths are in the caller's length unit (SI metres for measured grains),
/// areas and volumes in its square and cube. `L ≥ I ≥ S` denote the major,
/// intermediate and minor principal dimensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Descriptor {
    /// Grain volume `V`.
    Volume,
    /// Surface area `A`.
    SurfaceArea,
    /// Volume/surface ratio `V / A` (a length), the quantity of the quality
    /// control of Medina 2018, §2.4.
    VolumeSurfaceRatio,
    /// Equivalent-sphere diameter `(6 V / π)^(1/3)`: the "grain diameter" of
    /// Medina 2018, Tables 4–5, and the diameter of the grading curve.
    EquivalentDiameter,
    /// Major principal dimension `L`: full length along the major principal
    /// axis of the inertia-equivalent ellipsoid scaled to the grain volume.
    MajorPrincipalDimension,
    /// Intermediate principal dimension `I` (same construction as `L`).
    IntermediatePrincipalDimension,
    /// Minor principal dimension `S` (same construction as `L`): the
    /// "minimum principal direction" of Medina 2018, Table 1.
    MinPrincipalDimension,
    /// Extent of the grain along its major principal axis (max − min of the
    /// surface projected on the axis).
    MajorExtent,
    /// Extent of the grain along its intermediate principal axis.
    IntermediateExtent,
    /// Extent of the grain along its minor principal axis.
    MinorExtent,
    /// Aspect ratio `S / L` in (0, 1], 1 for a sphere (Jerves et al. 2017,
    /// doi:10.1007/s10035-017-0716-7, "a measure of sphericity" in Medina 2018).
    AspectRatio,
    /// Elongation `I / L` in (0, 1] (convention of the Sand Atlas and spam).
    Elongation,
    /// Flatness `S / I` in (0, 1] (convention of the Sand Atlas and spam).
    Flatness,
    /// Wadell true sphericity `π^(1/3) (6 V)^(2/3) / A` in (0, 1].
    Sphericity,
    /// Convexity: volume over convex-hull volume, in (0, 1].
    Convexity,
    /// 3D Wadell-type roundness: mean radius of curvature at corners over the
    /// radius of the largest inscribed sphere, in (0, 1].
    Roundness,
}

impl Descriptor {
    /// Every descriptor, in declaration order.
    pub const ALL: [Self; 16] = [
        Self::Volume,
        Self::SurfaceArea,
        Self::VolumeSurfaceRatio,
        Self::EquivalentDiameter,
        Self::MajorPrincipalDimension,
        Self::IntermediatePrincipalDimension,
        Self::MinPrincipalDimension,
        Self::MajorExtent,
        Self::IntermediateExtent,
        Self::MinorExtent,
        Self::AspectRatio,
        Self::Elongation,
        Self::Flatness,
        Self::Sphericity,
        Self::Convexity,
        Self::Roundness,
    ];

    /// The four descriptors of Medina 2018, Table 1, in its order.
    pub const MEDINA_2018_TABLE_1: [Self; 4] = [
        Self::AspectRatio,
        Self::Roundness,
        Self::VolumeSurfaceRatio,
        Self::MinPrincipalDimension,
    ];

    /// Snake-case name used in CSV headers and reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Volume => "volume",
            Self::SurfaceArea => "surface_area",
            Self::VolumeSurfaceRatio => "volume_surface_ratio",
            Self::EquivalentDiameter => "equivalent_diameter",
            Self::MajorPrincipalDimension => "major_principal_dimension",
            Self::IntermediatePrincipalDimension => "intermediate_principal_dimension",
            Self::MinPrincipalDimension => "min_principal_dimension",
            Self::MajorExtent => "major_extent",
            Self::IntermediateExtent => "intermediate_extent",
            Self::MinorExtent => "minor_extent",
            Self::AspectRatio => "aspect_ratio",
            Self::Elongation => "elongation",
            Self::Flatness => "flatness",
            Self::Sphericity => "sphericity",
            Self::Convexity => "convexity",
            Self::Roundness => "roundness",
        }
    }

    /// Inverse of [`Descriptor::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|d| d.name() == name)
    }
}

impl std::fmt::Display for Descriptor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
