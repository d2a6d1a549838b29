//! `cargo xtask convergence`: the spherical-harmonic convergence table
//! (relative volume and area error against degree 1..30) of the analytic
//! reference shapes of Radvilaitė 2016 (Tables 3.7–3.9 shapes), by Gauss
//! quadrature transform and Gauss integration. The judged rows (degree 30
//! and the doubling checkpoints) are `validate` cases
//! (`sph-harmonics/convergence`); this task writes the full table.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use sph_harmonics::fit::quadrature_transform;
use sph_harmonics::grid::RingGrid;
use sph_harmonics::integrals::{default_gauss_nodes, gauss_integrals};
use sph_harmonics::shapes::Shape;

/// Flags of `cargo xtask convergence`.
#[derive(Debug, Args)]
pub(crate) struct Convergence {
    /// Directory for `convergence.md` and `convergence.csv`.
    #[arg(long, default_value = "target/sh-report")]
    report: PathBuf,
    /// Highest degree.
    #[arg(long, default_value_t = 30)]
    max_degree: usize,
}

impl Convergence {
    pub(crate) fn run(self, root: &Path) -> anyhow::Result<()> {
        let shapes = [
            (
                "oblate ellipsoid 2,2,1",
                Shape::Ellipsoid {
                    a: 2.0,
                    b: 2.0,
                    c: 1.0,
                },
            ),
            (
                "triaxial ellipsoid 2,1.5,1",
                Shape::Ellipsoid {
                    a: 2.0,
                    b: 1.5,
                    c: 1.0,
                },
            ),
            ("cylinder a=2 c=1", Shape::Cylinder { a: 2.0, c: 1.0 }),
            (
                "box 4x4x2",
                Shape::Box {
                    a: 2.0,
                    b: 2.0,
                    c: 1.0,
                },
            ),
            ("bicone a=2 c=1", Shape::Bicone { a: 2.0, c: 1.0 }),
            (
                "octahedron 2,2,1",
                Shape::Octahedron {
                    a: 2.0,
                    b: 2.0,
                    c: 1.0,
                },
            ),
        ];
        let mut csv = String::from("shape,degree,rel_volume_error,rel_area_error\n");
        let mut md = String::from(
            "# Spherical-harmonic convergence of the reference shapes\n\nRelative |error| of volume / area of the degree-L quadrature transform (Gauss–Legendre × equiangular grid), integrated by Gauss quadrature. `-`: the degree-L model is not star-shaped.\n\n| L |",
        );
        for (name, _) in &shapes {
            let _ = write!(md, " {name} |");
        }
        md.push_str("\n|---:|");
        md.push_str(&"---|".repeat(shapes.len()));
        md.push('\n');
        for degree in 1..=self.max_degree {
            let _ = write!(md, "| {degree} |");
            for (name, shape) in &shapes {
                let grid = RingGrid::gauss_legendre(degree)?;
                let values: Vec<f64> = grid
                    .points()
                    .iter()
                    .map(|&(t, p)| shape.radius(t, p))
                    .collect();
                let model = quadrature_transform(&grid, &values, degree)?;
                match gauss_integrals(&model, default_gauss_nodes(degree) * 2) {
                    Ok(i) => {
                        let dv = (i.volume / shape.volume() - 1.0).abs();
                        let da = (i.area / shape.area() - 1.0).abs();
                        let _ = writeln!(csv, "{name},{degree},{dv:.6e},{da:.6e}");
                        let _ = write!(md, " {dv:.2e} / {da:.2e} |");
                    }
                    Err(_) => {
                        let _ = writeln!(csv, "{name},{degree},,");
                        md.push_str(" - |");
                    }
                }
            }
            md.push('\n');
        }
        let dir = root.join(&self.report);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        for (file, text) in [("convergence.md", &md), ("convergence.csv", &csv)] {
            let path = dir.join(file);
            std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        }
        println!("{md}");
        println!("wrote {}", dir.display());
        Ok(())
    }
}
