//! The scene hashes of the last deliberate change of the model's draws.
//!
//! The step may be rewritten for speed without changing a single draw; this
//! test says whether it did. A commit that changes the draws on purpose (a
//! new random protocol, a new rule) updates these hashes and says why; the
//! statistical, conservation and determinism tests are what show that the
//! model itself did not change.

const PINNED: [(&str, u64); 7] = [
    ("aggregation", 0xe4bc_b510_ff56_5b07),
    ("cluster", 0xe11d_8be6_4ca8_5340),
    ("smoke", 0x364d_5185_3028_84a5),
    ("water", 0x9de9_62cb_bfc4_4d25),
    ("every-part-Exhaustive", 0x0114_0269_18cb_6142),
    ("every-part-ExactFast", 0xfeb2_bbca_eb4b_f40f),
    ("every-part-Greedy", 0x98ed_6cff_3fa6_3d2a),
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
