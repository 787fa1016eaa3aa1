//! The two semihosting calls this program needs (ARM semihosting, `bkpt 0xAB`) and a
//! `println!` over them (as `crates/core-on-m4`).

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

/// Write a NUL-terminated byte string to the host's stdout.
pub fn write0(s: &[u8]) {
    if s.last() == Some(&0) {
        call(SYS_WRITE0, s.as_ptr() as u32);
    }
}

/// Exit QEMU: status 0 on success, 1 otherwise.
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

/// Fixed buffer for one formatted line.
pub struct Line {
    pub buf: [u8; 200],
    pub len: usize,
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

/// `println!` to the host's stdout through semihosting.
macro_rules! println {
    ($($arg:tt)*) => {{
        use core::fmt::Write as _;
        let mut l = $crate::semihosting::Line { buf: [0; 200], len: 0 };
        let _ = write!(l, $($arg)*);
        let _ = l.write_str("\n");
        l.buf[l.len] = 0;
        $crate::semihosting::write0(&l.buf[..=l.len]);
    }};
}
