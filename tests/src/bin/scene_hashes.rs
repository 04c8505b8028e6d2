//! Prints the state hash of the paper's four scenes after their step counts,
//! and of one scene that uses every optional part, one `name hash` line
//! each. `scripts/cross-target.sh` runs it natively and on 32-bit Arm under
//! QEMU and compares: M8 says the same seed and inputs give bit-identical
//! worlds on every target.

fn main() {
    for (name, hash) in mpca_tests::scenes::scene_hashes() {
        println!("{name} {hash:016x}");
    }
}
