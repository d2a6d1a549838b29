//! The staging folder that makes the files of a specimen atomic (the
//! writers of every format are `specimen::outputs` and `specimen::dem`).
//!
//! Every file is written into a hidden staging folder beside `out_dir`;
//! only when every stage has succeeded are the files renamed into
//! `out_dir`. On an error the staging folder is removed and `out_dir` is
//! left as it was (not even created).

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::Context;

/// A hidden folder beside `out_dir` collecting the run's files.
pub(crate) struct Staging {
    dir: PathBuf,
    files: Mutex<Vec<PathBuf>>,
    committed: bool,
}

static STAGING_COUNTER: AtomicU64 = AtomicU64::new(0);

impl Staging {
    /// A fresh staging folder for `out_dir`.
    pub(crate) fn new(out_dir: &Path) -> anyhow::Result<Self> {
        let name = out_dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "specimen".into());
        let parent = out_dir
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let dir = parent.join(format!(
            ".{name}.staging-{}-{}",
            std::process::id(),
            STAGING_COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self {
            dir,
            files: Mutex::new(Vec::new()),
            committed: false,
        })
    }

    /// The staged path of `rel` (its folder created).
    pub(crate) fn path(&self, rel: &str) -> anyhow::Result<PathBuf> {
        let p = self.dir.join(rel);
        if let Some(d) = p.parent() {
            std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
        }
        if let Ok(mut f) = self.files.lock() {
            f.push(PathBuf::from(rel));
        }
        Ok(p)
    }

    /// Stages `bytes` as `rel` (a path relative to `out_dir`).
    pub(crate) fn write(&self, rel: &str, bytes: &[u8]) -> anyhow::Result<()> {
        let p = self.path(rel)?;
        std::fs::write(&p, bytes).with_context(|| format!("writing {}", p.display()))
    }

    /// Stages a relative symbolic link `rel → target` (`target` relative to `rel`'s folder).
    pub(crate) fn link(&self, rel: &str, target: &str) -> anyhow::Result<()> {
        let p = self.path(rel)?;
        std::os::unix::fs::symlink(target, &p)
            .with_context(|| format!("linking {} to {target}", p.display()))
    }

    /// Moves every staged file into `out_dir` (renames within one file
    /// system; a staged folder such as `lsdem/` replaces the one already
    /// there) and returns their paths relative to `out_dir`, sorted.
    pub(crate) fn commit(mut self, out_dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
        let mut files = self.files.lock().map(|f| f.clone()).unwrap_or_default();
        files.sort();
        files.dedup();
        // an output folder of this run replaces the one of an earlier run
        // (no stale grain files beside the new ones)
        let mut folders: Vec<PathBuf> = files
            .iter()
            .filter(|f| f.components().count() > 1)
            .filter_map(|f| f.components().next().map(|c| PathBuf::from(c.as_os_str())))
            .collect();
        folders.dedup();
        for d in folders {
            let old = out_dir.join(d);
            if old.is_dir() {
                std::fs::remove_dir_all(&old)
                    .with_context(|| format!("replacing {}", old.display()))?;
            }
        }
        for rel in &files {
            let to = out_dir.join(rel);
            if let Some(d) = to.parent() {
                std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
            }
            std::fs::rename(self.dir.join(rel), &to)
                .with_context(|| format!("moving {} into place", to.display()))?;
        }
        self.committed = true;
        let _ = std::fs::remove_dir_all(&self.dir);
        Ok(files)
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}
