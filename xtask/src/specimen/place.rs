//! Placement of the clones in the container: the one function that turns
//! clone sizes into poses, so that a grain packer (dense non-overlapping
//! packing of star-shaped clones) can replace it without touching the rest
//! of the pipeline.
//!
//! Today's method is conservative and real: each clone's bounding sphere
//! (its largest node radius about the clone's origin, times
//! [`BOUNDING_MARGIN`] for the interpolation between mesh nodes) is packed
//! by `packer_quadtree::pack3d_sizes` in the container, sizes as given, and
//! every clone gets an isotropic random rotation from its own
//! `(seed, index)` stream. Bounding spheres do not overlap, so neither do
//! the grains: non-overlapping by construction, and loose (the grains fill
//! roughly a third of their spheres' volume less than a dense grain
//! packing would).

use anyhow::bail;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use packer_quadtree::{Container, Pack3Params};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::scene::Preset;

/// Bounding radius = largest node radius × this margin (the level set
/// between nodes is interpolated and may bulge slightly past the nodes).
pub(crate) const BOUNDING_MARGIN: f64 = 1.05;

/// Stream offset of the rotations, so that they never share a stream with
/// the cloner's (seed, index) streams.
const ROTATION_STREAM: u64 = 0x726f_7461_7465;

/// What placement needs to know of one clone: its bounding radius about
/// the clone frame's origin (major axis +x, minor +z).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ToPlace {
    /// Clone index (its random stream).
    pub(crate) index: u64,
    /// Radius of a sphere about the clone frame's origin that holds the grain.
    pub(crate) bounding_radius: f64,
}

/// The container cannot take every clone (an auto-sized one grows on it).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContainerFull {
    /// Clones to place.
    pub(crate) clones: usize,
    /// Bounding spheres that fitted.
    pub(crate) placed: usize,
}

impl std::fmt::Display for ContainerFull {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`container` cannot take all {} clones: their bounding spheres fill it after {}",
            self.clones, self.placed
        )
    }
}

impl std::error::Error for ContainerFull {}

/// Poses (clone frame → world) of every clone, in the order of `clones`.
///
/// # Errors
/// No clone; a container smaller than the largest clone's bounding sphere
/// (naming both sizes); a container that cannot take every clone (naming
/// how many fit); packer errors.
pub(crate) fn place(
    clones: &[ToPlace],
    container: &Container,
    preset: Preset,
    seed: u64,
) -> anyhow::Result<Vec<Isometry3<f64>>> {
    if clones.is_empty() {
        bail!("no clone to place");
    }
    let sizes: Vec<f64> = clones.iter().map(|c| 2.0 * c.bounding_radius).collect();
    let (lo, hi) = sizes
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(a, b), d| (a.min(*d), b.max(*d)));
    let room = inscribed_diameter(container);
    if hi > room {
        bail!(
            "`container` is too small for the largest clone: its bounding sphere has diameter {hi:.4}, the container takes at most {room:.4}"
        );
    }
    let params = match preset {
        Preset::Default => Pack3Params::default(),
        Preset::Dense => Pack3Params::dense(),
    };
    let packing = packer_quadtree::pack3d_sizes(container, &sizes, lo, hi, &params)?;
    if packing.spheres.len() < clones.len() {
        return Err(ContainerFull {
            clones: clones.len(),
            placed: packing.spheres.len(),
        }
        .into());
    }
    // The packer may place sizes out of order (its look-ahead window):
    // match every placed sphere to an unused clone of the same size.
    let mut order: Vec<usize> = (0..clones.len()).collect();
    order.sort_by(|&a, &b| sizes[a].total_cmp(&sizes[b]).then(a.cmp(&b)));
    let sorted: Vec<f64> = order.iter().map(|&k| sizes[k]).collect();
    let mut used = vec![false; clones.len()];
    let mut centres = vec![None; clones.len()];
    for s in &packing.spheres {
        let d = 2.0 * s.radius;
        let at = sorted.partition_point(|x| *x < d * (1.0 - 1e-12));
        let pick = (at..sorted.len())
            .take_while(|&j| sorted[j] <= d * (1.0 + 1e-12))
            .find(|&j| !used[j]);
        let Some(j) = pick else {
            bail!("placement: a packed sphere of diameter {d} matches no clone (a packer bug)");
        };
        used[j] = true;
        centres[order[j]] = Some(s.center);
    }
    clones
        .iter()
        .zip(centres)
        .map(|(c, p)| {
            let Some(p) = p else {
                bail!("placement: clone {} was not placed (a packer bug)", c.index);
            };
            Ok(Isometry3::from_parts(
                Translation3::from(p.coords),
                random_rotation(seed, c.index),
            ))
        })
        .collect()
}

/// Diameter of the largest sphere the container takes.
pub(crate) fn inscribed_diameter(container: &Container) -> f64 {
    match container {
        Container::Box { min, max, .. } => (max - min).min(),
        Container::Cylinder { radius, height, .. } => (2.0 * radius).min(*height),
        // meshes are not offered by scenes; let the packer decide
        _ => f64::INFINITY,
    }
}

/// An isotropic (Haar-uniform) rotation from the `(seed, index)` stream
/// (Shoemake's three uniforms).
pub(crate) fn random_rotation(seed: u64, index: u64) -> UnitQuaternion<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ ROTATION_STREAM);
    rng.set_stream(index);
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    UnitQuaternion::from_quaternion(Quaternion::new(
        b * (tau * u3).cos(),
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounding_spheres_do_not_overlap_and_rotations_are_unit_and_seeded() {
        let clones: Vec<ToPlace> = (0..40)
            .map(|i| ToPlace {
                index: i,
                bounding_radius: 1.0 + 0.02 * i as f64,
            })
            .collect();
        let c = Container::triaxial(20.0);
        let poses = place(&clones, &c, Preset::Default, 7).expect("fits");
        assert_eq!(poses.len(), clones.len());
        for i in 0..poses.len() {
            for j in 0..i {
                let d = (poses[i].translation.vector - poses[j].translation.vector).norm();
                assert!(
                    d >= clones[i].bounding_radius + clones[j].bounding_radius - 1e-9,
                    "{i} {j}"
                );
            }
            assert!((poses[i].rotation.norm() - 1.0).abs() < 1e-12);
        }
        assert_eq!(random_rotation(7, 3), random_rotation(7, 3));
        assert_ne!(random_rotation(7, 3), random_rotation(7, 4));
        // isotropy, roughly: the mean rotated x axis is near zero
        let m = (0..2000)
            .map(|i| random_rotation(1, i) * nalgebra::Vector3::x())
            .sum::<nalgebra::Vector3<f64>>()
            / 2000.0;
        assert!(m.norm() < 0.06, "{m}");
    }

    #[test]
    fn too_small_and_too_full_containers_are_errors() {
        let one = [ToPlace {
            index: 0,
            bounding_radius: 3.0,
        }];
        let e = place(&one, &Container::triaxial(5.0), Preset::Default, 1)
            .expect_err("too small")
            .to_string();
        assert!(e.contains("too small") && e.contains("6.0000"), "{e}");
        let many: Vec<ToPlace> = (0..200)
            .map(|i| ToPlace {
                index: i,
                bounding_radius: 1.0,
            })
            .collect();
        let e = place(&many, &Container::triaxial(6.0), Preset::Default, 1)
            .expect_err("too full")
            .to_string();
        assert!(e.contains("cannot take all 200"), "{e}");
    }
}
