//! `cargo xtask specimen-check DIR`: what a DEM deck of `dem.rs` left in `DIR` (`lammps/`,
//! `yade/` or `liggghts/` of a specimen) against what it started from, by one measure for
//! the three codes: `initial.dump` and `final.dump` (LAMMPS dump text or plain rows, columns
//! `id body x y z radius`) and `settle.txt` (bodies, spheres, d50, container: written by
//! `cargo xtask specimen`).
//!
//! - no atom or body lost: as many spheres and bodies at the end as written;
//! - the largest overlap of two spheres of different bodies at the end ≤ 1 % of d50;
//! - the solid fraction of the settled specimen within 0.01 of the packed one, both measured
//!   the same way: the share of a lattice (spacing d50/12) inside any sphere, in the core of
//!   the initial specimen (one d50 from the walls and the floor, and three d50 below the
//!   initial top of the bed, so that the bed's settlement does not empty the region).
//!
//! The deck itself checks the kinetic energy (it stops with an error above its limit). Lost
//! atoms and overlaps fail the check; the solid-fraction change fails it with `--strict`
//! and is reported otherwise (measured on the 200-clone example in LAMMPS: 0.613 → 0.628:
//! the packer's specimens are not in mechanical equilibrium — grains float with gaps of a
//! few percent of d50 between layers and the bed settles by up to half a d50 at the top).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::Args;
use nalgebra::Point3;

/// Flags of `cargo xtask specimen-check`.
#[derive(Debug, Args)]
pub(crate) struct SpecimenCheck {
    /// A deck folder after its run (`target/specimen/clumps/lammps`).
    dir: PathBuf,
    /// Also fail when the solid fraction changed by more than 0.01 (by default it is
    /// reported: the packed specimens are not yet in mechanical equilibrium and compact
    /// under gravity, see the README).
    #[arg(long)]
    strict: bool,
}

/// A sphere of a dump: body, centre, radius.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ball {
    pub(crate) body: u64,
    pub(crate) c: Point3<f64>,
    pub(crate) r: f64,
}

/// What `settle.txt` says.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Expect {
    pub(crate) bodies: usize,
    pub(crate) spheres: usize,
    pub(crate) d50: f64,
    /// Cylinder (`[cx, cy, r, z0, h]`) or box (`[x0, y0, z0, x1, y1, z1]` in `bbox`).
    pub(crate) cylinder: Option<[f64; 5]>,
    pub(crate) bbox: [f64; 6],
}

impl SpecimenCheck {
    pub(crate) fn run(self, _root: &Path) -> anyhow::Result<()> {
        let read = |name: &str| -> anyhow::Result<String> {
            let p = self.dir.join(name);
            std::fs::read_to_string(&p).with_context(|| format!("reading {}", p.display()))
        };
        let expect = parse_settle(&read("settle.txt")?)?;
        let initial = parse_dump(&read("initial.dump")?)?;
        let fin = parse_dump(&read("final.dump")?)?;
        let r = compare(&expect, &initial, &fin)?;
        println!(
            "specimen-check {}: bodies {} of {}, spheres {} of {}; largest overlap between bodies {:.3e} d50 (limit 0.01); core solid fraction packed {:.4}, settled {:.4} (|change| {:.4}, limit 0.01)",
            self.dir.display(),
            r.bodies,
            expect.bodies,
            r.spheres,
            expect.spheres,
            r.worst_overlap,
            r.fraction_before,
            r.fraction_after,
            (r.fraction_after - r.fraction_before).abs()
        );
        let mut bad = Vec::new();
        if r.bodies != expect.bodies || r.spheres != expect.spheres {
            bad.push("atoms or bodies were lost");
        }
        if r.worst_overlap > 0.01 {
            bad.push("an overlap exceeds 1 % of d50");
        }
        if (r.fraction_after - r.fraction_before).abs() > 0.01 {
            if self.strict {
                bad.push("the solid fraction changed by more than 0.01");
            } else {
                println!(
                    "specimen-check: NOT MET: the solid fraction changed by more than 0.01 (the packing compacted under gravity; --strict fails on it)"
                );
            }
        }
        if !bad.is_empty() {
            bail!("specimen-check failed: {}", bad.join("; "));
        }
        Ok(())
    }
}

/// The measured numbers.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Comparison {
    pub(crate) bodies: usize,
    pub(crate) spheres: usize,
    pub(crate) worst_overlap: f64,
    pub(crate) fraction_before: f64,
    pub(crate) fraction_after: f64,
}

/// Compares a final state with the initial one.
pub(crate) fn compare(e: &Expect, initial: &[Ball], fin: &[Ball]) -> anyhow::Result<Comparison> {
    let mut bodies: Vec<u64> = fin.iter().map(|b| b.body).collect();
    bodies.sort_unstable();
    bodies.dedup();
    // the core region of the initial specimen
    let top = initial
        .iter()
        .map(|b| b.c.z + b.r)
        .fold(f64::NEG_INFINITY, f64::max);
    let d = e.d50;
    let (z0, z1) = match e.cylinder {
        Some([_, _, _, z0, _]) => (z0 + d, top - 3.0 * d),
        None => (e.bbox[2] + d, top - 3.0 * d),
    };
    if z1 <= z0 {
        bail!("the specimen is too shallow for a core region (bed {top:e} m, d50 {d:e} m)");
    }
    let inside = |p: &Point3<f64>| match e.cylinder {
        Some([cx, cy, r, _, _]) => ((p.x - cx).powi(2) + (p.y - cy).powi(2)).sqrt() <= r - d,
        None => {
            p.x >= e.bbox[0] + d
                && p.x <= e.bbox[3] - d
                && p.y >= e.bbox[1] + d
                && p.y <= e.bbox[4] - d
        }
    };
    let fraction = |balls: &[Ball]| -> f64 {
        let grid = Cells::new(balls);
        let h = d / 12.0;
        let (x0, y0, x1, y1) = match e.cylinder {
            Some([cx, cy, r, _, _]) => (cx - r, cy - r, cx + r, cy + r),
            None => (e.bbox[0], e.bbox[1], e.bbox[3], e.bbox[4]),
        };
        let (mut hit, mut all) = (0usize, 0usize);
        let mut z = z0 + 0.5 * h;
        while z < z1 {
            let mut y = y0 + 0.5 * h;
            while y < y1 {
                let mut x = x0 + 0.5 * h;
                while x < x1 {
                    let p = Point3::new(x, y, z);
                    if inside(&p) {
                        all += 1;
                        if grid.covers(&p) {
                            hit += 1;
                        }
                    }
                    x += h;
                }
                y += h;
            }
            z += h;
        }
        hit as f64 / all.max(1) as f64
    };
    Ok(Comparison {
        bodies: bodies.len(),
        spheres: fin.len(),
        worst_overlap: Cells::new(fin).worst_overlap() / d,
        fraction_before: fraction(initial),
        fraction_after: fraction(fin),
    })
}

/// A uniform cell grid of spheres (cell = the largest diameter).
struct Cells<'a> {
    balls: &'a [Ball],
    cell: f64,
    map: BTreeMap<[i64; 3], Vec<usize>>,
}

impl<'a> Cells<'a> {
    fn new(balls: &'a [Ball]) -> Self {
        let cell = 2.0 * balls.iter().map(|b| b.r).fold(0.0, f64::max).max(1e-30);
        let mut map: BTreeMap<[i64; 3], Vec<usize>> = BTreeMap::new();
        for (i, b) in balls.iter().enumerate() {
            map.entry(Self::key_of(cell, &b.c)).or_default().push(i);
        }
        Self { balls, cell, map }
    }

    fn key_of(cell: f64, p: &Point3<f64>) -> [i64; 3] {
        [
            (p.x / cell).floor() as i64,
            (p.y / cell).floor() as i64,
            (p.z / cell).floor() as i64,
        ]
    }

    fn near(&self, p: &Point3<f64>) -> impl Iterator<Item = usize> + '_ {
        let k = Self::key_of(self.cell, p);
        (-1..=1).flat_map(move |dz| {
            (-1..=1).flat_map(move |dy| {
                (-1..=1).flat_map(move |dx| {
                    self.map
                        .get(&[k[0] + dx, k[1] + dy, k[2] + dz])
                        .into_iter()
                        .flatten()
                        .copied()
                })
            })
        })
    }

    fn covers(&self, p: &Point3<f64>) -> bool {
        self.near(p)
            .any(|i| (self.balls[i].c - p).norm_squared() <= self.balls[i].r.powi(2))
    }

    fn worst_overlap(&self) -> f64 {
        let mut worst = 0.0f64;
        for (i, a) in self.balls.iter().enumerate() {
            for j in self.near(&a.c) {
                let b = &self.balls[j];
                if j > i && b.body != a.body {
                    worst = worst.max(a.r + b.r - (a.c - b.c).norm());
                }
            }
        }
        worst
    }
}

/// Rows `id body x y z radius` of a LAMMPS/LIGGGHTS dump (`ITEM:` lines skipped) or of a
/// plain text file (`#` comments skipped).
pub(crate) fn parse_dump(text: &str) -> anyhow::Result<Vec<Ball>> {
    let mut out = Vec::new();
    let mut in_atoms = !text.contains("ITEM:");
    for (k, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.starts_with("ITEM:") {
            in_atoms = l.starts_with("ITEM: ATOMS");
            continue;
        }
        if !in_atoms || l.is_empty() || l.starts_with('#') {
            continue;
        }
        let v: Vec<f64> = l
            .split_whitespace()
            .map(str::parse::<f64>)
            .collect::<Result<_, _>>()
            .with_context(|| format!("line {}: not numbers", k + 1))?;
        if v.len() < 6 || v.iter().any(|x| !x.is_finite()) {
            bail!("line {}: expected `id body x y z radius`", k + 1);
        }
        out.push(Ball {
            body: v[1] as u64,
            c: Point3::new(v[2], v[3], v[4]),
            r: v[5],
        });
    }
    if out.is_empty() {
        bail!("no sphere rows");
    }
    Ok(out)
}

/// `settle.txt`: `key value…` lines.
pub(crate) fn parse_settle(text: &str) -> anyhow::Result<Expect> {
    let mut kv: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let mut it = line.split_whitespace();
        if let Some(k) = it.next() {
            let v = it
                .map(str::parse::<f64>)
                .collect::<Result<Vec<_>, _>>()
                .with_context(|| format!("settle.txt: `{k}`"))?;
            kv.insert(k, v);
        }
    }
    let one = |k: &str| -> anyhow::Result<f64> {
        kv.get(k)
            .and_then(|v| v.first().copied())
            .ok_or_else(|| anyhow::anyhow!("settle.txt: no `{k}`"))
    };
    let bbox: [f64; 6] = kv
        .get("box")
        .cloned()
        .unwrap_or_default()
        .try_into()
        .map_err(|_| anyhow::anyhow!("settle.txt: `box` needs 6 numbers"))?;
    let cylinder = match kv.get("cylinder") {
        Some(v) => Some(
            <[f64; 5]>::try_from(v.clone())
                .map_err(|_| anyhow::anyhow!("settle.txt: `cylinder` needs 5 numbers"))?,
        ),
        None => None,
    };
    Ok(Expect {
        bodies: one("bodies")? as usize,
        spheres: one("spheres")? as usize,
        d50: one("d50")?,
        cylinder,
        bbox,
    })
}

/// `settle.txt` of a deck folder.
pub(crate) fn settle_text(
    bodies: usize,
    spheres: usize,
    d50: f64,
    container: &packer_spheres::Container,
) -> String {
    let (lo, hi) = container.bbox();
    let mut s = format!(
        "# what cargo xtask specimen-check compares a settled deck with (SI)\nbodies {bodies}\nspheres {spheres}\nd50 {d50:e}\nbox {:e} {:e} {:e} {:e} {:e} {:e}\n",
        lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
    );
    if let packer_spheres::Container::Cylinder {
        base,
        radius,
        height,
    } = container
    {
        s.push_str(&format!(
            "cylinder {:e} {:e} {:e} {:e} {:e}\n",
            base.x, base.y, radius, base.z, height
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlaps_and_fractions_are_measured() {
        let e = parse_settle("bodies 3\nspheres 4\nd50 1\nbox 0 0 0 10 10 10\n").expect("settle");
        // two bodies low in the box (body 1 of two overlapping spheres), a third high up
        // setting the top of the bed (core region z in [1, 6])
        let a = vec![
            Ball {
                body: 1,
                c: Point3::new(5.0, 5.0, 2.0),
                r: 1.0,
            },
            Ball {
                body: 1,
                c: Point3::new(5.5, 5.0, 2.0),
                r: 1.0,
            },
            Ball {
                body: 2,
                c: Point3::new(7.0, 5.0, 2.0),
                r: 1.0,
            },
            Ball {
                body: 3,
                c: Point3::new(5.0, 5.0, 8.0),
                r: 1.0,
            },
        ];
        let r = compare(&e, &a, &a).expect("compare");
        assert!((r.worst_overlap - 0.5).abs() < 1e-12, "{r:?}");
        assert_eq!(r.bodies, 3);
        assert!(r.fraction_before > 0.0 && r.fraction_before == r.fraction_after);
        let dump = "ITEM: TIMESTEP\n1\nITEM: ATOMS id mol x y z radius\n1 1 0 0 0 1\n2 2 3 0 0 1\n";
        assert_eq!(parse_dump(dump).expect("dump").len(), 2);
        assert!(parse_dump("1 2 3\n").is_err());
        assert!(parse_settle("bodies x\n").is_err());
    }
}
