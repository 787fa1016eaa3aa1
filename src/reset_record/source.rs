//! What reset the MCU: the reset flags' source ([`ResetSource`], `RCC_CSR`) and the kind the
//! reset log counts ([`ResetKind`]: a power-on told from a brown-out by whether RAM
//! survived).

/// What reset the MCU, from the reset flags of `RCC_CSR` (STM32G4 reference manual RM0440,
/// "RCC control/status register"). Every reset also pulses the NRST pin, so the pin flag
/// means the button (or an external reset) only when no other flag is set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResetSource {
    /// The independent watchdog (`IWDGRSTF`, bit 29).
    IndependentWatchdog,
    /// The window watchdog (`WWDGRSTF`, bit 30; not used by the firmware).
    WindowWatchdog,
    /// A software reset (`SFTRSTF`, bit 28): the panic handler's, before the watchdog runs.
    Software,
    /// Loading the option bytes (`OBLRSTF`, bit 25).
    OptionBytes,
    /// An illegal low-power entry (`LPWRRSTF`, bit 31).
    LowPower,
    /// A power-on or a brown-out (`BORRSTF`, bit 27).
    PowerOnOrBrownOut,
    /// The reset button (NRST, `PINRSTF`, bit 26) or a debugger's reset.
    Pin,
    /// No flag set (the flags were cleared and nothing reset since).
    Unknown,
}

impl ResetSource {
    /// The source named by the reset flags of `RCC_CSR`'s value `csr`, most specific
    /// first (watchdogs, software, option bytes, low power, power/brown-out, the pin).
    pub fn from_csr(csr: u32) -> Self {
        let bit = |n: u32| csr & (1 << n) != 0;
        if bit(29) {
            ResetSource::IndependentWatchdog
        } else if bit(30) {
            ResetSource::WindowWatchdog
        } else if bit(28) {
            ResetSource::Software
        } else if bit(25) {
            ResetSource::OptionBytes
        } else if bit(31) {
            ResetSource::LowPower
        } else if bit(27) {
            ResetSource::PowerOnOrBrownOut
        } else if bit(26) {
            ResetSource::Pin
        } else {
            ResetSource::Unknown
        }
    }

    /// A short name for logs.
    pub const fn name(self) -> &'static str {
        match self {
            ResetSource::IndependentWatchdog => "watchdog",
            ResetSource::WindowWatchdog => "window watchdog",
            ResetSource::Software => "software",
            ResetSource::OptionBytes => "option-byte load",
            ResetSource::LowPower => "low-power",
            ResetSource::PowerOnOrBrownOut => "power-on or brown-out",
            ResetSource::Pin => "reset button",
            ResetSource::Unknown => "unknown",
        }
    }

    /// Whether the firmware caused the reset: a watchdog (the firmware stopped petting
    /// it), a software reset (the fault path's, the set-up deadline's), an illegal
    /// low-power entry. A power-on, a brown-out, the reset button (or a debugger's reset
    /// through NRST), an option-byte load and no flag at all are someone else's: the boot
    /// block's count of failed boots in a row starts again after them
    /// (`crate::boot_block::BootHistory::of`).
    pub const fn caused_by_firmware(self) -> bool {
        matches!(
            self,
            ResetSource::IndependentWatchdog
                | ResetSource::WindowWatchdog
                | ResetSource::Software
                | ResetSource::LowPower
        )
    }
}

/// What reset the MCU, as the reset log counts it: the reset flags' source
/// ([`ResetSource`]), the power-on/brown-out flag split by whether RAM survived.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResetKind {
    /// The supply came up (the power-on/brown-out flag, RAM lost).
    PowerOn,
    /// The supply dipped below the brown-out level (the same flag, RAM kept).
    BrownOut,
    /// The reset button (NRST) or an external reset.
    Pin,
    /// A watchdog.
    Watchdog,
    /// A software reset (the fault path's before the watchdog runs, a debugger's).
    Software,
    /// Anything else (an option-byte load, an illegal low-power entry, no flag).
    Other,
}

impl ResetKind {
    /// Every kind, in the order of [`ResetKind::index`].
    pub const ALL: [ResetKind; 6] = [
        ResetKind::PowerOn,
        ResetKind::BrownOut,
        ResetKind::Pin,
        ResetKind::Watchdog,
        ResetKind::Software,
        ResetKind::Other,
    ];

    /// The kind of a reset by `source` with RAM kept or not (`ram_kept`: the boot block
    /// was valid).
    pub const fn of(source: ResetSource, ram_kept: bool) -> ResetKind {
        match source {
            ResetSource::PowerOnOrBrownOut if ram_kept => ResetKind::BrownOut,
            ResetSource::PowerOnOrBrownOut => ResetKind::PowerOn,
            ResetSource::Pin => ResetKind::Pin,
            ResetSource::IndependentWatchdog | ResetSource::WindowWatchdog => ResetKind::Watchdog,
            ResetSource::Software => ResetKind::Software,
            ResetSource::OptionBytes | ResetSource::LowPower | ResetSource::Unknown => {
                ResetKind::Other
            }
        }
    }

    /// The kind's index (0..6).
    pub const fn index(self) -> usize {
        self as usize
    }

    /// A short name for the log and the boot report.
    pub const fn name(self) -> &'static str {
        match self {
            ResetKind::PowerOn => "power-on",
            ResetKind::BrownOut => "brown-out",
            ResetKind::Pin => "reset button",
            ResetKind::Watchdog => "watchdog",
            ResetKind::Software => "software",
            ResetKind::Other => "other",
        }
    }
}
