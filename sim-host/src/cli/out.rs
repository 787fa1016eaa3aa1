//! What every command writes through: standard output whose write errors are marked
//! ([`stdout`]; text a crew reads wrapped at [`LINE_WIDTH`]: [`text`]), a file written atomically when asked ([`write_out`]), and SIGINT/SIGTERM as
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
/// What is written goes out as it is (JSON, CSV); text a crew reads goes through [`text`].
pub fn stdout() -> Stdout {
    Stdout(std::io::stdout().lock())
}

/// [`stdout`] for text a crew reads: every line longer than [`LINE_WIDTH`] characters is
/// wrapped ([`wrap`]), a list one item a line.
pub fn text() -> Wrapped<Stdout> {
    Wrapped {
        out: stdout(),
        line: Vec::new(),
    }
}

/// The longest line the text outputs print.
pub const LINE_WIDTH: usize = 160;

/// `line` as the lines a reader gets, none longer than [`LINE_WIDTH`] characters (a line
/// that fits is kept whole): a list (items joined by `"; "`) one item a line, any part still
/// too long broken at its last space that fits, each following line indented by the
/// line's own indent and four spaces more.
pub fn wrap(line: &str) -> Vec<String> {
    if line.chars().count() <= LINE_WIDTH {
        return vec![line.to_string()];
    }
    let lead = line.len() - line.trim_start().len();
    let more = format!("{}    ", &line[..lead]);
    let mut out: Vec<String> = Vec::new();
    let items: Vec<&str> = line.split_inclusive("; ").collect();
    for (k, item) in items.iter().enumerate() {
        let item = if k + 1 < items.len() {
            item.trim_end()
        } else {
            item
        };
        let mut rest = if k == 0 { item } else { item.trim_start() };
        let mut prefix = if k == 0 { "" } else { more.as_str() };
        loop {
            let room = LINE_WIDTH.saturating_sub(prefix.chars().count()).max(20);
            if rest.chars().count() <= room {
                out.push(format!("{prefix}{rest}"));
                break;
            }
            // The byte index of the `room`-th character, and the last space before it.
            let end = rest.char_indices().nth(room).map_or(rest.len(), |(i, _)| i);
            let cut = rest[..end]
                .rfind(' ')
                .filter(|&i| i > end / 4)
                .unwrap_or(end);
            out.push(format!("{prefix}{}", rest[..cut].trim_end()));
            rest = rest[cut..].trim_start();
            prefix = more.as_str();
        }
    }
    out
}

/// A writer whose lines are [`wrap`]ped: it holds the line being written until its end.
pub struct Wrapped<W: std::io::Write> {
    out: W,
    line: Vec<u8>,
}

impl<W: std::io::Write> Wrapped<W> {
    /// Writes the line held, wrapped, and `end` after it.
    fn emit(&mut self, end: &[u8]) -> std::io::Result<()> {
        let line = String::from_utf8_lossy(&self.line).into_owned();
        self.line.clear();
        let lines = wrap(&line);
        let n = lines.len();
        for (k, l) in lines.into_iter().enumerate() {
            self.out.write_all(l.as_bytes())?;
            if k + 1 < n {
                self.out.write_all(b"\n")?;
            }
        }
        self.out.write_all(end)
    }
}

impl<W: std::io::Write> std::io::Write for Wrapped<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let mut rest = buf;
        while let Some(k) = rest.iter().position(|b| *b == b'\n') {
            self.line.extend_from_slice(&rest[..k]);
            self.emit(b"\n")?;
            rest = &rest[k + 1..];
        }
        self.line.extend_from_slice(rest);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if !self.line.is_empty() {
            self.emit(b"")?;
        }
        self.out.flush()
    }
}

impl<W: std::io::Write> Drop for Wrapped<W> {
    fn drop(&mut self) {
        let _ = std::io::Write::flush(self);
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_wraps_a_list_one_item_a_line_and_a_short_one_stays() {
        assert_eq!(wrap("verdict: healthy"), ["verdict: healthy"]);
        let items: Vec<String> = (0..8)
            .map(|k| format!("item {k} {}", "x".repeat(25)))
            .collect();
        let line = format!("  verdict: {}", items.join("; "));
        let lines = wrap(&line);
        assert!(
            lines.iter().all(|l| l.chars().count() <= LINE_WIDTH),
            "{lines:#?}"
        );
        assert_eq!(lines.len(), 8, "{lines:#?}");
        assert!(lines[1].starts_with("      item 1"), "{lines:#?}");
        let words = format!("model's error: {}", "word ".repeat(80));
        let lines = wrap(&words);
        assert!(lines.len() > 2 && lines.iter().all(|l| l.chars().count() <= LINE_WIDTH));
        // Nothing lost but the spaces the breaks took.
        let back: String = lines.iter().map(|l| l.trim()).collect::<Vec<_>>().join(" ");
        assert_eq!(
            back.split_whitespace().count(),
            words.split_whitespace().count()
        );
    }
}
