//! Assignment error (M10, M5.6): the extra cost of a method over the exact
//! optimum, and the share of particles not placed where they wanted, on
//! random blocks from one particle (dilute) to every cell (fully packed),
//! in 2D and 3D; with the time each method takes per block.
//!
//! A random block: `k` particles in distinct cells chosen uniformly, each
//! wanting its own cell shifted along each axis with probability 1/2 (every
//! desired cell of M5.3 is inside the block), a uniform squared speed for
//! greedy's ranking, and every cell free. The optimum is the exhaustive
//! search's (the paper's method, the reference of M5.6).

use mpca::assign::{assign_moves, cost, Assignment, MoveProblem};
use mpca::rng::block_stream;
use mpca::Method;

use super::{repeat, SetupRng, Timing, METHODS};

/// `count` random blocks of dimension `dim` with `k` particles.
pub fn problems(dim: u32, k: usize, count: usize, seed: u64) -> Vec<MoveProblem> {
    let cells = 1usize << dim;
    let mut rng = SetupRng::new(seed ^ (u64::from(dim) << 8 | k as u64));
    (0..count)
        .map(|_| {
            let mut p = MoveProblem { free: ((1u16 << cells) - 1) as u8, count: k, ..MoveProblem::default() };
            let mut local: Vec<u8> = (0..cells as u8).collect();
            for i in 0..k {
                // Partial Fisher-Yates: k distinct cells.
                let j = i + rng.below((cells - i) as u32) as usize;
                local.swap(i, j);
                p.current[i] = local[i];
                let mut want = local[i];
                for axis in 0..dim {
                    if rng.unit() < 0.5 {
                        want ^= 1 << axis;
                    }
                }
                p.desired[i] = want;
                p.speed2[i] = rng.below(1 << 16);
            }
            p
        })
        .collect()
}

fn solve(dim: u32, method: Method, problems: &[MoveProblem], seed: u64) -> Vec<Assignment> {
    let mut rng = block_stream(seed, 0, 0);
    problems
        .iter()
        .map(|p| if dim == 2 { assign_moves::<2>(method, p, &mut rng) } else { assign_moves::<3>(method, p, &mut rng) })
        .collect()
}

/// One (dimension, particles per block, method).
#[derive(Clone, Debug)]
pub struct AssignRow {
    /// 2 or 3.
    pub dim: u32,
    /// Particles per block.
    pub k: usize,
    /// The method.
    pub method: Method,
    /// Blocks solved.
    pub blocks: usize,
    /// Mean extra summed distance to the desired cells (M5.6's first cost)
    /// over the optimum, per particle.
    pub excess_cost: f64,
    /// Share of blocks whose (first, second) cost is not the optimum's.
    pub suboptimal_blocks: f64,
    /// Share of particles not placed in their desired cell.
    pub displaced: f64,
    /// Blocks where this method's cost differs from exhaustive's although
    /// the method claims the optimum (0 expected for exact-fast).
    pub mismatches: usize,
    /// Run times of solving all the blocks.
    pub timing: Timing,
}

impl AssignRow {
    /// Median nanoseconds per block.
    pub fn ns_per_block(&self) -> f64 {
        self.timing.median() * 1e9 / self.blocks as f64
    }
}

/// Every k from 1 to the block's cells, every method.
pub fn measure(dim: u32, blocks: impl Fn(usize) -> usize, runs: usize) -> Vec<AssignRow> {
    let cells = 1usize << dim;
    let mut rows = vec![];
    for k in 1..=cells {
        let set = problems(dim, k, blocks(k), 5);
        let optimum: Vec<(u32, u32)> =
            set.iter().zip(solve(dim, Method::Exhaustive, &set, 9)).map(|(p, a)| cost(p, &a)).collect();
        for method in METHODS {
            let (solved, timing) = repeat(runs, || {
                let start = std::time::Instant::now();
                let solved = solve(dim, method, std::hint::black_box(&set), 9);
                let seconds = start.elapsed().as_secs_f64();
                (solved, seconds)
            });
            let (mut excess, mut worse, mut displaced, mut mismatches) = (0u64, 0usize, 0u64, 0usize);
            for ((p, a), &best) in set.iter().zip(&solved).zip(&optimum) {
                let c = cost(p, a);
                excess += u64::from(c.0 - best.0);
                worse += usize::from(c != best);
                if method != Method::Greedy && c != best {
                    mismatches += 1;
                }
                displaced += (0..k).filter(|&i| a.target[i] != p.desired[i]).count() as u64;
            }
            let particles = (set.len() * k) as f64;
            rows.push(AssignRow {
                dim,
                k,
                method,
                blocks: set.len(),
                excess_cost: excess as f64 / particles,
                suboptimal_blocks: worse as f64 / set.len() as f64,
                displaced: displaced as f64 / particles,
                mismatches,
                timing,
            });
        }
    }
    rows
}

/// One method over every k of a dimension, each filling from dilute to
/// packed weighing the same: errors and nanoseconds per block are the means
/// over k of the per-k figures.
#[derive(Clone, Debug)]
pub struct AssignSummary {
    /// 2 or 3.
    pub dim: u32,
    /// The method.
    pub method: Method,
    /// Extra first cost per particle, mean over k.
    pub excess_cost: f64,
    /// Share of particles not placed where they wanted, mean over k.
    pub displaced: f64,
    /// Share of blocks not solved optimally, mean over k.
    pub suboptimal_blocks: f64,
    /// Seconds per block of each run, mean over k.
    pub per_block: Timing,
    /// Blocks in all.
    pub blocks: usize,
}

impl AssignSummary {
    /// Median nanoseconds per block.
    pub fn ns_per_block(&self) -> f64 {
        self.per_block.median() * 1e9
    }
}

/// Summarises the rows of one dimension and method.
pub fn summarise(rows: &[AssignRow], dim: u32, method: Method) -> AssignSummary {
    let mine: Vec<&AssignRow> = rows.iter().filter(|r| r.dim == dim && r.method == method).collect();
    let n = mine.len() as f64;
    let mean = |f: &dyn Fn(&AssignRow) -> f64| mine.iter().map(|r| f(r)).sum::<f64>() / n;
    let runs = mine[0].timing.seconds.len();
    let per_block = Timing {
        seconds: (0..runs).map(|i| mine.iter().map(|r| r.timing.seconds[i] / r.blocks as f64).sum::<f64>() / n).collect(),
    };
    AssignSummary {
        dim,
        method,
        excess_cost: mean(&|r| r.excess_cost),
        displaced: mean(&|r| r.displaced),
        suboptimal_blocks: mean(&|r| r.suboptimal_blocks),
        per_block,
        blocks: mine.iter().map(|r| r.blocks).sum(),
    }
}
