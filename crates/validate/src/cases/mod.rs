//! The case registry: each crate's reproductions plug in here as one module
//! exposing `cases()` and `EXPECTED_FAILURES`.

use crate::{Case, ExpectedFailure};

mod cloner;
mod fixture_integrity;
mod levelset;
mod pack3d;
mod packer_quadtree;
pub mod parents;
mod perez_morales;
mod rounding;
pub mod specimen;
mod specimen_dem;
mod sph_harmonics;
#[cfg(test)]
mod tests;
mod voxel_roundness;

/// Every registered case, in a stable order.
#[must_use]
pub fn registry() -> Vec<Case> {
    let mut cases = Vec::new();
    cases.extend(cloner::cases());
    cases.extend(fixture_integrity::cases());
    cases.extend(levelset::cases());
    cases.extend(pack3d::cases());
    cases.extend(packer_quadtree::cases());
    cases.extend(parents::cases());
    cases.extend(perez_morales::cases());
    cases.extend(specimen::cases());
    cases.extend(specimen_dem::cases());
    cases.extend(sph_harmonics::cases());
    cases.extend(voxel_roundness::cases());
    cases
}

/// Every known failure with its reason.
#[must_use]
pub fn expected_failures() -> Vec<ExpectedFailure> {
    let mut list = Vec::new();
    list.extend_from_slice(cloner::EXPECTED_FAILURES);
    list.extend_from_slice(fixture_integrity::EXPECTED_FAILURES);
    list.extend_from_slice(levelset::EXPECTED_FAILURES);
    list.extend_from_slice(pack3d::EXPECTED_FAILURES);
    list.extend_from_slice(packer_quadtree::EXPECTED_FAILURES);
    list.extend_from_slice(parents::EXPECTED_FAILURES);
    list.extend_from_slice(perez_morales::EXPECTED_FAILURES);
    list.extend_from_slice(specimen::EXPECTED_FAILURES);
    list.extend_from_slice(specimen_dem::EXPECTED_FAILURES);
    list.extend_from_slice(sph_harmonics::EXPECTED_FAILURES);
    list.extend_from_slice(voxel_roundness::EXPECTED_FAILURES);
    list
}
