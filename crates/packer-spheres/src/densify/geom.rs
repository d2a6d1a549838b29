//! The domain of a densification in the form the relaxation uses: a box
//! (periodic or walled per axis) or a cylinder, with its scaling about the
//! centre, periodic wrapping, and wall distances.

use nalgebra::Point3;

use super::Boundary;
use crate::Container;
use crate::error::{Error, Result, finite, positive};

/// The domain in the form the relaxation uses.
#[derive(Debug, Clone, Copy)]
pub(super) enum Geom {
    Box {
        lo: [f64; 3],
        hi: [f64; 3],
        periodic: [bool; 3],
    },
    Cylinder {
        centre: [f64; 3],
        radius: f64,
        height: f64,
    },
}

impl Geom {
    pub(super) fn new(b: &Boundary) -> Result<Self> {
        let g = match b {
            Boundary::Periodic { min, max } => Self::Box {
                lo: [min.x, min.y, min.z],
                hi: [max.x, max.y, max.z],
                periodic: [true; 3],
            },
            Boundary::Walls(Container::Box { min, max, periodic }) => Self::Box {
                lo: [min.x, min.y, min.z],
                hi: [max.x, max.y, max.z],
                periodic: [periodic[0], periodic[1], false],
            },
            Boundary::Walls(Container::Cylinder {
                base,
                radius,
                height,
            }) => Self::Cylinder {
                centre: [base.x, base.y, base.z + 0.5 * height],
                radius: *radius,
                height: *height,
            },
            Boundary::Walls(Container::Mesh(_)) => {
                return Err(Error::WrongContainer {
                    what: "densify",
                    expected: "box or cylinder",
                    got: "mesh",
                });
            }
        };
        match g {
            Self::Box { lo, hi, .. } => {
                for k in 0..3 {
                    finite("box min", lo[k])?;
                    finite("box max", hi[k])?;
                    positive("box side (max - min)", hi[k] - lo[k])?;
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => {
                for c in centre {
                    finite("cylinder base", c)?;
                }
                positive("cylinder radius", radius)?;
                positive("cylinder height", height)?;
            }
        }
        Ok(g)
    }

    pub(super) fn check_room(&self, d_max: f64) -> Result<()> {
        match *self {
            Self::Box { lo, hi, periodic } => {
                for k in 0..3 {
                    let side = hi[k] - lo[k];
                    let need = if periodic[k] { 4.0 * d_max } else { d_max };
                    if side < need {
                        return Err(Error::DomainTooSmall {
                            domain: side,
                            particle: need,
                        });
                    }
                }
            }
            Self::Cylinder { radius, height, .. } => {
                let inscribed = (2.0 * radius).min(height);
                if inscribed < d_max {
                    return Err(Error::DomainTooSmall {
                        domain: inscribed,
                        particle: d_max,
                    });
                }
            }
        }
        Ok(())
    }

    pub(super) fn volume(&self) -> f64 {
        match *self {
            Self::Box { lo, hi, .. } => (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]),
            Self::Cylinder { radius, height, .. } => {
                std::f64::consts::PI * radius * radius * height
            }
        }
    }

    pub(super) fn centre(&self) -> [f64; 3] {
        match *self {
            Self::Box { lo, hi, .. } => [
                0.5 * (lo[0] + hi[0]),
                0.5 * (lo[1] + hi[1]),
                0.5 * (lo[2] + hi[2]),
            ],
            Self::Cylinder { centre, .. } => centre,
        }
    }

    /// The domain scaled by `s` about its centre.
    pub(super) fn scaled(&self, s: f64) -> Self {
        let c = self.centre();
        match *self {
            Self::Box { lo, hi, periodic } => {
                let f = |k: usize, v: f64| c[k] + s * (v - c[k]);
                Self::Box {
                    lo: [f(0, lo[0]), f(1, lo[1]), f(2, lo[2])],
                    hi: [f(0, hi[0]), f(1, hi[1]), f(2, hi[2])],
                    periodic,
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => Self::Cylinder {
                centre,
                radius: s * radius,
                height: s * height,
            },
        }
    }

    /// Periods of the periodic axes (0 for walled ones).
    pub(super) fn periods(&self) -> [f64; 3] {
        match *self {
            Self::Box { lo, hi, periodic } => {
                let mut p = [0.0; 3];
                for k in 0..3 {
                    if periodic[k] {
                        p[k] = hi[k] - lo[k];
                    }
                }
                p
            }
            Self::Cylinder { .. } => [0.0; 3],
        }
    }

    /// Wraps `p` into the box along periodic axes.
    pub(super) fn wrap(&self, p: &mut [f64]) {
        if let Self::Box { lo, hi, periodic } = *self {
            for k in 0..3 {
                if periodic[k] {
                    let l = hi[k] - lo[k];
                    p[k] = lo[k] + (p[k] - lo[k]).rem_euclid(l);
                    if p[k] >= hi[k] {
                        p[k] = lo[k];
                    }
                }
            }
        }
    }

    /// Whether any side is a wall (a fully periodic box has none).
    pub(super) fn has_walls(&self) -> bool {
        !matches!(
            self,
            Self::Box {
                periodic: [true, true, true],
                ..
            }
        )
    }

    /// The wall force on a sphere (overlap times the inward normal, summed
    /// over walls) and its largest wall overlap.
    pub(super) fn wall(&self, p: &[f64], r: f64) -> ([f64; 3], f64) {
        let mut f = [0.0; 3];
        let mut worst = f64::NEG_INFINITY;
        match *self {
            Self::Box { lo, hi, periodic } => {
                for k in 0..3 {
                    if periodic[k] {
                        continue;
                    }
                    let a = r - (p[k] - lo[k]);
                    let b = r - (hi[k] - p[k]);
                    worst = worst.max(a).max(b);
                    if a > 0.0 {
                        f[k] += a;
                    }
                    if b > 0.0 {
                        f[k] -= b;
                    }
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => {
                let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
                let rho = dx.hypot(dy);
                let side = rho + r - radius;
                worst = worst.max(side);
                if side > 0.0 && rho > 0.0 {
                    f[0] -= side * dx / rho;
                    f[1] -= side * dy / rho;
                }
                let z0 = centre[2] - 0.5 * height;
                let a = r - (p[2] - z0);
                let b = r - (z0 + height - p[2]);
                worst = worst.max(a).max(b);
                if a > 0.0 {
                    f[2] += a;
                }
                if b > 0.0 {
                    f[2] -= b;
                }
            }
        }
        (f, worst)
    }

    /// The largest `ov / clearance` of a sphere against the walls (the
    /// relative expansion about the centre that clears it), 0 when clear.
    pub(super) fn wall_ratio(&self, p: &[f64], r: f64) -> f64 {
        let mut w = 0.0_f64;
        let mut one = |clearance: f64| {
            if clearance < r {
                w = w.max(if clearance > 0.0 {
                    (r - clearance) / clearance
                } else {
                    f64::INFINITY
                });
            }
        };
        match *self {
            Self::Box { lo, hi, periodic } => {
                for k in 0..3 {
                    if !periodic[k] {
                        let c = 0.5 * (lo[k] + hi[k]);
                        // the wall is at distance h from the centre; the sphere's centre at
                        // |p - c|; scaling by s moves both, so the clearance scales by s
                        let h = 0.5 * (hi[k] - lo[k]);
                        one(h - (p[k] - c).abs());
                    }
                }
            }
            Self::Cylinder {
                centre,
                radius,
                height,
            } => {
                one(radius - (p[0] - centre[0]).hypot(p[1] - centre[1]));
                one(0.5 * height - (p[2] - centre[2]).abs());
            }
        }
        w
    }

    /// Bounding box `(lo, hi)`.
    pub(super) fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match *self {
            Self::Box { lo, hi, .. } => (lo, hi),
            Self::Cylinder {
                centre,
                radius,
                height,
            } => (
                [
                    centre[0] - radius,
                    centre[1] - radius,
                    centre[2] - 0.5 * height,
                ],
                [
                    centre[0] + radius,
                    centre[1] + radius,
                    centre[2] + 0.5 * height,
                ],
            ),
        }
    }

    /// The input boundary with this geometry's extents.
    pub(super) fn boundary(&self, like: &Boundary) -> Boundary {
        match (*self, like) {
            (Self::Box { lo, hi, .. }, Boundary::Periodic { .. }) => Boundary::Periodic {
                min: Point3::from(lo),
                max: Point3::from(hi),
            },
            _ => Boundary::Walls(self.container()),
        }
    }

    /// The container of this geometry (a box keeps its x/y periodicity and
    /// has walls in z: what the front packs).
    pub(super) fn container(&self) -> Container {
        match *self {
            Self::Box { lo, hi, periodic } => Container::Box {
                min: Point3::from(lo),
                max: Point3::from(hi),
                periodic: [periodic[0], periodic[1]],
            },
            Self::Cylinder {
                centre,
                radius,
                height,
            } => Container::Cylinder {
                base: Point3::new(centre[0], centre[1], centre[2] - 0.5 * height),
                radius,
                height,
            },
        }
    }
}
