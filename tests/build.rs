//! Hands the target and host triples to the C ABI tests (tests/c_abi.rs):
//! the cc crate needs them to pick and configure the C compiler, and cargo
//! gives them only to build scripts.

fn main() {
    for (from, to) in [("TARGET", "MPCA_TEST_TARGET"), ("HOST", "MPCA_TEST_HOST")] {
        let triple = std::env::var(from).unwrap_or_else(|_| panic!("cargo sets {from} for build scripts"));
        println!("cargo:rustc-env={to}={triple}");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
