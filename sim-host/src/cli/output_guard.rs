//! The one guard against overwriting an input: a command names its inputs and every file
//! it will write, and the guard refuses before anything is written.
//!
//! Two paths are the same file when their canonical paths are equal (this catches `..`,
//! `./` and symbolic links) or, when both exist, when they have the same device and inode
//! (this catches hard links too, which no path comparison can). An output that does not
//! exist yet cannot be an input.
//!
//! What the commands write, for their callers:
//! - `simulate`: `--out` (through a temporary file beside it with a random name, which is
//!   created exclusively and so can never be an existing file);
//! - `compare` / `explain` with `--plot DIR` or `--report DIR`: each chart of
//!   `render::charts::COMPARE` or `EXPLAIN` as `<stem>.svg` and `<stem>.png`
//!   (`render::charts::file_names`), plus `render::html::REPORT_FILE` for `--report`,
//!   checked with [`OutputGuard::check_folder`]. Their temporary files, too, get random
//!   names created exclusively.

use std::path::{Path, PathBuf};

/// The inputs of a command.
pub struct OutputGuard {
    inputs: Vec<PathBuf>,
}

impl OutputGuard {
    /// A guard for these input files.
    pub fn new(inputs: &[&Path]) -> Self {
        OutputGuard {
            inputs: inputs.iter().map(|p| p.to_path_buf()).collect(),
        }
    }

    /// Refuses when an output file is one of the inputs (the same file by its canonical
    /// path, or by device and inode: a symbolic or hard link to an input is refused).
    ///
    /// # Errors
    /// "refusing to overwrite the input ..." naming the input and the output.
    pub fn check_files<P: AsRef<Path>>(&self, outputs: &[P]) -> anyhow::Result<()> {
        for out in outputs {
            let out = out.as_ref();
            if let Some(input) = self.input_at(out) {
                if same_path(input, out) {
                    anyhow::bail!("refusing to overwrite the input {}", input.display());
                }
                anyhow::bail!(
                    "refusing to overwrite the input {}: the output {} is the same file",
                    input.display(),
                    out.display()
                );
            }
        }
        Ok(())
    }

    /// Refuses a parameter-file output that is an input, or that exists without `force`
    /// (a parameter file may have been tuned by hand: it is kept unless asked).
    ///
    /// # Errors
    /// As [`OutputGuard::check_files`], or "... exists: refusing to overwrite it".
    pub fn check_new_file(&self, out: &Path, force: bool) -> anyhow::Result<()> {
        self.check_files(&[out])?;
        if out.exists() && !force {
            anyhow::bail!(
                "{} exists: refusing to overwrite it (give --force, or another --out)",
                out.display()
            );
        }
        Ok(())
    }

    /// Refuses an output folder that is an input file, then checks the `files` it will get
    /// (names relative to `dir`).
    ///
    /// # Errors
    /// As [`OutputGuard::check_files`], or "output folder ... is an input file".
    pub fn check_folder(&self, dir: &Path, files: &[String]) -> anyhow::Result<()> {
        if self.input_at(dir).is_some() {
            anyhow::bail!("output folder {} is an input file", dir.display());
        }
        let paths: Vec<PathBuf> = files.iter().map(|f| dir.join(f)).collect();
        self.check_files(&paths)
    }

    fn input_at(&self, out: &Path) -> Option<&PathBuf> {
        self.inputs.iter().find(|i| same_file(i, out))
    }
}

/// Whether `a` and `b` are the same existing file: equal canonical paths, or (Unix) equal
/// device and inode numbers. False when either does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ca), Ok(cb)) = (std::fs::canonicalize(a), std::fs::canonicalize(b)) else {
        return false;
    };
    if ca == cb {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(&ca), std::fs::metadata(&cb)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    false
}

/// Whether `a` and `b` name the file by the same canonical path (not through a link).
fn same_path(a: &Path, b: &Path) -> bool {
    matches!(
        (std::fs::canonicalize(a), std::fs::canonicalize(b)),
        (Ok(x), Ok(y)) if x == y
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup() -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().expect("tmp");
        let log = dir.path().join("run.csv");
        std::fs::write(&log, "t_s,ia_A,ib_A,ic_A\n0,1,2,-3\n").expect("write");
        (dir, log)
    }

    #[test]
    fn the_same_file_by_any_name_is_refused() {
        let (dir, log) = setup();
        let guard = OutputGuard::new(&[&log]);
        // Itself, by another spelling.
        let dotted = dir.path().join(".").join("run.csv");
        assert!(guard.check_files(&[&dotted]).is_err());
        // A hard link: another path, the same inode.
        let hard = dir.path().join("hard.csv");
        std::fs::hard_link(&log, &hard).expect("hard link");
        let e = guard.check_files(&[&hard]).unwrap_err().to_string();
        assert!(e.contains("run.csv") && e.contains("hard.csv"), "{e}");
        // A symbolic link.
        #[cfg(unix)]
        {
            let soft = dir.path().join("soft.csv");
            std::os::unix::fs::symlink(&log, &soft).expect("symlink");
            assert!(guard.check_files(&[&soft]).is_err());
        }
        // A new file, and an existing file that is not an input, are fine.
        let other = dir.path().join("other.csv");
        guard.check_files(&[&other]).expect("new file");
        std::fs::write(&other, "x").expect("write");
        guard.check_files(&[&other]).expect("not an input");
    }

    #[test]
    fn every_chart_and_the_report_are_checked_in_the_folder() {
        let (dir, log) = setup();
        let plots = dir.path().join("plots");
        std::fs::create_dir(&plots).expect("mkdir");
        let guard = OutputGuard::new(&[&log]);
        let stems = super::super::render::charts::COMPARE;
        let mut files = super::super::render::charts::file_names(&stems);
        files.push(super::super::render::html::REPORT_FILE.to_string());
        guard
            .check_folder(&plots, &files)
            .expect("no input in the folder");
        // The log hard-linked under the last chart's PNG name, then as the report page.
        for name in [
            format!("{}.png", stems[stems.len() - 1]),
            "report.html".into(),
        ] {
            let link = plots.join(&name);
            std::fs::hard_link(&log, &link).expect("hard link");
            let e = guard.check_folder(&plots, &files).unwrap_err().to_string();
            assert!(e.contains(&name) && !e.contains('\n'), "{e}");
            std::fs::remove_file(&link).expect("rm");
        }
        // The folder itself may not be an input file.
        assert!(guard.check_folder(&log, &files).is_err());
    }
}
