//! The base parameters' physical ranges: a fitted Rs, Ra, Ls, B + Bl or J outside its range
//! is not a value the machine has ([`base_implausible`]), and a step that takes one out of
//! range is not plausible.

use crate::effects;
use crate::prep::Prepared;
use crate::simplified_model::{BaseParameter, BaseParams, MachineConstants};

/// A fitted base parameter with its physical range ([`effects::plausible`]).
pub(crate) struct BaseValue {
    /// Which.
    pub(crate) key: BaseParameter,
    /// The fitted value, in the key's unit.
    pub(crate) value: f64,
    range: monitor_io::params::PlausibleRange,
    /// Where the range comes from.
    basis: &'static str,
}

impl BaseValue {
    fn new(key: BaseParameter, value: f64, (lo, hi): (f64, f64), basis: &'static str) -> Self {
        BaseValue {
            key,
            value,
            range: monitor_io::params::PlausibleRange { lo, hi },
            basis,
        }
    }

    /// Why the value is not plausible (`None`: it is).
    pub(crate) fn implausible_because(&self) -> Option<String> {
        let (key, unit) = (self.key.key(), self.key.unit());
        effects::outside(key, unit, self.value, &self.range, self.basis)
    }
}

/// The fitted base parameters `b` with their physical ranges.
pub(crate) fn base_values(n: &MachineConstants, b: &BaseParams, d: &Prepared) -> [BaseValue; 4] {
    use effects::plausible as pl;
    let bmax = (pl::BTOT_RATED_TORQUE * n.torque_scale_nm / effects::sync_speed_mech(d, n))
        .max(3.0 * n.btot_nms);
    let rel = |r: (f64, f64), x: f64| (r.0 * x, r.1 * x);
    [
        BaseValue::new(BaseParameter::Ra, n.ra_ohm * b.ra_scale, rel(pl::RA_RATIO, n.ra_ohm),
            "Ra follows the winding temperature: -20 C to 155 C is 0.84-1.53 x the 20 C value, plus 10 % data-sheet tolerance"),
        BaseValue::new(BaseParameter::Ls, n.ls_h * b.ls_scale, rel(pl::LS_RATIO, n.ls_h),
            "Ls moves at most about 30 % with saturation and tolerance"),
        BaseValue::new(BaseParameter::BPlusBl, b.btot_nms, (0.0, bmax),
            "a viscous load carries at most 1.5 x the rated torque at synchronous speed"),
        BaseValue::new(BaseParameter::J, n.j_kgm2 * b.j_scale, rel(pl::J_RATIO, n.j_kgm2),
            "the coupled load's inertia is the usual unknown, but a factor 3 either way is another machine"),
    ]
}

/// The fitted base parameters that are not physically plausible: their keys and why.
pub(crate) fn base_out_of_range(
    n: &MachineConstants,
    b: &BaseParams,
    d: &Prepared,
) -> Vec<(BaseParameter, String)> {
    base_values(n, b, d)
        .iter()
        .filter_map(|v| Some((v.key, v.implausible_because()?)))
        .collect()
}

/// Why the base parameters `after` are implausible where `before` (the model the step
/// started from) was not: each base parameter a fit takes out of its physical range, in
/// words; one the model already had out of range is not the step's doing.
pub(crate) fn base_newly_out_of_range(
    n: &MachineConstants,
    before: &BaseParams,
    after: &BaseParams,
    d: &Prepared,
) -> Vec<String> {
    let already: Vec<BaseParameter> = base_out_of_range(n, before, d)
        .into_iter()
        .map(|(k, _)| k)
        .collect();
    base_out_of_range(n, after, d)
        .into_iter()
        .filter(|(k, _)| !already.contains(k))
        .map(|(_, w)| w)
        .collect()
}

/// The reasons fitted base parameters are not physically plausible (empty: plausible).
pub fn base_implausible(n: &MachineConstants, b: &BaseParams, d: &Prepared) -> Vec<String> {
    base_out_of_range(n, b, d)
        .into_iter()
        .map(|(_, why)| why)
        .collect()
}
