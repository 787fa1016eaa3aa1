//! Link with cortex-m-rt's `link.x`, defmt's `defmt.x` and THIS package's `memory.x`
//! (mps2-an386), as `crates/core-on-m4` does: the file is copied into OUT_DIR and that
//! directory is put first on the link search path, so the G474 `memory.x` at the
//! repository root can never be picked up.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR")); // ok: build script
    fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x"); // ok: build script
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        println!("cargo:rustc-link-arg=-Tlink.x");
        println!("cargo:rustc-link-arg=-Tdefmt.x");
    }
}
