//! mpca in the browser: the page's two scenes (`scene`), and on
//! `wasm32` the exports the page's JavaScript binding (`web/mpca.js`)
//! calls. The core is built as it is everywhere else, `no_std` and
//! without an allocator: each world lives in a static buffer.
//!
//! The same scenes are built natively by `web_hash` (src/bin), and the
//! page test (`scripts/wasm.sh`) holds the browser's world hashes to its.
#![cfg_attr(target_arch = "wasm32", no_std)]
#![deny(missing_docs)]

pub mod scene;

#[cfg(target_arch = "wasm32")]
mod wasm;
