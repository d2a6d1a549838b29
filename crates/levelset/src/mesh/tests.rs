//! Oracles of the mesh distance and of closed-mesh preparation.

use super::*;
use approx::assert_abs_diff_eq;
use proptest::prelude::*;
use std::collections::BTreeMap;

/// The cube [−0.5, 0.5]³: 8 vertices, 12 triangles, two per face in the order z−, z+,
/// y−, y+, x−, x+ (face `f` is triangles `2f`, `2f + 1`).
pub(crate) fn cube_mesh() -> TriMesh {
    let v: Vec<Point3<f64>> = (0..8)
        .map(|c| {
            Point3::new(
                f64::from(c & 1) - 0.5,
                f64::from((c >> 1) & 1) - 0.5,
                f64::from((c >> 2) & 1) - 0.5,
            )
        })
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    TriMesh::new(v, t).expect("cube")
}

#[test]
fn cube_distance_is_exact_including_edges_and_corners() {
    let m = cube_mesh();
    assert_abs_diff_eq!(m.signed_volume(), 1.0, epsilon = 1e-14);
    let md = MeshDistance::new(&m).expect("closed");
    let cases = [
        (Point3::new(0.0, 0.0, 0.0), -0.5),
        (Point3::new(1.5, 0.0, 0.0), 1.0),
        (Point3::new(1.5, 1.5, 0.0), 2.0f64.sqrt()),
        (Point3::new(1.5, 1.5, 1.5), 3.0f64.sqrt()),
        (Point3::new(0.4, 0.45, 0.0), -0.05),
        (Point3::new(0.5, 0.5, 0.5), 0.0),
    ];
    for (p, d) in cases {
        assert_abs_diff_eq!(md.signed_distance(&p), d, epsilon = 1e-12);
    }
}

#[test]
fn open_and_bad_meshes_are_rejected() {
    let m = cube_mesh();
    let mut t = m.triangles().to_vec();
    t.pop();
    let open = TriMesh::new(m.vertices().to_vec(), t).expect("valid triangles");
    assert!(matches!(
        MeshDistance::new(&open),
        Err(Error::NonClosedMesh { .. })
    ));
    let mut t = m.triangles().to_vec();
    t[0].swap(1, 2);
    let flipped = TriMesh::new(m.vertices().to_vec(), t).expect("valid triangles");
    assert!(matches!(
        MeshDistance::new(&flipped),
        Err(Error::NonClosedMesh { .. })
    ));
    assert!(matches!(
        TriMesh::new(m.vertices().to_vec(), vec![[0, 1, 9]]),
        Err(Error::VertexIndexOutOfRange { .. })
    ));
    assert!(matches!(
        TriMesh::new(m.vertices().to_vec(), vec![[0, 0, 1]]),
        Err(Error::DegenerateTriangle { .. })
    ));
    assert!(matches!(
        TriMesh::new(vec![], vec![]),
        Err(Error::EmptyMesh)
    ));
    assert!(matches!(
        MeshDistance::new(&TriMesh::default()),
        Err(Error::EmptyMesh)
    ));
    let spec = GridSpec::cube(5, -1.0, 1.0).expect("spec");
    assert!(matches!(
        Grid::from_mesh(spec, &open),
        Err(Error::NonClosedMesh { .. })
    ));
}

/// A regular tetrahedron with outward orientation.
pub(crate) fn tetrahedron() -> TriMesh {
    let v = vec![
        Point3::new(1.0, 1.0, 1.0),
        Point3::new(1.0, -1.0, -1.0),
        Point3::new(-1.0, 1.0, -1.0),
        Point3::new(-1.0, -1.0, 1.0),
    ];
    TriMesh::new(v, vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]).expect("tetrahedron")
}

/// The icosahedron subdivided `levels` times, projected on the unit sphere, outward.
pub(crate) fn icosphere(levels: usize) -> TriMesh {
    let t = (1.0 + 5.0f64.sqrt()) / 2.0;
    let mut v: Vec<Point3<f64>> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Point3::from(Vector3::new(x, y, z).normalize()))
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        let mut next = Vec::with_capacity(4 * f.len());
        for &[a, b, c] in &f {
            let mut m = |i: usize, j: usize| {
                *mid.entry((i.min(j), i.max(j))).or_insert_with(|| {
                    v.push(Point3::from((v[i].coords + v[j].coords).normalize()));
                    v.len() - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    for tri in &mut f {
        let [a, b, c] = *tri;
        let n = (v[b] - v[a]).cross(&(v[c] - v[a]));
        if n.dot(&(v[a].coords + v[b].coords + v[c].coords)) < 0.0 {
            tri.swap(1, 2);
        }
    }
    TriMesh::new(v, f).expect("icosphere")
}

fn flipped(mesh: &TriMesh, which: &[usize]) -> TriMesh {
    let mut t = mesh.triangles().to_vec();
    for &i in which {
        t[i].swap(1, 2);
    }
    TriMesh::new(mesh.vertices().to_vec(), t).expect("valid")
}

/// Triangles as oriented cycles starting at their smallest index, sorted.
fn oriented_set(m: &TriMesh) -> Vec<[usize; 3]> {
    let mut out: Vec<[usize; 3]> = m
        .triangles()
        .iter()
        .map(|&[a, b, c]| {
            if a < b && a < c {
                [a, b, c]
            } else if b < c {
                [b, c, a]
            } else {
                [c, a, b]
            }
        })
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn closed_meshes_pass_unchanged() {
    for m in [cube_mesh(), tetrahedron(), icosphere(2)] {
        for policy in [Orientation::Repair, Orientation::Refuse] {
            let (p, r) = m.prepare_closed(policy).expect("closed");
            assert_eq!(r, MeshRepair::default());
            assert_eq!(p.triangles(), m.triangles());
            assert_eq!(p.vertices().len(), m.vertices().len());
            assert_abs_diff_eq!(p.signed_volume(), m.signed_volume(), epsilon = 0.0);
        }
    }
    let ico = icosphere(2);
    assert_eq!(ico.triangles().len(), 320);
    assert_abs_diff_eq!(ico.area(), 4.0 * std::f64::consts::PI, epsilon = 0.3);
}

#[test]
fn cube_with_three_faces_flipped_is_repaired_to_the_same_volume() {
    let cube = cube_mesh();
    // Faces z+, y−, x+ (triangles 2, 3, 4, 5, 10, 11): a tie, 6 of 12; the class of
    // triangle 0 (correct) is kept.
    let bad = flipped(&cube, &[2, 3, 4, 5, 10, 11]);
    assert!(matches!(
        bad.check_closed(),
        Err(Error::NonClosedMesh { .. })
    ));
    let (fixed, r) = bad.prepare_closed(Orientation::Repair).expect("repairable");
    assert_eq!(
        r,
        MeshRepair {
            flipped: 6,
            ..MeshRepair::default()
        }
    );
    assert_abs_diff_eq!(fixed.signed_volume(), 1.0, epsilon = 1e-14);
    assert_eq!(oriented_set(&fixed), oriented_set(&cube));
    fixed.check_closed().expect("closed and consistent");
    assert!(matches!(
        bad.prepare_closed(Orientation::Refuse),
        Err(Error::InconsistentOrientation {
            flipped: 6,
            triangles: 12
        })
    ));
    // Five faces flipped: the majority is inward, so the two correct triangles are the
    // minority and the consistent mesh is then inverted.
    let bad = flipped(&cube, &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]);
    let (fixed, r) = bad.prepare_closed(Orientation::Repair).expect("repairable");
    assert_eq!((r.flipped, r.inverted), (2, true));
    assert_eq!(oriented_set(&fixed), oriented_set(&cube));
}

#[test]
fn inverted_cube_is_reported_when_repaired_and_refused_otherwise() {
    let cube = cube_mesh();
    let inside_out = flipped(&cube, &(0..12).collect::<Vec<_>>());
    assert_abs_diff_eq!(inside_out.signed_volume(), -1.0, epsilon = 1e-14);
    // It is closed and consistent, so check_closed alone cannot see the problem.
    inside_out.check_closed().expect("consistent");
    let (fixed, r) = inside_out
        .prepare_closed(Orientation::Repair)
        .expect("repairable");
    assert_eq!(
        r,
        MeshRepair {
            inverted: true,
            ..MeshRepair::default()
        }
    );
    assert_abs_diff_eq!(fixed.signed_volume(), 1.0, epsilon = 1e-14);
    assert_eq!(oriented_set(&fixed), oriented_set(&cube));
    match inside_out.prepare_closed(Orientation::Refuse) {
        Err(Error::InwardOrientation { volume }) => {
            assert_abs_diff_eq!(volume, -1.0, epsilon = 1e-14)
        }
        other => panic!("expected InwardOrientation, got {other:?}"),
    }
}

#[test]
fn cube_with_a_face_removed_is_open_and_the_error_names_an_edge() {
    let cube = cube_mesh();
    // Remove face y+ (triangles 6, 7: [2, 6, 3], [3, 6, 7]).
    let t: Vec<[usize; 3]> = cube
        .triangles()
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != 6 && i != 7)
        .map(|(_, t)| *t)
        .collect();
    let open = TriMesh::new(cube.vertices().to_vec(), t).expect("valid");
    match open.prepare_closed(Orientation::Repair) {
        Err(Error::OpenMesh {
            a,
            b,
            pa,
            pb,
            boundary_edges,
        }) => {
            // The lowest boundary edge of the square 2–3–7–6.
            assert_eq!((a, b, boundary_edges), (2, 3, 4));
            assert_abs_diff_eq!(pa[1], 0.5, epsilon = 0.0);
            assert_abs_diff_eq!(pb[1], 0.5, epsilon = 0.0);
        }
        other => panic!("expected OpenMesh, got {other:?}"),
    }
    let msg = open
        .prepare_closed(Orientation::Refuse)
        .expect_err("open")
        .to_string();
    assert!(
        msg.contains("edge (2, 3)") && msg.contains("4 boundary edges"),
        "{msg}"
    );
}

/// Two cubes as one mesh, the second moved by `shift`, vertex positions duplicated.
fn two_cubes(shift: Vector3<f64>) -> TriMesh {
    let c = cube_mesh();
    let mut v = c.vertices().to_vec();
    v.extend(c.vertices().iter().map(|p| p + shift));
    let mut t = c.triangles().to_vec();
    t.extend(c.triangles().iter().map(|t| t.map(|i| i + 8)));
    TriMesh::new(v, t).expect("valid")
}

#[test]
fn two_disjoint_cubes_are_several_components() {
    let m = two_cubes(Vector3::new(3.0, 0.0, 0.0));
    assert!(matches!(
        m.prepare_closed(Orientation::Repair),
        Err(Error::SeveralComponents { count: 2 })
    ));
}

#[test]
fn bowtie_vertex_is_not_manifold() {
    // The second cube touches the first at the corner (0.5, 0.5, 0.5) (vertex 7 of the
    // first, vertex 8 + 0 of the second, welded).
    let m = two_cubes(Vector3::new(1.0, 1.0, 1.0));
    match m.prepare_closed(Orientation::Repair) {
        Err(Error::NonManifoldVertex {
            vertex,
            position,
            fans,
        }) => {
            assert_eq!((vertex, fans), (7, 2));
            for x in position {
                assert_abs_diff_eq!(x, 0.5, epsilon = 0.0);
            }
        }
        other => panic!("expected NonManifoldVertex, got {other:?}"),
    }
}

#[test]
fn duplicated_face_makes_non_manifold_edges() {
    let cube = cube_mesh();
    let mut t = cube.triangles().to_vec();
    t.push(t[0]);
    let m = TriMesh::new(cube.vertices().to_vec(), t).expect("valid");
    match m.prepare_closed(Orientation::Repair) {
        Err(Error::NonManifoldEdge {
            a, b, count, edges, ..
        }) => {
            // Triangle 0 is [0, 2, 1]: edges (0, 1), (0, 2), (1, 2) are used three times.
            assert_eq!((a, b, count, edges), (0, 1, 3, 3));
        }
        other => panic!("expected NonManifoldEdge, got {other:?}"),
    }
}

#[test]
fn welding_degenerate_and_unreferenced_are_counted() {
    let cube = cube_mesh();
    let mut v = cube.vertices().to_vec();
    // Vertex 8 duplicates vertex 3 (a UV seam); vertex 9 is unused.
    v.push(Point3::new(0.5, 0.5, -0.5));
    v.push(Point3::new(9.0, 9.0, 9.0));
    let mut t = cube.triangles().to_vec();
    for tri in &mut t[6..8] {
        for i in tri.iter_mut() {
            if *i == 3 {
                *i = 8;
            }
        }
    }
    // A repeated vertex, and a zero-area triangle that repeats a vertex only after welding.
    t.push([0, 0, 1]);
    t.push([3, 8, 1]);
    let m = TriMesh::new_allowing_degenerate(v, t).expect("valid");
    assert!(matches!(
        TriMesh::new(m.vertices().to_vec(), m.triangles().to_vec()),
        Err(Error::DegenerateTriangle { triangle: 12 })
    ));
    assert!(matches!(
        MeshDistance::new(&m),
        Err(Error::DegenerateTriangle { triangle: 12 })
    ));
    let (p, r) = m
        .prepare_closed(Orientation::Refuse)
        .expect("closed after welding");
    assert_eq!(
        r,
        MeshRepair {
            welded: 1,
            unreferenced: 1,
            degenerate_removed: 2,
            ..MeshRepair::default()
        }
    );
    assert_eq!(p.vertices().len(), 8);
    assert_eq!(oriented_set(&p), oriented_set(&cube));
    let ok = MeshDistance::new(&p).expect("distance");
    assert_abs_diff_eq!(ok.signed_distance(&Point3::origin()), -0.5, epsilon = 1e-15);
}

#[test]
fn negative_zero_welds_with_zero() {
    // A tetrahedron with a vertex at the origin written once as (0, 0, 0) and once as
    // (−0, 0, −0).
    let v = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(0.0, 0.0, 1.0),
        Point3::new(-0.0, 0.0, -0.0),
    ];
    let t = vec![[0, 2, 1], [4, 1, 3], [0, 3, 2], [1, 2, 3]];
    let m = TriMesh::new(v, t).expect("valid");
    let (p, r) = m.prepare_closed(Orientation::Refuse).expect("closed");
    assert_eq!(r.welded, 1);
    assert_abs_diff_eq!(p.signed_volume(), 1.0 / 6.0, epsilon = 1e-15);
}

#[test]
fn flat_and_one_sided_meshes_are_refused() {
    // Two triangles back to back: closed, consistent, no volume.
    let v = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let flat = TriMesh::new(v, vec![[0, 1, 2], [0, 2, 1]]).expect("valid");
    assert!(matches!(
        flat.prepare_closed(Orientation::Repair),
        Err(Error::ZeroVolume { .. })
    ));
    assert!(matches!(flat.centroid(), Err(Error::ZeroVolume { .. })));
    // The 6-vertex real projective plane: closed, manifold, one-sided (immersed with
    // self-intersections).
    let v = vec![
        Point3::new(1.0, 0.1, 0.0),
        Point3::new(-1.0, 0.0, 0.2),
        Point3::new(0.0, 1.0, 0.3),
        Point3::new(0.1, -1.0, 0.0),
        Point3::new(0.0, 0.2, 1.0),
        Point3::new(0.3, 0.0, -1.0),
    ];
    let t = [
        [1, 2, 3],
        [1, 3, 4],
        [1, 4, 5],
        [1, 5, 6],
        [1, 6, 2],
        [2, 3, 5],
        [3, 4, 6],
        [4, 5, 2],
        [5, 6, 3],
        [6, 2, 4],
    ]
    .iter()
    .map(|t| t.map(|i| i - 1))
    .collect();
    let rp2 = TriMesh::new(v, t).expect("valid");
    assert!(matches!(
        rp2.prepare_closed(Orientation::Repair),
        Err(Error::NonOrientable { .. })
    ));
    let empty = TriMesh::new_allowing_degenerate(vec![Point3::origin()], vec![[0, 0, 0]])
        .expect("valid indices");
    assert!(matches!(
        empty.prepare_closed(Orientation::Repair),
        Err(Error::EmptyMesh)
    ));
}

#[test]
fn centroid_of_shifted_solids() {
    let shift = Vector3::new(1.0, -2.0, 3.5);
    for m in [cube_mesh(), tetrahedron(), icosphere(1)] {
        let moved = TriMesh::new(
            m.vertices().iter().map(|p| p + shift).collect(),
            m.triangles().to_vec(),
        )
        .expect("valid");
        let c = moved.centroid().expect("volume");
        assert_abs_diff_eq!((c.coords - shift).norm(), 0.0, epsilon = 1e-14);
        // Orientation does not matter.
        let inv = flipped(&moved, &(0..moved.triangles().len()).collect::<Vec<_>>());
        let ci = inv.centroid().expect("volume");
        assert_abs_diff_eq!((ci - c).norm(), 0.0, epsilon = 1e-14);
    }
    // A non-symmetric solid: the corner tetrahedron has its centroid at (1/4, 1/4, 1/4).
    let v = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(0.0, 0.0, 1.0),
    ];
    let m = TriMesh::new(v, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]).expect("valid");
    let c = m.centroid().expect("volume");
    assert_abs_diff_eq!(
        (c - Point3::new(0.25, 0.25, 0.25)).norm(),
        0.0,
        epsilon = 1e-15
    );
    assert!(matches!(
        TriMesh::default().centroid(),
        Err(Error::EmptyMesh)
    ));
}

#[test]
fn grain_mesh_to_grid_around_its_centroid() {
    let shift = Vector3::new(0.3, 0.2, -0.1);
    let ico = icosphere(3);
    let m = TriMesh::new(
        ico.vertices().iter().map(|p| p + shift).collect(),
        ico.triangles().to_vec(),
    )
    .expect("valid");
    let (m, _) = m.prepare_closed(Orientation::Refuse).expect("closed");
    let c = m.centroid().expect("volume");
    let spec = GridSpec::around_points(m.vertices(), c, 45, 1.1).expect("spec");
    assert_eq!(spec.dims, [45; 3]);
    assert_abs_diff_eq!(spec.spacing, 2.2 / 44.0, epsilon = 1e-12);
    for a in 0..3 {
        assert_abs_diff_eq!(spec.origin[a] + 1.1, c[a], epsilon = 1e-12);
        assert_abs_diff_eq!(spec.max_corner()[a] - 1.1, c[a], epsilon = 1e-12);
    }
    let g = Grid::from_mesh(spec, &m).expect("grid");
    // The centre node lies at the centroid, one unit (less the facet sag) inside.
    assert_abs_diff_eq!(g.at(22, 22, 22), -1.0, epsilon = 6e-3);
    assert!(g.at(0, 0, 0) > 0.0);
    let vol = g.volume();
    assert_abs_diff_eq!(vol, m.signed_volume(), epsilon = 0.01 * m.signed_volume());
}

#[test]
fn around_points_rejects_bad_input() {
    let p = [Point3::new(1.0, 0.0, 0.0)];
    let o = Point3::origin();
    assert!(matches!(
        GridSpec::around_points(&p, o, 2, 1.1),
        Err(Error::TooFewNodes { nodes: 2, .. })
    ));
    for margin in [1.0, 0.5, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            GridSpec::around_points(&p, o, 45, margin),
            Err(Error::InvalidParameter { name: "margin", .. })
        ));
    }
    assert!(matches!(
        GridSpec::around_points(&[], o, 45, 1.1),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        GridSpec::around_points(&[o], o, 45, 1.1),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        GridSpec::around_points(&[Point3::new(f64::NAN, 0.0, 0.0)], o, 45, 1.1),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        GridSpec::around_points(&p, Point3::new(0.0, f64::INFINITY, 0.0), 45, 1.1),
        Err(Error::InvalidParameter { name: "centre", .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Any subset of flipped triangles of a closed sphere is repaired to the original
    /// orientation; the count is the minority class.
    #[test]
    fn random_flips_are_repaired(mask in proptest::collection::vec(any::<bool>(), 80)) {
        let ico = icosphere(1);
        let which: Vec<usize> = (0..80).filter(|&i| mask[i]).collect();
        let bad = flipped(&ico, &which);
        let (fixed, r) = bad.prepare_closed(Orientation::Repair).expect("repairable");
        let k = which.len();
        prop_assert_eq!(r.flipped, k.min(80 - k));
        // Triangle 0's class is kept on a tie; the mesh is inverted iff the kept class was
        // the flipped one.
        let kept_flipped = if 2 * k == 80 { mask[0] } else { 2 * k > 80 };
        prop_assert_eq!(r.inverted, kept_flipped);
        prop_assert_eq!(oriented_set(&fixed), oriented_set(&ico));
        prop_assert!((fixed.signed_volume() - ico.signed_volume()).abs() < 1e-14);
        let refused = bad.prepare_closed(Orientation::Refuse);
        prop_assert_eq!(refused.is_ok(), k == 0);
    }

    /// Random edits of a closed cube (flip, drop, duplicate or re-point a triangle, move a
    /// vertex onto another) never panic; accepted results are closed, consistent and
    /// outward, and a mesh with only flips is always accepted with the cube's volume.
    #[test]
    fn edited_cubes_never_panic(
        edits in proptest::collection::vec((0usize..5, 0usize..12, 0usize..8), 0..6),
    ) {
        let cube = cube_mesh();
        let mut v = cube.vertices().to_vec();
        let mut t = cube.triangles().to_vec();
        let mut only_flips = true;
        for &(kind, i, x) in &edits {
            let i = i % t.len().max(1);
            if t.is_empty() {
                break;
            }
            match kind {
                0 => t[i].swap(0, 1),
                1 => {
                    t.remove(i);
                    only_flips = false;
                }
                2 => {
                    t.push(t[i]);
                    only_flips = false;
                }
                3 => {
                    t[i][x % 3] = x;
                    only_flips = false;
                }
                _ => {
                    v[x] = v[(x + 1) % 8];
                    only_flips = false;
                }
            }
        }
        let Ok(m) = TriMesh::new_allowing_degenerate(v, t.clone()) else {
            prop_assert!(t.is_empty());
            return Ok(());
        };
        match m.prepare_closed(Orientation::Repair) {
            Ok((p, r)) => {
                p.check_closed().expect("closed and consistent");
                prop_assert!(p.signed_volume() > 0.0);
                prop_assert_eq!(p.vertices().len() + r.welded + r.unreferenced, 8);
                prop_assert_eq!(p.triangles().len() + r.degenerate_removed, t.len());
                MeshDistance::new(&p).expect("distance");
            }
            Err(e) => prop_assert!(!only_flips, "{e}"),
        }
        if only_flips {
            let (p, _) = m.prepare_closed(Orientation::Repair).expect("flips are repaired");
            prop_assert!((p.signed_volume() - 1.0).abs() < 1e-14);
        }
    }

    /// Arbitrary triangle soups never panic; whatever is accepted is closed, consistent,
    /// outward, and its counts add up.
    #[test]
    fn arbitrary_soups_never_panic(
        coords in proptest::collection::vec(-2i8..=2, 3 * 7),
        tris in proptest::collection::vec((0usize..7, 0usize..7, 0usize..7), 1..14),
    ) {
        let v: Vec<Point3<f64>> = coords
            .chunks_exact(3)
            .map(|c| Point3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])))
            .collect();
        let t: Vec<[usize; 3]> = tris.iter().map(|&(a, b, c)| [a, b, c]).collect();
        let m = TriMesh::new_allowing_degenerate(v, t).expect("indices in range");
        if let Ok((p, r)) = m.prepare_closed(Orientation::Repair) {
            p.check_closed().expect("closed and consistent");
            prop_assert!(p.signed_volume() > 0.0);
            prop_assert_eq!(p.vertices().len() + r.welded + r.unreferenced, 7);
            prop_assert_eq!(p.triangles().len() + r.degenerate_removed, tris.len());
            MeshDistance::new(&p).expect("distance");
            p.centroid().expect("centroid");
        }
        let _ = m.prepare_closed(Orientation::Refuse);
        let _ = m.centroid();
    }
}

/// The lumpy grain of the acceptance benchmark (radius 0.8 ± 0.17).
fn lumpy(u: Vector3<f64>) -> f64 {
    let theta = u.z.clamp(-1.0, 1.0).acos();
    let phi = u.y.atan2(u.x);
    0.8 + 0.12 * (3.0 * theta).sin() * (2.0 * phi).cos() + 0.05 * (5.0 * phi).sin() * theta.sin()
}
/// The lumpy grain as a latitude–longitude mesh of 4·m·(m − 1) triangles.
pub(crate) fn lumpy_mesh(m: usize) -> TriMesh {
    let seg = 2 * m;
    let point = |theta: f64, phi: f64| {
        let u = Vector3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        Point3::from(lumpy(u) * u)
    };
    let mut v = vec![point(0.0, 0.0)];
    for i in 1..m {
        let theta = std::f64::consts::PI * i as f64 / m as f64;
        for j in 0..seg {
            v.push(point(theta, std::f64::consts::TAU * j as f64 / seg as f64));
        }
    }
    let south = v.len();
    v.push(point(std::f64::consts::PI, 0.0));
    let at = |i: usize, j: usize| 1 + (i - 1) * seg + j % seg;
    let mut t = Vec::new();
    for j in 0..seg {
        t.push([0, at(1, j), at(1, j + 1)]);
        t.push([south, at(m - 1, j + 1), at(m - 1, j)]);
        for i in 1..m - 1 {
            t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TriMesh::new(v, t)
        .expect("mesh")
        .prepare_closed(Orientation::Refuse)
        .expect("c")
        .0
}
/// `Grid::from_mesh` (searches seeded with the neighbour's closest triangle) agrees with
/// unbounded exact queries at every node, on both sides of a lumpy, non-convex grain.
#[test]
fn from_mesh_equals_unbounded_queries() {
    let mesh = lumpy_mesh(16);
    let c = mesh.centroid().expect("centroid");
    let spec = GridSpec::around_points(mesh.vertices(), c, 21, 1.1).expect("spec");
    let g = Grid::from_mesh(spec, &mesh).expect("grid");
    let md = MeshDistance::new(&mesh).expect("distance");
    let [nx, ny, nz] = spec.dims;
    let mut inside = 0;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let exact = md.signed_distance(&spec.node(i, j, k));
                assert_abs_diff_eq!(g.at(i, j, k), exact, epsilon = 1e-12);
                inside += usize::from(exact < 0.0);
            }
        }
    }
    assert!(inside > 500 && inside < nx * ny * nz / 2, "{inside}");
}
