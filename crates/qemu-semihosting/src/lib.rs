//! The two ARM semihosting calls the QEMU test programs need (`bkpt 0xAB`: SYS_WRITE0 and
//! SYS_EXIT, as the ARM semihosting specification defines them) and a [`println!`] over
//! them. Shared by `crates/core-on-m4` (the core on the Cortex-M4F) and `crates/rtt-on-m4`
//! (the logger with a stalled reader); QEMU `mps2-an386` with `-semihosting`.

#![no_std]

const SYS_WRITE0: u32 = 0x04;
const SYS_EXIT: u32 = 0x18;
const ADP_STOPPED_APPLICATION_EXIT: u32 = 0x2_0026;
const ADP_STOPPED_RUNTIME_ERROR_UNKNOWN: u32 = 0x2_0023;

fn call(op: u32, arg: u32) -> u32 {
    let r: u32;
    // SAFETY: a semihosting request traps to the debugger/QEMU; r0/r1 carry the operation
    // and the argument as the ARM semihosting specification says.
    unsafe {
        core::arch::asm!("bkpt #0xab", inout("r0") op => r, in("r1") arg, options(nostack));
    }
    r
}

/// Writes a NUL-terminated byte string to the host's stdout (nothing without the NUL).
pub fn write0(s: &[u8]) {
    if s.last() == Some(&0) {
        call(SYS_WRITE0, s.as_ptr() as u32);
    }
}

/// Exits QEMU: status 0 on success, 1 otherwise.
pub fn exit(ok: bool) -> ! {
    let reason = if ok {
        ADP_STOPPED_APPLICATION_EXIT
    } else {
        ADP_STOPPED_RUNTIME_ERROR_UNKNOWN
    };
    call(SYS_EXIT, reason);
    loop {
        cortex_m::asm::nop();
    }
}

/// Longest line [`println!`] writes [bytes, with its newline]; longer text is cut.
pub const LINE_BYTES: usize = 200;

/// A fixed buffer for one formatted line (what [`println!`] formats into).
pub struct Line {
    /// The bytes, NUL-terminated by [`Line::send`].
    pub buf: [u8; LINE_BYTES],
    /// Bytes written.
    pub len: usize,
}

impl Line {
    /// An empty line.
    pub const fn new() -> Self {
        Self {
            buf: [0; LINE_BYTES],
            len: 0,
        }
    }

    /// Ends the line with a newline and writes it to the host's stdout.
    pub fn send(mut self) {
        let _ = core::fmt::Write::write_str(&mut self, "\n");
        let end = self.len.min(LINE_BYTES - 1);
        self.buf[end] = 0;
        write0(&self.buf[..=end]);
    }
}

impl Default for Line {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Write for Line {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for &b in s.as_bytes() {
            if self.len + 1 < self.buf.len() {
                self.buf[self.len] = b;
                self.len += 1;
            }
        }
        Ok(())
    }
}

/// `println!` to the host's stdout through semihosting (one [`Line`], cut at
/// [`LINE_BYTES`]).
#[macro_export]
macro_rules! println {
    ($($arg:tt)*) => {{
        use core::fmt::Write as _;
        let mut l = $crate::Line::new();
        let _ = write!(l, $($arg)*);
        l.send();
    }};
}
