//! One step of the automaton: emitters (M6), then the local map of M5 on
//! every occupied block of the step's Margolus partition (M3), then the
//! counters and the step number.
//!
//! The description fixes, once per step, which specialised block routine
//! runs (M9): the stored velocity width, the dimension and the force path
//! are compile-time parameters of [`Kernel`], so a scene pays nothing in its
//! inner loop for the parts it does not use.

use crate::layout::Layout;
use crate::force::ForceTerms;
use crate::kernel::{Kernel, Shared, Writable};
use crate::partition::Partition;
use crate::quant::Quant;
use crate::rng::StepKey;
use crate::layout::{groups, Planes};
use crate::world::{Counters, World};

/// The block order of a step. Blocks are independent (M3, M8); the reverse
/// order exists so tests can show that the result does not depend on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// x fastest, then y, then z.
    Forward,
    /// Exactly the reverse.
    Reverse,
}

/// How a step visits its blocks: in which order, and whether blocks of a
/// plain world may take the lean routine.
#[derive(Clone, Copy)]
pub(crate) struct Route {
    reverse: bool,
    lean: bool,
    /// Skip rows and words the summaries say are empty.
    skip: bool,
}

impl World {
    /// Advances the world `n` steps.
    pub fn step(&mut self, n: u64) {
        for _ in 0..n {
            self.step_in_order(Order::Forward);
        }
    }

    /// Advances one step, visiting blocks in `order`. The result is the
    /// same bit for bit either way (M8).
    ///
    /// Never inlined: `scripts/instructions.sh` counts the instructions
    /// spent inside it.
    #[inline(never)]
    pub fn step_in_order(&mut self, order: Order) {
        self.step_routed(Route { reverse: order == Order::Reverse, lean: true, skip: true });
    }

    /// Advances one step with every block through the block routine that
    /// handles every part (none through the lean one that plain worlds use
    /// away from the faces), and with every row and word of the occupancy
    /// swept (none skipped on the summaries' word). The world is the same
    /// bit for bit: the tests compare the two (feature `reference`).
    #[cfg(feature = "reference")]
    pub fn step_reference(&mut self) {
        self.step_routed(Route { reverse: false, lean: false, skip: false });
    }

    fn step_routed(&mut self, route: Route) {
        self.emit();
        crate::quant::with_quant!(self.head.desc.quantization, Q => {
            match self.head.desc.dim {
                #[cfg(feature = "dim3")]
                3 => with_force::<Q, 3, 8>(self, route),
                _ => with_force::<Q, 2, 4>(self, route),
            }
        });
        self.head.step += 1;
    }

    /// Runs `visit` over the step's partition with the step's shared data and
    /// the writable planes, and adds the counters it returns to the world's.
    pub(crate) fn sweep_with<Q: Quant, const D: usize>(
        &mut self,
        route: Route,
        visit: impl FnOnce(&Shared<'_>, Writable<'_, Q, D>, bool) -> Counters,
    ) {
        let part = Partition::new(self.layout(), &self.head.desc.boundary, self.dim(), self.head.step);
        let periodic = self.periodic();
        let dim = self.dim();
        let (head, p) = self.planes::<Q>();
        let desc = head.desc;
        let Layout { n, .. } = head.layout;
        let Planes { occupancy, rows, words, obstacle, velocity, mass_index, life, field, potential, mass_table, surface, .. } = p;
        let terms = ForceTerms {
            gravity: if desc.forces.uniform { desc.gravity } else { [0.0; 3] },
            field: desc.forces.field.then_some(&*field),
            potential: desc.forces.potential.then_some(&*potential),
            vortex: desc.forces.vortex.then_some(desc.vortex),
            n,
            periodic,
            dim,
        };
        let dt_q = desc.dt * Q::SCALE;
        let push = terms.gravity.map(|g| if dt_q == 0.0 { 0.0 } else { g * dt_q });
        let shared = Shared {
            desc,
            n,
            part,
            key: StepKey::blocks(desc.seed, head.step),
            obstacle,
            surface: &surface[..head.surfaces as usize],
            mass_table,
            push: (push != [0.0; 3]).then_some(push),
            terms,
            dt_q,
            moves: crate::quant::move_table_8(desc.drift),
            plain: route.lean && !desc.per_particle_mass && !desc.lifetimes,
        };
        let c = visit(&shared, Writable { occupancy, rows, words, velocity: groups(velocity), mass_index, life }, route.reverse);
        let h = &mut head.counters;
        h.exited += c.exited;
        h.expired += c.expired;
        h.particles -= c.exited + c.expired;
        h.collisions += c.collisions;
        h.clamps += c.clamps;
        h.clamp_energy = h.clamp_energy.saturating_add(c.clamp_energy);
        h.displaced += c.displaced;
        h.processed = c.processed;
        h.skipped = part.total_blocks() - c.processed;
    }
}

/// Picks the force path (M9): fields, potentials and the vortex are summed
/// per particle; a uniform force alone is one precomputed change.
fn with_force<Q: Quant, const D: usize, const CELLS: usize>(w: &mut World, route: Route) {
    #[cfg(feature = "fields")]
    if w.head.desc.forces.any_field() {
        return run::<Q, D, CELLS, true>(w, route);
    }
    run::<Q, D, CELLS, false>(w, route)
}

fn run<Q: Quant, const D: usize, const CELLS: usize, const GENERAL: bool>(w: &mut World, route: Route) {
    w.sweep_with::<Q, D>(route, |shared, planes, reverse| {
        let mut kernel = Kernel::<Q, D, CELLS, GENERAL> { shared, planes, counters: Counters::default() };
        shared.part.sweep(&mut kernel, reverse, route.skip);
        kernel.counters
    });
}
