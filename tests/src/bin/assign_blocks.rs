//! Solves random blocks with one assignment method, for
//! `scripts/instructions.sh --assign`, which counts the instructions of
//! [`solve`] under callgrind: the cost of M5.6 per block, by the number of
//! particles in it, without the rest of the step.
//!
//!     assign_blocks DIM K METHOD [BLOCKS]
//!
//! DIM is 2 or 3, K the particles per block (1 to 2^DIM), METHOD
//! `exhaustive`, `exact-fast` or `greedy`, BLOCKS the number of blocks
//! (default 4000): the random blocks of the report's assignment tables
//! (`mpca_tests::measure::assignment::problems`). Prints the blocks solved.

use mpca::assign::{assign_moves, MoveProblem};
use mpca::rng::block_stream;
use mpca::Method;
use mpca_tests::measure::assignment::problems;

/// Every block of `set` with `method`; what callgrind counts.
#[inline(never)]
fn solve<const D: usize>(method: Method, set: &[MoveProblem]) -> u64 {
    let mut rng = block_stream(9, 0, 0);
    set.iter().map(|p| u64::from(assign_moves::<D>(method, std::hint::black_box(p), &mut rng).target[0])).sum()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: assign_blocks DIM K METHOD [BLOCKS]";
    let (Some(dim), Some(k), Some(method)) = (args.first(), args.get(1), args.get(2)) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let dim: u32 = dim.parse().ok().filter(|d| [2, 3].contains(d)).unwrap_or_else(|| panic!("{usage}: DIM is 2 or 3"));
    let k: usize = k.parse().ok().filter(|&k| (1..=1 << dim).contains(&k)).unwrap_or_else(|| panic!("{usage}: K in 1..=2^DIM"));
    let method = match method.as_str() {
        "exhaustive" => Method::Exhaustive,
        "exact-fast" => Method::ExactFast,
        "greedy" => Method::Greedy,
        _ => panic!("{usage}: METHOD is exhaustive, exact-fast or greedy"),
    };
    let blocks: usize = args.get(3).map_or(4000, |b| b.parse().expect("BLOCKS is a number"));
    let set = problems(dim, k, blocks, 5);
    let sum = if dim == 2 { solve::<2>(method, &set) } else { solve::<3>(method, &set) };
    // The sum keeps the work from being optimised away.
    println!("{blocks} blocks ({sum})");
}
