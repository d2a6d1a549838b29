//! Placement of the clones in the container: the functions that turn
//! clones into poses (clone frame → world).
//!
//! [`place_grains`] (scene `placement: Grains`, the default) packs the
//! clones' star surfaces themselves with `packer_grains::pack_grains`
//! (sphere skeleton, then gap minimisation with the LS-DEM node test and
//! rigid moves): dense, and checked afterwards on level sets by
//! `check_grain_overlaps` in the `check` stage.
//!
//! [`place`] (scene `placement: BoundingSpheres`) is conservative: each
//! clone's bounding sphere
//! (its largest node radius about the clone's origin, times
//! [`BOUNDING_MARGIN`] for the interpolation between mesh nodes) is packed
//! by `packer_spheres::pack3d_sizes` in the container, sizes as given, and
//! every clone gets an isotropic random rotation from its own
//! `(seed, index)` stream. Bounding spheres do not overlap, so neither do
//! the grains: non-overlapping by construction, and loose (the grains fill
//! roughly a third of their spheres' volume less than a dense grain
//! packing would).

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use packer_grains::{
    GrainPackParams, GrainPackStats, GrainPacking, Settle, StarGrain, bed_top, container_for,
    pack_grains,
};
use packer_spheres::{Container, Pack3Params};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::error::{Error, Result};

/// The sphere packer's preset (of the bounding spheres, or of the grain
/// packer's skeleton).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize)]
pub enum Preset {
    /// `Pack3Params::default()`.
    #[default]
    Default,
    /// `Pack3Params::dense()`.
    Dense,
}

/// Bounding radius = largest node radius × this margin (the level set
/// between nodes is interpolated and may bulge slightly past the nodes).
pub const BOUNDING_MARGIN: f64 = 1.05;

/// Stream offset of the rotations, so that they never share a stream with
/// the cloner's (seed, index) streams.
const ROTATION_STREAM: u64 = 0x726f_7461_7465;

/// What placement needs to know of one clone: its bounding radius about
/// the clone frame's origin (major axis +x, minor +z).
#[derive(Debug, Clone, Copy)]
pub struct ToPlace {
    /// Clone index (its random stream).
    pub index: u64,
    /// Radius of a sphere about the clone frame's origin that holds the grain.
    pub bounding_radius: f64,
}

/// Poses (clone frame → world) of every clone, in the order of `clones`.
///
/// # Errors
/// No clone; a container smaller than the largest clone's bounding sphere
/// (naming both sizes); a container that cannot take every clone (naming
/// how many fit); packer errors.
pub fn place(
    clones: &[ToPlace],
    container: &Container,
    preset: Preset,
    seed: u64,
) -> Result<Vec<Isometry3<f64>>> {
    if clones.is_empty() {
        return Err(Error::Scene("no clone to place".to_owned()));
    }
    let sizes: Vec<f64> = clones.iter().map(|c| 2.0 * c.bounding_radius).collect();
    let (lo, hi) = sizes
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(a, b), d| (a.min(*d), b.max(*d)));
    let room = container.inscribed_diameter();
    if hi > room {
        return Err(Error::Scene(format!(
            "`container` is too small for the largest clone: its bounding sphere has diameter {hi:.4}, the container takes at most {room:.4}"
        )));
    }
    let params = match preset {
        Preset::Default => Pack3Params::default(),
        Preset::Dense => Pack3Params::dense(),
    };
    let packing = packer_spheres::pack3d_sizes(container, &sizes, lo, hi, &params)?;
    if packing.spheres.len() < clones.len() {
        return Err(Error::ContainerFull {
            clones: clones.len(),
            placed: packing.spheres.len(),
        });
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
            return Err(Error::Scene(format!(
                "placement: a packed sphere of diameter {d} matches no clone (a packer bug)"
            )));
        };
        used[j] = true;
        centres[order[j]] = Some(s.center);
    }
    clones
        .iter()
        .zip(centres)
        .map(|(c, p)| {
            let Some(p) = p else {
                return Err(Error::Scene(format!(
                    "placement: clone {} was not placed (a packer bug)",
                    c.index
                )));
            };
            Ok(Isometry3::from_parts(
                Translation3::from(p.coords),
                random_rotation(seed, c.index),
            ))
        })
        .collect()
}

/// A grain packing of the clones.
pub struct GrainPlacement {
    /// The container (sized by `AutoCylinder`).
    pub container: Container,
    /// Pose of every clone, in input order.
    pub poses: Vec<Isometry3<f64>>,
    /// Packings tried (`AutoCylinder` lowers the fraction per try).
    pub tries: usize,
    /// The packer's counters.
    pub stats: GrainPackStats,
}

/// Solid fraction of an `AutoCylinder` is lowered by this factor per try.
pub const FRACTION_STEP: f64 = 0.95;
/// Packings an `AutoCylinder` tries.
const FRACTION_TRIES: usize = 6;

/// The grain packer's parameters for a scene.
fn grain_params(preset: Preset, seed: u64) -> GrainPackParams {
    let d = GrainPackParams::default();
    GrainPackParams {
        seed: seed ^ ROTATION_STREAM,
        skeleton: match preset {
            Preset::Default => d.skeleton,
            Preset::Dense => Pack3Params {
                lookahead: d.skeleton.lookahead,
                ..Pack3Params::dense()
            },
        },
        ..d
    }
}

/// Packs the clones' star surfaces in `container`, or, for an
/// `AutoCylinder` (`auto = Some((solid_fraction, lower_if_needed))`), in a
/// triaxial cylinder sized for that fraction of grain volume; with
/// `lower_if_needed` the fraction is lowered by 5 % per try while the packer
/// cannot separate the grains ([`GrainPlacement::tries`] > 1 then: the caller
/// reports the requested and the reached fraction loudly).
///
/// With `settle` the packing is then settled under gravity
/// ([`packer_grains::Settle`]) and the container's lid (a box's or a
/// cylinder's top; a mesh is kept) is lowered onto the bed: to
/// [`bed_top`] plus the packer's wall margin of the largest grain. The
/// placement's solid fraction is then the settled bed's (grain volume over
/// the lowered container), not the requested one.
///
/// # Errors
/// No grain; a container smaller than the largest clone's bounding sphere
/// (naming both sizes); a container the grains cannot be separated in
/// (naming the count and the fraction); packer errors.
pub fn place_grains(
    grains: &[StarGrain],
    container: Option<Container>,
    auto: Option<(f64, bool)>,
    preset: Preset,
    seed: u64,
    settle: Option<Settle>,
) -> Result<GrainPlacement> {
    if grains.is_empty() {
        return Err(Error::Scene("no clone to place".to_owned()));
    }
    let params = GrainPackParams {
        settle,
        ..grain_params(preset, seed)
    };
    let largest = grains.iter().map(|g| 2.0 * g.r_max()).fold(0.0, f64::max);
    let total: f64 = grains.iter().map(StarGrain::volume).sum();
    let too_dense = |e: &packer_grains::Error| {
        matches!(
            e,
            packer_grains::Error::NotConverged { .. }
                | packer_grains::Error::TooDense { .. }
                | packer_grains::Error::FractionNotReached { .. }
        )
    };
    if let Some(c) = container {
        let room = c.inscribed_diameter();
        if largest > room {
            return Err(Error::Scene(format!(
                "`container` is too small for the largest clone: its bounding sphere has diameter {largest:.4}, the container takes at most {room:.4}"
            )));
        }
        return match pack_grains(grains, &c, &params) {
            Ok(p) => finish(grains, c, p, 1, &params),
            Err(e) if too_dense(&e) => {
                return Err(Error::Scene(format!(
                    "`container` cannot take all {} clones: they fill {:.3} of it and the grain packer cannot separate them ({e}); use a larger container or AutoCylinder",
                    grains.len(),
                    total / c.volume()
                )));
            }
            Err(e) => Err(e.into()),
        };
    }
    let (requested, lower) = auto.unwrap_or((0.5, false));
    let mut fraction = requested;
    let mut last = String::new();
    let tries_allowed = if lower { FRACTION_TRIES } else { 1 };
    for tries in 1..=tries_allowed {
        let c = container_for(&Container::triaxial(1.0), grains, fraction)?;
        let room = c.inscribed_diameter();
        if largest <= room {
            match pack_grains(grains, &c, &params) {
                Ok(p) => return finish(grains, c, p, tries, &params),
                Err(e) if too_dense(&e) => {
                    last = match e {
                        // grains at scale λ fill λ³ of their volume
                        packer_grains::Error::NotConverged { scale, .. } if scale < 1.0 => {
                            format!(
                                "at solid fraction {fraction:.4} the packer separated the grains only at scale {scale:.4} of their size, i.e. solid fraction {:.4} ({e})",
                                fraction * scale.powi(3)
                            )
                        }
                        packer_grains::Error::FractionNotReached { reached, .. } => format!(
                            "at solid fraction {fraction:.4} the compaction jammed: the grains were separated up to solid fraction {reached:.4} ({e})"
                        ),
                        packer_grains::Error::NotConverged { .. } => format!(
                            "at solid fraction {fraction:.4} the grains grew to full size but no overlap-free packing was found ({e})"
                        ),
                        _ => format!("at solid fraction {fraction:.4}: {e}"),
                    };
                }
                Err(e) => return Err(e.into()),
            }
        } else {
            last = format!(
                "at solid fraction {fraction:.3} the cylinder (inscribed diameter {room:.4}) is smaller than the largest clone ({largest:.4})"
            );
        }
        fraction *= FRACTION_STEP;
    }
    if !lower {
        return Err(Error::Scene(format!(
            "`container`: AutoCylinder cannot reach the requested solid fraction {requested:.4} with these {} clones: {last}; lower `solid_fraction`, or set `lower_if_needed: true` to accept a lower one",
            grains.len()
        )));
    }
    Err(Error::Scene(format!(
        "`container`: AutoCylinder could not separate the {} clones in {FRACTION_TRIES} tries down to solid fraction {:.4} (last {last}); lower `solid_fraction`",
        grains.len(),
        fraction / FRACTION_STEP
    )))
}

/// The placement of a packing; a settled one gets its lid lowered onto the
/// bed (see [`place_grains`]).
fn finish(
    grains: &[StarGrain],
    container: Container,
    packing: GrainPacking,
    tries: usize,
    params: &GrainPackParams,
) -> Result<GrainPlacement> {
    let GrainPacking { poses, mut stats } = packing;
    let mut container = container;
    if params.settle.is_some() {
        let d_max = grains
            .iter()
            .map(StarGrain::equivalent_diameter)
            .fold(0.0, f64::max);
        let lid = bed_top(grains, &poses)? + params.margin * d_max;
        match &mut container {
            Container::Box { max, .. } if lid < max.z => max.z = lid,
            Container::Cylinder { base, height, .. } if lid < base.z + *height => {
                *height = lid - base.z;
            }
            _ => {}
        }
        stats.solid_fraction =
            grains.iter().map(StarGrain::volume).sum::<f64>() / container.volume();
    }
    Ok(GrainPlacement {
        container,
        poses,
        tries,
        stats,
    })
}

/// How much of a specimen the walls hold.
pub struct WallShare {
    /// Horizontal width of the container (cylinder diameter, smaller box side).
    pub width: f64,
    /// Share of the grains whose centre lies within `d_max` of a wall.
    pub near_fraction: f64,
}

/// The container's width and the share of grain centres within `d_max` of
/// any wall (floor and lid included).
pub fn wall_share(c: &Container, poses: &[Isometry3<f64>], d_max: f64) -> WallShare {
    let width = match c {
        Container::Cylinder { radius, .. } => 2.0 * radius,
        Container::Box { min, max, periodic } => {
            let side = |k: usize| {
                if periodic[k] {
                    f64::INFINITY
                } else {
                    max[k] - min[k]
                }
            };
            side(0).min(side(1))
        }
        _ => c.inscribed_diameter(),
    };
    let near = poses
        .iter()
        .filter(|p| c.clearance(&nalgebra::Point3::from(p.translation.vector)) < d_max)
        .count();
    WallShare {
        width,
        near_fraction: near as f64 / poses.len().max(1) as f64,
    }
}

/// An isotropic (Haar-uniform) rotation from the `(seed, index)` stream
/// (Shoemake's three uniforms).
pub fn random_rotation(seed: u64, index: u64) -> UnitQuaternion<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ ROTATION_STREAM);
    rng.set_stream(index);
    packer_grains::random_rotation(&mut rng)
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

    fn ellipsoids(n: usize) -> Vec<StarGrain> {
        (0..n)
            .map(|i| {
                let s = 1.0 + 0.01 * i as f64;
                StarGrain::ellipsoid(1.2 * s, s, 0.8 * s, 8).expect("ellipsoid")
            })
            .collect()
    }

    #[test]
    fn grains_are_packed_clean_in_auto_and_fixed_containers() {
        let g = ellipsoids(60);
        let auto =
            place_grains(&g, None, Some((0.45, false)), Preset::Default, 3, None).expect("auto");
        assert_eq!(auto.poses.len(), g.len());
        assert!((auto.stats.solid_fraction - 0.45).abs() < 1e-9);
        assert_eq!(auto.tries, 1);
        let r = packer_grains::check_grain_overlaps(
            &g,
            &auto.poses,
            &auto.container,
            &packer_grains::CheckParams::default(),
        )
        .expect("check");
        assert!(r.is_clean(), "{r:?}");
        let fixed = Container::triaxial(12.0);
        let p = place_grains(&g, Some(fixed.clone()), None, Preset::Dense, 3, None).expect("fixed");
        assert_eq!(format!("{:?}", p.container), format!("{fixed:?}"));
        assert!(p.stats.worst_gap_over_d >= 0.01 * (1.0 - 1e-6));
        // seeded: the same scene gives the same poses
        let again =
            place_grains(&g, None, Some((0.45, false)), Preset::Default, 3, None).expect("auto");
        assert_eq!(again.poses, auto.poses);
    }

    #[test]
    fn a_settled_placement_lowers_the_lid_onto_a_denser_bed() {
        let g = ellipsoids(60);
        let p = place_grains(
            &g,
            None,
            Some((0.40, false)),
            Preset::Default,
            3,
            Some(Settle::default()),
        )
        .expect("settled");
        let Container::Cylinder { height, radius, .. } = p.container else {
            panic!("a cylinder: {:?}", p.container)
        };
        // H = 2 D before: the lid came down, the fraction went up
        assert!(height < 4.0 * radius * 0.97, "H {height}, R {radius}");
        assert!(p.stats.solid_fraction > 0.41, "{}", p.stats.solid_fraction);
        let top = bed_top(&g, &p.poses).expect("top");
        assert!(top < height, "{top} vs {height}");
        let r = packer_grains::check_grain_overlaps(
            &g,
            &p.poses,
            &p.container,
            &packer_grains::CheckParams::default(),
        )
        .expect("check");
        assert!(r.is_clean(), "{r:?}");
    }

    #[test]
    fn an_unreachable_auto_fraction_is_an_error_unless_lowering_is_asked() {
        let g = ellipsoids(60);
        let e = place_grains(&g, None, Some((0.7, false)), Preset::Default, 1, None)
            .err()
            .expect("0.70 is out of reach")
            .to_string();
        assert!(
            e.contains("cannot reach the requested solid fraction 0.7000")
                && e.contains("lower_if_needed"),
            "{e}"
        );
        let p =
            place_grains(&g, None, Some((0.6, true)), Preset::Default, 1, None).expect("lowered");
        assert!(p.tries > 1);
        assert!(p.stats.solid_fraction < 0.6 * 0.95 + 1e-9);
    }

    #[test]
    fn wall_share_counts_centres_within_d_max() {
        let c = Container::triaxial(10.0);
        let at = |x: f64, z: f64| Isometry3::translation(x, 0.0, z);
        // radius 5, height 20: x = 4.5 is 0.5 from the side, z = 0.5 from the floor
        let poses = [at(0.0, 10.0), at(4.5, 10.0), at(0.0, 0.5), at(-2.0, 8.0)];
        let w = wall_share(&c, &poses, 1.0);
        assert_eq!(w.width, 10.0);
        assert_eq!(w.near_fraction, 0.5);
    }

    #[test]
    fn grain_containers_too_small_or_too_full_are_errors() {
        let g = ellipsoids(60);
        let e = place_grains(
            &g,
            Some(Container::triaxial(1.5)),
            None,
            Preset::Default,
            1,
            None,
        )
        .err()
        .expect("too small")
        .to_string();
        assert!(e.contains("too small for the largest clone"), "{e}");
        let e = place_grains(
            &g,
            Some(Container::triaxial(5.0)),
            None,
            Preset::Default,
            1,
            None,
        )
        .err()
        .expect("too full")
        .to_string();
        assert!(e.contains("cannot take all 60 clones"), "{e}");
        let e = place_grains(&[], None, Some((0.5, false)), Preset::Default, 1, None)
            .err()
            .expect("empty")
            .to_string();
        assert!(e.contains("no clone"), "{e}");
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
