//! One step of the automaton: emitters (M6), then the local map of M5 on
//! every occupied block of the step's Margolus partition (M3), then the
//! counters and the step number.
//!
//! The description fixes, once per step, how the block pipeline
//! ([`Kernel`]) is instantiated (M9): the dimension is a compile-time
//! parameter, and so is the stored velocity width for the plain
//! instantiations (the one with every part reads it from the step's
//! data); the force path and the optional parts are switches read once per
//! block at most, and a world without them sends its blocks through the
//! plain instantiations, which have no code for them.


pub(crate) mod assign;
pub(crate) mod block;
pub(crate) mod clamp;
pub(crate) mod collision;
pub(crate) mod contacts;
pub(crate) mod emit;
pub(crate) mod force;
#[cfg(feature = "identity")]
pub(crate) mod identity;
pub(crate) mod kernel;
pub(crate) mod lanes;
pub(crate) mod moves;
pub(crate) mod partition;
pub(crate) mod reflection;
pub(crate) mod rest;
pub(crate) mod rounding;
#[cfg(target_has_atomic = "8")]
pub(crate) mod tasks;

use crate::rules::fixed::{divr, magnitude, quot, scaled, scaled_by, to_fine, unit_scale};
use crate::rules::force::{Flow, ForceTerms, Strength, Swirl};
use crate::rules::turbulence::{Eddies, TurbulenceConstants};
use crate::rules::quant::{Quant, Width};
use crate::rules::rng::StepKey;
use crate::rules::class::Class;
#[cfg(feature = "identity")]
use crate::step::block::Identified;
#[cfg(not(feature = "small-step"))]
use crate::step::block::BlockRules;
use crate::step::block::{Shared, Typed, Velocity, Writable};
use crate::step::block::Kernel;
use crate::step::rest::Support;
use crate::step::kernel::Sink;
use crate::step::partition::Partition;
use crate::storage::cells::Cells;
use crate::storage::layout::Layout;
use crate::storage::layout::{masses_and_classes, Planes};
#[cfg(target_has_atomic = "8")]
use crate::step::tasks::Host;
use crate::storage::world::{Counters, World};

/// The block order of a step. Blocks are independent (M3, M8); the reverse
/// order exists so tests can show that the result does not depend on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// x fastest, then y, then z.
    Forward,
    /// Exactly the reverse.
    Reverse,
}

/// A step's split into tasks: the most tasks and the host that runs them
/// (M11); `None` sweeps on the caller's thread.
#[cfg(target_has_atomic = "8")]
type Split<'h> = Option<(usize, Host<'h>)>;
#[cfg(not(target_has_atomic = "8"))]
type Split<'h> = Option<(usize, core::marker::PhantomData<&'h ()>)>;

/// How a step visits its blocks: in which order, whether blocks of a plain
/// world may take a plain instantiation of the pipeline, and whether rows
/// and words the summaries say are empty are skipped. A type, so that a
/// build holds the sweeps of the routes it takes and no other: the C
/// library steps forward only.
pub(crate) trait Route {
    const REVERSE: bool;
    const LEAN: bool;
    const SKIP: bool;
}

/// The step every caller takes.
pub(crate) enum Forward {}
impl Route for Forward {
    const REVERSE: bool = false;
    const LEAN: bool = true;
    const SKIP: bool = true;
}

/// [`Order::Reverse`]: the tests' proof that the order does not matter.
pub(crate) enum Backward {}
impl Route for Backward {
    const REVERSE: bool = true;
    const LEAN: bool = true;
    const SKIP: bool = true;
}

/// [`World::step_reference`]: every block through the pipeline with every
/// part, nothing skipped.
#[cfg(any(test, feature = "reference"))]
pub(crate) enum Reference {}
#[cfg(any(test, feature = "reference"))]
impl Route for Reference {
    const REVERSE: bool = false;
    const LEAN: bool = false;
    const SKIP: bool = false;
}

impl World {
    /// Advances the world `n` steps.
    pub fn step(&mut self, n: u64) {
        for _ in 0..n {
            self.step_forward();
        }
    }

    /// One step, forward: what [`World::step`] takes, apart from
    /// [`World::step_in_order`] so that a caller of `step` alone (the C
    /// library) holds no reverse sweep.
    ///
    /// Never inlined: `scripts/instructions.sh` and `scripts/firmware.sh`
    /// count the instructions spent inside it.
    #[inline(never)]
    fn step_forward(&mut self) {
        self.step_split::<Forward>(None);
    }

    /// Advances one step, visiting blocks in `order`. The result is the
    /// same bit for bit either way (M8).
    pub fn step_in_order(&mut self, order: Order) {
        match order {
            Order::Forward => self.step_forward(),
            Order::Reverse => self.step_split::<Backward>(None),
        }
    }

    /// Advances one step with every block through the pipeline with every
    /// part (none through the plain instantiations that plain worlds use
    /// away from the faces), and with every row and word of the occupancy
    /// swept (none skipped on the summaries' word). The world is the same
    /// bit for bit: the tests compare the two (feature `reference`, and
    /// the crate's own tests).
    #[cfg(any(test, feature = "reference"))]
    pub fn step_reference(&mut self) {
        self.step_split::<Reference>(None);
    }

    /// Advances one step split into at most `max_tasks` tasks (M11, at
    /// most [`crate::MAX_TASKS`]) that `host` runs: it is called once, as
    /// `host(count, task)`, and must call `task(i)` once for each `i` in
    /// `0..count`, in any order and on any threads, returning after every
    /// call has returned. The world is the one [`World::step`] gives, bit
    /// for bit, whatever the count, the order or the threads.
    ///
    /// A task called twice does nothing the second time, and a task the
    /// host did not call runs on this thread before the step ends.
    ///
    /// ```
    /// use mpca::{Description, World};
    ///
    /// let desc = Description::new_2d(64, 64);
    /// let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
    /// let world = World::init(&desc, &mut memory).unwrap();
    /// world.add_particle([3, 4, 0], [0.5, 0.0, 0.0]).unwrap();
    /// // The simplest host: a loop. A thread pool would spread the calls.
    /// world.step_parallel(4, &mut |count, task| (0..count).for_each(task));
    /// assert_eq!(world.stats().step, 1);
    /// ```
    #[cfg(target_has_atomic = "8")]
    pub fn step_parallel(&mut self, max_tasks: usize, host: Host<'_>) {
        self.step_split::<Forward>(Some((max_tasks, host)));
    }

    /// Advances `n` steps on `threads` threads of the standard library
    /// (feature `std`): [`World::step_parallel`] with scoped threads that
    /// take tasks as they finish others, four tasks a thread.
    #[cfg(feature = "std")]
    pub fn step_threads(&mut self, n: u64, threads: usize) {
        use core::sync::atomic::{AtomicUsize, Ordering};
        let threads = threads.max(1);
        let mut host = |count: usize, task: &(dyn Fn(usize) + Sync)| {
            let next = AtomicUsize::new(0);
            let work = || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= count {
                    break;
                }
                task(i);
            };
            std::thread::scope(|s| {
                for _ in 1..threads.min(count) {
                    s.spawn(work);
                }
                work();
            });
        };
        for _ in 0..n {
            self.step_parallel(4 * threads, &mut host);
        }
    }

    /// One step, its sweep run whole or, with `split`, as tasks (M11).
    fn step_split<R: Route>(&mut self, split: Split<'_>) {
        self.emit();
        crate::rules::quant::with_quant!(self.head.desc.quantization, Q => {
            match self.head.desc.dim {
                #[cfg(feature = "dim3")]
                3 => run::<Q, R, 3, 8>(self, split),
                _ => run::<Q, R, 2, 4>(self, split),
            }
        });
        #[cfg(feature = "obstacles")]
        self.end_body_step();
        // An image may carry any step number (M12): after 2^64 - 1 the
        // count wraps to 0 (the parity of M3 goes on alternating).
        self.head.step = self.head.step.wrapping_add(1);
    }

    /// Runs `visit` over the step's partition with the step's shared data and
    /// the writable planes, and adds the counters it returns to the world's.
    /// Only the velocity plane's view depends on the width: the rest is set
    /// up and counted once for every width ([`World::setup`]).
    pub(crate) fn sweep_with<Q: Quant, const D: usize>(&mut self, lean: bool, visit: impl FnOnce(&Shared<'_>, Writable<'_, D>) -> Counters) {
        // The shared data read where `setup` wrote it (moved out, it would
        // be a copy of all of it).
        let s = self.setup(lean, Q::UNIT);
        let velocity = Velocity::new(s.velocity, Width::of::<Q>());
        let planes = Writable { occupancy: s.occupancy, rows: s.rows, words: s.words, velocity, mass_index: s.mass_index, life: s.life };
        let c = visit(&s.shared, planes);
        count_step(s.counters, &c, s.shared.part.total_blocks());
    }

    /// A step's [`Setup`] for a velocity width of `unit` fine units per
    /// unit speed (M1c). Out of line: one copy serves every width and
    /// dimension.
    #[inline(never)]
    fn setup(&mut self, lean: bool, unit: i32) -> Setup<'_> {
        let part = Partition::new(self.layout(), &self.head.desc.boundary, self.dim(), self.head.step);
        // Read by the potential's gradient and the turbulence, which only
        // `fields` has.
        let periodic = if cfg!(feature = "fields") { self.periodic() } else { [false; 3] };
        let dim = self.dim();
        let (head, p) = self.planes::<u8>();
        // The description and the counters, borrowed from the header
        // together.
        let (desc, counters) = (&head.desc, &mut head.counters);
        let Layout { n, .. } = head.layout;
        #[cfg(feature = "obstacles")]
        let bodies = {
            let (head, table) = crate::storage::layout::head_and_bodies(p.bodies);
            let used = head.map_or(0, |h| h.surfaces as usize);
            crate::step::block::Moving { surface: &p.body_surface[..used], table, tally: Cells::new(&mut p.body_tally[..used]) }
        };
        let Planes { occupancy, rows, words, obstacle, velocity, mass_index, life, field, potential, wind, mass_table, surface, .. } = p;
        let forces = desc.built_forces();
        // M1c: every setting converted once, here, by integer arithmetic on
        // the floats' bits, with W = S 2^F (S odd).
        let (s, fine) = unit_scale(unit);
        let terms = ForceTerms {
            gravity: if forces.uniform { desc.gravity.map(|g| scaled_by(desc.dt, g, s, fine)) } else { [0; 3] },
            field: forces.field.then_some(&*field),
            potential: forces.potential.then_some(&*potential),
            vortex: forces.vortex.then(|| Swirl::of(&desc.vortex)),
            unit: (s, fine),
            n,
            periodic,
            dim,
        };
        let (push, vortex) = (terms.gravity, terms.vortex);
        // The classes of the table's masses in use, in its plane (its first
        // is the world's mass); a world of one mass has none, only `one`.
        let classes: &[Class] = if desc.has_masses() && head.masses > 0 {
            let (table, classes) = masses_and_classes(mass_table, desc.mass_classes as usize);
            let n = (head.masses as usize).min(classes.len());
            convert_classes(&table[..n], desc.dt, (s, fine), vortex, &mut classes[..n])
        } else {
            &[]
        };
        let one = match classes.first() {
            Some(c) => *c,
            None => convert_class(magnitude(desc.mass), magnitude(desc.mass), desc.dt, (s, fine), vortex),
        };
        // Fields, potentials, the vortex and drag are summed per particle;
        // a uniform force alone is one precomputed change (`push`).
        let summed = forces.any_field() || desc.has_drag();
        let small_push = push.iter().all(|g| g.unsigned_abs() < 1 << 29);
        // Component by component: an array comparison is a `memcmp` call on
        // small cores.
        let pushes = push[0] | push[1] | push[2] != 0;
        // With `small-step` every block takes the pipeline with every part:
        // nothing is plain, and nothing only the plain ones read is set up.
        let lean = !cfg!(feature = "small-step") && lean;
        let plain = lean && !desc.has_rest() && !desc.has_masses() && !desc.lifetimes && !desc.identity_planes().any() && !summed && small_push;
        let shared = Shared {
            #[cfg(feature = "small-step")]
            rules: desc,
            #[cfg(not(feature = "small-step"))]
            rules: BlockRules::of(desc),
            n,
            part,
            #[cfg(not(feature = "small-step"))]
            width: Width::of_quantization(desc.quantization),
            key: StepKey::blocks(desc.seed, head.step),
            obstacle,
            // A build without obstacles has no surface entry to slice.
            surface: if cfg!(feature = "obstacles") { &surface[..head.surfaces as usize] } else { &[] },
            one,
            classes,
            push: pushes.then_some(push),
            lean_push: if lean && small_push && pushes { Some(push.map(|g| g as i32)) } else { None },
            restitution: scaled(desc.restitution, 1.0, 16) as i32,
            rest: Support::of(desc, push, fine as u32),
            terms,
            drag: desc.has_drag().then(|| Flow {
                wind: desc.drag.wind.map(|u| to_fine(u, (s, fine))),
                field: desc.drag.field.then_some(&*wind),
                vortex: desc.drag.vortex.then(|| {
                    // Converted once: the force's where it is on too.
                    let swirl = vortex.unwrap_or_else(|| Swirl::of(&desc.vortex));
                    (swirl, swirl.gamma(1.0, (s, fine)))
                }),
                unit: (s, fine),
                dim,
                keep: divr(1 << 48, (1 << 32) + scaled(desc.dt, desc.drag.rate, 32) as u64) as i32,
                turbulence: TurbulenceConstants::of(desc, (s, fine)).map(|c| Eddies::of(c, head.step, dim, n, periodic)),
            }),
            moves: crate::rules::quant::move_table_8(desc.drift),
            #[cfg(not(feature = "small-step"))]
            tops: crate::rules::quant::move_tops_8(desc.drift),
            summed,
            plain,
            lanes: plain && !desc.has_contacts(),
            #[cfg(feature = "identity")]
            identity: Identified { id: Cells::new(p.id), age: Cells::new(p.age), tag: Cells::new(p.tag) },
            #[cfg(feature = "obstacles")]
            bodies,
        };
        Setup {
            counters,
            shared,
            velocity,
            occupancy: Cells::new(occupancy),
            rows: Cells::new(rows),
            words: Cells::new(words),
            mass_index: Cells::new(mass_index),
            life: Cells::new(life),
        }
    }
}

/// The mass classes `masses` (the mass table's entries in use) converted for a step of `dt` in a world of
/// `W = S 2^F` fine units to a unit speed, `(s, fine) = (S, F)` (M1c), into
/// `out`, one entry a class: `K`, the relative mass, the clamp's energy
/// factor and the vortex's push.
fn convert_classes<'a>(masses: &[f32], dt: f32, scale: (u32, i32), swirl: Option<Swirl>, out: &'a mut [Class]) -> &'a [Class] {
    // Masses are positive (checked): their bits order them as numbers.
    let largest = magnitude(f32::from_bits(masses.iter().fold(0, |a, &m| a.max(m.to_bits()))));
    for (slot, &m) in out.iter_mut().zip(masses) {
        *slot = convert_class(magnitude(m), largest, dt, scale, swirl);
    }
    out
}

/// The class of mass `m` (`(m, e)`, [`magnitude`]) where `largest` is the
/// largest mass in use: [`convert_classes`] for one class.
pub(crate) fn convert_class(m: (u32, i32), largest: (u32, i32), dt: f32, (s, fine): (u32, i32), swirl: Option<Swirl>) -> Class {
    let push = quot(magnitude(dt), m, 0);
    Class {
        push,
        relative: (scaled(quot(m, largest, 0), 1.0, 24) as u32).max(1),
        energy: quot(magnitude(quot(m, (s, 0), 0)), (s, 0), 31 - 2 * fine),
        spare: 0,
        swirl: swirl.map_or(Strength::default(), |v| v.gamma(push, (s, fine))),
    }
}

/// A step set up for its sweep, whatever its velocity width: the data every
/// block reads, the planes blocks write but the velocities (as bytes: the
/// width's routine views them as its own type) and the world's counters,
/// which the step's go to.
struct Setup<'a> {
    counters: &'a mut Counters,
    shared: Shared<'a>,
    velocity: &'a mut [u8],
    occupancy: Cells<'a, u64>,
    rows: Cells<'a, u8>,
    words: Cells<'a, u64>,
    mass_index: Cells<'a, u8>,
    life: Cells<'a, u16>,
}

/// Adds a step's counters `c` to the world's `h`; the partition had
/// `total` blocks.
fn count_step(h: &mut Counters, c: &Counters, total: u64) {
    h.add_step(c);
    h.particles -= c.exited + c.expired;
    h.processed = c.processed;
    h.skipped = total - c.processed;
}

fn run<Q: Typed, R: Route, const D: usize, const CELLS: usize>(w: &mut World, split: Split<'_>) {
    w.sweep_with::<Q, D>(R::LEAN, |shared, planes| {
        let sweep = |band| {
            let mut sink = Sink::<Q, D, CELLS>::new(Kernel { shared, planes, counters: Counters::default() });
            shared.part.sweep_band::<_, R>(&mut sink, band);
            sink.kernel.counters
        };
        match split {
            #[cfg(target_has_atomic = "8")]
            Some((max, host)) => crate::step::tasks::run(&shared.part, max, host, &sweep),
            _ => sweep(0..shared.part.block_rows()),
        }
    });
}
