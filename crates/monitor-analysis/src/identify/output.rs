//! The parameter file `identify` writes: the start file's, with the identified values in,
//! each line saying where its value came from; the start file's `[columns]` table kept.

use super::{Estimate, Identification};
use monitor_io::nameplate::{toml_entry, toml_number};
use monitor_io::params::ParamFile;

/// The start file with the identified values (the start's where not identified). The
/// leakage is split by the start's stator share; B + Bl by the start's B : Bl ratio.
pub(super) fn written_params(start: &ParamFile, e: &[Estimate], share: f64) -> ParamFile {
    let mut p = *start;
    let v = |k: usize| e.get(k).map_or(f64::NAN, Estimate::written);
    let (leak, lm) = (v(2), v(3));
    p.motor.rs_ohm = v(0);
    p.motor.rr_ohm = v(1);
    p.motor.lm_h = lm;
    p.motor.ls_h = lm + share * leak;
    p.motor.lr_h = lm + (1.0 - share) * leak;
    p.motor.j_kgm2 = v(4);
    let (b0, bl0) = (start.motor.b_nms, start.motor.bl_nms);
    let b_share = if b0 + bl0 > 0.0 { b0 / (b0 + bl0) } else { 1.0 };
    if e.get(5).is_some_and(|x| x.value.is_some()) {
        p.motor.b_nms = b_share * v(5);
        p.motor.bl_nms = (1.0 - b_share) * v(5);
    }
    p
}

/// "Lls" and "Llr": never identified apart (the reason says why and what is kept).
pub(super) fn leakage_split(e: &[Estimate], start: &ParamFile) -> Vec<Estimate> {
    let m = &start.motor;
    let why = "the terminals cannot split the leakage (the linear T-circuit is terminal-equivalent to the \
               inverse-Gamma circuit for any split): Lls + Llr is identified, split as in the start file";
    let unit = e.get(2).map_or("H".to_string(), |x| x.unit.clone());
    [
        ("Lls", "ls_h - lm_h", m.ls_h - m.lm_h),
        ("Llr", "lr_h - lm_h", m.lr_h - m.lm_h),
    ]
    .into_iter()
    .map(|(name, key, start)| Estimate {
        name: name.into(),
        key: key.into(),
        unit: unit.clone(),
        start,
        value: None,
        lo: None,
        hi: None,
        not_identified_because: Some(why.into()),
    })
    .collect()
}

/// Where estimate `e`'s value came from, for a comment.
fn source(e: &Estimate) -> String {
    match (e.value, e.lo, e.hi) {
        (Some(_), Some(lo), Some(hi)) => format!(
            "identified, 95 % interval [{}..{}] {}",
            toml_number(lo),
            toml_number(hi),
            e.unit
        ),
        _ => format!(
            "kept from the start file: {} not identified ({})",
            e.name,
            e.not_identified_because.as_deref().unwrap_or("")
        ),
    }
}

/// The line that opens the identified file's copy of the start file's `[columns]` table
/// ([`to_toml`]; [`without_columns`] cuts the file there).
pub const COLUMNS_COPIED: &str =
    "# The start file's [columns] table: the log's channels and units.\n[columns]\n";

/// The identified file's text ([`to_toml`]) without its copy of the start file's
/// `[columns]` table: a file that reads logs with the standard column names.
pub fn without_columns(toml: &str) -> &str {
    toml.find(COLUMNS_COPIED).map_or(toml, |k| &toml[..k])
}

/// The TOML text of the identified parameter file. `start_text` is the start file's text
/// (its `[columns]` table is copied, after [`COLUMNS_COPIED`]), `start_name` and
/// `log_name` name the inputs.
pub fn to_toml(id: &Identification, start_text: &str, start_name: &str, log_name: &str) -> String {
    let mut s = format!(
        "# Identified by `sim-host identify` (docs/own-motor.md) from {log_name}, {:.3}..{:.3} s\n\
         # ({} samples, {}), starting from {start_name}.\n\
         # Current error RMS {:.2} % of the current's RMS (the start file: {:.2} %). Each value:\n\
         # identified with its 95 % interval, or kept from the start file with the reason.\n[motor]\n",
        id.window_s.0,
        id.window_s.1,
        id.samples,
        if id.speed_imposed { "the measured speed imposed" } else { "no speed channel: the shaft simulated" },
        100.0 * id.relative_rms_error,
        100.0 * id.relative_rms_error_start,
    );
    if let Some(g) = id.inverse_gamma {
        s.push_str(&format!("{}\n", inverse_gamma_line("# ", &g)));
    }
    s.push_str(&motor_entries(id));
    s.push_str("[supply]\n");
    let (v_from, f_from) = match id.supply_from_log {
        Some(l) => (
            format!(
                "the log's (median of its voltage vector; the start file's {} V)",
                toml_number(l.file_v_ll_rms)
            ),
            format!(
                "the log's (its voltage vector's turn; the start file's {} Hz)",
                toml_number(l.file_f_hz)
            ),
        ),
        None => ("from the start file".into(), "from the start file".into()),
    };
    s.push_str(&toml_entry("v_ll_rms", id.params.supply.v_ll_rms, &v_from));
    s.push_str(&toml_entry("f_hz", id.params.supply.f_hz, &f_from));
    let columns = ParamFile::from_toml_str_with_columns(start_text, start_name)
        .map(|(_, c)| c)
        .unwrap_or_default();
    if !columns.is_empty() {
        s.push_str(COLUMNS_COPIED);
        s.push_str(&monitor_io::params::columns_entries_toml(&columns));
    }
    s
}

/// The `[motor]` table's entries of the identified file, each with where its value came
/// from.
fn motor_entries(id: &Identification) -> String {
    let m = &id.params.motor;
    let e = |k: usize| id.estimates.get(k).map(source).unwrap_or_default();
    let share = id.stator_leakage_share;
    let lines = [
        ("rs_ohm", m.rs_ohm, e(0)),
        ("rr_ohm", m.rr_ohm, e(1)),
        (
            "ls_h",
            m.ls_h,
            format!("Lm + Lls, Lls = {share:.3} x (Lls + Llr): Lls + Llr {} (the split kept from the start file: the terminals cannot tell it)", e(2)),
        ),
        ("lr_h", m.lr_h, format!("Lm + Llr, Llr = {:.3} x (Lls + Llr)", 1.0 - share)),
        ("lm_h", m.lm_h, e(3)),
    ];
    let mut s = String::new();
    for (key, v, why) in lines {
        s.push_str(&toml_entry(key, v, &why));
    }
    s.push_str(&format!("poles = {} # from the start file\n", m.poles));
    s.push_str(&toml_entry("j_kgm2", m.j_kgm2, &e(4)));
    let b = e(5);
    s.push_str(&toml_entry(
        "b_nms",
        m.b_nms,
        &format!("B + Bl {b}; split in the start file's ratio B : Bl"),
    ));
    s.push_str(&toml_entry("bl_nms", m.bl_nms, "the rest of B + Bl"));
    s
}

/// The split-free form in one line (for the TOML's comment and the text report).
pub fn inverse_gamma_line(prefix: &str, g: &super::InverseGamma) -> String {
    format!(
        "{prefix}Split-free (inverse-Gamma) form, what the log determines whatever the split: Rs {} ohm, \
         R_R {} ohm, L_sigma {} H, L_M {} H",
        toml_number(g.rs_ohm),
        toml_number(g.r_r_ohm),
        toml_number(g.l_sigma_h),
        toml_number(g.l_m_h)
    )
}
