//! Whether the speed channel's unit is the one the log says: a running motor turns between
//! about half its synchronous speed (a hard start, a heavy overload) and a little above it
//! (a load that drives it). A log whose speed sits far outside that, while the currents
//! alternate at the supply frequency, was recorded in another unit than the one read: rpm
//! read as rad/s reads 9.55 times too fast, rad/s given the unit rpm 9.55 times too slow.
//! Such a speed is a data-quality finding naming the likely unit, not a speed sensor fault.

/// Log-spaced bins of `|wm| / w_sync` from 1e-3 to 1e3.
const BINS: usize = 600;
const DECADES: f64 = 6.0;

/// The speed's median, over the rows that passed, as a multiple of the synchronous speed.
#[derive(Debug, Clone)]
pub(super) struct SpeedScale {
    sync_rad_s: f64,
    hist: Vec<u64>,
    count: u64,
    /// The last speed counted (its bits) and its bin: a speed channel read from an encoder
    /// repeats its value for many rows, and the bin's logarithm is then taken once.
    last: Option<(u64, usize)>,
}

/// Below this many rows with a speed nothing is judged.
const MIN_ROWS: u64 = 100;
/// A median speed above this multiple of synchronous is no motor's.
const MAX_RATIO: f64 = 1.15;
/// Nor one below this, while the currents alternate (a motor that draws its current).
const MIN_RATIO: f64 = 0.25;

impl SpeedScale {
    /// For a machine whose mechanical synchronous speed is `sync_rad_s` (> 0).
    pub(super) fn new(sync_rad_s: f64) -> Self {
        SpeedScale {
            sync_rad_s,
            hist: vec![0; BINS],
            count: 0,
            last: None,
        }
    }

    /// One passed row's mechanical speed [rad/s, as read].
    #[inline]
    pub(super) fn push(&mut self, wm_rad_s: f64) {
        let bin = match self.last {
            Some((bits, bin)) if bits == wm_rad_s.to_bits() => bin,
            _ => {
                let r = wm_rad_s.abs() / self.sync_rad_s;
                if !(r.is_finite() && self.sync_rad_s > 0.0) {
                    return;
                }
                let x = ((r.max(1e-3).log10() + 3.0) / DECADES * BINS as f64) as usize;
                let bin = x.min(BINS - 1);
                self.last = Some((wm_rad_s.to_bits(), bin));
                bin
            }
        };
        if let Some(b) = self.hist.get_mut(bin) {
            *b += 1;
        }
        self.count += 1;
    }

    /// [`SpeedScale::push`] of each speed in turn (a run of the last speed counted at
    /// once).
    pub(super) fn push_all(&mut self, wm_rad_s: &[f64]) {
        let mut rest = wm_rad_s;
        while let Some((&w, tail)) = rest.split_first() {
            if let Some((bits, bin)) = self.last {
                let run = rest.iter().take_while(|x| x.to_bits() == bits).count();
                if run > 0 {
                    if let Some(b) = self.hist.get_mut(bin) {
                        *b += run as u64;
                    }
                    self.count += run as u64;
                    rest = rest.get(run..).unwrap_or_default();
                    continue;
                }
            }
            self.push(w);
            rest = tail;
        }
    }

    /// The median speed over synchronous, `None` with fewer than [`MIN_ROWS`] rows.
    pub(super) fn median_ratio(&self) -> Option<f64> {
        if self.count < MIN_ROWS {
            return None;
        }
        let mut seen = 0;
        for (k, n) in self.hist.iter().enumerate() {
            seen += n;
            if 2 * seen >= self.count {
                return Some(10f64.powf((k as f64 + 0.5) / BINS as f64 * DECADES - 3.0));
            }
        }
        None
    }

    /// The finding, when the speed is no running motor's; `running`: the currents alternate
    /// at about the supply frequency; `supply_scale`: the currents' frequency over the
    /// parameter file's (a drive's output: the synchronous speed scales with it).
    /// `pole_pairs` names the electrical-speed mistake.
    pub(super) fn finding(
        &self,
        running: bool,
        supply_scale: f64,
        pole_pairs: f64,
    ) -> Option<String> {
        let r = self.median_ratio()? / supply_scale.max(1e-3);
        if r <= MAX_RATIO && (r >= MIN_RATIO || !running) {
            return None;
        }
        let tau = std::f64::consts::TAU;
        let candidates = [
            (60.0 / tau, "recorded in rpm but read as rad/s (give its unit = \"rpm\" in [columns])"),
            (tau / 60.0, "recorded in rad/s but given the unit rpm"),
            (pole_pairs, "electrical, not mechanical, rad/s (give unit = \"Hz_el\" for electrical hertz, or divide by the pole pairs)"),
            (tau, "recorded in revolutions per second (Hz) but read as rad/s"),
        ];
        let likely = candidates
            .iter()
            .filter(|(k, _)| {
                let fixed = r / k;
                (0.5..=1.05).contains(&fixed)
            })
            .map(|(_, what)| *what)
            .next()
            .unwrap_or("another unit, or another channel mapped as the speed");
        Some(format!(
            "the speed channel reads {:.2} times the synchronous speed (median over the log) while the currents {}: no running motor's speed; it is likely {likely}",
            r,
            if running { "alternate at the supply frequency" } else { "do not alternate" }
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpm_read_as_rad_s_is_named() {
        let sync = 157.08;
        let mut s = SpeedScale::new(sync);
        for _ in 0..1000 {
            s.push(1440.0); // rpm of a 4-pole motor at 4 % slip, read as rad/s
        }
        let f = s.finding(true, 1.0, 2.0).expect("a finding");
        assert!(f.contains("rpm but read as rad/s"), "{f}");
        let mut ok = SpeedScale::new(sync);
        for _ in 0..1000 {
            ok.push(150.8);
        }
        assert_eq!(ok.finding(true, 1.0, 2.0), None);
        // A drive at 1.5 times the base frequency turns the motor 1.5 times as fast.
        let mut fast = SpeedScale::new(sync);
        for _ in 0..1000 {
            fast.push(1.5 * 150.8);
        }
        assert_eq!(fast.finding(true, 1.5, 2.0), None);
        let mut slow = SpeedScale::new(sync);
        for _ in 0..1000 {
            slow.push(150.8 * std::f64::consts::TAU / 60.0);
        }
        let f = slow.finding(true, 1.0, 2.0).expect("a finding");
        assert!(f.contains("given the unit rpm"), "{f}");
        // At standstill (the currents do not alternate) a low speed is no finding.
        assert_eq!(slow.finding(false, 1.0, 2.0), None);
    }
}
