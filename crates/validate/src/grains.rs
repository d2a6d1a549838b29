//! The embedded real grains as models: the 100 NIST/VCCTL Ottawa-sand grains
//! at min(`Nnn`, file degree) — NIST's own degree from its geometry table
//! (see `fixtures/grains/README.md`) — shared by `cargo xtask calibrate` and
//! the cloner's validation cases.

use sph_harmonics::ShModel;

use crate::error::Error;
use crate::fixtures;

/// NIST geometry-table degree `Nnn` by file name.
fn nnn_by_file() -> Result<Vec<(String, usize)>, Error> {
    let name = "vcctl/Ottawa-sand-geom-shipped.txt";
    let text = fixtures::grain(name)?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split_whitespace().collect();
    let col = header
        .iter()
        .position(|h| *h == "Nnn")
        .ok_or_else(|| Error::MissingColumn {
            table: name.into(),
            column: "Nnn".into(),
        })?;
    let mut out = Vec::new();
    for (n, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split('\t').map(str::trim).collect();
        let cell = f.get(col).copied().unwrap_or("");
        let v: f64 = cell.parse().map_err(|_| Error::NotANumber {
            table: name.into(),
            line: n + 2,
            column: "Nnn".into(),
            value: cell.into(),
        })?;
        out.push((f.first().copied().unwrap_or("").to_owned(), v as usize));
    }
    Ok(out)
}

/// The shipped Ottawa grains `(file stem, model, degree used)` in file-name
/// order, each at min(`Nnn`, degree in file).
///
/// # Errors
/// [`Error::MissingFixture`], table errors, and [`Error::Computation`] for a
/// file that does not parse.
pub fn ottawa_models() -> Result<Vec<(String, ShModel, usize)>, Error> {
    let nnn = nnn_by_file()?;
    let err = |e: sph_harmonics::Error| Error::Computation {
        message: e.to_string(),
    };
    let mut out = Vec::new();
    for (name, text) in fixtures::grains_in("vcctl/ottawa", ".dat") {
        let file = name.rsplit('/').next().unwrap_or(name);
        let coeffs = sph_harmonics::vcctl::read_anm(text.as_bytes()).map_err(err)?;
        let degree = nnn
            .iter()
            .find(|(g, _)| g == file)
            .map_or(coeffs.degree, |(_, d)| *d);
        let (model, used) = coeffs.to_model(degree).map_err(err)?;
        out.push((file.trim_end_matches(".dat").to_owned(), model, used));
    }
    Ok(out)
}

/// The shipped Ottawa grains as cloner parents: 45³ level sets over each
/// grain's bounding cube ×1.1 (`cloner::grid_from_sh`, the construction of
/// `cargo xtask dna`), measured with the default `morph_dna::MeasureParams`.
/// Shared by `cargo xtask calibrate`, `cargo xtask clone` and the cloner
/// validation case.
///
/// # Errors
/// Those of [`ottawa_models`], and [`Error::Computation`] for a grain that
/// cannot be rasterised or measured.
pub fn ottawa_parents() -> Result<cloner::Parents, Error> {
    let err = |e: cloner::Error| Error::Computation {
        message: e.to_string(),
    };
    let grids = ottawa_models()?
        .iter()
        .map(|(_, m, _)| cloner::grid_from_sh(m, 45, 1.1).map_err(err))
        .collect::<Result<Vec<_>, _>>()?;
    cloner::Parents::from_grids(grids, &morph_dna::MeasureParams::default()).map_err(err)
}
