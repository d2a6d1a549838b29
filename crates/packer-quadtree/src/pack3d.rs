//! Dense 3D sphere packing: the advancing front of Pinto 2009 (Ch. 3, 2D)
//! carried to 3D with the closed-form three-sphere wrapper of
//! [`crate::contact3d`] (Pérez Morales et al. 2016, §3.1), in a box, a
//! cylinder or a closed mesh ([`Container`]), with metrics, an independent
//! overlap checker and writers for LAMMPS/LIGGGHTS, Yade, CSV and VTU.

mod container;
mod metrics;

pub use container::{Container, MeshContainer};
pub use metrics::{
    CoreFraction, GradingReport, GradingStats, RadialBin, SphereReport, check_spheres,
    core_solid_fraction, grading_report, radial_profile, solid_fraction,
};

use nalgebra::Point3;

/// A placed sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Point3<f64>,
    /// Radius.
    pub radius: f64,
}
