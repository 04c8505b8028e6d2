//! Solves random blocks with one assignment method, for
//! `scripts/instructions.sh --assign` and `--classes`, which count the
//! instructions of [`solve`] under callgrind: the cost of M5.6 per block, by
//! the number of particles in it (and of free cells), without the rest of
//! the step.
//!
//!     assign_blocks DIM K METHOD [BLOCKS [FREE [raw] [searched] [each]]]
//!
//! DIM is 2 or 3, K the particles per block (1 to 2^DIM), METHOD
//! `exhaustive`, `exact-fast` or `greedy`, BLOCKS the number of blocks
//! (default 4000): the random blocks of the report's assignment tables
//! (`mpca_tests::measure::assignment::problems`). FREE (K to 2^DIM, default
//! 2^DIM) is the number of free cells of each block: the K cells the
//! particles are in and FREE - K of the others, drawn at random; the rest
//! are blocked. A particle that wants a blocked cell then stays, as M5.4
//! makes that wish in the step, unless `raw` is given: then it keeps the
//! wish, as a direct caller of `assign_moves` may pose it. With `each`,
//! [`solve`] is called once with no block and then once per block (a fresh
//! stream each time), for `--per-block`, which has callgrind dump a
//! profile before each call and so counts every block apart. Prints the
//! blocks solved.

use mpca::assign::{assign_moves, MoveProblem};
use mpca::rng::block_stream;
use mpca::Method;
use mpca_tests::measure::assignment::problems;
use mpca_tests::setup::SetupRng;

/// Every block of `set` with `method`; what callgrind counts.
#[inline(never)]
fn solve<const D: usize>(method: Method, set: &[MoveProblem]) -> u64 {
    let mut rng = block_stream(9, 0, 0);
    set.iter().map(|p| u64::from(assign_moves::<D>(method, std::hint::black_box(p), &mut rng).target[0])).sum()
}

/// Leaves `free` cells of each block of `set` free (`cells` in all): its
/// particles' cells and others drawn by a stream of its own, so that the
/// particles, their wishes and speeds stay those of `problems`. Without
/// `raw`, a wish for a blocked cell becomes staying.
fn block_cells(set: &mut [MoveProblem], cells: usize, free: usize, raw: bool, seed: u64) {
    let mut rng = SetupRng::new(seed << 16 ^ 0xb10c ^ (free as u64) << 8);
    for p in set {
        let count = p.count;
        p.free = p.current[..count].iter().fold(0, |bits, &c| bits | 1 << c);
        let mut others: Vec<u8> = (0..cells as u8).filter(|&c| p.free >> c & 1 == 0).collect();
        for i in 0..free - count {
            // Partial Fisher-Yates: free - count distinct cells.
            let j = i + rng.below((others.len() - i) as u32) as usize;
            others.swap(i, j);
            p.free |= 1 << others[i];
        }
        if !raw {
            for i in 0..count {
                if p.free >> p.desired[i] & 1 == 0 {
                    p.desired[i] = p.current[i];
                }
            }
        }
    }
}

/// Whether two particles of `p` want one cell or one wants a blocked cell:
/// the blocks no method settles by giving everyone their wish.
fn needs_search(p: &MoveProblem) -> bool {
    let wants = &p.desired[..p.count];
    wants.iter().enumerate().any(|(i, &w)| p.free >> w & 1 == 0 || wants[..i].contains(&w))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: assign_blocks DIM K METHOD [BLOCKS [FREE [raw] [searched] [each]]]";
    let (Some(dim), Some(k), Some(method)) = (args.first(), args.get(1), args.get(2)) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let dim: u32 = dim.parse().ok().filter(|d| [2, 3].contains(d)).unwrap_or_else(|| panic!("{usage}: DIM is 2 or 3"));
    let cells = 1usize << dim;
    let k: usize = k.parse().ok().filter(|&k| (1..=cells).contains(&k)).unwrap_or_else(|| panic!("{usage}: K in 1..=2^DIM"));
    let method = match method.as_str() {
        "exhaustive" => Method::Exhaustive,
        "exact-fast" => Method::ExactFast,
        "greedy" => Method::Greedy,
        _ => panic!("{usage}: METHOD is exhaustive, exact-fast or greedy"),
    };
    let blocks: usize = args.get(3).map_or(4000, |b| b.parse().expect("BLOCKS is a number"));
    let free: usize = args.get(4).map_or(cells, |f| {
        f.parse().ok().filter(|f| (k..=cells).contains(f)).unwrap_or_else(|| panic!("{usage}: FREE in K..=2^DIM"))
    });
    let words = &args[args.len().min(5)..];
    let raw = words.iter().any(|w| w == "raw");
    let searched = words.iter().any(|w| w == "searched");
    let each = words.iter().any(|w| w == "each");
    assert!(words.iter().all(|w| ["raw", "searched", "each"].contains(&w.as_str())), "{usage}");
    let mut set = Vec::with_capacity(blocks);
    for seed in 5..69 {
        let mut batch = problems(dim, k, blocks, seed);
        if free < cells {
            block_cells(&mut batch, cells, free, raw, seed);
        }
        set.extend(batch.into_iter().filter(|p| !searched || needs_search(p)));
        if set.len() >= blocks {
            break;
        }
    }
    if set.is_empty() {
        println!("no such blocks");
        return;
    }
    set.truncate(blocks);
    let blocks = set.len();
    let sum = match (dim, each) {
        (2, false) => solve::<2>(method, &set),
        (_, false) => solve::<3>(method, &set),
        // A call with no block first, whose count is what a call costs
        // besides its blocks.
        (2, true) => solve::<2>(method, &[]) + set.iter().map(|p| solve::<2>(method, std::slice::from_ref(p))).sum::<u64>(),
        (_, true) => solve::<3>(method, &[]) + set.iter().map(|p| solve::<3>(method, std::slice::from_ref(p))).sum::<u64>(),
    };
    // The sum keeps the work from being optimised away.
    println!("{blocks} blocks ({sum})");
}
