//! A report asked in the library's own words (`monitor_api::words::FieldNames`, the default of
//! a request) names fields, never a command line's flags (issue 64): the advice of
//! `diagnose` (commission), `compare` (a later start, the effects to add) and `explain` (the
//! effect to add) in the words a fleet table or a program passes.

use monitor_api::words::FieldNames;
use monitor_api::{AnalysisRequest, DiagnoseRequest, ParamsSource};
use std::path::PathBuf;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/logs")
        .join(name)
}

/// The places `text` names a long flag (`--` then a lowercase letter).
fn flags(text: &str) -> Vec<String> {
    text.match_indices("--")
        .filter(|(k, _)| {
            text.as_bytes()
                .get(k + 2)
                .is_some_and(|c| c.is_ascii_lowercase())
        })
        .map(|(k, _)| text[k.saturating_sub(40)..(k + 20).min(text.len())].to_string())
        .collect()
}

#[test]
fn no_sentence_of_a_report_in_the_librarys_words_names_a_flag() {
    let (log, params) = (
        example("motulator_2p2kw_dol.csv"),
        example("motulator_2p2kw_dol.toml"),
    );
    let p = ParamsSource::Path(&params);
    // diagnose without commissioning: the report advises it.
    let d = monitor_api::diagnose(p, &log, &DiagnoseRequest::default(), &mut |_| {})
        .expect("diagnoses");
    let doc = monitor_api::words::diagnose::document(&d.report, &monitor_api::words::FieldNames);
    let text = doc.to_string();
    assert!(flags(&text).is_empty(), "{:#?}", flags(&text));
    let advice = doc["commissioning"]["advice"]
        .as_str()
        .unwrap_or_default()
        .to_string();
    assert!(
        advice.contains("commission (commission = START:END)"),
        "{advice}"
    );
    // compare over the start: add the dynamics effects.
    let c =
        monitor_api::compare(p, &log, &AnalysisRequest::default(), &FieldNames).expect("compares");
    let text = c.to_string();
    assert!(flags(&text).is_empty(), "{:#?}", flags(&text));
    assert!(text.contains("(effects = "), "{}", c["advice"]);
    // explain past the start: the missing effect, and how to add it.
    let req = AnalysisRequest {
        from_s: Some(0.8),
        ..AnalysisRequest::default()
    };
    let e = monitor_api::explain(p, &log, &req, &monitor_api::words::FieldNames).expect("explains");
    let text = e.to_string();
    assert!(flags(&text).is_empty(), "{:#?}", flags(&text));
    let verdict = e["verdict"].as_str().unwrap_or_default();
    assert!(
        verdict.contains("Add it with effects = load_torque"),
        "{verdict}"
    );
}
