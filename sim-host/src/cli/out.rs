//! What every command writes through: standard output whose write errors are marked
//! ([`stdout`]), a file written atomically when asked ([`write_out`]), and SIGINT/SIGTERM as
//! a flag a long loop checks ([`Interruption`]) with the error it ends in ([`Interrupted`]).

/// Writes `bytes` to `out` atomically when an output was asked for (`--out`); nothing
/// otherwise.
///
/// # Errors
/// "writing PATH" with the I/O error.
pub fn write_out(out: Option<&std::path::Path>, bytes: &[u8]) -> anyhow::Result<()> {
    if let Some(out) = out {
        anyhow::Context::with_context(monitor_api::files::write_atomic(out, bytes), || {
            format!("writing {}", out.display())
        })?;
    }
    Ok(())
}

/// Standard output for the renderers: locked, and every write error marked as a
/// [`StdoutError`] (kept as the `io::Error`'s inner error, its kind unchanged), so that
/// `main` can tell a closed pipe (quiet exit) or a full disk on stdout from other errors.
pub fn stdout() -> Stdout {
    Stdout(std::io::stdout().lock())
}

/// Locked standard output whose write errors are [`StdoutError`]s ([`stdout`]).
pub struct Stdout(std::io::StdoutLock<'static>);

/// A write to standard output failed (the reader closed the pipe, the disk is full, ...).
#[derive(Debug, thiserror::Error)]
#[error("cannot write to standard output: {0}")]
pub struct StdoutError(std::io::Error);

impl Stdout {
    fn mark(e: std::io::Error) -> std::io::Error {
        std::io::Error::new(e.kind(), StdoutError(e))
    }
}

impl std::io::Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf).map_err(Self::mark)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush().map_err(Self::mark)
    }
}

/// The kind of the stdout write error in `e`'s chain ([`StdoutError`]), if any.
pub fn stdout_error_kind(e: &anyhow::Error) -> Option<std::io::ErrorKind> {
    e.chain().find_map(|c| {
        let io = c.downcast_ref::<std::io::Error>()?;
        io.get_ref()?.downcast_ref::<StdoutError>()?;
        Some(io.kind())
    })
}

/// A command stopped by SIGINT or SIGTERM after removing its partial output.
#[derive(Debug, thiserror::Error)]
#[error("interrupted by {signal_name}: {what}")]
pub struct Interrupted {
    /// The signal's number.
    pub signal: i32,
    /// "SIGINT" or "SIGTERM".
    pub signal_name: &'static str,
    /// What was done about the output, e.g. "no output written, temporary file removed".
    pub what: String,
}

impl Interrupted {
    /// The shell's convention: 128 + the signal number (130 for SIGINT, 143 for SIGTERM).
    pub fn exit_status(&self) -> u8 {
        u8::try_from(128 + self.signal).unwrap_or(1)
    }
}

/// SIGINT and SIGTERM as a flag a long loop checks ([`Interruption::signal`]), from
/// [`Interruption::catch`] to the end of the process.
///
/// Only the commands that clean up or report on a signal catch it (`simulate` and
/// `convert` around their write loops, `diagnose` around its replay); every other
/// command keeps the default action (the process ends at once; its outputs are written
/// atomically at the end, so it leaves at most a small temporary file).
/// A second signal while the first is being handled ends the process at once with
/// 128 + the signal, as the default action would.
pub struct Interruption {
    /// The signal that arrived, 0 for none.
    signal: std::sync::Arc<std::sync::atomic::AtomicUsize>,
}

impl Interruption {
    /// Starts catching SIGINT and SIGTERM. (There is no way back to the default action:
    /// catch only where the rest of the command checks [`Interruption::signal`].)
    ///
    /// # Errors
    /// The handlers could not be installed.
    pub fn catch() -> anyhow::Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use signal_hook::flag;
        use std::sync::atomic::{AtomicBool, AtomicUsize};
        use std::sync::Arc;
        let armed = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for sig in [SIGINT, SIGTERM] {
            // The order matters: the shutdown sees the flag as the previous signal left it.
            flag::register_conditional_shutdown(sig, 128 + sig, Arc::clone(&armed))?;
            flag::register(sig, Arc::clone(&armed))?;
            flag::register_usize(sig, Arc::clone(&signal), sig.unsigned_abs() as usize)?;
        }
        Ok(Interruption { signal })
    }

    /// Whether SIGINT or SIGTERM has arrived (one atomic load: cheap enough for every row).
    pub fn caught(&self) -> bool {
        self.signal.load(std::sync::atomic::Ordering::Relaxed) != 0
    }

    /// The signal caught so far, if any, as an [`Interrupted`] error saying `what` was done.
    pub fn signal(&self, what: &str) -> Option<Interrupted> {
        use signal_hook::consts::SIGINT;
        let sig = self.signal.load(std::sync::atomic::Ordering::SeqCst);
        let signal = i32::try_from(sig).ok().filter(|s| *s != 0)?;
        Some(Interrupted {
            signal,
            signal_name: if signal == SIGINT {
                "SIGINT"
            } else {
                "SIGTERM"
            },
            what: what.to_string(),
        })
    }
}
