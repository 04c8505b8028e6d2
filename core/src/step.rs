//! One step of the automaton: emitters (M6), then the local map of M5 on
//! every occupied block of the step's Margolus partition (M3).
//!
//! The description fixes, once per step, which specialised block routine
//! runs (M9): dimension, stored velocity width, obstacles, the force path
//! and per-particle masses are compile-time parameters of it, so a scene pays
//! nothing in its inner loop for the parts it does not use.
//!
//! Inside a block velocities are `f32` in quanta (`v * SCALE`): eqs. 7-9 are
//! linear, so they hold in any unit, and a velocity nothing touched is an
//! exact integer that is stored back unchanged.

use crate::assign::{assign_moves, MoveProblem, MAX_CELLS};
use crate::collision::{block_pairs, clamp, collide_pair, dot, random_unit};
use crate::desc::{Boundary, Description, Drift};
use crate::force::ForceTerms;
use crate::obstacle::{normalise, reflect, surface_at, Surface};
use crate::partition::{BlockSink, Partition};
use crate::quant::Quant;
use crate::rng::{below, block_stream, chance, Stream};
use crate::world::{put_bit, test_bit, Counters, Planes, Site, World, ENERGY_SCALE};

/// No force term.
pub(crate) const FORCE_NONE: u8 = 0;
/// A uniform acceleration only: one precomputed velocity change.
pub(crate) const FORCE_UNIFORM: u8 = 1;
/// Fields, potentials or the vortex: evaluated per particle.
#[cfg_attr(not(feature = "fields"), allow(dead_code))]
pub(crate) const FORCE_GENERAL: u8 = 2;

/// The block order of a step. Blocks are independent (M3, M8); the reverse
/// order exists so tests can show that the result does not depend on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// x fastest, then y, then z.
    Forward,
    /// Exactly the reverse.
    Reverse,
}

struct Ctx<'a, Q, const D: usize, const OBST: bool, const FORCE: u8, const MASS: bool> {
    occupancy: &'a mut [u64],
    obstacle: &'a [u64],
    velocity: &'a mut [Q],
    mass_index: &'a mut [u8],
    life: &'a mut [u16],
    mass_table: &'a [f32],
    surface: &'a [Surface],
    terms: ForceTerms<'a>,
    part: Partition,
    desc: Description,
    layout: crate::desc::Layout,
    step: u64,
    /// `dt * g` in quanta, for the uniform force path.
    dv: [f32; 3],
    /// `dt * SCALE`: turns an acceleration into quanta per step.
    dt_q: f32,
    counters: Counters,
}

/// The gathered state of one block.
struct Block {
    site: [Site; MAX_CELLS],
    pos: [[usize; 3]; MAX_CELLS],
    /// Cells inside the domain.
    inside: u8,
    /// Cells holding a particle.
    occ: u8,
    /// Obstacle cells and cells beyond a wall face: no particle may go there.
    blocked: u8,
    /// Cells beyond an open face: a particle going there leaves.
    open: u8,
    /// Inward normal of each cell beyond a wall.
    wall_normal: [[f32; 3]; MAX_CELLS],
    v: [[f32; 3]; MAX_CELLS],
    mass: [f32; MAX_CELLS],
    class: [u8; MAX_CELLS],
    life: [u16; MAX_CELLS],
}

/// Iterates the set bits of a block mask, lowest first.
#[inline]
fn cells_of(mut mask: u8) -> impl Iterator<Item = usize> {
    core::iter::from_fn(move || {
        (mask != 0).then(|| {
            let c = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            c
        })
    })
}

impl<Q: Quant, const D: usize, const OBST: bool, const FORCE: u8, const MASS: bool> Ctx<'_, Q, D, OBST, FORCE, MASS> {
    /// M5.5: clamp and count.
    #[inline]
    fn clamp(&mut self, v: &mut [f32; 3], m: f32) {
        // In quanta |v| <= SCALE; compare in unit speed.
        let mut u = v.map(|c| c * (1.0 / Q::SCALE));
        if let Some(energy) = clamp(&mut u, m) {
            *v = u.map(|c| c * Q::SCALE);
            self.counters.clamps += 1;
            let fixed = (energy * ENERGY_SCALE) as u128; // saturating cast
            self.counters.clamp_energy = self.counters.clamp_energy.saturating_add(fixed);
        }
    }

    /// M5.3: the probability of wanting a move along an axis.
    #[inline]
    fn move_probability(&self, speed: f32) -> f32 {
        match self.desc.drift {
            Drift::Paper => speed,
            Drift::Calibrated => 2.0 * speed / (1.0 + speed),
        }
    }

    fn gather(&self, origin: [isize; 3]) -> Block {
        let mut b = Block {
            site: [Site { cell: 0, bit: 0 }; MAX_CELLS],
            pos: [[0; 3]; MAX_CELLS],
            inside: 0,
            occ: 0,
            blocked: 0,
            open: 0,
            wall_normal: [[0.0; 3]; MAX_CELLS],
            v: [[0.0; 3]; MAX_CELLS],
            mass: [self.desc.mass; MAX_CELLS],
            class: [0; MAX_CELLS],
            life: [0; MAX_CELLS],
        };
        for c in 0..1usize << D {
            let mut pos = [0usize; 3];
            let mut wall = [0.0f32; 3];
            let (mut is_wall, mut is_open) = (false, false);
            for k in 0..D {
                let d = (c >> k) & 1;
                match self.part.coord(k, origin[k], d) {
                    Some(x) => pos[k] = x,
                    None => {
                        let high = origin[k] + d as isize >= 0;
                        match self.desc.boundary[k][usize::from(high)] {
                            Boundary::Wall => {
                                is_wall = true;
                                wall[k] = if high { -1.0 } else { 1.0 };
                            }
                            _ => is_open = true,
                        }
                    }
                }
            }
            let bit = 1u8 << c;
            if is_wall {
                // M4: beyond a wall is an obstacle with the face's inward
                // normal (the normalised sum where two walls meet).
                b.blocked |= bit;
                b.wall_normal[c] = normalise(wall).unwrap_or([0.0; 3]);
            } else if is_open {
                b.open |= bit;
            } else {
                let s = self.layout.site(pos[0], pos[1], pos[2]);
                b.site[c] = s;
                b.pos[c] = pos;
                b.inside |= bit;
                if OBST && test_bit(self.obstacle, s.bit) {
                    b.blocked |= bit;
                }
                if test_bit(self.occupancy, s.bit) {
                    b.occ |= bit;
                    for k in 0..D {
                        b.v[c][k] = self.velocity[s.cell * D + k].to_int() as f32;
                    }
                    if MASS {
                        let class = self.mass_index[s.cell];
                        b.class[c] = class;
                        b.mass[c] = self.mass_table[usize::from(class)];
                    }
                    if self.desc.lifetimes {
                        b.life[c] = self.life[s.cell];
                    }
                }
            }
        }
        b
    }

    /// The local map of M5 on one block.
    fn process(&mut self, origin: [isize; 3], index: u64) {
        let mut rng: Stream = block_stream(self.desc.seed, self.step, index);
        let mut b = self.gather(origin);

        // M5.1 external force: v <- v + dt F / m (eqs. 4-5).
        if FORCE != FORCE_NONE {
            for c in cells_of(b.occ) {
                let dv = if FORCE == FORCE_UNIFORM {
                    self.dv
                } else {
                    // dt = 0 means no change, even for an infinite force
                    // (0 * inf would be NaN).
                    self.terms.accel(b.pos[c], b.site[c].cell, b.mass[c]).map(|a| if self.dt_q == 0.0 { 0.0 } else { a * self.dt_q })
                };
                // A force that changes nothing is no step 1: a zero-valued
                // part gives the same world as a world without it (M9).
                if dv == [0.0; 3] {
                    continue;
                }
                for k in 0..D {
                    b.v[c][k] += dv[k];
                }
                let m = b.mass[c];
                self.clamp(&mut b.v[c], m);
            }
        }

        // M5.2 collision: one of the block's pairs, uniformly (eqs. 7-8).
        let count = b.occ.count_ones() as usize;
        if count >= 2 {
            let pairs = block_pairs::<D>();
            let (p, q) = pairs[below(&mut rng, pairs.len() as u32) as usize];
            let (p, q) = (usize::from(p), usize::from(q));
            if b.occ & (1 << p) != 0 && b.occ & (1 << q) != 0 {
                let r = random_unit::<D, _>(&mut rng);
                let (vp, vq) = collide_pair(b.v[p], b.v[q], b.mass[p], b.mass[q], self.desc.restitution, r);
                b.v[p] = vp;
                b.v[q] = vq;
                self.counters.collisions += 1;
                self.clamp(&mut b.v[p], b.mass[p]);
                self.clamp(&mut b.v[q], b.mass[q]);
            }
        }

        // M5.3 desired move, M5.4 obstacle reflection.
        let mut problem = MoveProblem { free: !b.blocked & ((1u16 << (1 << D)) - 1) as u8, count, ..Default::default() };
        for (i, c) in cells_of(b.occ).enumerate() {
            let mut want = c;
            for k in 0..D {
                let vk = b.v[c][k];
                let low_side = (c >> k) & 1 == 0;
                // Only a move that stays inside the block can be wanted.
                if (vk > 0.0 && low_side) || (vk < 0.0 && !low_side) {
                    let p = self.move_probability(vk.abs() * (1.0 / Q::SCALE));
                    if chance(&mut rng, p) {
                        want ^= 1 << k;
                    }
                }
            }
            if want != c && b.blocked & (1 << want) != 0 {
                let (n, e) = if b.inside & (1 << want) != 0 {
                    let cell = b.site[want].cell as u32;
                    match surface_at(self.surface, cell) {
                        Some(s) => (s.normal, s.restitution),
                        // Unreachable for obstacles added through the API
                        // (every cell next to a free one has an entry); fall
                        // back to the direction back to the particle.
                        None => (back_normal::<D>(c, want), self.desc.wall_restitution),
                    }
                } else {
                    (b.wall_normal[want], self.desc.wall_restitution)
                };
                // A normal that does not face the incoming particle (a
                // half-space seen across a periodic seam, a mask corner) would
                // leave it pressing on the obstacle for ever: reflect off the
                // face it came through instead.
                let n = if dot(b.v[c], n) < 0.0 { n } else { back_normal::<D>(c, want) };
                b.v[c] = reflect(b.v[c], n, e); // eq. 9
                let m = b.mass[c];
                self.clamp(&mut b.v[c], m);
                want = c;
            }
            problem.current[i] = c as u8;
            problem.desired[i] = want as u8;
            problem.speed2[i] = dot(b.v[c], b.v[c]);
        }

        // M5.6 move.
        let moves = assign_moves::<D, _>(self.desc.method, &problem, &mut rng);
        for c in cells_of(b.occ) {
            put_bit(self.occupancy, b.site[c].bit, false);
        }
        for i in 0..count {
            let (c, t) = (usize::from(problem.current[i]), usize::from(moves.target[i]));
            self.counters.displaced += u64::from(moves.target[i] != problem.desired[i]);
            if b.open & (1 << t) != 0 {
                self.counters.exited += 1; // M4 open face
                continue;
            }
            let mut life = b.life[c];
            if self.desc.lifetimes && life > 0 {
                if life == 1 {
                    self.counters.expired += 1; // M6 lifetime
                    continue;
                }
                life -= 1;
            }
            let s = b.site[t];
            put_bit(self.occupancy, s.bit, true);
            for k in 0..D {
                self.velocity[s.cell * D + k] = Q::stochastic(b.v[c][k], &mut rng);
            }
            if MASS {
                self.mass_index[s.cell] = b.class[c];
            }
            if self.desc.lifetimes {
                self.life[s.cell] = life;
            }
        }
        self.counters.processed += 1;
    }
}

/// A unit normal from cell `to` back towards cell `from` of the same block.
fn back_normal<const D: usize>(from: usize, to: usize) -> [f32; 3] {
    let mut n = [0.0f32; 3];
    for (k, nk) in n.iter_mut().enumerate().take(D) {
        let (f, t) = ((from >> k) & 1, (to >> k) & 1);
        *nk = f as f32 - t as f32;
    }
    normalise(n).unwrap_or([0.0; 3])
}

impl<Q: Quant, const D: usize, const OBST: bool, const FORCE: u8, const MASS: bool> BlockSink
    for Ctx<'_, Q, D, OBST, FORCE, MASS>
{
    fn occupancy(&self) -> &[u64] {
        self.occupancy
    }

    fn visit(&mut self, origin: [isize; 3], index: u64) {
        self.process(origin, index);
    }
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
        self.emit();
        let reverse = order == Order::Reverse;
        let d = self.head.desc;
        with_dim_and_quant(self, d.dim, reverse);
        self.head.step += 1;
    }

    fn run<Q: Quant, const D: usize, const OBST: bool, const FORCE: u8, const MASS: bool>(&mut self, reverse: bool) {
        let dim = self.dim();
        let periodic = self.periodic();
        let part = Partition::new(self.layout(), &self.head.desc.boundary, dim, self.head.step);
        let (head, p) = self.planes::<Q>();
        let desc = head.desc;
        let Planes { occupancy, obstacle, velocity, mass_index, life, field, potential, mass_table, surface, .. } = p;
        let terms = ForceTerms {
            gravity: if desc.forces.uniform { desc.gravity } else { [0.0; 3] },
            field: desc.forces.field.then_some(&*field),
            potential: desc.forces.potential.then_some(&*potential),
            vortex: desc.forces.vortex.then_some(desc.vortex),
            n: head.layout.n,
            periodic,
            dim,
        };
        let dt_q = desc.dt * Q::SCALE;
        let mut ctx = Ctx::<Q, D, OBST, FORCE, MASS> {
            occupancy,
            obstacle,
            velocity,
            mass_index,
            life,
            mass_table,
            surface: &surface[..head.surfaces as usize],
            dv: terms.gravity.map(|g| g * dt_q),
            terms,
            part,
            desc,
            layout: head.layout,
            step: head.step,
            dt_q,
            counters: Counters::default(),
        };
        part.sweep(&mut ctx, reverse);
        let c = ctx.counters;
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

/// Picks the specialised step (M9): first dimension and velocity width...
fn with_dim_and_quant(w: &mut World, dim: u32, reverse: bool) {
    crate::world::with_quant!(w.head.desc.quantization, Q => {
        match dim {
            #[cfg(feature = "dim3")]
            3 => with_parts::<Q, 3>(w, reverse),
            _ => with_parts::<Q, 2>(w, reverse),
        }
    })
}

/// ...then obstacles, the force path and per-particle masses.
fn with_parts<Q: Quant, const D: usize>(w: &mut World, reverse: bool) {
    #[cfg(feature = "obstacles")]
    if w.head.desc.obstacles {
        return with_force::<Q, D, true>(w, reverse);
    }
    with_force::<Q, D, false>(w, reverse)
}

fn with_force<Q: Quant, const D: usize, const OBST: bool>(w: &mut World, reverse: bool) {
    let f = w.head.desc.forces;
    #[cfg(feature = "fields")]
    if f.any_field() {
        return with_mass::<Q, D, OBST, FORCE_GENERAL>(w, reverse);
    }
    if f.uniform {
        with_mass::<Q, D, OBST, FORCE_UNIFORM>(w, reverse)
    } else {
        with_mass::<Q, D, OBST, FORCE_NONE>(w, reverse)
    }
}

fn with_mass<Q: Quant, const D: usize, const OBST: bool, const FORCE: u8>(w: &mut World, reverse: bool) {
    #[cfg(feature = "mass")]
    if w.head.desc.per_particle_mass {
        return w.run::<Q, D, OBST, FORCE, true>(reverse);
    }
    w.run::<Q, D, OBST, FORCE, false>(reverse)
}
