//! Build script: linker arguments for the firmware target only.
//!
//! On the host (`cargo test`) nothing is emitted, so the root package links as a normal
//! program. For `target_os = "none"` it adds cortex-m-rt's `link.x` (which includes the
//! root `memory.x`) and defmt's `defmt.x`.

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    let target_os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target_os == "none" {
        let dir = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default();
        println!("cargo:rustc-link-search={dir}");
        println!("cargo:rustc-link-arg-bins=--nmagic");
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
}
