//! Gives the shared library its SONAME on Linux, `libmpca.so.MAJOR`, so a
//! program linked against it records that name (not the file name
//! `libmpca.so`) and keeps loading any later library of the same major
//! version. scripts/install.sh installs the file as
//! `libmpca.so.MAJOR.MINOR.PATCH` with the links `libmpca.so.MAJOR` and
//! `libmpca.so`. The argument reaches only the cdylib's link: the staticlib
//! and firmware targets are untouched. The version script `exports.map`
//! keeps the dynamic symbol table to the `mpca_` functions.

fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if os == "linux" {
        let major = std::env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets CARGO_PKG_VERSION_MAJOR");
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libmpca.so.{major}");
        // Only the header's functions in the dynamic symbol table
        // (exports.map says why a second version script is needed).
        let dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
        println!("cargo:rustc-cdylib-link-arg=-Wl,--version-script={dir}/exports.map");
        println!("cargo:rerun-if-changed=exports.map");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
