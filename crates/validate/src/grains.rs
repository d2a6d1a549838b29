//! The embedded real grains as models and cloner parents, shared by
//! `cargo xtask calibrate` / `clone` / `dna` and the validation cases.
//!
//! Three sets of NIST/VCCTL scans are embedded (see `fixtures/grains/README.md`):
//!
//! * `vcctl/ottawa-random` — 71 Ottawa-sand grains drawn at random from NIST's
//!   whole population of 2,201: **the default parents** of `calibrate` and
//!   `clone`, because their shape statistics match the population (NIST
//!   thickness/width median 0.760, population 0.744) and so match independent
//!   scans of Ottawa sand;
//! * `vcctl/ottawa` — the first 100 ids (20001–20334), kept for the
//!   spherical-harmonic validation against NIST's table; flatter than the
//!   population (thickness/width median 0.698, ≈ 3.7 standard errors off);
//! * `vcctl/MA106A-1-fine`, `vcctl/MA107-6-fine` — crushed fine aggregates.
//!
//! Ottawa grains are evaluated at min(`Nnn`, degree in file), `Nnn` being
//! NIST's own degree from its geometry tables; grains without a table row at
//! their file's degree.

use sph_harmonics::ShModel;

use crate::error::Error;
use crate::fixtures;

/// The folder of the default parents (71 randomly drawn Ottawa grains).
pub const DEFAULT_PARENTS: &str = "vcctl/ottawa-random";

/// NIST's per-grain geometry tables of the embedded Ottawa grains.
pub const GEOM_TABLES: [&str; 2] = [
    "vcctl/Ottawa-sand-geom-shipped.txt",
    "vcctl/Ottawa-sand-geom-random.txt",
];

/// One row of a NIST geometry table (lengths in the table's units: scan
/// units / 100, volume / 10⁶, area / 10⁴).
#[derive(Debug, Clone, PartialEq)]
pub struct GeomRow {
    /// File name, e.g. `Ottawa-sand-anm-20001.dat`.
    pub file: String,
    /// Volume (table units).
    pub volume: f64,
    /// Surface area (table units).
    pub area: f64,
    /// Area over the area of the equal-volume sphere.
    pub normalised_area: f64,
    /// NIST's degree of the row.
    pub nnn: usize,
    /// Length, width, thickness (table units).
    pub ltw: [f64; 3],
    /// NIST's printed L/T and W/T.
    pub lt_wt: [f64; 2],
}

/// The rows of one NIST geometry table, in file order.
///
/// # Errors
/// [`Error::MissingFixture`], [`Error::MissingColumn`], [`Error::NotANumber`].
pub fn geom_table(name: &str) -> Result<Vec<GeomRow>, Error> {
    let text = fixtures::grain(name)?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split_whitespace().collect();
    let col = |c: &str| {
        header
            .iter()
            .position(|h| *h == c)
            .ok_or_else(|| Error::MissingColumn {
                table: name.into(),
                column: c.into(),
            })
    };
    let cols = [
        col("volume")?,
        col("surf._area")?,
        col("norm_surf_area")?,
        col("Nnn")?,
        col("length(mm)")?,
        col("width(mm)")?,
        col("thick(mm)")?,
        col("L/T")?,
        col("W/T")?,
    ];
    let names = [
        "volume",
        "surf._area",
        "norm_surf_area",
        "Nnn",
        "length(mm)",
        "width(mm)",
        "thick(mm)",
        "L/T",
        "W/T",
    ];
    let mut out = Vec::new();
    for (n, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        let mut v = [0.0; 9];
        for (k, (&c, cname)) in cols.iter().zip(names).enumerate() {
            let cell = f.get(c).copied().unwrap_or("");
            v[k] = cell.parse().map_err(|_| Error::NotANumber {
                table: name.into(),
                line: n + 2,
                column: cname.into(),
                value: cell.into(),
            })?;
        }
        out.push(GeomRow {
            file: f.first().copied().unwrap_or("").to_owned(),
            volume: v[0],
            area: v[1],
            normalised_area: v[2],
            nnn: v[3] as usize,
            ltw: [v[4], v[5], v[6]],
            lt_wt: [v[7], v[8]],
        });
    }
    Ok(out)
}

/// The row of `file` in any of the [`GEOM_TABLES`], if listed.
///
/// # Errors
/// Those of [`geom_table`].
pub fn geom_row(file: &str) -> Result<Option<GeomRow>, Error> {
    for t in GEOM_TABLES {
        if let Some(r) = geom_table(t)?.into_iter().find(|r| r.file == file) {
            return Ok(Some(r));
        }
    }
    Ok(None)
}

/// The grains of one embedded VCCTL folder `(file stem, model, degree used)`
/// in file-name order, each at min(`Nnn`, degree in file) when NIST's
/// geometry tables list it, else at the file's degree.
///
/// # Errors
/// [`Error::MissingFixture`] for an empty folder, table errors, and
/// [`Error::Computation`] for a file that does not parse.
pub fn vcctl_models(folder: &str) -> Result<Vec<(String, ShModel, usize)>, Error> {
    let mut rows = Vec::new();
    for t in GEOM_TABLES {
        rows.extend(geom_table(t)?);
    }
    let err = |e: sph_harmonics::Error| Error::Computation {
        message: e.to_string(),
    };
    let files = fixtures::grains_in(folder, ".dat");
    if files.is_empty() {
        return Err(Error::MissingFixture {
            name: format!("grains/{folder}/*.dat"),
        });
    }
    let mut out = Vec::new();
    for (name, text) in files {
        let file = name.rsplit('/').next().unwrap_or(name);
        let coeffs = sph_harmonics::vcctl::read_anm(text.as_bytes()).map_err(err)?;
        let degree = rows
            .iter()
            .find(|r| r.file == file)
            .map_or(coeffs.degree, |r| r.nnn);
        let (model, used) = coeffs.to_model(degree).map_err(err)?;
        out.push((file.trim_end_matches(".dat").to_owned(), model, used));
    }
    Ok(out)
}

/// The first 100 shipped Ottawa grains (`vcctl/ottawa`), see [`vcctl_models`].
///
/// # Errors
/// Those of [`vcctl_models`].
pub fn ottawa_models() -> Result<Vec<(String, ShModel, usize)>, Error> {
    vcctl_models("vcctl/ottawa")
}

/// Cloner parents of spherical-harmonic models: 45³ level sets over each
/// grain's bounding cube ×1.1 (`cloner::grid_from_sh`, the construction of
/// `cargo xtask dna`), measured with the default `morph_dna::MeasureParams`.
///
/// # Errors
/// [`Error::Computation`] for a grain that cannot be rasterised or measured,
/// or fewer than two grains.
pub fn parents_of_models(models: &[(String, ShModel, usize)]) -> Result<cloner::Parents, Error> {
    let err = |e: cloner::Error| Error::Computation {
        message: e.to_string(),
    };
    let grids = models
        .iter()
        .map(|(_, m, _)| cloner::grid_from_sh(m, 45, 1.1).map_err(err))
        .collect::<Result<Vec<_>, _>>()?;
    cloner::Parents::from_grids(grids, &morph_dna::MeasureParams::default()).map_err(err)
}

/// The grains of an embedded VCCTL folder as cloner parents
/// ([`vcctl_models`] then [`parents_of_models`]).
///
/// # Errors
/// Those of [`vcctl_models`] and [`parents_of_models`].
pub fn vcctl_parents(folder: &str) -> Result<cloner::Parents, Error> {
    parents_of_models(&vcctl_models(folder)?)
}

/// The default parents of `cargo xtask calibrate` and `clone`: the 71
/// randomly drawn Ottawa grains ([`DEFAULT_PARENTS`]).
///
/// # Errors
/// Those of [`vcctl_parents`].
pub fn ottawa_parents() -> Result<cloner::Parents, Error> {
    vcctl_parents(DEFAULT_PARENTS)
}
