//! What the C test programs share: the workspace root and libmpca, built
//! once per test process by a nested cargo (c_abi.rs and examples.rs use
//! the same target directory and features, so one build serves both).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The workspace root.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("tests/ lies in the workspace")
}

/// The directory holding `libmpca.a` and `libmpca.so` as shipped (default
/// features: no panic boundary, a panic aborts), built once per test process
/// with the `panic-test` feature (for `mpca_debug_panic`), in the `c-test`
/// profile: release code with debug assertions and overflow checks, so that
/// the C tests also meet Rust's checks of unsafe preconditions.
///
/// A nested cargo, because the C programs need the real libraries: mpca-ffi
/// is a staticlib and a cdylib with no rlib, so this crate cannot depend on
/// it and the outer build never produces them for the tests. Its own target
/// directory keeps it off the build directory lock that the outer `cargo
/// test` holds while the tests run.
pub fn library() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| build_library("c-test", "panic-test"))
}

/// The same library built with `catch-panics` (the `c-test-unwind`
/// profile: `c-test` with unwinding panics), whose exports return
/// `MPCA_STATUS_PANIC` instead of aborting: for the test of that boundary.
pub fn catching_library() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| build_library("c-test-unwind", "panic-test,catch-panics"))
}

/// The shipped library (as [`library`]) with ThreadSanitizer compiled in,
/// for the C tests of threads under `MPCA_C_SANITIZE=thread`: built by
/// nightly Rust (`-Zsanitizer=thread`, with `core` and `alloc` rebuilt by
/// `-Zbuild-std` so that their code is instrumented too), so the sanitizer
/// sees the library's own reads and writes, not only the C program's.
/// Needs the nightly toolchain with `rust-src`, as `.ci/run` installs.
pub fn tsan_library() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let target_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("ffi-tsan");
        let triple = env!("MPCA_TEST_HOST");
        let mut cargo = Command::new("cargo");
        // The outer cargo's settings are for the stable build.
        for var in ["RUSTFLAGS", "CARGO_ENCODED_RUSTFLAGS", "RUSTC", "RUSTC_WRAPPER", "RUSTDOC", "RUSTUP_TOOLCHAIN", "CARGO_BUILD_TARGET"] {
            cargo.env_remove(var);
        }
        let out = cargo
            .current_dir(root())
            .env("RUSTFLAGS", "-Zsanitizer=thread")
            .args(["+nightly", "build", "-Zbuild-std=core,alloc", "--target", triple, "--profile", "c-test", "-p", "mpca-ffi"])
            .args(["--features", "panic-test", "--target-dir"])
            .arg(&target_dir)
            .output()
            .expect("cargo +nightly runs");
        assert!(out.status.success(), "building libmpca with ThreadSanitizer failed:\n{}", String::from_utf8_lossy(&out.stderr));
        let dir = target_dir.join(triple).join("c-test");
        assert!(dir.join("libmpca.a").is_file(), "libmpca.a missing from {}", dir.display());
        dir
    })
}

fn build_library(profile: &str, features: &str) -> PathBuf {
    let target_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("ffi");
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| env!("CARGO").into());
    let out = Command::new(cargo)
        .current_dir(root())
        .args(["build", "--profile", profile, "-p", "mpca-ffi", "--features", features, "--target-dir"])
        .arg(&target_dir)
        .output()
        .expect("cargo runs");
    assert!(out.status.success(), "building libmpca ({profile}) failed:\n{}", String::from_utf8_lossy(&out.stderr));
    let dir = target_dir.join(profile);
    for lib in ["libmpca.a", "libmpca.so"] {
        assert!(dir.join(lib).is_file(), "{lib} missing from {}", dir.display());
    }
    // Programs linked with libmpca.so record its SONAME, libmpca.so.MAJOR
    // (ffi/build.rs), and the loader looks for that name: an installed
    // library has the link (scripts/install.sh); here it is made beside
    // the build.
    let soname = dir.join(soname());
    #[cfg(unix)]
    if let Err(e) = std::os::unix::fs::symlink("libmpca.so", &soname) {
        assert_eq!(e.kind(), std::io::ErrorKind::AlreadyExists, "linking {}: {e}", soname.display());
    }
    dir
}

/// The SONAME ffi/build.rs gives libmpca.so: `libmpca.so.MAJOR`, the major
/// version being the workspace's (mpca-ffi's and this crate's).
pub fn soname() -> &'static str {
    concat!("libmpca.so.", env!("CARGO_PKG_VERSION_MAJOR"))
}
