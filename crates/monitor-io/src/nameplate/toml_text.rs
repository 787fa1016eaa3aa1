//! The estimate as a parameter file: TOML numbers and entries, each value with its range
//! and source as a comment.

use super::{Connection, Estimated, NameplateEstimate};

/// `x` for a TOML file: five significant digits, always a float (a decimal point or an
/// exponent).
pub fn toml_number(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 {
        return "0.0".to_string();
    }
    if (1e-3..1e6).contains(&a) {
        let digits = (4 - a.log10().floor() as i32).max(1) as usize;
        let t = format!("{x:.digits$}");
        let t = t.trim_end_matches('0');
        if t.ends_with('.') {
            format!("{t}0")
        } else {
            t.to_string()
        }
    } else {
        format!("{x:.4e}")
    }
}

/// One line of a parameter file: `key = value # comment` ([`toml_number`]'s value).
pub fn toml_entry(key: &str, x: f64, comment: &str) -> String {
    format!("{key} = {} # {comment}\n", toml_number(x))
}

impl NameplateEstimate {
    /// The value of `key` (a key of [`NameplateEstimate::values`]).
    pub fn value(&self, key: &str) -> Option<&Estimated> {
        self.values.iter().find(|v| v.key == key)
    }

    /// The parameter file as TOML, each value with its range and source as a comment.
    pub fn to_toml(&self) -> String {
        let n = &self.nameplate;
        let mut s = self.toml_header();
        s.push_str("[motor]\n");
        s.push_str(&self.motor_entries());
        for v in self.values.iter().filter(|v| !v.key.starts_with("motor.")) {
            s.push_str(&format!(
                "# {} = {} [{}..{}] {}\n",
                v.key,
                toml_number(v.value),
                toml_number(v.lo),
                toml_number(v.hi),
                v.unit
            ));
        }
        s.push_str("[supply]\n");
        s.push_str(&toml_entry(
            "v_ll_rms",
            n.voltage_v,
            "rated line-to-line voltage [V], from the nameplate",
        ));
        s.push_str(&toml_entry(
            "f_hz",
            n.frequency_hz,
            "rated frequency [Hz], from the nameplate",
        ));
        s
    }

    /// The file's opening comment: the nameplate, the slip, the method.
    fn toml_header(&self) -> String {
        let n = &self.nameplate;
        let mut s = String::new();
        s.push_str("# Estimated from a nameplate by `sim-host params from-nameplate` (docs/own-motor.md):\n");
        s.push_str(&format!(
            "#   {} kW, {} V, {} A, {} Hz, {} rpm, power factor {}, efficiency {}, {} poles ({}), {} connection\n",
            n.power_kw, n.voltage_v, n.current_a, n.frequency_hz, n.speed_rpm, n.power_factor,
            n.efficiency, self.poles,
            if self.poles_inferred { "inferred from the speed" } else { "given" },
            match n.connection {
                Connection::Star => "star",
                Connection::Delta => "delta",
            },
        ));
        s.push_str(&format!(
            "#   rated slip {:.2} %. Method after Lee, Frank, Sen et al., NAPS 2012 (nameplate-only\n\
             #   estimation); per-phase star-equivalent values.\n",
            100.0 * self.slip
        ));
        if n.connection == Connection::Delta {
            s.push_str(
                "#   Delta winding: its own phase resistances and inductances are 3x these.\n",
            );
        }
        s.push_str("# A starting point: refine it with a log of the healthy motor. Each value: [range] and source.\n");
        s
    }

    /// The `[motor]` table's entries, each with its range and source; the poles after Lm.
    fn motor_entries(&self) -> String {
        let mut s = String::new();
        for v in self.values.iter().filter(|v| v.key.starts_with("motor.")) {
            let key = v.key.trim_start_matches("motor.");
            s.push_str(&toml_entry(
                key,
                v.value,
                &format!(
                    "[{}..{}] {}; {}",
                    toml_number(v.lo),
                    toml_number(v.hi),
                    v.unit,
                    v.source
                ),
            ));
            if key == "lm_h" {
                s.push_str(&format!(
                    "poles = {} # {}\n",
                    self.poles,
                    if self.poles_inferred {
                        "inferred: the largest even number whose synchronous speed is above the rated speed"
                    } else {
                        "from the nameplate"
                    }
                ));
            }
        }
        s
    }
}
