//! Walls of the container, measured independently of `Container::clearance`:
//! box faces one by one, the cylinder radially and axially, closed meshes
//! with parry3d.

use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{TriMesh as ParryMesh, TriMeshFlags};

use crate::Container;
use crate::error::{Error, Result};

/// The checker's own description of the container walls.
pub(super) enum Walls {
    Box {
        min: [f64; 3],
        max: [f64; 3],
        walled: [bool; 3],
    },
    Cylinder {
        cx: f64,
        cy: f64,
        z0: f64,
        radius: f64,
        height: f64,
    },
    Mesh(Box<ParryMesh>),
}

impl Walls {
    pub(super) fn new(container: &Container) -> Result<Self> {
        container.validate()?;
        Ok(match container {
            Container::Box { min, max, periodic } => Self::Box {
                min: [min.x, min.y, min.z],
                max: [max.x, max.y, max.z],
                walled: [!periodic[0], !periodic[1], true],
            },
            Container::Cylinder {
                base,
                radius,
                height,
            } => Self::Cylinder {
                cx: base.x,
                cy: base.y,
                z0: base.z,
                radius: *radius,
                height: *height,
            },
            Container::Mesh(m) => {
                let mesh = m.mesh();
                let vertices = mesh
                    .vertices()
                    .iter()
                    .map(|v| parry3d_f64::math::Vector::new(v.x, v.y, v.z))
                    .collect();
                let index = |k: usize| {
                    u32::try_from(k).map_err(|_| Error::CheckerMesh {
                        reason: format!("vertex index {k} does not fit in u32"),
                    })
                };
                let mut triangles = Vec::with_capacity(mesh.triangles().len());
                for t in mesh.triangles() {
                    triangles.push([index(t[0])?, index(t[1])?, index(t[2])?]);
                }
                let pm = ParryMesh::with_flags(vertices, triangles, TriMeshFlags::ORIENTED)
                    .map_err(|e| Error::CheckerMesh {
                        reason: e.to_string(),
                    })?;
                Self::Mesh(Box::new(pm))
            }
        })
    }

    /// Containment distance of a point: a sphere of radius `r` at `p` is
    /// inside exactly when `clearance(p) ≥ r`. Box: the smallest signed
    /// distance to a walled face plane; cylinder: the smaller of the radial
    /// (`R − ρ`) and axial distances; mesh: parry's exact signed distance
    /// (positive inside, sign from the pseudo-normals).
    pub(super) fn clearance(&self, p: [f64; 3]) -> f64 {
        match self {
            Self::Box { min, max, walled } => {
                let mut c = f64::INFINITY;
                for k in 0..3 {
                    if walled[k] {
                        c = c.min(p[k] - min[k]).min(max[k] - p[k]);
                    }
                }
                c
            }
            Self::Cylinder {
                cx,
                cy,
                z0,
                radius,
                height,
            } => {
                let rho = (p[0] - cx).hypot(p[1] - cy);
                (radius - rho).min(p[2] - z0).min(z0 + height - p[2])
            }
            Self::Mesh(mesh) => {
                let q = parry3d_f64::math::Vector::new(p[0], p[1], p[2]);
                let proj = mesh.project_local_point(q, true);
                let d = (proj.point - q).length();
                if proj.is_inside { d } else { -d }
            }
        }
    }
}
