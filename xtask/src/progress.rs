//! Progress bars (indicatif) and atomic file writes shared by the tasks.
//!
//! A bar shows position, rate and ETA on a terminal; when stderr is not a
//! terminal (CI logs, pipes) indicatif draws nothing, and `--quiet` hides it
//! everywhere. Files are written to a temporary name beside the target and
//! renamed, so an interrupted or failed run never leaves a half-written file.

use std::path::Path;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar of `total` steps labelled `label` (hidden under `quiet` or off a terminal).
pub(crate) fn bar(label: &str, total: u64, quiet: bool) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(
        Some(total),
        if quiet {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        },
    );
    if let Ok(style) =
        ProgressStyle::with_template("  {msg:<40} [{bar:30}] {pos}/{len} {per_sec:>10} ETA {eta}")
    {
        pb.set_style(style.progress_chars("#>-"));
    }
    pb.set_message(label.to_owned());
    pb
}

/// A cloner progress callback driving `pb`.
pub(crate) fn clone_callback(pb: &ProgressBar) -> impl Fn(cloner::Progress) + Sync + '_ {
    move |p: cloner::Progress| {
        pb.set_length(p.total);
        pb.set_position(p.done);
        if p.done == p.total {
            pb.finish();
        }
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder and
/// a rename (nothing half-written on failure); creates the parent folder.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&tmp, bytes).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| {
        let _ = std::fs::remove_file(&tmp);
        format!("renaming {} to {}", tmp.display(), path.display())
    })
}

/// A spinner labelled `label` for a stage without steps (hidden under
/// `quiet` or off a terminal).
pub(crate) fn spinner(label: &str, quiet: bool) -> ProgressBar {
    let pb = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new_spinner()
    };
    pb.set_message(label.to_owned());
    pb.enable_steady_tick(std::time::Duration::from_millis(200));
    pb
}
