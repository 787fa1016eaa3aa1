//! Physical ranges of the effects' and the base parameters' fitted values, with their
//! sources. A fit outside them is reported `plausible: false` with the reason, is never
//! ranked first by `explain`, and the verdict says so. The ranges are for induction motors
//! of about 0.1 kW to 1 MW; they are deliberately wide (a real machine must never be
//! flagged), so that a flagged value is one that no machine of that size can have.

/// Winding temperature rise `rise_k` [K]: -40..155. IEC 60034-1 (table of limits of
/// temperature rise, resistance method): class B 80 K, F 105 K, H 125 K above a 40 C
/// ambient, plus 30 K for a hot spot or a short overload; down to -40 K when a log
/// starts warm and the machine cools towards ambient.
pub const RISE_K: (f64, f64) = (-40.0, 155.0);
/// Basis of [`RISE_K`].
pub const RISE_K_BASIS: &str = "IEC 60034-1 limits of temperature rise: class H 125 K plus a 30 K hot-spot margin; cooling at most 40 K";
/// Thermal time constant `tau_s` [s]: 1..1e5. Winding (stator) thermal time constants of
/// totally enclosed motors of 0.1 to 100 kW are about 5 to 60 min (the IEC 60034-1 heat
/// run ends when the temperature changes by less than 2 K/h; thermal networks of
/// Boglietti et al., IEEE Trans. Ind. Electron. 56(3), 2009, give minutes for the
/// winding-to-core constant). The floor of 1 s only admits accelerated simulated heat
/// runs (the test suite uses 3 s); a faster "heating" is a step, a glitch or a gap in
/// the data, not a temperature.
pub const TAU_S: (f64, f64) = (1.0, 1e5);
/// Basis of [`TAU_S`].
pub const TAU_S_BASIS: &str = "winding thermal time constants are minutes (Boglietti et al. 2009; IEC 60034-1 heat runs); below 1 s it is not heating";
/// Saturation flux `psi_sat_wb` relative to the rated flux of the log: 0.7..3. In the
/// magnetisation curves of standard motors the knee is near the rated flux and Lm has
/// fallen to about half at 1.3 to 2 times it (Vas, *Electrical Machines and Drives: a
/// Space-Vector Theory Approach*, ch. 6; Levi's saturated models).
pub const PSI_SAT_RATIO: (f64, f64) = (0.7, 3.0);
/// Basis of [`PSI_SAT_RATIO`].
pub const PSI_SAT_BASIS: &str = "magnetisation curves of standard motors: Lm halves at 1.3-2 x the rated flux (Vas 1992, Levi 1995)";
/// Core-loss resistance over the magnetising reactance, Rfe/Xm: at least 3 (core loss at
/// most about 10 % of the no-load reactive power; measured core losses of 0.1 to 100 kW
/// motors are 1 % to 5 % of the rated power, IEC 60034-2-1 loss segregation, i.e.
/// Rfe of about 10 to 60 Xm); a negative conductance (beyond 1 % of 1/Xm) is not physical.
pub const RFE_OVER_XM_MIN: f64 = 3.0;
/// Basis of [`RFE_OVER_XM_MIN`].
pub const G_FE_BASIS: &str = "core loss of 1-5 % of rated power (IEC 60034-2-1): Rfe of 10-60 x Xm, at least 3 x Xm; never negative, but for 1 % of 1/Xm left to the noise of the fit";
/// Dry friction torque relative to the rated torque estimate: -0.02..0.25. Bearing and
/// seal friction of the motor itself is below 1 to 2 % of its rated torque (SKF rolling
/// bearing friction model); a driven machine's breakaway torque (gears, seals) adds up
/// to about 20 %.
pub const COULOMB_RATIO: (f64, f64) = (-0.02, 0.25);
/// Basis of [`COULOMB_RATIO`].
pub const COULOMB_BASIS: &str = "bearing friction is 1-2 % of rated torque (SKF friction model), a driven machine's breakaway up to about 20 %";
/// Speed-squared torque at synchronous speed relative to the rated torque estimate:
/// -0.02..1.5 (the motor's own fan takes 1 % to 3 %; a fan or pump load sized to the motor
/// at most its rated torque at rated speed, which the synchronous speed's square, a few
/// per cent above the rated one's, and a service factor (NEMA MG 1: 1.15 to 1.5) bring to
/// about 1.2 there; the rated torque estimate from the file reads up to 15 % low, as on
/// motulator's 2.2 kW fan of 1.10 x rated at synchronous speed, read as 1.28 x).
pub const WINDAGE_RATIO: (f64, f64) = (-0.02, 1.5);
/// Basis of [`WINDAGE_RATIO`].
pub const WINDAGE_BASIS: &str = "a fan or pump load takes at most about its rated torque at rated speed (service factor up to 1.5, NEMA MG 1); the motor's own fan 1-3 %";
/// Load torque levels relative to the rated torque estimate: -3..3 (breakdown torque of
/// design N / NEMA design A-C motors is 2 to 3 times rated, IEC 60034-12, NEMA MG 1).
pub const LOAD_RATIO: (f64, f64) = (-3.0, 3.0);
/// Basis of [`LOAD_RATIO`].
pub const LOAD_BASIS: &str =
    "breakdown torque is 2-3 x rated (IEC 60034-12, NEMA MG 1): no steady load beyond it";
/// Negative-sequence admittance relative to the nominal 1/Z2 (real part 0.3..3,
/// imaginary part -1.5..1.5). Z2 is about the locked-rotor impedance (NEMA MG 1 14.35
/// takes the locked-rotor current ratio for it); the rotor's skin effect at twice the
/// supply frequency and data-sheet tolerances keep it within about 0.5 to 2 times the
/// nominal.
pub const Y2_RE: (f64, f64) = (0.3, 3.0);
/// Imaginary part of the relative negative-sequence admittance, see [`Y2_RE`].
pub const Y2_IM: (f64, f64) = (-1.5, 1.5);
/// Basis of [`Y2_RE`].
pub const Y2_BASIS: &str = "the negative-sequence impedance is about the locked-rotor impedance (NEMA MG 1 14.35), within 0.5-2 x nominal";
/// Negative-sequence current over positive-sequence current from a winding asymmetry,
/// each component of `c`: -0.3..0.3 (negative-sequence protection, ANSI 46, trips at 10
/// to 20 %; a machine drawing more is being switched off).
pub const ASYM_C: (f64, f64) = (-0.3, 0.3);
/// Basis of [`ASYM_C`].
pub const ASYM_BASIS: &str =
    "negative-sequence protection (ANSI 46) trips at 10-20 % of the positive-sequence current";
/// Time constants of the dynamics effects (rotor Lr/Rr, stator sigma Ls) relative to
/// nominal: 0.5..2. The rotor resistance changes by -10 % to +60 % from cold to hot
/// (aluminium +0.40 %/K) and with the skin effect at start; the inductances by up to
/// about 30 % with saturation of the main and leakage paths.
pub const DYNAMICS_RATIO: (f64, f64) = (0.5, 2.0);
/// Basis of [`DYNAMICS_RATIO`].
pub const DYNAMICS_BASIS: &str = "resistances change -10..+60 % with temperature, inductances up to 30 % with saturation: within 0.5-2 x nominal";
/// Ra relative to nominal: 0.75..1.6 (copper +0.393 %/K, aluminium +0.40 %/K: -20 C to
/// 155 C is 0.84 to 1.53 times the 20 C value; data-sheet tolerance 10 %).
pub const RA_RATIO: (f64, f64) = (0.75, 1.6);
/// Rr relative to the file's (the ladder's base rung): 0.6..2 (aluminium +0.40 %/K over
/// -20 C to 155 C is 0.84-1.53 x; a locked-rotor test at line frequency reads the skin
/// effect's Rr, up to about 1.3 x the running value; data-sheet tolerance).
pub const RR_RATIO: (f64, f64) = (0.6, 2.0);
/// The leakage inductances relative to the file's (the ladder's base rung): 0.5..2 (the
/// split of a locked-rotor reactance by design class, IEEE 112, and the leakage paths'
/// saturation in a locked-rotor test at high current).
pub const LEAKAGE_RATIO: (f64, f64) = (0.5, 2.0);
/// Lm relative to the file's (the ladder's base rung): 0.6..1.5 (a no-load test's rated
/// point against the unsaturated value, and its tolerance).
pub const LM_RATIO: (f64, f64) = (0.6, 1.5);
/// Ls relative to nominal: 0.7..1.3 (saturation and data-sheet tolerance).
pub const LS_RATIO: (f64, f64) = (0.7, 1.3);
/// J relative to nominal: 0.33..3 (the file's J is rotor plus load; the coupled
/// load's inertia is the usual unknown, a factor 3 either way is a different machine).
pub const J_RATIO: (f64, f64) = (0.33, 3.0);
/// B + Bl: 0 up to the viscous coefficient that carries 1.5 times the rated torque
/// estimate at synchronous speed (or 3 times the nominal, whichever is larger).
pub const BTOT_RATED_TORQUE: f64 = 1.5;
