//! `cargo xtask validate`: run the reference cases, print the table, write a
//! report directory on request, exit non-zero on failure.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;

/// Flags of `cargo xtask validate`.
#[derive(Debug, Args)]
pub(crate) struct Validate {
    /// Run only the cases whose name contains this pattern (or one of
    /// several, comma-separated).
    #[arg(long)]
    filter: Option<String>,
    /// Write `validate.md` and `validate.csv` into this directory.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Run only the fast subset (what `cargo test` runs).
    #[arg(long)]
    fast: bool,
    /// Also run the heavy cases (tens of minutes on 2 cores, e.g.
    /// `specimen/scale`; not part of CI).
    #[arg(long)]
    heavy: bool,
    /// Print only the summary and the failing rows.
    #[arg(long)]
    quiet: bool,
}

impl Validate {
    pub(crate) fn run(self) -> anyhow::Result<()> {
        let options = validate::RunOptions {
            filter: self.filter.clone(),
            fast_only: self.fast,
            heavy: self.heavy,
        };
        let start = Instant::now();
        let report = validate::run(
            &validate::registry(),
            &validate::expected_failures(),
            &options,
        );
        let elapsed = start.elapsed();
        let markdown = report.to_markdown();
        if self.quiet {
            for row in report.rows.iter().filter(|r| r.status.is_failure()) {
                println!(
                    "{} | {} | ref {} | ours {} | {} | {} | {}",
                    row.case,
                    row.metric,
                    row.reference,
                    row.ours,
                    row.tolerance,
                    row.status.label(),
                    row.note
                );
            }
            println!("{}", markdown.lines().last().unwrap_or_default());
        } else {
            println!("{markdown}");
        }
        println!("validation took {:.2} s", elapsed.as_secs_f64());
        if let Some(dir) = &self.report {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            let md = dir.join("validate.md");
            std::fs::write(&md, &markdown).with_context(|| format!("writing {}", md.display()))?;
            let csv = dir.join("validate.csv");
            let file = std::fs::File::create(&csv)
                .with_context(|| format!("creating {}", csv.display()))?;
            report
                .write_csv(std::io::BufWriter::new(file))
                .with_context(|| format!("writing {}", csv.display()))?;
            println!("report written to {}", dir.display());
        }
        match report.verdict() {
            Ok(_) => Ok(()),
            Err(err) => bail!(err),
        }
    }
}
