//! The live simulation behind `sim-host hmi` (no arguments): the demo's motor (the
//! 3 hp reference motor started direct-on-line with the paper's viscous load and 12-bit
//! noisy sensors, [`monitor_studies::demo`]) simulated as it is watched, its sensor rows fed to the
//! core row by row, with the paper's switches: each Table 1 fault on and off, load and
//! supply steps, commissioning.
//!
//! The simulator ([`monitor_api::sim::simulate_interactive`]) and the monitor run on a worker
//! thread that advances exactly as many rows as [`LiveSim::run_for`] asks and answers
//! with the readings ([`Snapshot`], every [`SNAPSHOT_EVERY_S`] of simulated time): the
//! simulation is deterministic whatever the screen's pace, and tests drive it directly.

use super::{quit_key, Controls, HmiState, Key, LiveControls, Snapshot, Source, SNAPSHOT_EVERY_S};
use monitor_api::files::ParamFile;
use monitor_api::replay::{Replay, ReplayOptions};
use monitor_api::sim::{simulate_interactive, FaultSpec, LoadStep, ScenarioEvent, SupplyStep};
use monitor_core::{CommissioningState, Fault, RunStage};
use monitor_studies::fault_signatures::{scenario, Protocol};
use std::ops::ControlFlow;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::thread::JoinHandle;

/// Evaluated running a commissioning run learns over [s].
pub const COMMISSIONING_S: f32 = 3.0;
/// Relative fault sizes the `s` key cycles through.
pub const CHANGES: [f64; 4] = [0.5, -0.5, 0.2, -0.2];
/// Load step of the `+`/`-` keys (fraction of the parameter file's Bl).
pub const LOAD_STEP: f64 = 0.1;
/// Supply voltage step of `v`/`V` (fraction of the nominal voltage).
pub const VOLTAGE_STEP: f64 = 0.05;
/// Supply frequency step of `f`/`F` [Hz].
pub const FREQUENCY_STEP_HZ: f64 = 1.0;
/// Longest simulated time a live run lasts [s] (about 28 hours).
const LIVE_DURATION_S: f64 = 1.0e5;

/// What the screen asks the worker.
enum LiveCommand {
    /// Simulate this many rows, then answer.
    Run(u64),
    /// An event from the next row on.
    Event(ScenarioEvent),
    /// Start a commissioning run.
    Commission,
}

/// The worker's answer to [`LiveCommand::Run`].
struct Reply {
    snapshots: Vec<Snapshot>,
    messages: Vec<String>,
}

/// The live simulation source.
pub struct LiveSim {
    name: String,
    params: ParamFile,
    sample_rate_hz: f64,
    tx: Option<Sender<LiveCommand>>,
    rx: Receiver<Reply>,
    worker: Option<JoinHandle<Result<(), monitor_api::sim::SimError>>>,
    /// Simulated time [s] so far.
    t_s: f64,
    controls: LiveControls,
    /// Simulated time owed to the wall clock (rows are whole).
    carry_s: f64,
}

impl LiveSim {
    /// Starts the demo's motor (the 3 hp reference motor at 10 kHz).
    ///
    /// # Errors
    /// The core refuses the configuration (not expected for the reference motor).
    pub fn demo_motor() -> Result<Self, monitor_studies::experiment::ExperimentError> {
        let mut live = Self::new(
            ParamFile::reference_3hp(),
            Protocol::default().sample_rate_hz,
        )?;
        live.name = "3 hp reference motor".to_string();
        Ok(live)
    }

    /// Starts a live simulation of the `params` motor at `sample_rate_hz`: direct-on-line
    /// start, viscous load, 12-bit noisy sensors, fixed thresholds until commissioned.
    ///
    /// # Errors
    /// The core refuses the configuration.
    pub fn new(
        params: ParamFile,
        sample_rate_hz: f64,
    ) -> Result<Self, monitor_studies::experiment::ExperimentError> {
        // The replay's monitor and isolation, fed row by row; its timeline is not kept (a
        // live run has no end), commissioning starts on the `c` key.
        let opts = ReplayOptions {
            timeline_step: monitor_api::replay::TimelineStep::NONE,
            // The load is an unknown input, as `diagnose` reads it by default: a load step
            // (`+`, `-`, the paper's Bl switch) is the load's move, the amber state, never a
            // FAULT (the simulated load itself is the paper's viscous one).
            load: monitor_api::replay::LoadModel::Unknown,
            ..ReplayOptions::default()
        };
        let channels = monitor_api::sim::SensorSpec::default().channels();
        let replay = Replay::new(&params, channels, sample_rate_hz, opts)?;
        let (tx, cmd_rx) = channel();
        let (reply_tx, rx) = channel();
        let proto = Protocol {
            duration_s: LIVE_DURATION_S,
            sample_rate_hz,
            ..Protocol::default()
        };
        let worker = std::thread::spawn(move || {
            let sc = scenario(None, &proto);
            Worker {
                params,
                replay,
                dt_s: 1.0 / sample_rate_hz,
                rows: 0,
                next_snapshot_s: 0.0,
                budget: 0,
                answer_due: false,
                snapshots: Vec::new(),
                messages: Vec::new(),
                reply: reply_tx,
                learning: false,
            }
            .run(&sc, &cmd_rx)
        });
        Ok(LiveSim {
            name: "the parameter file's motor".to_string(),
            params,
            sample_rate_hz,
            tx: Some(tx),
            rx,
            worker: Some(worker),
            t_s: 0.0,
            controls: LiveControls {
                faults: Vec::new(),
                change: CHANGES[0],
                load_scale: 1.0,
                voltage_scale: 1.0,
                supply_hz: params.supply.f_hz,
                paused: false,
            },
            carry_s: 0.0,
        })
    }

    /// Simulated time so far [s].
    pub fn time_s(&self) -> f64 {
        self.t_s
    }

    /// The switches as they stand.
    pub fn controls(&self) -> &LiveControls {
        &self.controls
    }

    /// Simulates `seconds` more (whole rows) and returns the readings and the worker's
    /// messages. An empty answer once the worker has stopped (its error is then among the
    /// messages).
    pub fn run_for(&mut self, seconds: f64) -> (Vec<Snapshot>, Vec<String>) {
        let rows = (seconds * self.sample_rate_hz).round().max(0.0) as u64;
        if rows == 0 {
            return (Vec::new(), Vec::new());
        }
        let sent = self
            .tx
            .as_ref()
            .is_some_and(|tx| tx.send(LiveCommand::Run(rows)).is_ok());
        match self.rx.recv() {
            Ok(r) if sent => {
                self.t_s += rows as f64 / self.sample_rate_hz;
                (r.snapshots, r.messages)
            }
            _ => (Vec::new(), self.stop()),
        }
    }

    /// Switches `fault` on (with the current size) or, when on, off; returns the event
    /// text.
    pub fn toggle_fault(&mut self, fault: Fault) -> String {
        let t = self.t_s;
        if let Some(k) = self.controls.faults.iter().position(|(f, _)| *f == fault) {
            let (_, change) = self.controls.faults.remove(k);
            self.send(ScenarioEvent::Fault(clearing(fault, change, t)));
            format!("{t:.2} s: {} cleared", fault.name())
        } else {
            let change = self.controls.change;
            self.controls.faults.push((fault, change));
            self.send(ScenarioEvent::Fault(FaultSpec::at_change(fault, t, change)));
            format!(
                "{t:.2} s: {} {:+.0} % switched on",
                fault.name(),
                change * 100.0
            )
        }
    }

    /// Clears every fault switched on.
    pub fn clear_faults(&mut self) -> Option<String> {
        if self.controls.faults.is_empty() {
            return None;
        }
        for (f, change) in std::mem::take(&mut self.controls.faults) {
            self.send(ScenarioEvent::Fault(clearing(f, change, self.t_s)));
        }
        Some(format!("{:.2} s: every fault cleared", self.t_s))
    }

    /// Steps the load Bl by `delta` (fraction of the nominal), kept in 0.1..3.
    pub fn step_load(&mut self, delta: f64) -> String {
        let c = &mut self.controls;
        c.load_scale = (c.load_scale + delta).clamp(0.1, 3.0);
        let scale = c.load_scale;
        self.send(ScenarioEvent::Load(LoadStep {
            t_s: self.t_s,
            torque_nm: None,
            bl_scale: Some(scale),
        }));
        format!("{:.2} s: load Bl x{scale:.2}", self.t_s)
    }

    /// Steps the supply voltage by `delta` (fraction of the nominal, kept in 0.5..1.2)
    /// and the frequency by `delta_hz` (kept within 50 %..120 % of the nominal).
    pub fn step_supply(&mut self, delta: f64, delta_hz: f64) -> String {
        let nominal = self.params.supply.f_hz;
        let c = &mut self.controls;
        c.voltage_scale = (c.voltage_scale + delta).clamp(0.5, 1.2);
        c.supply_hz = (c.supply_hz + delta_hz).clamp(0.5 * nominal, 1.2 * nominal);
        let (v, f) = (c.voltage_scale, c.supply_hz);
        self.send(ScenarioEvent::Supply(SupplyStep {
            t_s: self.t_s,
            v_scale: Some(v),
            f_hz: Some(f),
        }));
        format!("{:.2} s: supply {:.0} % at {f:.1} Hz", self.t_s, v * 100.0)
    }

    /// Starts a commissioning run of [`COMMISSIONING_S`] (the worker reports the start or
    /// why it could not start).
    pub fn commission(&mut self) {
        if let Some(tx) = &self.tx {
            let _ = tx.send(LiveCommand::Commission);
        }
    }

    /// Cycles the size of the next fault through [`CHANGES`].
    pub fn next_change(&mut self) -> String {
        let k = CHANGES
            .iter()
            .position(|c| *c == self.controls.change)
            .map_or(0, |k| (k + 1) % CHANGES.len());
        self.controls.change = CHANGES[k];
        format!("next fault: {:+.0} %", self.controls.change * 100.0)
    }

    fn send(&self, ev: ScenarioEvent) {
        if let Some(tx) = &self.tx {
            let _ = tx.send(LiveCommand::Event(ev));
        }
    }

    /// Stops the worker; its error, if it ended with one.
    fn stop(&mut self) -> Vec<String> {
        self.tx = None;
        match self.worker.take().map(JoinHandle::join) {
            Some(Ok(Err(e))) => vec![format!("the simulation stopped: {e}")],
            Some(Err(_)) => vec!["the simulation stopped: its thread panicked".to_string()],
            _ => Vec::new(),
        }
    }
}

impl Drop for LiveSim {
    fn drop(&mut self) {
        // Dropping the sender ends the worker at its next wait.
        self.tx = None;
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}

/// The fault that undoes `fault` of relative size `change` at `t`: the inverse change for
/// a parametric fault (they compose multiplicatively), a zero gain error for a sensor.
fn clearing(fault: Fault, change: f64, t: f64) -> FaultSpec {
    if fault.is_sensor() {
        FaultSpec::sensor_gain(fault, t, 0.0)
    } else {
        FaultSpec::parametric(fault, t, 1.0 / (1.0 + change) - 1.0)
    }
}

/// The simulator's side of the live run.
struct Worker {
    params: ParamFile,
    /// The core monitor and the isolation, as `diagnose` replays a log.
    replay: Replay,
    dt_s: f64,
    rows: u64,
    next_snapshot_s: f64,
    budget: u64,
    answer_due: bool,
    snapshots: Vec<Snapshot>,
    messages: Vec<String>,
    reply: Sender<Reply>,
    /// A commissioning run was learning at the previous row.
    learning: bool,
}

impl Worker {
    fn run(
        mut self,
        sc: &monitor_api::sim::Scenario,
        rx: &Receiver<LiveCommand>,
    ) -> Result<(), monitor_api::sim::SimError> {
        let params = self.params;
        simulate_interactive(&params, sc, |row, events| {
            if self.wait_for_work(rx, events).is_break() {
                return ControlFlow::Break(());
            }
            let t = self.rows as f64 * self.dt_s;
            let out = self.replay.push(row);
            self.note_commissioning(&out, t);
            if t + 0.5 * self.dt_s >= self.next_snapshot_s {
                self.next_snapshot_s += SNAPSHOT_EVERY_S;
                let snap = Snapshot::from_replay(t, &out, &self.replay, &params);
                self.snapshots.push(snap);
            }
            self.rows += 1;
            self.budget = self.budget.saturating_sub(1);
            ControlFlow::Continue(())
        })
        .map(|_| ())
    }

    /// Answers when the rows asked for are done, then waits for the next request; events
    /// and commands arriving meanwhile are queued or carried out.
    fn wait_for_work(
        &mut self,
        rx: &Receiver<LiveCommand>,
        events: &mut Vec<ScenarioEvent>,
    ) -> ControlFlow<()> {
        while self.budget == 0 {
            if self.answer_due {
                self.answer_due = false;
                let reply = Reply {
                    snapshots: std::mem::take(&mut self.snapshots),
                    messages: std::mem::take(&mut self.messages),
                };
                if self.reply.send(reply).is_err() {
                    return ControlFlow::Break(());
                }
            }
            match rx.recv() {
                Ok(LiveCommand::Run(n)) => {
                    self.budget = n;
                    self.answer_due = true;
                }
                Ok(LiveCommand::Event(e)) => events.push(e),
                Ok(LiveCommand::Commission) => self.commission(),
                Err(_) => return ControlFlow::Break(()),
            }
        }
        ControlFlow::Continue(())
    }

    /// An event when a commissioning run ends.
    fn note_commissioning(&mut self, out: &monitor_core::MonitorOutput, t: f64) {
        let learning = matches!(out.commissioning, CommissioningState::Learning(_));
        if self.learning && !learning {
            let Some(run) = self.replay.monitor().map(|m| m.commissioning()) else {
                return;
            };
            self.messages.push(match run.stage {
                RunStage::Done => format!(
                    "{t:.2} s: commissioning run {} done: learned thresholds in force",
                    run.id
                ),
                RunStage::Failed(why) => format!(
                    "{t:.2} s: commissioning run {} failed ({})",
                    run.id,
                    why.name()
                ),
                _ => format!("{t:.2} s: commissioning run {} ended", run.id),
            });
        }
        self.learning = learning;
    }

    fn commission(&mut self) {
        let t = self.rows as f64 * self.dt_s;
        self.messages.push(
            match self
                .replay
                .monitor_mut()
                .map(|m| m.start_commissioning(COMMISSIONING_S))
            {
                Some(Ok(id)) => format!(
                "{t:.2} s: commissioning run {id} started ({COMMISSIONING_S} s of steady running)"
            ),
                Some(Err(e)) => format!("{t:.2} s: commissioning not started: {e}"),
                None => format!("{t:.2} s: commissioning not started: no monitor"),
            },
        );
    }
}

impl Source for LiveSim {
    fn advance(&mut self, wall_s: f64, state: &mut HmiState) {
        if self.controls.paused {
            return;
        }
        // At most a quarter second at once: a stalled screen does not make the motor jump.
        self.carry_s = (self.carry_s + wall_s).min(0.25);
        let rows = (self.carry_s * self.sample_rate_hz).floor();
        self.carry_s -= rows / self.sample_rate_hz;
        let (snapshots, messages) = self.run_for(rows / self.sample_rate_hz);
        for s in snapshots {
            state.push(s);
        }
        for m in messages {
            state.event(m);
        }
        state.controls = Controls::Live(self.controls.clone());
    }

    fn key(&mut self, key: Key, state: &mut HmiState) -> bool {
        let Key::Char(c) = key else {
            return quit_key(key, state);
        };
        if let Some(f) = super::fault_of_key(c) {
            let e = self.toggle_fault(f);
            state.event(e);
            state.controls = Controls::Live(self.controls.clone());
            return true;
        }
        let event = match c {
            '0' => self.clear_faults(),
            's' => Some(self.next_change()),
            '+' | '=' => Some(self.step_load(LOAD_STEP)),
            '-' => Some(self.step_load(-LOAD_STEP)),
            'v' => Some(self.step_supply(-VOLTAGE_STEP, 0.0)),
            'V' => Some(self.step_supply(VOLTAGE_STEP, 0.0)),
            'f' => Some(self.step_supply(0.0, -FREQUENCY_STEP_HZ)),
            'F' => Some(self.step_supply(0.0, FREQUENCY_STEP_HZ)),
            'c' => {
                self.commission();
                None
            }
            ' ' => {
                self.controls.paused = !self.controls.paused;
                Some(
                    if self.controls.paused {
                        "paused"
                    } else {
                        "running"
                    }
                    .to_string(),
                )
            }
            _ => return quit_key(key, state),
        };
        if let Some(e) = event {
            state.event(e);
        }
        state.controls = Controls::Live(self.controls.clone());
        true
    }

    fn initial_state(&self) -> HmiState {
        HmiState::new(
            format!(
                "live simulation: {}, {:.0} V {:.0} Hz, {:.0} kHz",
                self.name,
                self.params.supply.v_ll_rms,
                self.params.supply.f_hz,
                self.sample_rate_hz / 1000.0
            ),
            Controls::Live(self.controls.clone()),
        )
    }
}
