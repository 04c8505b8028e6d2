//! [`Method::Greedy`](super::Method::Greedy), the paper's 3D approximation
//! (M5.6): the particles, fastest first, each take their best untaken cell.

use super::{move_costs, Assignment, MoveProblem, MAX_CELLS};
use crate::rules::rng::Stream;

pub(super) fn greedy(problem: &MoveProblem, free: u8, count: usize, rng: &mut Stream) -> Assignment {
    // Fastest first; a stable insertion sort keeps equal speeds in problem
    // order (and a NaN speed where it is).
    let mut order = [0usize; MAX_CELLS];
    for i in 0..count {
        let mut slot = i;
        while slot > 0 && problem.speed2[order[slot - 1]] < problem.speed2[i] {
            order[slot] = order[slot - 1];
            slot -= 1;
        }
        order[slot] = i;
    }
    let costs = move_costs(problem, count);
    let mut taken = 0u8;
    let mut assignment = Assignment::default();
    for &i in &order[..count] {
        let mut best = u8::MAX;
        let mut tied = [0u8; MAX_CELLS];
        let mut ties = 0;
        let mut open = free & !taken;
        while open != 0 {
            let cell = open.trailing_zeros() as u8;
            open &= open - 1;
            let c = costs[i][usize::from(cell)];
            if c < best {
                best = c;
                ties = 0;
            }
            if c == best {
                tied[ties] = cell;
                ties += 1;
            }
        }
        let pick = if ties > 1 { rng.below(ties as u32) as usize } else { 0 };
        let cell = tied[pick];
        assignment.target[i] = cell;
        taken |= 1 << cell;
    }
    assignment
}

#[cfg(test)]
mod tests {
    use crate::rules::assign::tests::block;
    use crate::rules::assign::{assign_moves, Method};
    use crate::rules::rng::block_stream;

    #[test]
    fn greedy_serves_the_fastest_first() {
        // Expect: two particles want the empty cell 0 of a 3D block; greedy
        // gives it to the faster one whichever is listed first, and the
        // slower one stays.
        let mut rng = block_stream(4, 0, 0);
        for fast in 0..2 {
            let mut problem = block(0xff, &[1, 2], &[0, 0]);
            problem.speed2[fast] = 2;
            problem.speed2[1 - fast] = 1;
            let a = assign_moves::<3>(Method::Greedy, &problem, &mut rng);
            assert_eq!(a.target[fast], 0);
            assert_eq!(a.target[1 - fast], problem.current[1 - fast]);
        }
    }
}
