//! The command line's side of the one guard against overwriting an input: a command names
//! its inputs and every file it will write, and the guard refuses before anything is
//! written. The test itself (the same file by canonical path, or by device and inode, so
//! that `..`, `./`, symbolic and hard links are all caught) is the library's,
//! `monitor_api::files::check_outputs`, which the Python package and the fleet run call
//! too; this adds the command line's own refusal of an existing parameter file without
//! `--force`.
//!
//! What the commands write, for their callers:
//! - `simulate`: `--out` (through a temporary file beside it with a random name, which is
//!   created exclusively and so can never be an existing file);
//! - `compare` / `explain` with `--plot DIR` or `--report DIR`: each chart of
//!   `render::charts::COMPARE` or `EXPLAIN` as `<stem>.svg` and `<stem>.png`
//!   (`render::charts::file_names`), plus `render::html::REPORT_FILE` for `--report`,
//!   checked with [`OutputGuard::check_folder`]. Their temporary files, too, get random
//!   names created exclusively.

use monitor_api::files::{check_output_folder, check_outputs, NamedFile};
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

    /// The inputs as the library's guard takes them: named by their paths alone.
    fn named(&self) -> Vec<NamedFile<'_>> {
        self.inputs.iter().map(|p| NamedFile::path(p)).collect()
    }

    /// Refuses when an output file is one of the inputs (the same file by its canonical
    /// path, or by device and inode: a symbolic or hard link to an input is refused), by
    /// the library's one guard (`monitor_api::files::check_outputs`).
    ///
    /// # Errors
    /// "refusing to overwrite the input ..." naming the input (and the output, when it is
    /// a hard link to it).
    pub fn check_files<P: AsRef<Path>>(&self, outputs: &[P]) -> anyhow::Result<()> {
        let outputs: Vec<NamedFile<'_>> = outputs
            .iter()
            .map(|o| NamedFile::path(o.as_ref()))
            .collect();
        Ok(check_outputs(&self.named(), &outputs)?)
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
        Ok(check_output_folder(
            &self.named(),
            NamedFile::path(dir),
            files,
        )?)
    }
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
