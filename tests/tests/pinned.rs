//! The scene hashes of the last deliberate change of the model's draws.
//!
//! The step may be rewritten for speed without changing a single draw; this
//! test says whether it did. A commit that changes the draws on purpose (a
//! new random protocol, a new rule) updates these hashes and says why; the
//! statistical, conservation and determinism tests are what show that the
//! model itself did not change.

const PINNED: [(&str, u64); 7] = [
    ("aggregation", 0xf95e_a063_c3e9_c0d6),
    ("cluster", 0xcd12_9217_86df_8f0d),
    ("smoke", 0xe616_2efc_7b1a_41c3),
    ("water", 0xd79a_c2c2_50ef_812a),
    ("every-part-Exhaustive", 0xc432_051f_aa39_dddd),
    ("every-part-ExactFast", 0xa0b3_0fff_4049_396a),
    ("every-part-Greedy", 0x277f_2b83_e9e5_cb86),
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
