//! What README.md shows a newcomer to copy: every ```rust block is a whole
//! `main.rs` (its own `fn main`, no lines hidden as rustdoc's `# ` lines
//! hide them), so it pastes and runs as it stands. The blocks themselves
//! compile and run as doctests of this crate's library (src/lib.rs
//! includes the README for that).

use std::path::Path;

/// The contents of every ```rust block of README.md, in order.
fn rust_blocks() -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    let readme = std::fs::read_to_string(&path).expect("README.md");
    let mut blocks = Vec::new();
    let mut rest = readme.as_str();
    while let Some(at) = rest.find("```rust\n") {
        let body = &rest[at + "```rust\n".len()..];
        let end = body.find("```").expect("a ```rust block of README.md ends");
        blocks.push(body[..end].to_string());
        rest = &body[end + 3..];
    }
    blocks
}

#[test]
fn every_rust_example_of_the_readme_is_a_whole_main_rs() {
    let blocks = rust_blocks();
    assert!(blocks.len() >= 3, "README.md has {} ```rust blocks", blocks.len());
    for (i, block) in blocks.iter().enumerate() {
        let hidden: Vec<&str> = block.lines().filter(|l| l.trim_start() == "#" || l.trim_start().starts_with("# ")).collect();
        assert!(hidden.is_empty(), "```rust block {} hides lines from a reader: {hidden:?}", i + 1);
        assert!(block.contains("\nfn main(") || block.starts_with("fn main("), "```rust block {} has no fn main:\n{block}", i + 1);
    }
}
