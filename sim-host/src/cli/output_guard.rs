//! The one guard against overwriting an input: a command names its inputs and every file
//! it will write, and the guard refuses before anything is written.

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
    /// path: a path that does not exist yet cannot be an input).
    ///
    /// # Errors
    /// "refusing to overwrite the input ..." naming the input.
    pub fn check_files<P: AsRef<Path>>(&self, outputs: &[P]) -> anyhow::Result<()> {
        for out in outputs {
            if let Some(input) = self.input_at(out.as_ref()) {
                anyhow::bail!("refusing to overwrite the input {}", input.display());
            }
        }
        Ok(())
    }

    /// Refuses an output folder that is an input file, then checks the `files` it will get.
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
        let o = std::fs::canonicalize(out).ok()?;
        self.inputs
            .iter()
            .find(|i| std::fs::canonicalize(i).ok().as_ref() == Some(&o))
    }
}
