//! The scene hashes of the last deliberate change of the model's draws.
//!
//! The step may be rewritten for speed without changing a single draw; this
//! test says whether it did. A commit that changes the draws on purpose (a
//! new random protocol, a new rule) updates these hashes and says why; the
//! statistical, conservation and determinism tests are what show that the
//! model itself did not change.

const PINNED: [(&str, u64); 7] = [
    ("aggregation", 0xded8_21e5_62af_ff54),
    ("cluster", 0x1850_a97c_efcf_d232),
    ("smoke", 0xb60d_4363_9d16_eb72),
    ("water", 0xfd3e_26ed_33bf_9a34),
    ("every-part-Exhaustive", 0x7f96_b228_22d0_8746),
    ("every-part-ExactFast", 0x8723_95ae_7858_6fc3),
    ("every-part-Greedy", 0x953f_53c4_a077_ae2c),
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
