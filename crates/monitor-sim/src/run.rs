//! One simulation run: the stiff supply, the scenario's events at their output samples,
//! the integration loop and the true state of each output sample.

use super::machine::Machine;
use super::resolve::{
    checked_machine, rated_point, MachineBuilder, ParameterScales, ResolvedEffects,
};
use super::sensors::Sensors;
use super::supply::Supply;
use super::{LoadKind, Scenario, ScenarioEvent, SimError, SimSummary, Truth};
use monitor_core::frames::{inverse_clarke, AlphaBeta};
use monitor_io::log::Row;
use monitor_io::params::{ParamFile, SensorRanges};
use std::ops::ControlFlow;

/// The scenario's supply steps, load steps and faults at their output-sample indices.
fn scenario_events(scenario: &Scenario) -> Vec<(u64, ScenarioEvent)> {
    let rate = scenario.sample_rate_hz;
    let idx = |t: f64| (t * rate - 1e-9).ceil().max(0.0) as u64;
    let mut events: Vec<(u64, ScenarioEvent)> = Vec::new();
    events.extend(
        scenario
            .supply
            .steps
            .iter()
            .map(|s| (idx(s.t_s), ScenarioEvent::Supply(*s))),
    );
    events.extend(
        scenario
            .load
            .steps
            .iter()
            .map(|s| (idx(s.t_s), ScenarioEvent::Load(*s))),
    );
    events.extend(
        scenario
            .faults
            .iter()
            .map(|f| (idx(f.at_s), ScenarioEvent::Fault(*f))),
    );
    events.sort_by_key(|e| e.0);
    events
}

/// Checks the scenario and the parameters and resolves the run.
pub(super) fn checked_run<'a>(
    params: &'a ParamFile,
    scenario: &'a Scenario,
) -> Result<SimRun<'a>, SimError> {
    scenario.validate()?;
    params.check().map_err(|e| SimError::Invalid {
        key: "params".into(),
        message: e.to_string(),
    })?;
    check_against_run(params, scenario)?;
    SimRun::new(params, scenario)
}

/// Supply frequencies a run accepts, as multiples of the parameter file's (a V/f drive
/// from a tenth of base speed to twice it).
pub const SUPPLY_F_RANGE: (f64, f64) = (0.1, 2.0);
/// Fewest output rows of a run.
pub const MIN_ROWS: f64 = 2.0;

/// The scenario's values against the run and the machine: every time at or before the end of the run,
/// at least [`MIN_ROWS`] rows, supply
/// frequencies within [`SUPPLY_F_RANGE`] of the parameter file's, sensor offsets inside
/// the sensor's range and sensor gains that leave a reading (`change > -1`; a dead sensor
/// is `mode = "disconnected"`).
///
/// # Errors
/// [`SimError::Invalid`] naming the key.
fn check_against_run(params: &ParamFile, sc: &Scenario) -> Result<(), SimError> {
    let bad = |key: &str, message: String| {
        Err(SimError::Invalid {
            key: key.into(),
            message,
        })
    };
    let end = sc.duration_s;
    let times = sc
        .faults
        .iter()
        .map(|f| ("faults.at_s", f.at_s))
        .chain(sc.supply.steps.iter().map(|s| ("supply.steps.t_s", s.t_s)))
        .chain(sc.load.steps.iter().map(|s| ("load.steps.t_s", s.t_s)));
    for (key, t) in times {
        // (At exactly the end is allowed: a list of steps up to the duration is common.)
        if t > end {
            return bad(
                key,
                format!("{t} s is after the run's end (duration_s = {end} s): it would never act"),
            );
        }
    }
    let f0 = params.supply.f_hz;
    let (lo, hi) = (SUPPLY_F_RANGE.0 * f0, SUPPLY_F_RANGE.1 * f0);
    let freqs = sc
        .supply
        .f_hz
        .map(|f| ("supply.f_hz", f))
        .into_iter()
        .chain(
            sc.supply
                .steps
                .iter()
                .filter_map(|s| s.f_hz.map(|f| ("supply.steps.f_hz", f))),
        );
    for (key, f) in freqs {
        if !(lo..=hi).contains(&f) {
            return bad(
                key,
                format!(
                    "{f} Hz is outside {lo}..={hi} Hz (0.1 to 2 x the parameter file's {f0} Hz)"
                ),
            );
        }
    }
    let rows = (sc.duration_s * sc.sample_rate_hz).round();
    if rows < MIN_ROWS {
        return bad(
            "duration_s",
            format!(
                "{end} s at {} Hz gives {rows} rows; at least {MIN_ROWS} are needed",
                sc.sample_rate_hz
            ),
        );
    }
    check_sensor_faults(params, sc)
}

/// Sensor faults the sensors can show: offsets inside the range, gains that leave a reading.
fn check_sensor_faults(params: &ParamFile, sc: &Scenario) -> Result<(), SimError> {
    let ranges = params.sensor_ranges();
    let wm_max = f64::from(params.log_limits().wm_max_rad_s);
    for f in sc.faults.iter().filter(|f| f.kind.is_sensor()) {
        if let Some(c) = f.change.filter(|c| *c <= -1.0) {
            return Err(SimError::Invalid {
                key: "faults.change".into(),
                message: format!(
                    "a sensor gain change of {c} leaves no reading (gain {}); a dead sensor is mode = \"disconnected\"",
                    1.0 + c
                ),
            });
        }
        use monitor_core::{FaultTarget::Sensor, SensorChannel};
        let range = match f.kind.target() {
            Sensor(SensorChannel::Voltage) => ranges.v_range_v,
            Sensor(SensorChannel::Current) => ranges.i_range_a,
            _ => wm_max,
        };
        if let Some(o) = f.offset.filter(|o| o.abs() > range) {
            return Err(SimError::Invalid {
                key: "faults.offset".into(),
                message: format!(
                    "{o} is beyond the sensor's range of +/-{range} (the reading would only clip)"
                ),
            });
        }
    }
    Ok(())
}

/// One simulation run: the resolved scenario and the state of the loop.
pub(super) struct SimRun<'a> {
    scenario: &'a Scenario,
    builder: MachineBuilder<'a>,
    scales: ParameterScales,
    events: Vec<(u64, ScenarioEvent)>,
    machine: Machine,
    sensors: Sensors,
    supply: Supply,
    /// Output rows, RK4 steps per row, output period [s].
    n: u64,
    nsub: u32,
    dt: f64,
    np: f64,
}

impl<'a> SimRun<'a> {
    /// Resolves the scenario and checks every parameter set the run will pass through,
    /// before the first row.
    fn new(params: &'a ParamFile, scenario: &'a Scenario) -> Result<Self, SimError> {
        let m = &params.motor;
        let v_ll = scenario.supply.v_ll_rms.unwrap_or(params.supply.v_ll_rms);
        let f0 = scenario.supply.f_hz.unwrap_or(params.supply.f_hz);
        let np = m.model::<f64>().np();
        let rated = rated_point(params, scenario, v_ll, f0, np);
        let eff = ResolvedEffects::new(scenario, m, rated)?;
        let torque_load = scenario.load.kind == LoadKind::Torque || eff.load_torque.is_some();
        let scales = ParameterScales {
            torque_nm: eff.load_torque.or(scenario.load.torque_nm).unwrap_or(0.0),
            ..ParameterScales::default()
        };
        let builder = MachineBuilder {
            m,
            eff,
            torque_load,
            bl_base: rated.bl_base,
        };
        let dt = 1.0 / scenario.sample_rate_hz;
        let work = scenario.workload();
        // At most 1e7 (1 s period over the 0.1 us floor of `validate`).
        let nsub = u32::try_from(work.steps_per_row).unwrap_or(u32::MAX);
        let events = scenario_events(scenario);
        let machine = checked_machine(&builder, scales, &events)?;
        let ranges = SensorRanges::new(m, v_ll, f0);
        let sp = &scenario.sensors;
        let sensors = Sensors::new(
            sp,
            sp.v_range_v.unwrap_or(ranges.v_range_v),
            sp.i_range_a.unwrap_or(ranges.i_range_a),
            scenario.seed,
        );
        let h = dt / f64::from(nsub);
        let supply = Supply::new(
            rated.vpk0,
            rated.we0,
            h,
            builder.eff.unbalance,
            &scenario.supply.harmonics,
        );
        Ok(SimRun {
            scenario,
            builder,
            scales,
            events,
            machine,
            sensors,
            supply,
            n: work.rows,
            nsub,
            dt,
            np,
        })
    }

    /// Applies the events due at output sample `k`; true when the machine must be rebuilt.
    fn apply_events(&mut self, k: u64, next_event: &mut usize) -> bool {
        let mut rebuild = false;
        while *next_event < self.events.len() && self.events[*next_event].0 <= k {
            match self.events[*next_event].1 {
                ScenarioEvent::Supply(s) => self.supply.step(&s),
                ScenarioEvent::Load(s) => {
                    if let Some(tq) = s.torque_nm {
                        self.scales.torque_nm = tq;
                    }
                    if let Some(b) = s.bl_scale {
                        self.scales.bl_scale = b;
                    }
                    rebuild = true;
                }
                ScenarioEvent::Fault(f) => {
                    if f.kind.is_sensor() {
                        self.sensors.apply_fault(&f);
                    } else {
                        self.scales.apply_fault(&f);
                        rebuild = true;
                    }
                }
            }
            *next_event += 1;
        }
        rebuild
    }

    /// The winding temperature rise at time `t` (`thermal_drift`), from the previous one and
    /// the last output sample's losses; `None` when it did not change.
    fn temperature_rise(&self, t: f64, k: u64, dtemp: f64, last_p_loss: f64) -> Option<f64> {
        let th = self.builder.eff.thermal?;
        let new = match th.rise_k {
            Some(rise) if t >= th.at_s => {
                monitor_laws::library::heating_rise_k(rise, th.tau_s, th.at_s, t)
            }
            Some(_) => 0.0,
            None if t >= th.at_s => {
                let target = th.r_th * last_p_loss;
                target + (dtemp - target) * (-self.dt / th.tau_s).exp()
            }
            None => 0.0,
        };
        (new != dtemp || k == 0).then_some(new)
    }

    /// Runs to the end, or until `on_row` breaks; the summary and whether it ran to the end.
    pub(super) fn run(
        self,
        mut on_row: impl FnMut(&Row, &Truth) -> ControlFlow<()>,
    ) -> Result<(SimSummary, bool), SimError> {
        self.run_with_events(|r, t, _| on_row(r, t))
    }

    /// Queues `added` to act at output sample `k`, leaving out an event that would make
    /// the machine unphysical.
    fn insert_events(&mut self, k: u64, next_event: usize, added: &mut Vec<ScenarioEvent>) {
        for (n, ev) in added.drain(..).enumerate() {
            if let ScenarioEvent::Fault(f) = ev {
                let mut scratch = self.scales;
                scratch.apply_fault(&f);
                if f.validate().is_err() || self.builder.build(&scratch).is_err() {
                    continue;
                }
            }
            let at = (next_event + n).min(self.events.len());
            self.events.insert(at, (k, ev));
        }
    }

    /// The machine at sample `k` (`t` [s]): the events due, the rise `dtemp` [K] from the last
    /// losses `p_loss` [W], the users' resistance laws; rebuilt where any moved.
    fn machine_at(
        &mut self,
        k: u64,
        t: f64,
        next_event: &mut usize,
        dtemp: &mut f64,
        p_loss: f64,
    ) -> Result<(), SimError> {
        let mut rebuild = self.apply_events(k, next_event);
        if let Some(new) = self.temperature_rise(t, k, *dtemp, p_loss) {
            *dtemp = new;
            let th = self.builder.eff.thermal;
            let (alpha, rotor) = th.map_or((0.0, false), |h| (h.alpha, h.rotor));
            self.scales.th_s = 1.0 + alpha * new;
            self.scales.th_r = if rotor { self.scales.th_s } else { 1.0 };
            rebuild = true;
        }
        if self.builder.eff.has_resistance_laws() {
            let (ls, lr) = self.builder.eff.resistance_law_scales(t, self.builder.m);
            rebuild |= (ls, lr) != (self.scales.law_s, self.scales.law_r);
            (self.scales.law_s, self.scales.law_r) = (ls, lr);
        }
        if !rebuild {
            return Ok(());
        }
        let b = &self.builder;
        let nm = b.build(&self.scales).map_err(|e| SimError::Invalid {
            key: b.blamed_key().to_string(),
            message: e.to_string(),
        })?;
        nm.take_guess(&self.machine);
        self.machine = nm;
        Ok(())
    }

    /// [`SimRun::run`] whose callback may add events ([`simulate_interactive`]).
    pub(super) fn run_with_events(
        mut self,
        mut on_row: impl FnMut(&Row, &Truth, &mut Vec<ScenarioEvent>) -> ControlFlow<()>,
    ) -> Result<(SimSummary, bool), SimError> {
        let mut added = Vec::new();
        let mut x = [0.0f64; 6];
        let mut next_event = 0usize;
        let mut dtemp = 0.0f64;
        let mut max_i2 = 0.0f64;
        let mut last_p_loss = 0.0f64;
        let mut i_f = self.supply.loop_start(&self.machine);
        for k in 0..self.n {
            let t = k as f64 * self.dt;
            self.machine_at(k, t, &mut next_event, &mut dtemp, last_p_loss)?;
            // Outputs at t.
            let v = self.supply.voltage(self.supply.p);
            let tr = truth(&self.machine, &x, i_f, v, t, self.supply.we, dtemp);
            last_p_loss = tr.p_cu_w + tr.p_fe_w;
            max_i2 = max_i2.max(tr.i_ab[0] * tr.i_ab[0] + tr.i_ab[1] * tr.i_ab[1]);
            let row = self.sensors.measure(&tr, self.dt);
            if on_row(&row, &tr, &mut added).is_break() {
                return Ok((self.summary(x[4], max_i2.sqrt()), false));
            }
            if !added.is_empty() {
                self.insert_events(k + 1, next_event, &mut added);
            }
            // Integrate to t + dt.
            self.supply
                .integrate(&self.machine, &mut x, &mut i_f, self.nsub, t);
            if !(x[0].is_finite() && x[2].is_finite() && x[4].is_finite()) {
                return Err(SimError::Diverged {
                    t_s: t + self.dt,
                    cause: self.divergence_cause(next_event),
                });
            }
        }
        Ok((self.summary(x[4], max_i2.sqrt()), true))
    }

    /// What a divergence followed, in the scenario's keys: the last event applied (of the
    /// first `applied`), or, with none, the values in force from the start.
    fn divergence_cause(&self, applied: usize) -> String {
        let opt = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:e}"));
        let Some((k, ev)) = applied.checked_sub(1).and_then(|i| self.events.get(i)) else {
            return "from the start: a value out of any motor's range in the parameter file                     (j_kgm2, b_nms, bl_nms, the inductances) or the scenario (load.torque_nm,                     load.bl_nms, supply, the effects' values); the machine's states grew                     without bound"
                .into();
        };
        let at = *k as f64 * self.dt;
        let what = match ev {
            ScenarioEvent::Supply(s) => format!(
                "supply.steps (v_scale {}, f_hz {})",
                opt(s.v_scale),
                opt(s.f_hz)
            ),
            ScenarioEvent::Load(s) => format!(
                "load.steps (torque_nm {}, bl_scale {})",
                opt(s.torque_nm),
                opt(s.bl_scale)
            ),
            ScenarioEvent::Fault(f) => {
                format!("faults (kind {}, change {})", f.kind.name(), opt(f.change))
            }
        };
        format!(
            "right after the step at {at} s in {what}; a value that size is out of any motor's range"
        )
    }

    fn summary(&self, wm: f64, max_abs_current_a: f64) -> SimSummary {
        let sc = self.scenario;
        SimSummary {
            rows: self.n,
            duration_s: sc.duration_s,
            sample_rate_hz: sc.sample_rate_hz,
            step_s: self.supply.h,
            substeps_per_sample: self.nsub,
            v_range_v: self.sensors.v_range_v,
            i_range_a: self.sensors.i_range_a,
            noise_v: self.sensors.noise_v,
            noise_i: self.sensors.noise_i,
            final_wm_rad_s: wm,
            final_slip: 1.0 - self.np * wm / self.supply.we,
            max_abs_current_a,
            effects: sc
                .effects
                .iter()
                .map(|e| e.kind().name().to_string())
                .collect(),
            faults: sc.faults.len(),
        }
    }
}

/// Phase values of an alpha-beta vector (amplitude-invariant Clarke).
fn abc_of(a: [f64; 2]) -> [f64; 3] {
    inverse_clarke(
        AlphaBeta {
            alpha: a[0],
            beta: a[1],
        },
        0.0,
    )
    .to_array()
}

/// The true quantities at state `x` with the shorted loop's current `i_f` (0 without a turn
/// fault) and the supply `v`.
#[allow(clippy::too_many_arguments)]
fn truth(
    model: &Machine,
    x: &[f64; 6],
    i_f: f64,
    v: [f64; 2],
    t: f64,
    we: f64,
    dtemp: f64,
) -> Truth {
    let ps = [x[0], x[1]];
    let pr = [x[2], x[3]];
    let c = model.currents(ps, pr);
    let is = c.i_s;
    let u = model.u(v, is);
    // The machine's branch current (with the iron-loss current), then the terminals'.
    let ib = [is[0] + u[0] * model.inv_rfe, is[1] + u[1] * model.inv_rfe];
    let loop_i = model.turn.map_or([0.0; 2], |l| l.terminal(i_f));
    let it = [ib[0] + loop_i[0], ib[1] + loop_i[1]];
    let (loop_loss, loop_stored) = model
        .turn
        .map_or((0.0, 0.0), |l| (l.loss_w(i_f), l.stored_j(i_f)));
    let te = model.torque(pr, c.i_r);
    let wm = x[4];
    Truth {
        t_s: t,
        v_abc: abc_of(v),
        i_abc: abc_of(it),
        v_ab: v,
        i_ab: it,
        psi_s: ps,
        psi_r: pr,
        i_s: is,
        i_r: c.i_r,
        wm_rad_s: wm,
        theta_m_rad: x[5],
        we_rad_s: we,
        te_nm: te,
        t_load_nm: model.load_torque(t, wm, x[5]),
        rs_ohm: model.rs,
        rr_ohm: model.rr,
        lm_h: c.lm,
        p_in_w: 1.5 * (v[0] * it[0] + v[1] * it[1]),
        p_cu_w: 1.5
            * (model.rs * (ib[0] * ib[0] + ib[1] * ib[1]) + model.rotor_r(x[5]).quad(c.i_r))
            + loop_loss,
        p_fe_w: 1.5 * (u[0] * u[0] + u[1] * u[1]) * model.inv_rfe,
        p_mech_w: te * wm,
        stored_energy_j: 0.75
            * (ps[0] * is[0] + ps[1] * is[1] + pr[0] * c.i_r[0] + pr[1] * c.i_r[1])
            + loop_stored,
        temperature_rise_k: dtemp,
    }
}
