//! The clock's source at boot (`src/firmware.rs`, `drive_monitor::clock::ClockSource`): the
//! 24 MHz crystal started on the registers with a bounded wait before embassy-stm32's
//! `init` (whose own wait for `HSERDY` has no bound), the PLL fed from it, the HSI as the
//! fallback, said in the boot report and on the panel. The firmware does not run on the
//! host; these checks read its source, so that taking a remedy out fails here.

fn firmware(file: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    std::fs::read_to_string(path).unwrap()
}

fn body<'a>(src: &'a str, signature: &str) -> &'a str {
    let from = &src[src.find(signature).unwrap_or_else(|| panic!("{signature}"))..];
    &from[..from.find("\n}\n").expect("its end")]
}

#[test]
fn the_crystal_is_started_with_a_bound_before_init_and_the_hsi_is_the_fallback() {
    let src = firmware("src/firmware.rs");
    let main = body(&src, "async fn main(");
    let crystal = main.find("start_crystal()").expect("start_crystal in main");
    let init = main
        .find("embassy_stm32::init(clock_config(source))")
        .expect("init");
    assert!(crystal < init);
    assert!(main.contains("set_clock_fallback(source == ClockSource::Hsi)"));
    assert!(main.contains("logs::log_clock(source)"));
    let start = body(&src, "fn start_crystal()");
    for needle in [
        "set_hseon(true)",
        "clock::HSE_STARTUP_TIMEOUT_MS",
        "hserdy()",
        "set_hseon(false)",
        "ClockSource::Hsi",
    ] {
        assert!(start.contains(needle), "start_crystal lacks {needle}");
    }
    let config = body(&src, "fn clock_config(");
    for needle in ["PllSource::HSE", "clock::HSE_HZ", "source.prediv()"] {
        assert!(config.contains(needle), "clock_config lacks {needle}");
    }
}

/// Every defmt frame has a timestamp (the time since boot in us, embassy-time's clock).
#[test]
fn the_log_has_timestamps() {
    let src = firmware("src/firmware.rs");
    let line = src
        .lines()
        .find(|l| l.starts_with("defmt::timestamp!("))
        .expect("a defmt timestamp in src/firmware.rs");
    assert!(
        line.contains("{=u64:us}") && line.contains("Instant::now()"),
        "{line}"
    );
}
