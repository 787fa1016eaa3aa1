//! The firmware's status line: its one format, its writer and its parser, shared by the
//! board (which writes it with defmt) and the host (whose HMI reads it,
//! `cargo fw-run | sim-host hmi --stdin`).
//!
//! The line's fields are documented once, in docs/firmware.md ("The status line"). One
//! line, as defmt's decoder prints it:
//!
//! ```text
//! r=[r1, r2, r3, r4] lamps=[b1, b2, b3, b4] fault=B call=CALL top=NAME(P) 2nd=NAME(P)
//! wm=Xrad/s zc_locked=.. mode=MODE run=ID:LEARNED/NEEDED overruns=N restarts=N samples=N
//! max_cyc=N iqs=XA ids=XA vqs=XV f=XHz steady=B eval=B sens=B,B,B mid=[..] half=[..]
//! iso=NAME iso_change=X iso_p=P wind=PHASE wind_i2=X moved=B rise=XK vdda=XV bor=N
//! clip=N enc_rej=N stack=NB clip_range=B
//! ```
//!
//! - **The format** is one literal ([`FORMAT`]) with its arguments, the fields of a
//!   [`StatusLine`], in one macro of this module: the board's writer
//!   ([`StatusLine::log_info`], with the `defmt` feature the firmware turns on) and the
//!   host's ([`StatusLine`]'s `Display`, the text defmt's decoder prints) both expand it, so
//!   they cannot disagree.
//! - **The parser** ([`parse`]) finds the `key=` fields anywhere in a line, so the decoder's
//!   decorations (a timestamp, the level, the location, on the same or the next line) do not
//!   matter; a line is a status line when it has `r=[..]`, `lamps=[..]` and `fault=`. Fields
//!   an older firmware does not print are `None` ([`StatusReading`]). Terminal colours are
//!   the reader's to take out first.

mod read;

pub use read::{parse, StatusReading};

#[cfg(doc)]
use crate::{verdict::Verdict, Fault, Phase};

/// The format literal and the arguments of the status line, handed to the macro `$then`
/// (the board's defmt call, the host's text, or the literal alone): the one place the
/// line's fields and their order are written. `$s` is the [`StatusLine`] written.
macro_rules! with_status_line {
    ($then:ident, $s:ident) => {
        $then!(
            "r={} lamps={} fault={=bool} call={=str} top={=str}({=f32}) 2nd={=str}({=f32}) wm={=f32}rad/s zc_locked={} mode={=str} run={=u16}:{=u32}/{=u32} overruns={=u32} restarts={=u32} samples={=u32} max_cyc={=u32} iqs={=f32}A ids={=f32}A vqs={=f32}V f={=f32}Hz steady={=bool} eval={=bool} sens={=bool},{=bool},{=bool} mid={} half={} iso={=str} iso_change={=f32} iso_p={=f32} wind={=str} wind_i2={=f32} moved={=bool} rise={=f32}K vdda={=f32}V bor={=u8} clip={=u32} enc_rej={=u32} stack={=u32}B clip_range={=bool}",
            $s.residuals,
            $s.lamps,
            $s.fault,
            $s.call,
            $s.top.0,
            $s.top.1,
            $s.second.0,
            $s.second.1,
            $s.speed_rad_s,
            $s.zero_crossing_locked,
            $s.mode,
            $s.run.0,
            $s.run.1,
            $s.run.2,
            $s.overruns,
            $s.restarts,
            $s.samples,
            $s.max_update_cycles,
            $s.iqs_a,
            $s.ids_a,
            $s.vqs_v,
            $s.frame_hz,
            $s.quasi_steady,
            $s.evaluating,
            $s.sensors.0,
            $s.sensors.1,
            $s.sensors.2,
            $s.mid,
            $s.half,
            $s.isolation.0,
            $s.isolation.1,
            $s.isolation.2,
            $s.winding.0,
            $s.winding.1,
            $s.moved,
            $s.winding_rise_k,
            $s.vdda_v,
            $s.bor,
            $s.clipped,
            $s.encoder_rejects,
            $s.stack_used_bytes,
            $s.clip_range
        )
    };
}

/// The literal of a [`with_status_line`] expansion, its arguments dropped unevaluated.
macro_rules! format_only {
    ($format:literal, $($arg:expr),*) => {
        $format
    };
}

/// The status line's format string, as the firmware's defmt call has it (`{=f32}`,
/// `{}` ...): what docs/firmware.md documents field by field.
pub const FORMAT: &str = with_status_line!(format_only, unused);

/// One status line's values, as the firmware writes them every panel period.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StatusLine<'a> {
    /// `r=`: the normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// `lamps=`: the residual lamps r1..r4 as the core decided them.
    pub lamps: [bool; 4],
    /// `fault=`: the core detected a fault (a lamp or a sensor fault).
    pub fault: bool,
    /// `call=`: the decision table's verdict ([`Verdict::name`]).
    pub call: &'a str,
    /// `top=`: the most probable lamp-pattern candidate's name ([`Fault::name`] or `none`)
    /// and its probability.
    pub top: (&'a str, f32),
    /// `2nd=`: the second candidate, as `top`.
    pub second: (&'a str, f32),
    /// `wm=`: the shaft speed [rad/s].
    pub speed_rad_s: f32,
    /// `zc_locked=`: the zero-crossing detector's lock (`None` with other angle sources).
    pub zero_crossing_locked: Option<bool>,
    /// `mode=`: the panel's mode (`commissioned`, `not-commissioned`, `commissioning`,
    /// `sampling-stalled`, `failed`).
    pub mode: &'a str,
    /// `run=`: the latest commissioning run's id, evaluated blocks learned and needed.
    pub run: (u16, u32, u32),
    /// `overruns=`: the ADC DMA overruns since boot.
    pub overruns: u32,
    /// `restarts=`: the sampling restarts since boot.
    pub restarts: u32,
    /// `samples=`: the samples processed since boot (wrapping).
    pub samples: u32,
    /// `max_cyc=`: the longest `Monitor::update` [CPU cycles].
    pub max_update_cycles: u32,
    /// `iqs=`: I_qs [A].
    pub iqs_a: f32,
    /// `ids=`: i_ds [A].
    pub ids_a: f32,
    /// `vqs=`: V_qs [V].
    pub vqs_v: f32,
    /// `f=`: the frame (supply) frequency [Hz].
    pub frame_hz: f32,
    /// `steady=`: the quasi-steady gate is open.
    pub quasi_steady: bool,
    /// `eval=`: the lamps are being evaluated.
    pub evaluating: bool,
    /// `sens=`: the sensor faults flagged: current, voltage, speed.
    pub sensors: (bool, bool, bool),
    /// `mid=`: the threshold bands' centres, r1..r4.
    pub mid: [f32; 4],
    /// `half=`: the threshold bands' half-widths, r1..r4.
    pub half: [f32; 4],
    /// `iso=`, `iso_change=`, `iso_p=`: the fault the isolation names ([`Fault::name`],
    /// `b/bl`, `unknown`, `none` or `not-judged`), its relative change and its probability.
    pub isolation: (&'a str, f32, f32),
    /// `wind=`, `wind_i2=`: the phase of shorted turns ([`Phase::name`] or `none`) and the
    /// winding's part of |I2/I1|.
    pub winding: (&'a str, f32),
    /// `moved=`: the operating point has left the commissioned range.
    pub moved: bool,
    /// `rise=`: the winding temperature rise since commissioning the isolation tracks [K].
    pub winding_rise_k: f32,
    /// `vdda=`: the latest VDDA [V] (0 before the first reading or when unreadable).
    pub vdda_v: f32,
    /// `bor=`: the brown-out reset level (255: a reserved value).
    pub bor: u8,
    /// `clip=`: samples since boot with a conversion at the front end's linear limit
    /// (held out of the residuals, no sensor named; the board's per-conversion clip check).
    pub clipped: u32,
    /// `enc_rej=`: latched encoder counts since boot rejected as a step beyond the
    /// maximum speed (a glitch, not motion).
    pub encoder_rejects: u32,
    /// `stack=`: the stack's high-water mark since boot [bytes] (the painted stack).
    pub stack_used_bytes: u32,
    /// `clip_range=`: clipping persists in steady running, so the front end's linear range
    /// is too small for this motor (the board's range state; its verdict could not judge).
    pub clip_range: bool,
}

#[cfg(feature = "defmt")]
impl StatusLine<'_> {
    /// Writes the line to the defmt log at level info (the board's writer; one defmt frame
    /// of [`FORMAT`] and the fields).
    pub fn log_info(&self) {
        let s = self;
        macro_rules! defmt_info {
            ($format:literal, $($arg:expr),*) => {
                defmt::info!($format, $($arg),*)
            };
        }
        with_status_line!(defmt_info, s);
    }
}

/// A value of the line, written as defmt's decoder prints it.
trait DecoderText {
    /// Writes the value to `out`.
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result;
}

impl DecoderText for f32 {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(out, "{self:?}")
    }
}

impl DecoderText for bool {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(out, "{self}")
    }
}

impl DecoderText for &str {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        out.write_str(self)
    }
}

impl DecoderText for u8 {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(out, "{self}")
    }
}

impl DecoderText for u16 {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(out, "{self}")
    }
}

impl DecoderText for u32 {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(out, "{self}")
    }
}

impl<T: core::fmt::Debug> DecoderText for [T; 4] {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(out, "{self:?}")
    }
}

impl DecoderText for Option<bool> {
    fn write_to(&self, out: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(out, "{self:?}")
    }
}

/// `format` with each `{..}` placeholder replaced by the next of `args`.
fn render(
    out: &mut core::fmt::Formatter<'_>,
    format: &str,
    args: &[&dyn DecoderText],
) -> core::fmt::Result {
    let mut args = args.iter();
    let mut rest = format;
    while let Some(open) = rest.find('{') {
        out.write_str(rest.get(..open).unwrap_or(""))?;
        let after = rest.get(open..).unwrap_or("");
        let close = after.find('}').map_or(after.len(), |c| c + 1);
        if let Some(arg) = args.next() {
            arg.write_to(out)?;
        }
        rest = after.get(close..).unwrap_or("");
    }
    out.write_str(rest)
}

/// The host's writer: the line as defmt's decoder prints it (without its decorations).
impl core::fmt::Display for StatusLine<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let s = self;
        macro_rules! decoder_text {
            ($format:literal, $($arg:expr),*) => {
                render(f, $format, &[$(&$arg as &dyn DecoderText),*])
            };
        }
        with_status_line!(decoder_text, s)
    }
}
