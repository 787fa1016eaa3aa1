//! The one guard against overwriting an input, for every front end (the command line, the
//! Python package, the fleet run): a call names its inputs and every file it will write,
//! and [`check_outputs`] refuses before anything is written.
//!
//! Two paths are the same file ([`same_file`]) when their canonical paths are equal (this
//! catches `..`, `./` and symbolic links) or, when both exist, when they have the same
//! device and inode (this catches hard links too, which no path comparison can). An output
//! that does not exist yet cannot be an input.

use std::path::{Path, PathBuf};

/// A file a call reads or writes, and the field that names it in the library's words
/// (`params`, `scenario`, `out`, `store`; empty where the caller's messages name files by
/// their paths alone, as the command line's do).
#[derive(Debug, Clone, Copy)]
pub struct NamedFile<'a> {
    /// The field (`params`, `out`, ...), or empty.
    pub field: &'a str,
    /// The file's path, as the caller gave it.
    pub path: &'a Path,
}

impl<'a> NamedFile<'a> {
    /// The file at `path`, named by `field` (`""` for none).
    pub fn new(field: &'a str, path: &'a Path) -> Self {
        NamedFile { field, path }
    }

    /// The file at `path`, named by its path alone.
    pub fn path(path: &'a Path) -> Self {
        NamedFile { field: "", path }
    }
}

/// An output that is one of the call's inputs; nothing was written. One line, naming both
/// files (and their fields, where the caller named them).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OverwriteError {
    /// An output file is an input file (the same path, or a link to it).
    #[error("{}", self.message())]
    Input {
        /// The input's path, as given.
        input: String,
        /// The input's field (`scenario`, `params`, ...), or empty.
        input_field: String,
        /// The output's path, as given.
        output: String,
        /// The output's field (`out`, `store`, ...), or empty.
        output_field: String,
        /// True when the output is the input under another canonical path (a hard
        /// link); false for the same canonical path (`./`, `..`, a symbolic link).
        by_link: bool,
    },
    /// An output folder is an input file.
    #[error("{}", self.message())]
    FolderIsInput {
        /// The folder's path, as given.
        dir: String,
        /// The folder's field (`plot`, `report`, ...), or empty.
        dir_field: String,
    },
}

impl OverwriteError {
    /// The one-line message: the paths alone where no field was given ("refusing to
    /// overwrite the input run.csv"), else the fields too.
    fn message(&self) -> String {
        match self {
            OverwriteError::Input {
                input,
                input_field,
                output,
                output_field,
                by_link,
            } => {
                if input_field.is_empty() && output_field.is_empty() {
                    if *by_link {
                        format!(
                            "refusing to overwrite the input {input}: the output {output} is the same file"
                        )
                    } else {
                        format!("refusing to overwrite the input {input}")
                    }
                } else {
                    let input_field = if input_field.is_empty() {
                        String::new()
                    } else {
                        format!(" (the {input_field})")
                    };
                    let output_field = if output_field.is_empty() {
                        "the output".to_string()
                    } else {
                        format!("{output_field} =")
                    };
                    format!(
                        "refusing to overwrite the input {input}{input_field}: {output_field} {output} is the same file; give another path"
                    )
                }
            }
            OverwriteError::FolderIsInput { dir, dir_field } => {
                if dir_field.is_empty() {
                    format!("output folder {dir} is an input file")
                } else {
                    format!("output folder {dir_field} = {dir} is an input file")
                }
            }
        }
    }
}

/// Refuses when any of `outputs` is one of `inputs` (the same file by its canonical path,
/// or by device and inode: a symbolic or hard link to an input is refused). Nothing is
/// written or created; outputs that do not exist yet always pass.
///
/// # Errors
/// [`OverwriteError::Input`] naming the first such input and output.
pub fn check_outputs(
    inputs: &[NamedFile<'_>],
    outputs: &[NamedFile<'_>],
) -> Result<(), OverwriteError> {
    for out in outputs {
        if let Some(input) = inputs.iter().find(|i| same_file(i.path, out.path)) {
            return Err(OverwriteError::Input {
                input: input.path.display().to_string(),
                input_field: input.field.to_string(),
                output: out.path.display().to_string(),
                output_field: out.field.to_string(),
                by_link: !same_path(input.path, out.path),
            });
        }
    }
    Ok(())
}

/// Refuses an output folder that is an input file, then checks the `files` it will get
/// (names relative to `dir.path`) as [`check_outputs`] does.
///
/// # Errors
/// [`OverwriteError::FolderIsInput`]; as [`check_outputs`].
pub fn check_output_folder(
    inputs: &[NamedFile<'_>],
    dir: NamedFile<'_>,
    files: &[String],
) -> Result<(), OverwriteError> {
    if inputs.iter().any(|i| same_file(i.path, dir.path)) {
        return Err(OverwriteError::FolderIsInput {
            dir: dir.path.display().to_string(),
            dir_field: dir.field.to_string(),
        });
    }
    let paths: Vec<PathBuf> = files.iter().map(|f| dir.path.join(f)).collect();
    let outputs: Vec<NamedFile<'_>> = paths.iter().map(|p| NamedFile::new(dir.field, p)).collect();
    check_outputs(inputs, &outputs)
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

/// Whether `a` and `b` name the file by the same canonical path (a hard link has its
/// own).
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
        let inputs = [NamedFile::new("log", &log)];
        let out = |p: &Path| check_outputs(&inputs, &[NamedFile::new("out", p)]);
        // Itself, by another spelling.
        let dotted = dir.path().join(".").join("run.csv");
        let e = out(&dotted).unwrap_err().to_string();
        assert!(e.contains("(the log)") && e.contains("out = "), "{e}");
        // A hard link: another path, the same inode.
        let hard = dir.path().join("hard.csv");
        std::fs::hard_link(&log, &hard).expect("hard link");
        let e = out(&hard).unwrap_err().to_string();
        assert!(
            e.contains("run.csv") && e.contains("hard.csv") && !e.contains('\n'),
            "{e}"
        );
        // A symbolic link.
        #[cfg(unix)]
        {
            let soft = dir.path().join("soft.csv");
            std::os::unix::fs::symlink(&log, &soft).expect("symlink");
            let e = out(&soft).unwrap_err().to_string();
            assert!(e.contains("soft.csv") && e.contains("(the log)"), "{e}");
        }
        // A new file, and an existing file that is not an input, are fine.
        let other = dir.path().join("other.csv");
        out(&other).expect("new file");
        std::fs::write(&other, "x").expect("write");
        out(&other).expect("not an input");
    }

    #[test]
    fn without_fields_the_message_names_the_paths_alone() {
        let (dir, log) = setup();
        let inputs = [NamedFile::path(&log)];
        let e = check_outputs(&inputs, &[NamedFile::path(&log)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("refusing to overwrite the input {}", log.display())
        );
        let hard = dir.path().join("hard.csv");
        std::fs::hard_link(&log, &hard).expect("hard link");
        let e = check_outputs(&inputs, &[NamedFile::path(&hard)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "refusing to overwrite the input {}: the output {} is the same file",
                log.display(),
                hard.display()
            )
        );
        let e = check_output_folder(&inputs, NamedFile::path(&log), &[]).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("output folder {} is an input file", log.display())
        );
    }

    #[test]
    fn a_folders_files_are_checked() {
        let (dir, log) = setup();
        let inputs = [NamedFile::path(&log)];
        let files = vec!["a.svg".to_string(), "report.html".to_string()];
        let folder = NamedFile::new("report", dir.path());
        check_output_folder(&inputs, NamedFile::path(&dir.path().join("new")), &files)
            .expect("a new folder");
        check_output_folder(&inputs, folder, &files).expect("no input in it");
        std::fs::hard_link(&log, dir.path().join("report.html")).expect("hard link");
        let e = check_output_folder(&inputs, folder, &files)
            .unwrap_err()
            .to_string();
        assert!(e.contains("report.html") && e.contains("report ="), "{e}");
    }
}
