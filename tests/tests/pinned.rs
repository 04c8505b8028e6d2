//! The scene hashes of the last deliberate change of the model's draws.
//!
//! The step may be rewritten for speed without changing a single draw; this
//! test says whether it did. A commit that changes the draws on purpose (a
//! new random protocol, a new rule) updates these hashes and says why; the
//! statistical, conservation and determinism tests are what show that the
//! model itself did not change.

const PINNED: [(&str, u64); 7] = [
    ("aggregation", 0x4f0a_7b5f_950f_f8fe),
    ("cluster", 0x414b_a7f0_2d7f_b502),
    ("smoke", 0xfcb2_7b76_d877_385b),
    ("water", 0x8fdd_31aa_a8ba_896f),
    ("every-part-Exhaustive", 0x94cb_cfad_100e_4e61),
    ("every-part-ExactFast", 0x1df0_9e5c_18a9_f91a),
    ("every-part-Greedy", 0x489a_91a0_1e73_eb78),
];

#[test]
fn scene_hashes_are_pinned() {
    let got = mpca_tests::scenes::scene_hashes();
    let names: Vec<&str> = got.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, PINNED.map(|(n, _)| n), "the list of pinned scenes changed");
    let differ: Vec<String> = got
        .iter()
        .zip(PINNED)
        .filter(|((_, h), (_, want))| h != want)
        .map(|((n, h), (_, want))| format!("{n}: {h:#018x}, pinned {want:#018x}"))
        .collect();
    assert!(differ.is_empty(), "scene hashes changed:\n{}", differ.join("\n"));
}
