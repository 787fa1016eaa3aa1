//! The register-level model of the STM32G474's ADC + DMA the recovery tests drive (the
//! module docs of `recovery` say what it keeps and checks).

use super::super::FS;
use drive_monitor::acquisition::{
    conversion_ns, trigger_rate_hz, CHANNELS, HALF_LEN, LATCH_LEN, OVERSAMPLING,
    RING_LEN as FW_RING_LEN,
};
use drive_monitor::acquisition::{DMA_HALF_LEN, LATCH_HALF_LEN};
use drive_monitor::recovery::{AcqRegisters, AdcFlags, RegisterAcquisition};
use drive_monitor::ring_read::{RingRead, RingReads};

/// The ring's length in DMA transfers: the firmware's.
pub(crate) const RING_LEN: u16 = FW_RING_LEN as u16;
/// The model's time one poll of a register takes [ns] (about 10 cycles at 170 MHz).
pub(crate) const POLL_NS: u64 = 60;

// ADC_CR's bits (RM0440, "ADC control register"), the model's own copy.
pub(crate) const CR_ADEN: u32 = 1 << 0;
pub(crate) const CR_ADDIS: u32 = 1 << 1;
pub(crate) const CR_ADSTART: u32 = 1 << 2;
pub(crate) const CR_JADSTART: u32 = 1 << 3;
pub(crate) const CR_ADSTP: u32 = 1 << 4;
pub(crate) const CR_JADSTP: u32 = 1 << 5;
pub(crate) const CR_ADVREGEN: u32 = 1 << 28;
pub(crate) const CR_ADCAL: u32 = 1 << 31;
/// The bits software sets and hardware clears.
pub(crate) const CR_SET_ONLY: u32 =
    CR_ADEN | CR_ADDIS | CR_ADSTART | CR_JADSTART | CR_ADSTP | CR_JADSTP | CR_ADCAL;
/// The idle time after which the first conversion may be wrong (G4 errata) [ns].
pub(crate) const IDLE_ERRATUM_NS: u64 = 1_000_000;
/// VREFINT's injected conversion: 247.5 + 12.5 cycles at 42.5 MHz [ns].
pub(crate) const INJECTED_NS: u64 = 6_118;
/// A ring word's rank marked as a conversion the errata make wrong.
pub(crate) const BAD: usize = 0x100;

/// One ADC as the recovery sees it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AdcModel {
    pub(crate) adstart: bool,
    /// An injected conversion (the reference's) is ongoing until `injected_until_ns`.
    pub(crate) jadstart: bool,
    pub(crate) injected_until_ns: u64,
    /// The last conversion's end [ns] (`None`: none since the model began).
    pub(crate) last_conversion_ns: Option<u64>,
    pub(crate) ovr: bool,
    pub(crate) eoc: bool,
    pub(crate) eos: bool,
    /// `ADC_DR`: the rank (channel 0..3) whose result it holds.
    pub(crate) dr: usize,
    /// `DMAEN` with `DMACFG` circular.
    pub(crate) dma_circular: bool,
    /// The conversion in flight ends at this time [ns] (`ADSTP` waits for it).
    pub(crate) busy_until_ns: u64,
    /// `ADSTP` was set: `ADSTART` clears when the conversion in flight ends.
    pub(crate) stopping: bool,
    /// A broken ADC: `ADSTART` never clears.
    pub(crate) stuck: bool,
}

/// One DMA channel.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DmaModel {
    pub(crate) en: bool,
    pub(crate) teif: bool,
    pub(crate) cndtr: u16,
    /// The ADC's DMA request, raised and not served yet.
    pub(crate) request: bool,
    /// The results the channel moved.
    pub(crate) moved: u32,
    /// The rank of the word at each ring position.
    pub(crate) ring: [usize; FW_RING_LEN],
    /// The trigger whose sequence each ring position's word came from.
    pub(crate) ids: [u64; FW_RING_LEN],
    /// Halves completed since the last sample was taken.
    pub(crate) halves: u32,
}

/// The encoder latch: TIM4's capture at each trigger, copied by its DMA channel into a
/// ring of [`LATCH_LEN`] counts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LatchModel {
    pub(crate) en: bool,
    /// `TIM4_DIER.CC3DE`: each capture raises a DMA request.
    pub(crate) cc3de: bool,
    /// A capture's DMA request not served yet, and the trigger it captured at.
    pub(crate) request: Option<u64>,
    pub(crate) cndtr: u16,
    /// The trigger each ring position's count was captured at.
    pub(crate) ids: [u64; LATCH_LEN],
}

/// The two ADCs, their DMA channels and the trigger, at register level (module docs).
#[derive(Clone, Debug)]
pub(crate) struct AdcDmaModel {
    pub(crate) trigger_on: bool,
    /// Triggers so far (each one's id).
    pub(crate) triggers: u64,
    pub(crate) latch: LatchModel,
    /// Completed sample blocks whose conversions and latched counts came from different
    /// triggers (the count does not belong to the readings), and those checked.
    pub(crate) unpaired_samples: u32,
    pub(crate) paired_samples: u32,
    pub(crate) adc: [AdcModel; 2],
    pub(crate) dma: [DmaModel; 2],
    /// The model's clock [ns].
    pub(crate) now_ns: u64,
    pub(crate) conversions: u32,
    /// Overruns the hardware latched (each conversion that ended with `EOC` still set).
    pub(crate) overruns: u32,
    /// Completed halves with a word at the place of another channel.
    pub(crate) misaligned_halves: u32,
    /// Register accesses made against their precondition (RM0440), in words.
    pub(crate) violations: Vec<String>,
    /// Whether the last sample block completed on each channel held a word the errata
    /// make wrong (the first conversion after more than 1 ms idle).
    pub(crate) last_block_bad: [bool; 2],
    /// A DMA transfer error on channel `.1` while the sample task awaits ring `.0`'s half
    /// (`ring_read::RingReads::read_adc`), once.
    pub(crate) error_on_read: Option<(usize, usize)>,
    /// The HAL's reads of each ADC ring (`read_adc`).
    pub(crate) reads: [u32; 2],
    /// The rings whose next read finds the DMA a lap ahead (samples lost): ADC1's, ADC2's,
    /// the latch's; once each.
    pub(crate) lap_on_read: [bool; 3],
}

/// The acquisition the rig runs: the firmware's sequence over the model.
pub(crate) type ModelAcq = RegisterAcquisition<AdcDmaModel>;

impl AdcDmaModel {
    pub(crate) fn running() -> ModelAcq {
        let adc = AdcModel {
            adstart: true,
            dma_circular: true,
            ..AdcModel::default()
        };
        let dma = DmaModel {
            en: true,
            teif: false,
            cndtr: RING_LEN,
            request: false,
            moved: 0,
            ring: [0; FW_RING_LEN],
            ids: [0; FW_RING_LEN],
            halves: 0,
        };
        RegisterAcquisition {
            regs: AdcDmaModel {
                trigger_on: true,
                triggers: 0,
                latch: LatchModel {
                    en: true,
                    cc3de: true,
                    request: None,
                    cndtr: LATCH_LEN as u16,
                    ids: [0; LATCH_LEN],
                },
                unpaired_samples: 0,
                paired_samples: 0,
                adc: [adc; 2],
                dma: [dma; 2],
                now_ns: 0,
                conversions: 0,
                overruns: 0,
                misaligned_halves: 0,
                violations: Vec::new(),
                last_block_bad: [false; 2],
                error_on_read: None,
                reads: [0; 2],
                lap_on_read: [false; 3],
            },
            ring_len: RING_LEN,
        }
    }

    /// The acquisition as the set-up leaves it before the first start: the ADCs enabled,
    /// `DMAEN` circular (the HAL's `configure_dma`), nothing converting, the DMA channels
    /// and the latch's off, the trigger stopped.
    pub(crate) fn stopped() -> ModelAcq {
        let mut acq = Self::running();
        acq.regs.trigger_on = false;
        acq.regs.latch.en = false;
        for (a, d) in acq.regs.adc.iter_mut().zip(&mut acq.regs.dma) {
            a.adstart = false;
            d.en = false;
        }
        acq
    }

    /// The DMA serves channel `i`'s request: one word from `ADC_DR` into the ring.
    fn serve(&mut self, i: usize) {
        let (a, d) = (&mut self.adc[i], &mut self.dma[i]);
        if !(d.request && d.en) {
            return;
        }
        d.request = false;
        a.eoc = false;
        let at = usize::from(RING_LEN - d.cndtr);
        d.ring[at] = a.dr;
        d.ids[at] = self.triggers.wrapping_sub(1);
        d.moved += 1;
        d.cndtr = if d.cndtr <= 1 { RING_LEN } else { d.cndtr - 1 };
        if (at + 1) % HALF_LEN == 0 {
            let half = at + 1 - HALF_LEN;
            let aligned = (0..HALF_LEN).all(|k| d.ring[half + k] & !BAD == k % CHANNELS);
            self.misaligned_halves += u32::from(!aligned);
            self.last_block_bad[i] = (0..HALF_LEN).any(|k| d.ring[half + k] & BAD != 0);
            d.halves += 1;
            // The sample's latched counts sit at the same place of the latch's ring.
            let first = half / CHANNELS;
            let paired = (0..OVERSAMPLING)
                .all(|s| self.latch.ids.get(first + s) == d.ids.get(half + s * CHANNELS));
            self.paired_samples += 1;
            self.unpaired_samples += u32::from(!paired);
        }
    }

    /// The latch's DMA channel serves the capture's request: the captured count into the
    /// latch's ring.
    fn serve_latch(&mut self) {
        let l = &mut self.latch;
        let Some(id) = l.request.filter(|_| l.en) else {
            return;
        };
        l.request = None;
        let at = LATCH_LEN - usize::from(l.cndtr);
        l.ids[at] = id;
        l.cndtr = if l.cndtr <= 1 {
            LATCH_LEN as u16
        } else {
            l.cndtr - 1
        };
    }

    /// A DMA transfer error on the latch's channel: the hardware clears its `EN`.
    pub(crate) fn inject_latch_dma_error(&mut self) {
        self.latch.en = false;
    }

    /// Embassy-stm32 0.6's `RingBufferedAdc::read` on ADC `i` as it begins: a ring whose
    /// DMA channel is off is restarted by the HAL's own `start()`: the channel enabled
    /// (no flag cleared, no `CNDTR` reloaded) and `ADC_CR` written by read-modify-write
    /// with `ADSTART` (`ADEN` written back: a violation of the register rules).
    pub(crate) fn hal_read(&mut self, i: usize) {
        if self.dma[i].en {
            return;
        }
        self.dma_enable(i);
        let cr = self.adc_cr(i);
        self.adc_cr_write(i, cr | CR_ADSTART);
    }

    /// One trigger: each converting ADC runs its sequence of [`CHANNELS`] conversions
    /// (each ends an 870 ns conversion: an overrun if `EOC` is still set, else a result
    /// and a DMA request), the DMA serving the requests; then the clock runs to the next
    /// trigger.
    pub(crate) fn trigger(&mut self) {
        let period_ns = 1_000_000_000 / u64::from(trigger_rate_hz(FS));
        let t0 = self.now_ns;
        if self.trigger_on {
            self.conversions += 1;
            // TIM4 captures its count at the trigger; the capture's DMA request moves it
            // (held while the channel is off: the latest capture's, CCR3 overwritten).
            if self.latch.cc3de {
                self.latch.request = Some(self.triggers);
            }
            self.serve_latch();
            self.triggers += 1;
            for rank in 0..CHANNELS {
                let end = t0 + (rank as u64 + 1) * u64::from(conversion_ns());
                for i in 0..2 {
                    let a = &mut self.adc[i];
                    if !a.adstart || a.stopping {
                        continue;
                    }
                    a.busy_until_ns = end;
                    if a.eoc {
                        // OVRMOD = 0: the old result stays in ADC_DR.
                        let first = !a.ovr;
                        a.ovr = true;
                        self.overruns += u32::from(first);
                        continue;
                    }
                    // The first conversion after more than 1 ms idle may be wrong (errata).
                    let idle = a
                        .last_conversion_ns
                        .is_none_or(|t| end - t > IDLE_ERRATUM_NS);
                    a.last_conversion_ns = Some(end);
                    a.dr = rank | if idle { BAD } else { 0 };
                    a.eoc = true;
                    a.eos = rank + 1 == CHANNELS;
                    if a.dma_circular && !a.ovr {
                        self.dma[i].request = true;
                    }
                    self.serve(i);
                }
            }
        }
        self.now_ns = t0 + period_ns;
    }

    /// One sample period ([`OVERSAMPLING`] triggers): whether both ADCs completed a half
    /// buffer (the sample task's read returns).
    pub(crate) fn sample(&mut self) -> bool {
        for _ in 0..OVERSAMPLING {
            self.trigger();
        }
        let done = self.dma.iter().all(|d| d.halves > 0);
        for d in &mut self.dma {
            d.halves = 0;
        }
        done
    }

    /// A conversion ended before the DMA took the previous result: `OVR` set, the data
    /// register holding the unread result (`EOC = 1`).
    pub(crate) fn inject_overrun(&mut self) {
        for a in &mut self.adc {
            a.ovr = true;
            a.eoc = true;
        }
        self.overruns += 1;
    }

    /// A DMA transfer error: the hardware sets `TEIF` and clears `EN`.
    pub(crate) fn inject_dma_error(&mut self) {
        for d in &mut self.dma {
            d.teif = true;
            d.en = false;
        }
    }

    /// Thread mode starts the reference's injected conversion on ADC1 now (it interrupts
    /// a regular one, which the model does not time; it keeps `JADSTART` for its 6.1 us).
    pub(crate) fn start_injected(&mut self) {
        let a = &mut self.adc[0];
        a.jadstart = true;
        a.injected_until_ns = self.now_ns + INJECTED_NS;
    }

    fn violation(&mut self, what: String) {
        self.violations.push(what);
    }
}

impl AcqRegisters for AdcDmaModel {
    fn adc_flags(&mut self, i: usize) -> AdcFlags {
        let a = self.adc[i];
        AdcFlags {
            ovr: a.ovr,
            eoc: a.eoc,
            eos: a.eos,
        }
    }
    fn adc_clear(&mut self, i: usize, f: AdcFlags) {
        let a = &mut self.adc[i];
        a.ovr &= !f.ovr;
        a.eoc &= !f.eoc;
        a.eos &= !f.eos;
    }
    fn adc_cr(&mut self, i: usize) -> u32 {
        self.now_ns += POLL_NS;
        let now = self.now_ns;
        let a = &mut self.adc[i];
        if a.stopping && !a.stuck && now >= a.busy_until_ns {
            a.adstart = false;
            a.stopping = false;
        }
        if a.jadstart && now >= a.injected_until_ns {
            a.jadstart = false;
        }
        let bit = |on: bool, b: u32| if on { b } else { 0 };
        CR_ADVREGEN
            | CR_ADEN
            | bit(a.adstart, CR_ADSTART)
            | bit(a.stopping, CR_ADSTP)
            | bit(a.jadstart, CR_JADSTART)
    }
    fn adc_cr_write(&mut self, i: usize, value: u32) {
        let set = value & CR_SET_ONLY;
        if set.count_ones() > 1 {
            self.violation(format!(
                "ADC{}_CR written with several set-only bits ({set:#x}): a read-modify-write",
                i + 1
            ));
        }
        if value & CR_ADVREGEN == 0 {
            self.violation(format!("ADC{}_CR written with ADVREGEN = 0", i + 1));
        }
        if value & CR_ADSTP != 0 {
            if !self.adc[i].adstart || value & CR_ADDIS != 0 {
                self.violation(format!("ADSTP on ADC{} while ADSTART = 0", i + 1));
            }
            // The conversion in flight (one may have started at the trigger) ends first:
            // ADSTART clears one conversion time from now.
            let now = self.now_ns;
            let a = &mut self.adc[i];
            a.stopping = true;
            a.busy_until_ns = a.busy_until_ns.max(now + u64::from(conversion_ns()));
        }
        if value & CR_ADSTART != 0 {
            self.adc[i].adstart = true;
        }
    }
    fn adc_dma_circular(&mut self, i: usize) {
        if self.adc[i].adstart {
            self.violation(format!(
                "DMAEN/DMACFG of ADC{} written while ADSTART = 1",
                i + 1
            ));
        }
        self.adc[i].dma_circular = true;
    }
    fn adc_dma_off(&mut self, i: usize) {
        if self.adc[i].adstart {
            // The hardware ignores the write.
            self.violation(format!("DMAEN of ADC{} cleared while ADSTART = 1", i + 1));
            return;
        }
        if self.adc[i].jadstart {
            self.violation(format!("DMAEN of ADC{} cleared while JADSTART = 1", i + 1));
            return;
        }
        self.adc[i].dma_circular = false;
        // The request is withdrawn with DMAEN.
        self.dma[i].request = false;
    }
    fn dma_error(&mut self, i: usize) -> bool {
        self.dma[i].teif
    }
    fn dma_clear(&mut self, i: usize) {
        self.dma[i].teif = false;
    }
    fn dma_enabled(&mut self, i: usize) -> bool {
        self.now_ns += POLL_NS;
        self.dma[i].en
    }
    fn dma_disable(&mut self, i: usize) {
        self.dma[i].en = false;
    }
    fn dma_reload(&mut self, i: usize, transfers: u16) {
        if self.dma[i].en {
            self.violation(format!(
                "CNDTR of DMA channel {} written while EN = 1",
                i + 1
            ));
        }
        self.dma[i].cndtr = transfers;
        self.dma[i].halves = 0;
    }
    fn dma_enable(&mut self, i: usize) {
        self.dma[i].en = true;
        // A request raised while the channel was off is served now.
        self.serve(i);
    }
    fn latch_disable(&mut self) {
        self.latch.en = false;
    }
    fn latch_enabled(&mut self) -> bool {
        self.now_ns += POLL_NS;
        self.latch.en
    }
    fn latch_clear(&mut self) {}
    fn latch_reload(&mut self, transfers: u16) {
        if self.latch.en {
            self.violation("CNDTR of the latch's DMA channel written while EN = 1".into());
        }
        self.latch.cndtr = transfers;
    }
    fn latch_enable(&mut self) {
        self.latch.en = true;
        // A capture's request raised while the channel was off is served now.
        self.serve_latch();
    }
    fn latch_request(&mut self, on: bool) {
        self.latch.cc3de = on;
        if !on {
            // Clearing CC3DE withdraws the timer's pending request.
            self.latch.request = None;
        }
    }
    fn trigger_stop(&mut self) {
        self.trigger_on = false;
    }
    fn trigger_start(&mut self) {
        self.trigger_on = true;
    }
}

/// The sample task's reads on the model: a half is there at once; the HAL's `read` restarts
/// a ring it finds off ([`AdcDmaModel::hal_read`], the violation it makes); a DMA error set
/// up with `error_on_read` hits while the read of its ring is awaited.
impl RingReads for AdcDmaModel {
    fn start_wait(&mut self) {}

    async fn read_adc(&mut self, i: usize, _buf: &mut [u16; DMA_HALF_LEN]) -> RingRead {
        self.hal_read(i);
        self.reads[i] += 1;
        if let Some((ring, channel)) = self.error_on_read {
            if ring == i {
                self.error_on_read = None;
                self.dma[channel].teif = true;
                self.dma[channel].en = false;
            }
        }
        match self.lap_on_read.get_mut(i) {
            Some(lap) if *lap => {
                *lap = false;
                RingRead::Lapped
            }
            _ => RingRead::Data,
        }
    }

    async fn read_latch(&mut self, _buf: &mut [u16; LATCH_HALF_LEN]) -> RingRead {
        if std::mem::take(&mut self.lap_on_read[2]) {
            RingRead::Lapped
        } else {
            RingRead::Data
        }
    }
}
