//! Software in the loop: the firmware's own logic (ADC quantization, sample path, core,
//! commissioning state machine, flash record, panel) driven sample by sample by the
//! simulator in `sim-host`, with the LED outputs asserted.
//!
//! Timeline (2.2 kW reference motor, started direct-on-line, viscous load, 10 kHz):
//! 0-1.5 s run-up; button at 1.5 s -> 1 s of learning -> record "written" to a fake flash
//! page; 4.0 s: Rs +50 %; 6.5 s end.

use drive_monitor::app::{Command, SamplePath};
use drive_monitor::board::{self, RECORD_PAGE_SIZE};
use drive_monitor::commissioning::{Action, CommissioningProcedure, Event, State};
use drive_monitor::flash_record::{CalibrationRecord, RECORD_LEN};
use drive_monitor::panel::{self, Lamp, Mode, PanelInput, PanelLamps};
use drive_monitor::sampling::RawFrame;
use monitor_core::Fault;
use monitor_core::{Abc, MonitorOutput};
use sim_host::params::ParamFile;
use sim_host::sim::simulate_to_vec;
use sim_host::sim::{FaultSpec, Scenario};

const FS: u32 = board::DEFAULT_SAMPLE_RATE_HZ;
const PANEL_EVERY: usize = 500; // 50 ms at 10 kHz, as in the firmware

/// The firmware's thread loop without hardware: panel every 50 ms, button events,
/// commissioning, a fake flash page.
struct Rig {
    path: SamplePath,
    procedure: CommissioningProcedure,
    flash: [u8; RECORD_PAGE_SIZE as usize],
    last: MonitorOutput,
    panel: PanelLamps,
    fault_trace: Vec<bool>,
}

impl Rig {
    fn boot(flash: [u8; RECORD_PAGE_SIZE as usize]) -> Self {
        let mut path = SamplePath::for_board(FS).unwrap();
        let mut procedure = CommissioningProcedure::new(1.0);
        let loaded = match CalibrationRecord::decode(&flash) {
            Ok(rec) => path.command(Command::SetCalibration(rec)).is_ok(),
            Err(_) => false,
        };
        procedure.handle(Event::RecordLoaded(loaded), 0);
        Rig {
            path,
            procedure,
            flash,
            last: MonitorOutput::default(),
            panel: PanelLamps::default(),
            fault_trace: Vec::new(),
        }
    }

    fn press(&mut self, now_ms: u32) {
        if let Action::StartLearning { duration_s } =
            self.procedure.handle(Event::ButtonPressed, now_ms)
        {
            self.path
                .command(Command::StartCommissioning { duration_s })
                .unwrap();
        }
    }

    fn step(&mut self, raw: &RawFrame, k: usize) {
        let now_ms = (k as u64 * 1000 / u64::from(FS)) as u32;
        let r = self.path.on_frame(raw);
        self.last = r.output;
        let ev = match (r.learned, r.learning_failed) {
            (Some(rec), _) => Some(Event::LearningDone(rec)),
            (None, true) => Some(Event::LearningFailed),
            _ => None,
        };
        if let Some(ev) = ev {
            if let Action::Save(rec) = self.procedure.handle(ev, now_ms) {
                let bytes = rec.encode().unwrap();
                self.flash = [0xFF; RECORD_PAGE_SIZE as usize];
                self.flash[..RECORD_LEN].copy_from_slice(&bytes);
                let ok = CalibrationRecord::decode(&self.flash) == Ok(rec);
                self.procedure.handle(Event::SaveDone(ok), now_ms);
            }
        }
        if k.is_multiple_of(PANEL_EVERY) {
            self.procedure.handle(Event::Tick, now_ms);
            self.panel = panel::render(
                &PanelInput::from_output(self.procedure.panel_mode(), &self.last),
                now_ms,
            );
            self.fault_trace.push(self.panel.is_on(Lamp::Fault));
        }
    }
}

fn frames(scenario: &Scenario) -> Vec<RawFrame> {
    let params = ParamFile::reference_2p2kw();
    let rows = simulate_to_vec(&params, scenario).expect("simulation");
    let q = SamplePath::for_board(FS).unwrap();
    let q = q.sampler();
    let mut theta_counts = 0.0f64;
    let dt = 1.0 / f64::from(FS);
    rows.iter()
        .map(|row| {
            let v = row.v_abc.unwrap_or([0.0; 3]);
            let i = row.i_abc;
            let count = match row.enc_count {
                Some(c) => c as u32,
                None => {
                    theta_counts += row.wm_rad_s.unwrap_or(0.0) * dt / std::f64::consts::TAU
                        * f64::from(board::ENCODER_COUNTS_PER_REV);
                    theta_counts.floor() as i64 as u32
                }
            };
            q.quantize(
                Abc {
                    a: v[0] as f32,
                    b: v[1] as f32,
                    c: v[2] as f32,
                },
                Abc {
                    a: i[0] as f32,
                    b: i[1] as f32,
                    c: i[2] as f32,
                },
                count,
            )
        })
        .collect()
}

#[test]
fn commission_then_detect_rs_fault_on_the_panel() {
    let mut scenario = Scenario::steady(6.5, f64::from(FS));
    scenario
        .faults
        .push(FaultSpec::parametric(Fault::Rs, 4.0, 0.5));
    let frames = frames(&scenario);
    assert!(frames.len() >= 64_000, "{} samples", frames.len());

    let mut rig = Rig::boot([0xFF; RECORD_PAGE_SIZE as usize]);
    assert_eq!(rig.procedure.panel_mode(), Mode::NotCommissioned);
    let mut before_fault = None;
    for (k, raw) in frames.iter().enumerate() {
        if k == 15_000 {
            rig.press(1500);
        }
        rig.step(raw, k);
        if k == 39_500 {
            before_fault = Some((rig.last, rig.panel, rig.procedure.state()));
        }
    }

    // Commissioned before the fault, no residual lamp, no fault lamp.
    let (out, lamps, state) = before_fault.unwrap();
    assert_eq!(state, State::Commissioned, "commissioning did not finish");
    assert_eq!(
        out.lamps, [false; 4],
        "false alarm before the fault: {out:?}"
    );
    assert!(!out.fault_detected);
    for l in [Lamp::R1, Lamp::R2, Lamp::R3, Lamp::R4, Lamp::Fault] {
        assert!(!lamps.is_on(l), "{l:?} lit before the fault");
    }

    // After the fault: detected, the residual LEDs are the core's lamps, and the fault
    // LED blinks the top candidate's code.
    let out = rig.last;
    assert!(out.fault_detected, "Rs +50 % not detected: {out:?}");
    assert!(out.lamps.iter().any(|l| *l));
    let input = PanelInput::from_output(rig.procedure.panel_mode(), &out);
    let now = panel::render(&input, 0);
    for (k, l) in [Lamp::R1, Lamp::R2, Lamp::R3, Lamp::R4]
        .into_iter()
        .enumerate()
    {
        assert_eq!(now.is_on(l), out.lamps[k]);
    }
    let (top, _) = out.top().expect("a candidate");
    let trace: Vec<bool> = (0..400u32)
        .map(|t| panel::render(&input, t * 50).is_on(Lamp::Fault))
        .collect();
    assert_eq!(
        panel::read_blink_code(&trace, 50),
        Some(top.index() as u8 + 1)
    );

    // The stored record brings the next boot up commissioned.
    let rig2 = Rig::boot(rig.flash);
    assert_eq!(rig2.procedure.state(), State::Commissioned);
}

#[test]
fn saturated_adc_lights_the_fault_lamp_steadily() {
    let mut rig = Rig::boot([0xFF; RECORD_PAGE_SIZE as usize]);
    let q = *rig.path.sampler();
    for k in 0..2_000 {
        let t = k as f32 / FS as f32;
        let w = std::f32::consts::TAU * 50.0 * t;
        let v = Abc {
            a: 326.0 * w.cos(),
            b: 326.0 * (w - 2.094).cos(),
            c: 326.0 * (w + 2.094).cos(),
        };
        // 20 A peak on a +-10 A front end: the current codes hit the rails.
        let i = Abc {
            a: 20.0 * w.cos(),
            b: 20.0 * (w - 2.094).cos(),
            c: 20.0 * (w + 2.094).cos(),
        };
        rig.step(&q.quantize(v, i, 0), k);
    }
    assert!(rig.last.sensor_fault.current);
    let p = panel::render(
        &PanelInput::from_output(rig.procedure.panel_mode(), &rig.last),
        0,
    );
    assert!(p.is_on(Lamp::Fault));
    let p2 = panel::render(
        &PanelInput::from_output(rig.procedure.panel_mode(), &rig.last),
        777,
    );
    assert!(p2.is_on(Lamp::Fault), "steady, not blinking");
}
