//! Gives the shared library its SONAME on Linux, `libmpca.so.MAJOR`, so a
//! program linked against it records that name (not the file name
//! `libmpca.so`) and keeps loading any later library of the same major
//! version. scripts/install.sh installs the file as
//! `libmpca.so.MAJOR.MINOR.PATCH` with the links `libmpca.so.MAJOR` and
//! `libmpca.so`. The argument reaches only the cdylib's link: the staticlib
//! and firmware targets are untouched.

fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if os == "linux" {
        let major = std::env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets CARGO_PKG_VERSION_MAJOR");
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libmpca.so.{major}");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
