//! [`Method::Exhaustive`](super::Method::Exhaustive), the paper's method
//! and the reference for the others: every permutation of the particles
//! over the free cells, depth first, one optimal leaf kept by reservoir
//! sampling (M5.6).

use super::{dist, Assignment, MoveProblem, MAX_CELLS};
use crate::rules::rng::Stream;

/// The depth-first search of [`Method::Exhaustive`](super::Method::Exhaustive).
struct Search<'a> {
    /// `steps[i][t]`: particle `i` in cell `t` costs `cost1 << 8 | cost2`.
    /// Both sums stay below 256, so comparing packed sums compares
    /// (cost1, cost2) lexicographically; this packing is not the fast
    /// method's weighting, so the reference shares no shortcut with it.
    steps: [[u16; MAX_CELLS]; MAX_CELLS],
    free: u8,
    count: usize,
    /// Cells chosen so far, particle by particle.
    path: [u8; MAX_CELLS],
    /// Best packed cost seen, the leaves at that cost seen so far, and the
    /// one of them the reservoir holds.
    best: u16,
    ties: u32,
    kept: [u8; MAX_CELLS],
    rng: &'a mut Stream,
}

impl Search<'_> {
    /// Particle `i` tries every free cell not in `used`. Leaves are scored
    /// in the loop of the last particle rather than in a call of their own:
    /// half the tree's nodes are leaves.
    fn descend(&mut self, i: usize, used: u8, sum: u16) {
        let row = self.steps[i];
        let last = i + 1 == self.count;
        let mut open = self.free & !used;
        while open != 0 {
            let cell = open.trailing_zeros() as usize;
            open &= open - 1;
            self.path[i] = cell as u8;
            let sum = sum + row[cell];
            if last {
                self.leaf(sum);
            } else {
                self.descend(i + 1, used | 1 << cell, sum);
            }
        }
    }

    #[inline]
    fn leaf(&mut self, cost: u16) {
        if cost < self.best {
            self.best = cost;
            self.ties = 1;
            self.kept = self.path;
        } else if cost == self.best {
            // Reservoir sampling: after n optimal leaves each has been kept
            // with probability 1/n, so the tie-break is uniform.
            self.ties += 1;
            if self.rng.below(self.ties) == 0 {
                self.kept = self.path;
            }
        }
    }
}

pub(super) fn exhaustive(problem: &MoveProblem, free: u8, count: usize, rng: &mut Stream) -> Assignment {
    let mut steps = [[0; MAX_CELLS]; MAX_CELLS];
    for (i, row) in steps.iter_mut().enumerate().take(count) {
        for (cell, step) in (0..).zip(row.iter_mut()) {
            *step = u16::from(dist(cell, problem.desired[i])) << 8
                | u16::from(dist(cell, problem.current[i]));
        }
    }
    let mut search = Search {
        steps,
        free,
        count,
        path: [0; MAX_CELLS],
        best: u16::MAX,
        ties: 0,
        kept: [0; MAX_CELLS],
        rng,
    };
    // No particle: the one (empty) assignment.
    if count > 0 {
        search.descend(0, 0, 0);
    }
    Assignment {
        target: search.kept,
    }
}
