//! What a block's random stream costs to start (M8): the step's
//! counter-based stream (`StepKey::stream`, one multiply and an add per
//! block) against seeding a PCG32 per block from (seed, step, block), the
//! sequential generator M8 would otherwise call for. Each function below
//! starts a stream for each of N blocks and draws the first two outputs
//! (a typical 2D block uses one or two); `scripts/instructions.sh
//! --streams` counts each under callgrind and divides by N.
//!
//!     stream_seeding counter|pcg [blocks]

use std::hint::black_box;

use mpca::rng::StepKey;
use rand_core::Rng;
use rand_pcg::Pcg32;

/// The step's streams: the key is derived once per step, as the step does.
#[inline(never)]
fn counter_streams(seed: u64, step: u64, blocks: u64) -> u64 {
    let key = StepKey::blocks(seed, step);
    let mut acc = 0;
    for b in 0..blocks {
        let mut s = key.stream(black_box(b));
        acc ^= s.next_u64() ^ s.next_u64();
    }
    acc
}

/// A PCG32 seeded per block. Its state and stream number must depend on
/// every bit of (seed, step, block), as the counter stream's do, so each
/// is hashed in with a SplitMix64 finaliser; Pcg32::new then advances the
/// state once, as PCG's seeding prescribes. Two outputs of 64 bits are
/// four of PCG32's 32.
#[inline(never)]
fn pcg_streams(seed: u64, step: u64, blocks: u64) -> u64 {
    let mut acc = 0;
    for b in 0..blocks {
        let b = black_box(b);
        let state = mix(seed ^ mix(step ^ mix(b)));
        let stream = mix(state ^ 0x9e37_79b9_7f4a_7c15);
        let mut rng = Pcg32::new(state, stream);
        acc ^= rng.next_u64() ^ rng.next_u64();
    }
    acc
}

fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let which = args.next().unwrap_or_else(|| "counter".into());
    let blocks: u64 = args.next().map_or(100_000, |n| n.parse().expect("a block count"));
    let acc = match which.as_str() {
        "counter" => counter_streams(black_box(7), black_box(3), blocks),
        "pcg" => pcg_streams(black_box(7), black_box(3), blocks),
        other => panic!("counter or pcg, not {other}"),
    };
    println!("{which} {blocks} blocks {acc:016x}");
}
