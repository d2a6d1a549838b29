//! Advancing-front dense packing of disks, spheres and general grains
//! (Pinto 2009; Pérez Morales et al. 2016).
//!
//! This crate will hold (issues 7 and later): the advancing-front disk packer
//! with halos and its MX-quadtree and cell-grid spatial indexes, grading
//! curves, arbitrary domains, porosity and contact metrics, genetic-algorithm
//! porosity control, functionally graded layers, particle-in-contact solvers,
//! and CSV/VTU/LIGGGHTS/Yade/SVG writers.
//!
//! Layer 2: may depend on `levelset` only.
