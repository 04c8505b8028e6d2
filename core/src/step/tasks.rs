//! A step split into tasks that the host runs on its own threads (M11).
//!
//! The blocks of a step are independent and every draw comes from its
//! block's stream (M8), so the rows of blocks of a step can be cut into
//! bands ([`Partition::band`]) and swept in any order, on any threads. The
//! library starts no thread: the caller hands in its parallel-for (a job
//! system, a thread pool, `std::thread::scope`, or a plain loop), which is
//! called once per step with the number of tasks and a task to run for each
//! index. Emitters run before the tasks; each task counts into a slot of its
//! own, and the slots are added in task order after the host returns, so
//! the world is the serial step's bit for bit at any task or thread count.
//!
//! A host that breaks its contract cannot break the world: a task run a
//! second time does nothing, a task the host never ran is run on the
//! caller's thread before the step ends, and a task that panicked makes the
//! step panic instead of ending half done.

use core::cell::UnsafeCell;
use core::ops::Range;
use core::sync::atomic::{AtomicU8, Ordering};

use crate::step::partition::Partition;
use crate::storage::world::Counters;

/// The most tasks one step is split into.
pub const MAX_TASKS: usize = 64;

/// The host's parallel-for: called once per step as `host(count, task)`, it
/// calls `task(i)` once for each `i` in `0..count`, in any order and on any
/// threads, and returns after every call has returned.
pub type Host<'h> = &'h mut dyn FnMut(usize, &(dyn Fn(usize) + Sync));

const IDLE: u8 = 0;
const RUNNING: u8 = 1;
const DONE: u8 = 2;
const FAILED: u8 = 3;

/// One task's state and what it counted.
struct Slot {
    state: AtomicU8,
    counters: UnsafeCell<Counters>,
}

// SAFETY: `counters` is written only by the one call that moved `state`
// from IDLE to RUNNING, before it stores DONE with release ordering, and
// read only after DONE is loaded with acquire ordering.
unsafe impl Sync for Slot {}

/// Sets a task's state to FAILED if the task unwinds before it is done.
struct Unwinding<'a>(&'a AtomicU8);

impl Drop for Unwinding<'_> {
    fn drop(&mut self) {
        // Only reached with RUNNING still set when the sweep panicked: DONE
        // is stored after the guard is forgotten.
        self.0.store(FAILED, Ordering::Release);
    }
}

/// The number of tasks a step of `part` is split into for a request of
/// `max` (at least one, at most [`MAX_TASKS`] and the rows of blocks).
pub(crate) fn task_count(part: &Partition, max: usize) -> usize {
    max.clamp(1, MAX_TASKS).min(part.block_rows()).max(1)
}

/// Runs the step's sweep as tasks through `host`: `sweep(band)` sweeps one
/// band of rows of blocks and returns what it counted. Returns the sum of
/// every task's counters, added in task order.
pub(crate) fn run(part: &Partition, max: usize, host: Host<'_>, sweep: &(dyn Fn(Range<usize>) -> Counters + Sync)) -> Counters {
    let count = task_count(part, max);
    // Every slot idle and counting nothing: zeros, which the array fills
    // in one go. A constant, not a shared value: each slot of the array is
    // a fresh copy of it, as an array repeat of a constant makes.
    #[allow(clippy::declare_interior_mutable_const)]
    const IDLE_SLOT: Slot = Slot { state: AtomicU8::new(IDLE), counters: UnsafeCell::new(Counters::ZERO) };
    let slots: [Slot; MAX_TASKS] = [IDLE_SLOT; MAX_TASKS];
    let task = |i: usize| {
        let Some(slot) = slots[..count].get(i) else { return };
        if slot.state.compare_exchange(IDLE, RUNNING, Ordering::Acquire, Ordering::Relaxed).is_err() {
            return; // run already, or running
        }
        let guard = Unwinding(&slot.state);
        let counted = sweep(part.band(i, count));
        core::mem::forget(guard);
        // SAFETY: this call moved the state to RUNNING, so it is the only
        // one writing the slot, and nobody reads it before DONE (see Slot).
        unsafe { *slot.counters.get() = counted };
        slot.state.store(DONE, Ordering::Release);
    };
    host(count, &task);
    let mut total = Counters::default();
    for (i, slot) in slots[..count].iter().enumerate() {
        // A task the host left out runs here; one it left running (a host
        // that returned early) is waited for.
        task(i);
        loop {
            match slot.state.load(Ordering::Acquire) {
                DONE => break,
                FAILED => panic!("task {i} of the step panicked"),
                _ => core::hint::spin_loop(),
            }
        }
        // SAFETY: DONE was loaded with acquire ordering: the write is
        // complete and nothing writes the slot again.
        total.add_step(unsafe { &*slot.counters.get() });
    }
    total
}
