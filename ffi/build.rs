//! Gives the shared library its SONAME on Linux, `libmpca.so.MAJOR`, so a
//! program linked against it records that name (not the file name
//! `libmpca.so`) and keeps loading any later library of the same major
//! version. scripts/install.sh installs the file as
//! `libmpca.so.MAJOR.MINOR.PATCH` with the links `libmpca.so.MAJOR` and
//! `libmpca.so`. The argument reaches only the cdylib's link: the staticlib
//! and firmware targets are untouched.
//!
//! It also sets `personality_in_asm` where a shared library is built and
//! `src/sys.rs` has `rust_eh_personality` in assembly for the target, so
//! that the library exports the `mpca_` functions alone.

fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if os == "linux" {
        let major = std::env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets CARGO_PKG_VERSION_MAJOR");
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libmpca.so.{major}");
    }
    let arch = std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default();
    let asm = match os.as_str() {
        "linux" => matches!(arch.as_str(), "x86_64" | "aarch64" | "arm"),
        "windows" => arch == "x86_64",
        _ => false,
    };
    println!("cargo:rustc-check-cfg=cfg(personality_in_asm)");
    if asm && std::env::var_os("CARGO_FEATURE_CATCH_PANICS").is_none() {
        println!("cargo:rustc-cfg=personality_in_asm");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
