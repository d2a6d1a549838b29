//! The region a grain packing fills: its walls (a container, or none) and
//! its periodic axes, with the periodic images the neighbour searches use.
//!
//! Periodic axes are handled by images: the centres are wrapped into the
//! cell, and a grain within `width` of a periodic face gets an image
//! (its centre shifted by ± the side) beyond the opposite face, for each
//! combination of the faces it is near (up to 7 in a corner of a fully
//! periodic cell). A neighbour search over the centres and their images
//! then finds every pair closer than `width` once, either directly or
//! through exactly one image, provided every periodic side is longer than
//! `2 · width` (checked at entry: sides of at least 3 d_max, the widths
//! used are at most about d_max plus a margin or a skin).

use nalgebra::{Point3, Vector3};

use packer_spheres::{Boundary, Container};

/// Shift code of the identity (no image): see [`Region::shift`].
pub(crate) const NO_SHIFT: u8 = 13;

/// Walls and periodic axes of a packing.
pub(crate) struct Region<'a> {
    /// The container whose walls bound the grains (its periodic faces are
    /// not walls); `None` in a fully periodic cell.
    walls: Option<&'a Container>,
    lo: Vector3<f64>,
    hi: Vector3<f64>,
    period: [bool; 3],
}

impl<'a> Region<'a> {
    pub(crate) fn new(boundary: &'a Boundary) -> Self {
        match boundary {
            Boundary::Periodic { min, max } => Self {
                walls: None,
                lo: min.coords,
                hi: max.coords,
                period: [true; 3],
            },
            Boundary::Walls(c) => Self::of(c),
        }
    }

    pub(crate) fn of(c: &'a Container) -> Self {
        let (lo, hi) = c.bbox();
        let [px, py] = c.periodic();
        Self {
            walls: Some(c),
            lo: lo.coords,
            hi: hi.coords,
            period: [px, py, false],
        }
    }

    /// Distance to the nearest wall, positive inside (`+inf` without walls).
    #[inline]
    pub(crate) fn clearance(&self, p: &Point3<f64>) -> f64 {
        self.walls.map_or(f64::INFINITY, |c| c.clearance(p))
    }

    /// Wall contact forces on a sphere of radius `r` at `p`, added to `acc`
    /// (unit stiffness: overlap times the wall's inward normal); returns
    /// the deepest overlap (`−inf` without contact).
    ///
    /// Each wall is a separate contact, as in a DEM code: the floor, the
    /// lid and each non-periodic side of a box are half-spaces, a
    /// cylinder's mantle is the infinite cylinder. So a sphere pressed into
    /// a corner feels both walls, and the energy is smooth there (a force
    /// from the nearest wall only would jump between the walls at the
    /// corner's bisector and never come to rest). A mesh container has no
    /// faces to tell apart: its contact is the nearest wall's, along the
    /// clearance gradient.
    #[inline]
    pub(crate) fn wall_push(&self, p: &Point3<f64>, r: f64, acc: &mut [f64; 3]) -> f64 {
        let mut worst = f64::NEG_INFINITY;
        let mut push = |ov: f64, n: [f64; 3], acc: &mut [f64; 3]| {
            if ov > 0.0 {
                worst = worst.max(ov);
                for k in 0..3 {
                    acc[k] += ov * n[k];
                }
            }
        };
        match self.walls {
            None => {}
            Some(Container::Box { min, max, periodic }) => {
                for k in 0..3 {
                    if k < 2 && periodic[k] {
                        continue;
                    }
                    let mut n = [0.0; 3];
                    n[k] = 1.0;
                    push(r - (p[k] - min[k]), n, acc);
                    n[k] = -1.0;
                    push(r - (max[k] - p[k]), n, acc);
                }
            }
            Some(Container::Cylinder {
                base,
                radius,
                height,
            }) => {
                push(r - (p.z - base.z), [0.0, 0.0, 1.0], acc);
                push(r - (base.z + height - p.z), [0.0, 0.0, -1.0], acc);
                let (dx, dy) = (p.x - base.x, p.y - base.y);
                let rho = dx.hypot(dy);
                if rho > 0.0 {
                    push(r - (radius - rho), [-dx / rho, -dy / rho, 0.0], acc);
                }
            }
            Some(c @ Container::Mesh(_)) => {
                let cl = c.clearance(p);
                if cl < r {
                    match self.inward(p, 1e-4 * r) {
                        Some(n) => push(r - cl, [n.x, n.y, n.z], acc),
                        None => worst = worst.max(r - cl),
                    }
                }
            }
        }
        worst
    }

    /// The unit inward normal of the nearest wall at `p`: the clearance's
    /// gradient by central differences of step `h` (`None` where it
    /// vanishes).
    pub(crate) fn inward(&self, p: &Point3<f64>, h: f64) -> Option<Vector3<f64>> {
        let mut g = Vector3::zeros();
        for k in 0..3 {
            let (mut e, mut w) = (*p, *p);
            e[k] += h;
            w[k] -= h;
            g[k] = (self.clearance(&e) - self.clearance(&w)) / (2.0 * h);
        }
        let len = g.norm();
        (len > 0.0).then(|| g / len)
    }

    /// Whether any axis is periodic.
    pub(crate) fn is_periodic(&self) -> bool {
        self.period.iter().any(|&p| p)
    }

    /// Which axes are periodic.
    pub(crate) fn period(&self) -> [bool; 3] {
        self.period
    }

    /// Bounding box of the cell.
    pub(crate) fn bbox(&self) -> (Vector3<f64>, Vector3<f64>) {
        (self.lo, self.hi)
    }

    /// Side `k` of the cell.
    pub(crate) fn side(&self, k: usize) -> f64 {
        self.hi[k] - self.lo[k]
    }

    /// `p` moved by whole sides into `[lo, hi)` on the periodic axes.
    pub(crate) fn wrap(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let mut q = *p;
        for k in 0..3 {
            if self.period[k] {
                let l = self.side(k);
                let t = ((q[k] - self.lo[k]) / l).floor();
                if t != 0.0 {
                    q[k] -= t * l;
                }
                // rounding may land exactly on hi
                if q[k] >= self.hi[k] {
                    q[k] = self.lo[k];
                }
            }
        }
        q
    }

    /// The translation of shift code `code`: `(a, b, c) ∈ {−1, 0, 1}³`
    /// whole sides along x, y, z, coded `(a + 1) + 3 (b + 1) + 9 (c + 1)`.
    #[inline]
    pub(crate) fn shift(&self, code: u8) -> Vector3<f64> {
        let c = i32::from(code);
        let a = [c % 3 - 1, (c / 3) % 3 - 1, c / 9 - 1];
        Vector3::new(
            f64::from(a[0]) * self.side(0),
            f64::from(a[1]) * self.side(1),
            f64::from(a[2]) * self.side(2),
        )
    }

    /// The periodic images of the (wrapped) `centres` within `width` of a
    /// periodic face, as `(grain, shift code)`, in grain order.
    pub(crate) fn images(&self, centres: &[Vector3<f64>], width: f64) -> Vec<(u32, u8)> {
        let mut out = Vec::new();
        if !self.is_periodic() {
            return out;
        }
        for (i, p) in centres.iter().enumerate() {
            // per axis: the shifts the centre needs (0 always)
            let mut opts = [[0i8; 2]; 3];
            let mut count = [1usize; 3];
            for k in 0..3 {
                if !self.period[k] {
                    continue;
                }
                if p[k] - self.lo[k] < width {
                    opts[k][1] = 1;
                    count[k] = 2;
                } else if self.hi[k] - p[k] < width {
                    opts[k][1] = -1;
                    count[k] = 2;
                }
            }
            for c in 0..count[2] {
                for b in 0..count[1] {
                    for a in 0..count[0] {
                        if a + b + c == 0 {
                            continue;
                        }
                        let s = [opts[0][a], opts[1][b], opts[2][c]];
                        let code = (s[0] + 1) + 3 * (s[1] + 1) + 9 * (s[2] + 1);
                        out.push((i as u32, code as u8));
                    }
                }
            }
        }
        out
    }

    /// The centres followed by their images within `width` (see
    /// [`Region::images`]) and, for each entry, its grain and shift code.
    pub(crate) fn extended(
        &self,
        centres: &[Vector3<f64>],
        width: f64,
    ) -> (Vec<Vector3<f64>>, Vec<u32>, Vec<u8>) {
        let images = self.images(centres, width);
        let n = centres.len();
        let mut c = Vec::with_capacity(n + images.len());
        let mut real = Vec::with_capacity(n + images.len());
        let mut code = Vec::with_capacity(n + images.len());
        c.extend_from_slice(centres);
        real.extend(0..n as u32);
        code.resize(n, NO_SHIFT);
        for (i, s) in images {
            c.push(centres[i as usize] + self.shift(s));
            real.push(i);
            code.push(s);
        }
        (c, real, code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_cover_faces_edges_and_corners_once() {
        let b = Boundary::Periodic {
            min: Point3::new(0.0, 0.0, 0.0),
            max: Point3::new(10.0, 20.0, 30.0),
        };
        let r = Region::new(&b);
        assert_eq!(r.shift(NO_SHIFT), Vector3::zeros());
        let centres = [
            Vector3::new(5.0, 10.0, 15.0), // interior: none
            Vector3::new(0.5, 10.0, 15.0), // one face: +x
            Vector3::new(9.5, 19.5, 15.0), // edge: -x, -y, -x-y
            Vector3::new(0.5, 0.5, 29.5),  // corner: 7
        ];
        let im = r.images(&centres, 1.0);
        let count = |i: u32| im.iter().filter(|x| x.0 == i).count();
        assert_eq!((count(0), count(1), count(2), count(3)), (0, 1, 3, 7));
        let one = im.iter().find(|x| x.0 == 1).map(|x| r.shift(x.1));
        assert_eq!(one, Some(Vector3::new(10.0, 0.0, 0.0)));
        for (i, s) in &im {
            let p = centres[*i as usize] + r.shift(*s);
            // every image lies within the width outside the cell
            for k in 0..3 {
                assert!(p[k] > -1.0 && p[k] < r.hi[k] + 1.0, "{p:?}");
            }
        }
        let w = r.wrap(&Vector3::new(-0.5, 41.0, 30.0));
        assert!((w - Vector3::new(9.5, 1.0, 0.0)).norm() < 1e-12, "{w:?}");
    }

    #[test]
    fn walled_axes_get_no_images() {
        let c = Container::Box {
            min: Point3::origin(),
            max: Point3::new(10.0, 10.0, 10.0),
            periodic: [true, false],
        };
        let r = Region::of(&c);
        let im = r.images(&[Vector3::new(0.5, 0.5, 0.5)], 1.0);
        assert_eq!(im.len(), 1);
        assert_eq!(r.shift(im[0].1), Vector3::new(10.0, 0.0, 0.0));
        assert!(r.clearance(&Point3::new(5.0, 5.0, 0.25)) < 0.3);
        let free = Boundary::Periodic {
            min: Point3::origin(),
            max: Point3::new(1.0, 1.0, 1.0),
        };
        assert_eq!(
            Region::new(&free).clearance(&Point3::new(5.0, 5.0, 5.0)),
            f64::INFINITY
        );
    }

    #[test]
    fn every_wall_is_a_separate_contact() {
        // a sphere in the corner between floor and mantle feels both walls
        let cyl = Container::Cylinder {
            base: Point3::origin(),
            radius: 2.0,
            height: 5.0,
        };
        let r = Region::of(&cyl);
        let mut acc = [0.0; 3];
        let worst = r.wall_push(&Point3::new(1.6, 0.0, 0.3), 0.5, &mut acc);
        assert!((worst - 0.2).abs() < 1e-12, "{worst}");
        assert!(
            (acc[0] + 0.1).abs() < 1e-12 && acc[1].abs() < 1e-12,
            "{acc:?}"
        );
        assert!((acc[2] - 0.2).abs() < 1e-12, "{acc:?}");
        // the force is continuous across the corner's bisector
        let f = |x: f64| {
            let mut a = [0.0; 3];
            r.wall_push(&Point3::new(2.0 - x, 0.0, x), 0.5, &mut a);
            a
        };
        let (a, b) = (f(0.3 - 1e-9), f(0.3 + 1e-9));
        assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-8), "{a:?} {b:?}");
        // no contact: nothing added
        let mut none = [0.0; 3];
        assert_eq!(
            r.wall_push(&Point3::new(0.0, 0.0, 2.5), 0.5, &mut none),
            f64::NEG_INFINITY
        );
        assert_eq!(none, [0.0; 3]);
        // a box corner: three walls; a periodic axis has none
        let bx = Container::Box {
            min: Point3::origin(),
            max: Point3::new(4.0, 4.0, 4.0),
            periodic: [true, false],
        };
        let mut acc = [0.0; 3];
        Region::of(&bx).wall_push(&Point3::new(0.1, 0.2, 3.7), 0.5, &mut acc);
        assert!(acc[0].abs() < 1e-12, "{acc:?}");
        assert!(
            (acc[1] - 0.3).abs() < 1e-12 && (acc[2] + 0.2).abs() < 1e-12,
            "{acc:?}"
        );
        // fully periodic: no walls
        let free = Boundary::Periodic {
            min: Point3::origin(),
            max: Point3::new(1.0, 1.0, 1.0),
        };
        let mut acc = [0.0; 3];
        Region::new(&free).wall_push(&Point3::new(0.0, 0.0, 0.0), 0.5, &mut acc);
        assert_eq!(acc, [0.0; 3]);
    }
}
