//! Containers of 3D packings: a box (walls, or periodic in x and/or y), a
//! vertical cylinder (the triaxial specimen) and any closed triangle mesh.
//!
//! Every container answers the same three questions the packer and the
//! metrics ask: its volume, its bounding box, and the clearance of a point
//! (the distance to the nearest wall, positive inside; a sphere of radius
//! `r` centred at `p` is inside when `clearance(p) ≥ r`). Periodic
//! directions have no walls and do not count in the clearance.

use levelset::{MeshDistance, TriMesh};
use nalgebra::{Point3, Vector3};

use crate::error::{Result, finite, positive};

/// A closed, consistently oriented triangle mesh used as a container, with
/// its exact signed distance (levelset's BVH and angle-weighted
/// pseudonormals) prepared once.
#[derive(Debug, Clone)]
pub struct MeshContainer {
    mesh: TriMesh,
    distance: MeshDistance,
    volume: f64,
    lo: Point3<f64>,
    hi: Point3<f64>,
}

impl MeshContainer {
    /// Checks the mesh (closed, edge-manifold, consistently oriented,
    /// non-degenerate triangles, positive volume) and prepares its distance.
    /// A mesh oriented inwards (negative signed volume) is flipped.
    ///
    /// # Errors
    /// [`Error::Mesh`](crate::Error::Mesh) naming the first open or non-manifold edge or the
    /// degenerate triangle; [`Error::NonPositive`](crate::Error::NonPositive) for a zero volume.
    pub fn new(mesh: TriMesh) -> Result<Self> {
        let mut mesh = mesh;
        mesh.check_closed()?;
        let mut volume = mesh.signed_volume();
        if volume < 0.0 {
            let tris = mesh
                .triangles()
                .iter()
                .map(|t| [t[0], t[2], t[1]])
                .collect();
            mesh = TriMesh::new(mesh.vertices().to_vec(), tris)?;
            volume = -volume;
        }
        positive("mesh container volume", volume)?;
        let distance = MeshDistance::new(&mesh)?;
        let (mut lo, mut hi) = (Point3::from([f64::MAX; 3]), Point3::from([f64::MIN; 3]));
        for v in mesh.vertices() {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        Ok(Self {
            mesh,
            distance,
            volume,
            lo,
            hi,
        })
    }

    /// The (outward-oriented) mesh.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// Exact clearance: minus the signed distance (positive inside).
    pub fn clearance(&self, p: &Point3<f64>) -> f64 {
        -self.distance.signed_distance(p)
    }

    /// Clearance when only values up to `bound` matter: exact when the true
    /// clearance is below `bound` in magnitude, otherwise some value
    /// `≥ bound` of the correct sign (cheap far from the walls).
    pub fn clearance_bounded(&self, p: &Point3<f64>, bound: f64) -> f64 {
        -self.distance.signed_distance_bounded(p, bound)
    }
}

/// The region a 3D packing fills.
#[derive(Debug, Clone)]
pub enum Container {
    /// Axis-aligned box `[min, max]`; `periodic[0]` / `periodic[1]` make x /
    /// y periodic (no walls there: spheres may cross the face and interact
    /// with the images on the other side). z always has walls (gravity is
    /// along −z).
    Box {
        /// Lower corner.
        min: Point3<f64>,
        /// Upper corner.
        max: Point3<f64>,
        /// Periodicity in x and y.
        periodic: [bool; 2],
    },
    /// Vertical cylinder of axis z: the disk of `radius` around `(cx, cy)`
    /// from `z0` to `z0 + height` (the triaxial specimen: `height = 2 ·
    /// diameter`).
    Cylinder {
        /// Centre of the bottom face.
        base: Point3<f64>,
        /// Radius.
        radius: f64,
        /// Height.
        height: f64,
    },
    /// A closed triangle mesh (e.g. read from STL with `levelset::io`).
    Mesh(Box<MeshContainer>),
}

impl Container {
    /// Walled box `[0, size]`.
    pub fn walled_box(size: Vector3<f64>) -> Self {
        Self::Box {
            min: Point3::origin(),
            max: Point3::from(size),
            periodic: [false; 2],
        }
    }

    /// Cylinder on the origin with `height = 2 · diameter` (the triaxial
    /// specimen's aspect).
    pub fn triaxial(diameter: f64) -> Self {
        Self::Cylinder {
            base: Point3::origin(),
            radius: 0.5 * diameter,
            height: 2.0 * diameter,
        }
    }

    /// A mesh container (see [`MeshContainer::new`]).
    ///
    /// # Errors
    /// As [`MeshContainer::new`].
    pub fn mesh(mesh: TriMesh) -> Result<Self> {
        Ok(Self::Mesh(Box::new(MeshContainer::new(mesh)?)))
    }

    /// Checks the geometry (finite, positive extents).
    ///
    /// # Errors
    /// [`Error::NonFinite`](crate::Error::NonFinite) /
    /// [`Error::NonPositive`](crate::Error::NonPositive) naming the field.
    pub fn validate(&self) -> Result<()> {
        match self {
            Self::Box { min, max, .. } => {
                for k in 0..3 {
                    finite("box min", min[k])?;
                    finite("box max", max[k])?;
                    positive("box side (max - min)", max[k] - min[k])?;
                }
            }
            Self::Cylinder {
                base,
                radius,
                height,
            } => {
                for k in 0..3 {
                    finite("cylinder base", base[k])?;
                }
                positive("cylinder radius", *radius)?;
                positive("cylinder height", *height)?;
            }
            Self::Mesh(_) => {}
        }
        Ok(())
    }

    /// Volume.
    pub fn volume(&self) -> f64 {
        match self {
            Self::Box { min, max, .. } => (max - min).product(),
            Self::Cylinder { radius, height, .. } => {
                std::f64::consts::PI * radius * radius * height
            }
            Self::Mesh(m) => m.volume,
        }
    }

    /// Bounding box `(lo, hi)`.
    pub fn bbox(&self) -> (Point3<f64>, Point3<f64>) {
        match self {
            Self::Box { min, max, .. } => (*min, *max),
            Self::Cylinder {
                base,
                radius,
                height,
            } => (
                base - Vector3::new(*radius, *radius, 0.0),
                base + Vector3::new(*radius, *radius, *height),
            ),
            Self::Mesh(m) => (m.lo, m.hi),
        }
    }

    /// Periodicity in x and y (only boxes can be periodic).
    pub fn periodic(&self) -> [bool; 2] {
        match self {
            Self::Box { periodic, .. } => *periodic,
            _ => [false; 2],
        }
    }

    /// Distance from `p` to the nearest wall, positive inside (exact for
    /// every container; periodic faces are not walls).
    pub fn clearance(&self, p: &Point3<f64>) -> f64 {
        match self {
            Self::Box { min, max, periodic } => {
                let mut c = (p.z - min.z).min(max.z - p.z);
                for k in 0..2 {
                    if !periodic[k] {
                        c = c.min(p[k] - min[k]).min(max[k] - p[k]);
                    }
                }
                // Outside a corner the distance is Euclidean, not the
                // minimum over faces; the sign is what matters there.
                if c < 0.0 {
                    let mut o = 0.0_f64;
                    for k in 0..3 {
                        if k < 2 && periodic[k] {
                            continue;
                        }
                        let e = (min[k] - p[k]).max(p[k] - max[k]).max(0.0);
                        o += e * e;
                    }
                    return -o.sqrt();
                }
                c
            }
            Self::Cylinder {
                base,
                radius,
                height,
            } => {
                let rho = (p.x - base.x).hypot(p.y - base.y);
                let radial = radius - rho;
                let axial = (p.z - base.z).min(base.z + height - p.z);
                if radial < 0.0 && axial < 0.0 {
                    -(radial.hypot(axial))
                } else {
                    radial.min(axial)
                }
            }
            Self::Mesh(m) => m.clearance(p),
        }
    }

    /// Diameter of the largest sphere that fits, or an upper bound of it
    /// (exact for boxes and cylinders; for meshes twice the largest
    /// clearance found at the centre and on a coarse lattice).
    pub fn inscribed_diameter(&self) -> f64 {
        match self {
            Self::Box { min, max, periodic } => {
                let mut s = max.z - min.z;
                for k in 0..2 {
                    if !periodic[k] {
                        s = s.min(max[k] - min[k]);
                    }
                }
                s
            }
            Self::Cylinder { radius, height, .. } => (2.0 * radius).min(*height),
            Self::Mesh(m) => {
                let n = 16;
                let mut best = 0.0_f64;
                for i in 0..=n {
                    for j in 0..=n {
                        for k in 0..=n {
                            let t = Vector3::new(i as f64, j as f64, k as f64) / n as f64;
                            let p = m.lo + (m.hi - m.lo).component_mul(&t);
                            best = best.max(m.clearance(&p));
                        }
                    }
                }
                2.0 * best
            }
        }
    }
}
