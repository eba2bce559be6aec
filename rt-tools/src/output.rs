//! The files a run writes, checked before the work and written as a set.
//!
//! [`Outputs::check`] runs before anything is rendered: each file's folder
//! (or the nearest existing folder above it) must take a new file, and the
//! file must not be a folder — so an impossible `--out` fails in
//! milliseconds, not after the render. A missing folder is created when
//! its first file is written, and said on stderr. Files are then
//! written under hidden staging names beside their targets
//! ([`Outputs::staging`]) and renamed into place together by
//! [`Outputs::commit`]; a run that fails part-way removes what it staged,
//! so a set from an earlier run is never left half replaced.

use std::{
    fs,
    path::{Path, PathBuf},
};

use anyhow::{Context, bail};

/// The files of one run.
#[derive(Debug)]
pub struct Outputs {
    /// `(target, staging)` pairs.
    files: Vec<(PathBuf, PathBuf)>,
    committed: bool,
}

/// Makes the folder `dir` if it is missing, and says so on stderr (a run
/// that writes a folder of files of its own, as `rt demo` does).
///
/// # Errors
/// `dir` cannot be made, or is a file.
pub fn make_folder(dir: &Path) -> anyhow::Result<()> {
    if !dir.exists() {
        fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
        eprintln!("rt: created folder {}", dir.display());
    } else if !dir.is_dir() {
        bail!("{}: is not a folder", dir.display());
    }
    Ok(())
}

impl Outputs {
    /// Refuses an `--out` that names a folder, for a run whose files are
    /// named after it (`<stem>-reference.png`, …) rather than written to it.
    ///
    /// # Errors
    /// `out` is a folder.
    pub fn refuse_folder(out: &Path) -> anyhow::Result<()> {
        if out.is_dir() {
            bail!(
                "{}: is a folder; give a file name (e.g. {})",
                out.display(),
                out.join("image.png").display()
            );
        }
        Ok(())
    }

    /// Checks that every path in `targets` can be written.
    ///
    /// # Errors
    /// A path that is a folder, a folder that cannot be created or is a
    /// file, or a folder that does not take a new file (read-only, no
    /// permission): one line naming it.
    pub fn check(targets: &[PathBuf]) -> anyhow::Result<Self> {
        let mut probed: Vec<PathBuf> = Vec::new();
        let mut files = Vec::with_capacity(targets.len());
        for target in targets {
            Self::refuse_folder(target)?;
            let name = target
                .file_name()
                .with_context(|| format!("{}: not a file name", target.display()))?;
            let dir = match target.parent().filter(|d| !d.as_os_str().is_empty()) {
                Some(d) => d.to_path_buf(),
                None => PathBuf::from("."),
            };
            // The folder, or the nearest one above it that exists (the
            // rest is created when the first file is staged): a folder
            // that takes a new file.
            let existing = dir.ancestors().find(|d| d.exists()).unwrap_or(Path::new("."));
            if !existing.is_dir() {
                bail!("{}: is not a folder", existing.display());
            }
            if !probed.iter().any(|p| p == existing) {
                let probe = existing.join(format!(".rt-probe-{}", std::process::id()));
                fs::write(&probe, b"").with_context(|| {
                    format!("{}: cannot write in this folder", existing.display())
                })?;
                let _ = fs::remove_file(&probe);
                probed.push(existing.to_path_buf());
            }
            let staging = dir.join(format!(".{}.rt-partial", name.to_string_lossy()));
            files.push((target.clone(), staging));
        }
        Ok(Self { files, committed: false })
    }

    /// Where to write `target` (one of the checked paths) until the set is
    /// committed.
    ///
    /// # Panics
    /// If `target` was not checked (a programming error).
    #[must_use]
    pub fn staging(&self, target: &Path) -> PathBuf {
        let staging =
            self.files.iter().find(|(t, _)| t == target).map(|(_, s)| s.clone()).unwrap_or_else(
                || panic!("{} was not among the checked outputs", target.display()),
            );
        // A missing folder is made now (the work is done), and said; if
        // that fails, writing the file says why.
        if let Some(dir) = staging.parent().filter(|d| !d.as_os_str().is_empty() && !d.exists())
            && fs::create_dir_all(dir).is_ok()
        {
            eprintln!("rt: created folder {}", dir.display());
        }
        staging
    }

    /// Moves every staged file into place.
    ///
    /// # Errors
    /// A staged file missing (not written) or a rename refused.
    pub fn commit(mut self) -> anyhow::Result<()> {
        for (target, staging) in &self.files {
            fs::rename(staging, target).with_context(|| target.display().to_string())?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for Outputs {
    /// An uncommitted set leaves nothing behind.
    fn drop(&mut self) {
        if !self.committed {
            for (_, staging) in &self.files {
                let _ = fs::remove_file(staging);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rt-outputs-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn a_set_appears_whole_or_not_at_all() {
        let dir = scratch("set");
        let (a, b) = (dir.join("new/a.png"), dir.join("new/b.raw"));
        fs::create_dir_all(&dir).unwrap();
        let outs = Outputs::check(&[a.clone(), b.clone()]).unwrap();
        assert!(!dir.join("new").exists(), "no folder before there is a file to write");
        fs::write(outs.staging(&a), b"a").unwrap();
        assert!(dir.join("new").is_dir(), "the missing folder is created");
        fs::write(outs.staging(&b), b"b").unwrap();
        assert!(!a.exists() && !b.exists(), "nothing in place before the commit");
        outs.commit().unwrap();
        assert_eq!(fs::read(&a).unwrap(), b"a");
        // A second run that fails after writing one file: the first set
        // stays as it was, and no staging file is left.
        let outs = Outputs::check(&[a.clone(), b.clone()]).unwrap();
        fs::write(outs.staging(&a), b"A").unwrap();
        drop(outs);
        assert_eq!(fs::read(&a).unwrap(), b"a");
        let left: Vec<_> = fs::read_dir(dir.join("new")).unwrap().collect();
        assert_eq!(left.len(), 2, "{left:?}");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn impossible_outputs_fail_before_the_work() {
        let dir = scratch("bad");
        fs::create_dir_all(dir.join("folder")).unwrap();
        fs::write(dir.join("file"), b"").unwrap();
        let e = Outputs::check(&[dir.join("folder")]).unwrap_err().to_string();
        assert!(e.contains("is a folder"), "{e}");
        let e = Outputs::check(&[dir.join("file/x.png")]).unwrap_err();
        assert!(format!("{e:#}").contains("file"), "{e:#}");
        fs::remove_dir_all(&dir).unwrap();
    }
}
