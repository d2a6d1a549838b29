//! Oracles of the surface DNA and the interpolation: spheres and ellipsoids
//! on the spherical mesh, constant fields, smoothing invariants.

use super::*;
use approx::assert_relative_eq;

fn geom(n_az: usize, n_pol: usize) -> MeshGeometry {
    MeshGeometry::new(SphericalMesh { n_az, n_pol })
}

fn ellipsoid_field(g: &MeshGeometry, semi: [f64; 3]) -> Vec<f64> {
    (0..g.n_nodes())
        .map(|k| g.ellipsoid_radius(k, semi))
        .collect()
}

#[test]
fn weights_sum_to_the_full_solid_angle() {
    for (a, p) in [(4, 2), (16, 8), (28, 18), (34, 24)] {
        let g = geom(a, p);
        let s: f64 = (0..g.n_nodes()).map(|k| g.weight(k)).sum();
        assert_relative_eq!(s, 4.0 * PI, max_relative = 1e-12);
    }
}

#[test]
fn sphere_surface_dna() {
    let g = geom(28, 18);
    let r = vec![2.0; g.n_nodes()];
    let d = g.surface_dna(&r, 45, 1.1).expect("valid sphere");
    assert_relative_eq!(d.volume, 4.0 / 3.0 * PI * 8.0, max_relative = 1e-12);
    assert_relative_eq!(d.area, 4.0 * PI * 4.0, max_relative = 1e-12);
    // the cell quadrature integrates u uᵀ to 0.1 %: principal dimensions are
    // exact to that order only
    for k in d.dims {
        assert_relative_eq!(k, 4.0, max_relative = 2e-3);
    }
    assert_relative_eq!(d.roundness, 1.0, max_relative = 1e-6);
    assert_relative_eq!(d.volume_surface_ratio(), 2.0 / 3.0, max_relative = 1e-12);
}

#[test]
fn ellipsoid_surface_dna_converges() {
    // semi-axes (2, 1.5, 1): V = 4π, dims (4, 3, 2)
    let semi = [2.0, 1.5, 1.0];
    let mut last = f64::INFINITY;
    for (a, p) in [(16, 8), (28, 18), (56, 36)] {
        let g = geom(a, p);
        let d = g
            .surface_dna(&ellipsoid_field(&g, semi), 45, 1.1)
            .expect("valid");
        let ev = (d.volume / (4.0 * PI) - 1.0).abs();
        assert!(
            ev < last,
            "volume error must fall with refinement: {ev} after {last}"
        );
        last = ev;
        if a == 28 {
            assert!(ev < 0.01, "28x18 volume error {ev}");
            assert_relative_eq!(d.dims[0], 4.0, max_relative = 0.02);
            assert_relative_eq!(d.dims[1], 3.0, max_relative = 0.02);
            assert_relative_eq!(d.dims[2], 2.0, max_relative = 0.02);
            // exact area of this ellipsoid: 30.59 (Knud Thomsen within 1 %)
            let pp = 1.6075;
            let ap = (2.0f64 * 1.5).powf(pp) + 2.0f64.powf(pp) + 1.5f64.powf(pp);
            let thomsen = 4.0 * PI * (ap / 3.0).powf(1.0 / pp);
            assert_relative_eq!(d.area, thomsen, max_relative = 0.02);
            assert!(d.roundness > 0.0 && d.roundness <= 1.0);
        }
    }
}

#[test]
fn surface_dna_rejects_bad_fields() {
    let g = geom(8, 4);
    let mut r = vec![1.0; g.n_nodes()];
    r[3] = -1.0;
    assert!(g.surface_dna(&r, 45, 1.1).is_none());
    r[3] = f64::NAN;
    assert!(g.surface_dna(&r, 45, 1.1).is_none());
    assert!(g.surface_dna(&[1.0; 3], 45, 1.1).is_none());
}

#[test]
fn interpolation_reproduces_nodes_and_constants() {
    let g = geom(12, 7);
    let semi = [1.3, 1.0, 0.7];
    let r = ellipsoid_field(&g, semi);
    let angles = g.mesh().node_angles();
    for how in [Interpolation::Bilinear, Interpolation::CatmullRom] {
        for (k, (t, p)) in angles.iter().enumerate() {
            assert_relative_eq!(g.interpolate(&r, *t, *p, how), r[k], max_relative = 1e-12);
        }
        let c = vec![0.9; g.n_nodes()];
        for t in [0.0, 0.1, 1.0, 2.9, PI] {
            for p in [-1.0, 0.0, 0.3, 6.0, 7.0] {
                assert_relative_eq!(g.interpolate(&c, t, p, how), 0.9, max_relative = 1e-12);
            }
        }
    }
}

#[test]
fn catmull_rom_is_closer_to_a_smooth_surface_than_bilinear() {
    let g = geom(16, 8);
    let semi = [1.5, 1.0, 0.8];
    let r = ellipsoid_field(&g, semi);
    let (mut el, mut ec) = (0.0f64, 0.0f64);
    for i in 0..40 {
        for j in 1..40 {
            let (t, p) = (PI * j as f64 / 40.0, TAU * (i as f64 + 0.37) / 40.0);
            let u = Vector3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            let exact = 1.0
                / ((u.x / semi[0]).powi(2) + (u.y / semi[1]).powi(2) + (u.z / semi[2]).powi(2))
                    .sqrt();
            el = el.max((g.interpolate(&r, t, p, Interpolation::Bilinear) - exact).abs());
            ec = ec.max((g.interpolate(&r, t, p, Interpolation::CatmullRom) - exact).abs());
        }
    }
    assert!(ec < 0.5 * el, "Catmull-Rom {ec} vs bilinear {el}");
}

#[test]
fn smoothing_keeps_constants_and_raises_roundness() {
    let g = geom(28, 18);
    let c = vec![1.0; g.n_nodes()];
    let mut out = vec![0.0; g.n_nodes()];
    g.smooth_into(&c, 0.5, &mut out);
    for v in &out {
        assert_relative_eq!(*v, 1.0, max_relative = 1e-15);
    }
    // a rough field: a checkerboard of ±8 %
    let rough: Vec<f64> = (0..g.n_nodes())
        .map(|k| if k % 2 == 0 { 1.08 } else { 0.92 })
        .collect();
    let r0 = g.roundness(&rough, 45, 1.1);
    g.smooth_into(&rough, 0.5, &mut out);
    let r1 = g.roundness(&out, 45, 1.1);
    assert!(r1 > r0, "smoothing must round: {r0} -> {r1}");
    let d = g.surface_dna(&out, 45, 1.1).expect("valid");
    assert!(d.roundness > 0.0 && d.roundness <= 1.0);
}

#[test]
fn needle_and_flat_ellipsoids_stay_finite() {
    let g = geom(28, 18);
    for semi in [[10.0, 0.5, 0.5], [3.0, 3.0, 0.05], [1.0, 1.0, 1e-3]] {
        let d = g.surface_dna(&ellipsoid_field(&g, semi), 45, 1.1);
        if let Some(d) = d {
            assert!(d.volume.is_finite() && d.area.is_finite());
            assert!(d.roundness > 0.0 && d.roundness <= 1.0);
            assert!(d.dims.iter().all(|x| x.is_finite() && *x > 0.0));
        }
    }
}

#[test]
fn the_moments_only_path_equals_the_full_one() {
    let g = geom(28, 18);
    let r: Vec<f64> = (0..g.n_nodes())
        .map(|k| {
            g.ellipsoid_radius(k, [1.4, 1.0, 0.7]) * (1.0 + 0.03 * ((k * 7) % 11) as f64 / 11.0)
        })
        .collect();
    let full = g.surface_dna(&r, 45, 1.1).expect("valid");
    let fast = g.surface_dna_with(&r, 45, 1.1, false).expect("valid");
    assert_eq!(full.volume.to_bits(), fast.volume.to_bits());
    assert_eq!(full.area.to_bits(), fast.area.to_bits());
    assert_eq!(full.dims, fast.dims);
    assert!(fast.roundness.is_nan() && full.roundness > 0.0);
}

/// The inscribed-radius estimate: a sphere's radius (centred or not, the
/// search finds it), an ellipsoid's smallest semi-axis (the largest
/// inscribed sphere of an ellipsoid), within the node spacing; bad fields
/// are `None`.
#[test]
fn inscribed_radius_of_spheres_and_ellipsoids() {
    let g = geom(28, 18);
    let sphere = vec![2.0; g.n_nodes()];
    assert_relative_eq!(
        g.inscribed_radius(&sphere).expect("r"),
        2.0,
        max_relative = 1e-9
    );
    let e = ellipsoid_field(&g, [3.0, 2.0, 1.0]);
    let r = g.inscribed_radius(&e).expect("r");
    assert!((r - 1.0).abs() < 0.02, "{r}");
    // an off-centre sphere, seen from the origin (centre at 0.3 along x)
    let off: Vec<f64> = g
        .dirs
        .iter()
        .map(|u| {
            let b = 0.3 * u.x;
            b + (b * b - (0.09 - 1.0)).sqrt()
        })
        .collect();
    let r = g.inscribed_radius(&off).expect("r");
    assert!((r - 1.0).abs() < 0.01, "{r}");
    let mut bad = sphere.clone();
    bad[3] = f64::NAN;
    assert!(g.inscribed_radius(&bad).is_none());
    assert!(g.inscribed_radius(&sphere[1..]).is_none());
}
