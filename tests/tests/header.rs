//! `include/mpca.h` is exactly what the pinned cbindgen generates from
//! `ffi/src` with `ffi/cbindgen.toml` (STYLE.md: never edited by hand).
//! `MPCA_BLESS=1 cargo test -p mpca-tests --test header` rewrites it.

use std::path::Path;

#[test]
fn header_matches_cbindgen_output() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let ffi = root.join("ffi");
    let config = cbindgen::Config::from_file(ffi.join("cbindgen.toml")).expect("ffi/cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_crate(&ffi)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let path = root.join("include/mpca.h");
    if std::env::var_os("MPCA_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == generated,
        "include/mpca.h differs from cbindgen's output; regenerate with \
         `MPCA_BLESS=1 cargo test -p mpca-tests --test header` and commit it"
    );
}
