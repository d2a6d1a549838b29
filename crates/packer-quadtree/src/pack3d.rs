//! Dense 3D sphere packing: the advancing front of Pinto 2009 (Ch. 3, 2D)
//! carried to 3D with the closed-form three-sphere wrapper of
//! [`crate::contact3d`] (Pérez Morales et al. 2016, §3.1), in a box, a
//! cylinder or a closed mesh ([`Container`]), with metrics, an independent
//! overlap checker and writers and readers for LAMMPS/LIGGGHTS, Yade, CSV
//! and VTU.

mod container;
mod io;

pub use container::{Container, MeshContainer};
pub use io::{
    LammpsData3, read_csv3, read_lammps_data3, read_vtu3, read_yade3, write_csv3,
    write_lammps_data3, write_vtu3, write_yade3,
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
