//! The narrow-band redistancing of [`Redistance::Band`]: the phases of the build over
//! z-slabs ([`band_build`]), the band consistency check and the band's membership bits.

use nalgebra::{Point3, Unit, Vector3};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{OnceLock, RwLock};

use super::cube_map::CubeMap;
use super::estimate::BandSlab;
use super::far_field::Coarse;
use super::shell::Shell;
use super::{FAR, Radii, Redistance};
use crate::crew;
use crate::error::{Error, Result};
use crate::grid::GridSpec;

/// Largest `| |∇φ| − 1 |` of a band node's central differences before it leaves the band.
const EIKONAL_SLACK: f64 = 0.1;

/// The band estimates of one z-slab.
struct SlabBand {
    /// Band nodes and their values (in-slab indices).
    found: Vec<(usize, f64)>,
    /// Band membership bits of the slab.
    bits: Vec<u64>,
    /// The interior band nodes, for the consistency check.
    inner: Vec<usize>,
}

/// The narrow-band redistancing of [`Redistance::Band`], as phases over z-slabs
/// ([`crate::crew`]; on the rayon pool if `parallel`, else in order on the calling thread):
///
/// 0. cube-map rows (only for [`Radii::Calls`]); 1. the table and its shell;
/// 2. radial values per slab (into the output grid); 3. band estimates per slab
///    (second-order, else the seed's interface estimate) and the sign-change test;
/// 4. the estimates written over the radial values; 5. band consistency check per slab;
/// 6. (one item) the band and the far field; 7. assembly per slab.
///
/// Each phase reads only what earlier phases wrote, and every slab does the same arithmetic
/// in either mode, so the grid does not depend on the thread count (tested). The phases are
/// the methods of [`BandPhases`].
pub(super) fn band_build(
    spec: &GridSpec,
    centre: &Point3<f64>,
    radii: Radii<'_>,
    parallel: bool,
) -> Result<Vec<f64>> {
    let nz = spec.dims[2];
    let (premade, calls, mut values) = match radii {
        Radii::Map(map) => (Some(map), None, vec![FAR; spec.len()]),
        Radii::Calls { face_cells, radius } => {
            (None, Some((face_cells, radius)), vec![FAR; spec.len()])
        }
        // The exact table's radial values are the output grid's starting values.
        Radii::Nodes(g) => (None, None, g),
    };
    let exact = premade.is_none() && calls.is_none();
    let phases = BandPhases::new(spec, centre, premade, calls, &mut values);
    let m = phases.m;
    let counts = [
        6 * m,
        usize::from(calls.is_some()),
        if exact { 0 } else { nz },
        nz,
        nz,
        nz,
        1,
        nz,
    ];
    let work = |phase: usize, k: usize| match phase {
        0 => phases.cube_map_row(k),
        1 => phases.cube_map(),
        2 => phases.radial(k),
        3 => phases.estimate(k),
        4 => phases.write_back(k),
        5 => phases.consistency(k),
        6 => phases.far_field(),
        _ => phases.assemble(k),
    };
    crew::run_phases(&counts, parallel, &work);
    phases.finish()?;
    Ok(values)
}

/// A cube map still to tabulate: cells per face edge and the shareable radius function
/// ([`Radii::Calls`]).
type Calls<'r> = (usize, &'r (dyn Fn(Unit<Vector3<f64>>) -> f64 + Sync));

/// The state shared by the phases of [`band_build`]: the inputs, the output grid by z-slabs
/// and the phase outputs, each written once.
struct BandPhases<'a, 'r> {
    spec: &'a GridSpec,
    centre: &'a Point3<f64>,
    /// The cube map still to tabulate, if any.
    calls: Option<Calls<'r>>,
    /// Nodes per face edge of that cube map (0 without one).
    m: usize,
    /// Phase 0: the face rows of the cube map.
    rows: Vec<OnceLock<Vec<f64>>>,
    /// Phase 1 (or given): the radial shell, or the error of an invalid radius.
    shell: OnceLock<Result<Shell>>,
    /// Phase 3: the band estimates per slab.
    bands: Vec<OnceLock<SlabBand>>,
    /// Phase 3: whether some slab holds a sign change.
    crossed: AtomicBool,
    /// Phase 5: the band nodes that leave the band, per slab.
    demoted: Vec<OnceLock<Vec<usize>>>,
    /// Phase 6: the band and the far field, or why there is none.
    field: OnceLock<Result<(Band, Coarse)>>,
    est: BandSlab,
    /// The output grid, by z-slabs.
    out: Vec<RwLock<&'a mut [f64]>>,
    /// The band bits of a slab without band estimates.
    no_bits: Vec<u64>,
}

impl<'a, 'r> BandPhases<'a, 'r> {
    /// The phase state over the output grid `values` (radial values of the exact table, else
    /// far markers), with the shell of a `premade` table or the `calls` to tabulate one.
    fn new(
        spec: &'a GridSpec,
        centre: &'a Point3<f64>,
        premade: Option<CubeMap>,
        calls: Option<Calls<'r>>,
        values: &'a mut [f64],
    ) -> Self {
        let [nx, ny, nz] = spec.dims;
        let plane = nx * ny;
        let m = calls.map_or(0, |(n, _)| n + 1);
        // Phase outputs, each written once.
        let rows: Vec<OnceLock<Vec<f64>>> = (0..6 * m).map(|_| OnceLock::new()).collect();
        let shell: OnceLock<Result<Shell>> = OnceLock::new();
        if let Some(map) = premade {
            let _ = shell.set(Ok(Shell::new(spec, centre, map, Redistance::Band)));
        }
        let bands: Vec<OnceLock<SlabBand>> = (0..nz).map(|_| OnceLock::new()).collect();
        let demoted: Vec<OnceLock<Vec<usize>>> = (0..nz).map(|_| OnceLock::new()).collect();
        Self {
            spec,
            centre,
            calls,
            m,
            rows,
            shell,
            bands,
            crossed: AtomicBool::new(false),
            demoted,
            field: OnceLock::new(),
            est: BandSlab::new(spec, centre),
            out: values.chunks_mut(plane).map(RwLock::new).collect(),
            no_bits: vec![0u64; plane.div_ceil(64)],
        }
    }

    /// Whether the radii are valid so far (no table yet, or a valid one).
    fn radii_valid(&self) -> bool {
        matches!(self.shell.get(), Some(Ok(_)) | None)
    }

    /// Phase 0: the radii of face row `k` of the cube map.
    fn cube_map_row(&self, k: usize) {
        if let Some((n, radius)) = self.calls {
            let m = self.m;
            let (f, q) = (k / m, k % m);
            let row = (0..m)
                .map(|p| radius(CubeMap::direction(n, f, p, q)))
                .collect();
            let _ = self.rows[k].set(row);
        }
    }

    /// Phase 1: the cube map from its rows (validated) and its shell.
    fn cube_map(&self) {
        if let Some((n, _)) = self.calls {
            let map = CubeMap::from_rows(n, &self.rows);
            let _ = self
                .shell
                .set(map.map(|map| Shell::new(self.spec, self.centre, map, Redistance::Band)));
        }
    }

    /// Phase 2: the radial values of slab `k`, into the output grid.
    fn radial(&self, k: usize) {
        if let (Some(Ok(shell)), Ok(mut dst)) = (self.shell.get(), self.out[k].write()) {
            shell.fill(k, &mut dst);
        }
    }

    /// Phase 3: the band estimates of slab `k` and the sign-change test.
    fn estimate(&self, k: usize) {
        if !self.radii_valid() {
            // Invalid radii (reported from the shell).
            return;
        }
        let [nx, ny, _] = self.spec.dims;
        let plane = nx * ny;
        let out = &self.out;
        let Ok(mid) = out[k].read() else { return };
        let up = out.get(k + 1).and_then(|s| s.read().ok());
        let mut found = Vec::new();
        if k > 0
            && let (Ok(lo), Some(up)) = (out[k - 1].read(), &up)
        {
            self.est.estimates(k, [&lo, &mid, up], &mut found);
        }
        // The sign-change test stops once one slab has found a change.
        if !self.crossed.load(Ordering::Relaxed)
            && slab_crosses(nx, &mid, up.as_deref().map(|u| &**u))
        {
            self.crossed.store(true, Ordering::Relaxed);
        }
        let mut bits = vec![0u64; plane.div_ceil(64)];
        let mut inner = Vec::new();
        for &(c, d) in &found {
            bits[c / 64] |= 1 << (c % 64);
            if d < 0.0 {
                inner.push(c);
            }
        }
        let _ = self.bands[k].set(SlabBand { found, bits, inner });
    }

    /// Phase 4: the estimates of slab `k` written over its radial values.
    fn write_back(&self, k: usize) {
        if let (Some(b), Ok(mut dst)) = (self.bands[k].get(), self.out[k].write()) {
            for &(c, d) in &b.found {
                dst[c] = d;
            }
        }
    }

    /// Phase 5: the band consistency check of slab `k` ([`consistency`]).
    fn consistency(&self, k: usize) {
        let Some(b) = self.bands[k].get() else { return };
        if b.inner.is_empty() {
            let _ = self.demoted[k].set(Vec::new());
            return;
        }
        // Band nodes are interior nodes: slabs k ± 1 exist.
        let bits = |k: usize| {
            self.bands[k]
                .get()
                .map_or(&self.no_bits[..], |b| &b.bits[..])
        };
        let out = &self.out;
        let (Ok(gl), Ok(gm), Ok(gu)) = (out[k - 1].read(), out[k].read(), out[k + 1].read()) else {
            return;
        };
        let d = consistency(
            self.spec.dims[0],
            self.spec.spacing,
            [&gl, &gm, &gu],
            [bits(k - 1), &b.bits, bits(k + 1)],
            &b.inner,
        );
        let _ = self.demoted[k].set(d);
    }

    /// Phase 6 (one item): the band of the whole grid and the far field
    /// ([`Coarse::interior`]); [`Error::NoSurface`] if no slab holds a sign change.
    fn far_field(&self) {
        if !self.radii_valid() {
            return;
        }
        if !self.crossed.load(Ordering::Relaxed) {
            let _ = self.field.set(Err(Error::NoSurface));
            return;
        }
        let spec = self.spec;
        let [nx, ny, nz] = spec.dims;
        let plane = nx * ny;
        let mut band = Band(vec![0; spec.len().div_ceil(64)]);
        for (k, b) in self.bands.iter().enumerate() {
            let Some(b) = b.get() else { return };
            for &(c, _) in &b.found {
                band.set(plane * k + c, true);
            }
            for &c in self.demoted[k].get().map_or(&[][..], Vec::as_slice) {
                band.set(plane * k + c, false);
            }
        }
        let guards: Vec<_> = self.out.iter().filter_map(|s| s.read().ok()).collect();
        let slabs: Vec<&[f64]> = guards.iter().map(|g| &***g).collect();
        if slabs.len() == nz {
            let _ = self
                .field
                .set(Coarse::interior(spec, &slabs, &band).map(|c| (band, c)));
        }
    }

    /// Phase 7: the final values of slab `k` ([`Coarse::assemble_slab`]).
    fn assemble(&self, k: usize) {
        if let (Some(Ok((band, coarse))), Ok(mut dst)) = (self.field.get(), self.out[k].write()) {
            // Demoted band nodes lost their radial value; −∞ (sign only, no bound) keeps
            // the suspect band value from clamping the far field that replaces it.
            for &c in self.demoted[k].get().map_or(&[][..], Vec::as_slice) {
                dst[c] = f64::NEG_INFINITY;
            }
            coarse.assemble_slab(self.spec, k, &mut dst, band);
        }
    }

    /// The outcome of the phases: the error of an invalid radius, else the far field's.
    fn finish(self) -> Result<()> {
        if let Some(Err(e)) = self.shell.into_inner() {
            return Err(e);
        }
        match self.field.into_inner() {
            Some(Ok(_)) => Ok(()),
            Some(Err(e)) => Err(e),
            // Only after invalid radii, reported above.
            None => Err(Error::NoSurface),
        }
    }
}

/// Whether the radial field changes sign between neighbouring nodes of slab `mid` (rows of
/// `nx`) or between `mid` and the next slab `up`.
fn slab_crosses(nx: usize, mid: &[f64], up: Option<&[f64]>) -> bool {
    let neg = |v: f64| v < 0.0;
    let within = mid
        .chunks_exact(nx)
        .any(|r| r.windows(2).any(|w| neg(w[0]) != neg(w[1])))
        || mid.iter().zip(&mid[nx..]).any(|(&a, &b)| neg(a) != neg(b));
    within || up.is_some_and(|up| mid.iter().zip(up).any(|(&a, &b)| neg(a) != neg(b)))
}

/// Consistency check of one slab's interior band nodes `inner` (in-slab indices; values
/// and band bits of the slabs below, at and above): near a ridge of the distance (the medial
/// axis, which reaches the surface at convex kinks of r), the expansion can err without its
/// guards noticing; there the band values break |∇φ| = 1. A node whose six neighbours are
/// interior band nodes and whose central-difference gradient norm is off by more than
/// EIKONAL_SLACK leaves the band (one pass, on the values before the pass) and takes the far
/// field. Nodes next to the surface stay (their far-field value would be poor); outside,
/// the far field is only a bound, so exterior band values are kept. Returns the nodes that
/// leave.
fn consistency(
    nx: usize,
    h: f64,
    [lo, mid, up]: [&[f64]; 3],
    [blo, bmid, bup]: [&[u64]; 3],
    inner: &[usize],
) -> Vec<usize> {
    let has = |b: &[u64], c: usize| b[c / 64] >> (c % 64) & 1 == 1;
    let (lo2, hi2) = (
        (1.0 - EIKONAL_SLACK).powi(2) * 4.0 * h * h,
        (1.0 + EIKONAL_SLACK).powi(2) * 4.0 * h * h,
    );
    let sy = nx;
    let mut demote = Vec::new();
    for &c in inner {
        let ok = [c - 1, c + 1, c - sy, c + sy]
            .iter()
            .all(|&q| has(bmid, q) && mid[q] < 0.0)
            && has(blo, c)
            && lo[c] < 0.0
            && has(bup, c)
            && up[c] < 0.0;
        if !ok {
            continue;
        }
        let gx = mid[c + 1] - mid[c - 1];
        let gy = mid[c + sy] - mid[c - sy];
        let gz = up[c] - lo[c];
        let n2 = gx * gx + gy * gy + gz * gz;
        if n2 > hi2 || n2 < lo2 {
            demote.push(c);
        }
    }
    demote
}

/// Membership bits of the band nodes (one bit per node).
pub(super) struct Band(Vec<u64>);

impl Band {
    #[inline]
    pub(super) fn has(&self, c: usize) -> bool {
        self.0[c / 64] >> (c % 64) & 1 == 1
    }
    #[inline]
    fn set(&mut self, c: usize, on: bool) {
        let (w, b) = (c / 64, c % 64);
        self.0[w] = (self.0[w] & !(1 << b)) | (u64::from(on) << b);
    }
}
