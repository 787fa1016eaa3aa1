//! The register-level model of the STM32G474's ADC + DMA the recovery tests drive (the
//! module docs of `recovery` say what it keeps and checks).

use super::super::FS;
use drive_monitor::acquisition::{
    conversion_ns, trigger_rate_hz, CHANNELS, HALF_LEN, OVERSAMPLING, RING_LEN as FW_RING_LEN,
};
use drive_monitor::recovery::{AcqRegisters, AdcFlags, RegisterAcquisition};

/// The ring's length in DMA transfers: the firmware's.
pub(crate) const RING_LEN: u16 = FW_RING_LEN as u16;
/// The model's time one poll of a register takes [ns] (about 10 cycles at 170 MHz).
pub(crate) const POLL_NS: u64 = 60;

/// One ADC as the recovery sees it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AdcModel {
    pub(crate) adstart: bool,
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
    /// Halves completed since the last sample was taken.
    pub(crate) halves: u32,
}

/// The two ADCs, their DMA channels and the trigger, at register level (module docs).
#[derive(Clone, Debug)]
pub(crate) struct AdcDmaModel {
    pub(crate) trigger_on: bool,
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
            halves: 0,
        };
        RegisterAcquisition {
            regs: AdcDmaModel {
                trigger_on: true,
                adc: [adc; 2],
                dma: [dma; 2],
                now_ns: 0,
                conversions: 0,
                overruns: 0,
                misaligned_halves: 0,
                violations: Vec::new(),
            },
            ring_len: RING_LEN,
        }
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
        d.moved += 1;
        d.cndtr = if d.cndtr <= 1 { RING_LEN } else { d.cndtr - 1 };
        if (at + 1) % HALF_LEN == 0 {
            let half = at + 1 - HALF_LEN;
            let aligned = (0..HALF_LEN).all(|k| d.ring[half + k] == k % CHANNELS);
            self.misaligned_halves += u32::from(!aligned);
            d.halves += 1;
        }
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
                    a.dr = rank;
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
    fn adc_started(&mut self, i: usize) -> bool {
        self.now_ns += POLL_NS;
        let a = &mut self.adc[i];
        if a.stopping && !a.stuck && self.now_ns >= a.busy_until_ns {
            a.adstart = false;
            a.stopping = false;
        }
        a.adstart
    }
    fn adc_disabling(&mut self, _i: usize) -> bool {
        false
    }
    fn adc_stop(&mut self, i: usize) {
        if !self.adc[i].adstart {
            self.violation(format!("ADSTP on ADC{} while ADSTART = 0", i + 1));
        }
        // The conversion in flight (one may have started at the trigger) ends first:
        // ADSTART clears one conversion time from now.
        let a = &mut self.adc[i];
        a.stopping = true;
        a.busy_until_ns = a
            .busy_until_ns
            .max(self.now_ns + u64::from(conversion_ns()));
    }
    fn adc_start(&mut self, i: usize) {
        self.adc[i].adstart = true;
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
    fn trigger_stop(&mut self) {
        self.trigger_on = false;
    }
    fn trigger_start(&mut self) {
        self.trigger_on = true;
    }
}
