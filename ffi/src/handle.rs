//! Handles: how the `mpca_world *` C holds reaches its world, and how it
//! stops reaching it.
//!
//! Hosted builds (`hosted`): a handle is a number this library issued, never
//! the world's address, and no number is issued twice in a process. A
//! registry maps the live ones to their worlds, and is asked before any
//! memory is read, so a handle whose world ended is refused whatever has
//! since happened to that memory.
//!
//! Firmware builds (no `hosted`, so no registry): the handle is the world's
//! address, and only the tag in the world's header tells a live world from
//! anything else (`mpca_world` in the header says what that promises).

use mpca_core::World;

use crate::{mpca_status, mpca_world};

#[cfg(feature = "hosted")]
pub(crate) use hosted::{begin_step, close_tasks, end_step, issue, issue_owned, open_tasks, reserve, resolve, revoke, run_task};

#[cfg(not(feature = "hosted"))]
pub(crate) use firmware::{issue, reserve, resolve, revoke};

#[cfg(feature = "hosted")]
mod hosted {
    use alloc::vec::Vec;
    use core::ptr::NonNull;

    use crate::sys::{Held, Lock};

    use super::{mpca_status, mpca_world, World};

    /// A live world: where it starts, how many bytes it spans, whether the
    /// library allocated it, and whether a parallel step holds it.
    struct Entry {
        at: NonNull<u8>,
        bytes: usize,
        owned: bool,
        step: Step,
    }

    /// Where a world is in mpca_world_step_parallel (M11).
    enum Step {
        /// Not in it: every call may reach the world.
        Idle,
        /// In it, between the host's task runs: no call reaches the world.
        Busy,
        /// The host is running the tasks of one step: only
        /// mpca_world_step_task with this step's ticket reaches it.
        Tasks(Tasks),
    }

    /// The tasks of the step in flight.
    struct Tasks {
        ticket: u64,
        count: usize,
        /// Bit `i`: task `i` was handed out.
        claimed: u64,
        /// Tasks handed out and not yet returned.
        running: u32,
        task: TaskRef,
    }

    /// The step's task, its borrow's lifetime erased: it lives until
    /// `close_tasks` returns, which waits until no task is running, and
    /// `close_tasks` runs before the borrow ends.
    #[derive(Clone, Copy)]
    struct TaskRef(*const (dyn Fn(usize) + Sync + 'static));

    // SAFETY: the registry stores the address and hands it back; it never
    // reads or writes the world through it. Who uses the world, from which
    // thread, is the C contract's business (one thread at a time), except
    // during a parallel step, when the registry itself refuses every call
    // but the step's tasks. The task pointer is called only as `TaskRef`
    // says, and the task is `Sync`.
    unsafe impl Send for Entry {}

    struct Registry {
        /// How many handle numbers have been taken.
        taken: usize,
        /// How many parallel steps' tickets have been issued.
        tickets: u64,
        /// Live worlds by handle value.
        live: Live,
    }

    /// Live worlds, sorted by handle value, found by binary search. A
    /// program holds a few worlds, rarely thousands, so moving the ones
    /// after an inserted or removed entry costs nothing that shows beside
    /// building a world; a BTreeMap's code made libmpca.so 13 KB larger
    /// (395,472 against 382,120 bytes stripped).
    struct Live(Vec<(usize, Entry)>);

    impl Live {
        fn get(&self, handle: &usize) -> Option<&Entry> {
            let i = self.0.binary_search_by_key(handle, |&(h, _)| h).ok()?;
            Some(&self.0[i].1)
        }

        fn get_mut(&mut self, handle: &usize) -> Option<&mut Entry> {
            let i = self.0.binary_search_by_key(handle, |&(h, _)| h).ok()?;
            Some(&mut self.0[i].1)
        }

        fn insert(&mut self, handle: usize, entry: Entry) {
            match self.0.binary_search_by_key(&handle, |&(h, _)| h) {
                Ok(i) => self.0[i].1 = entry,
                Err(i) => self.0.insert(i, (handle, entry)),
            }
        }

        fn remove(&mut self, handle: &usize) {
            if let Ok(i) = self.0.binary_search_by_key(handle, |&(h, _)| h) {
                self.0.remove(i);
            }
        }

        fn retain(&mut self, mut keep: impl FnMut(&usize, &mut Entry) -> bool) {
            self.0.retain_mut(|(h, e)| keep(h, e));
        }
    }

    static REGISTRY: Lock<Registry> = Lock::new(Registry { taken: 0, tickets: 0, live: Live(Vec::new()) });

    fn registry() -> Held<'static, Registry> {
        // Every change below is one insert, remove or retain, so a panic
        // while the lock was held (caught with catch-panics; the lock is
        // freed as it unwinds) left nothing half-done.
        REGISTRY.lock()
    }

    /// The handle value of number `n`: a bijection of `usize` (xor-shifts
    /// and a multiplication by an odd constant are each invertible), so
    /// distinct numbers give distinct values, and 0 (NULL) only for 0, which
    /// is never issued. Scrambled so that a value near a handle (the handle
    /// plus an offset) is not another handle.
    fn value(n: usize) -> usize {
        const HALF: u32 = usize::BITS / 2;
        let mut x = n ^ (n >> HALF);
        x = x.wrapping_mul(0x9e37_79b9_7f4a_7c15_u64 as usize);
        x ^ (x >> HALF)
    }

    /// A handle number set aside for a world about to be built.
    pub(crate) struct Reserved(usize);

    /// Takes the next handle number, before the world is built, so that
    /// nothing can fail once it is. A number whose world is then refused is
    /// never used; numbers are not reused either way.
    pub(crate) fn reserve() -> Result<Reserved, mpca_status> {
        let mut r = registry();
        // 2^64 - 1 numbers never run out; 2^32 - 1 on 32-bit targets might.
        r.taken = r.taken.checked_add(1).ok_or(mpca_status::OutOfMemory)?;
        Ok(Reserved(r.taken))
    }

    /// Registers a world just built and returns its handle. A world built in
    /// caller memory that held live worlds ends them: their handles are
    /// refused from now on.
    pub(crate) fn issue(number: Reserved, world: &mut World) -> *mut mpca_world {
        let entry = Entry { at: NonNull::from(&mut *world).cast(), bytes: world.size_in_bytes(), owned: world.is_owned(), step: Step::Idle };
        register(number, entry)
    }

    /// Registers a world the library allocated, by the pointer
    /// `WorldBox::into_raw` gives: the allocation's own, which
    /// mpca_world_destroy frees through (one derived from the `&mut World`
    /// would not reach the allocation's alignment slack).
    pub(crate) fn issue_owned(number: Reserved, world: mpca_core::WorldBox) -> *mut mpca_world {
        let bytes = world.size_in_bytes();
        let at = NonNull::new(world.into_raw()).expect("an allocation is not NULL");
        register(number, Entry { at, bytes, owned: true, step: Step::Idle })
    }

    fn register(number: Reserved, entry: Entry) -> *mut mpca_world {
        let handle = value(number.0);
        let mut r = registry();
        if !entry.owned {
            let (start, end) = (entry.at.as_ptr() as usize, entry.at.as_ptr() as usize + entry.bytes);
            r.live.retain(|_, e| {
                let (s, t) = (e.at.as_ptr() as usize, e.at.as_ptr() as usize + e.bytes);
                e.owned || t <= start || end <= s
            });
        }
        r.live.insert(handle, entry);
        core::ptr::without_provenance_mut(handle)
    }

    /// Where the world of a live handle is; `BadHandle` for anything else,
    /// found without reading any memory `handle` might point to, and `Busy`
    /// while a parallel step holds the world.
    // Not inlined: every export calls it, and the lock and the map search
    // inlined into each made libmpca.so 8.5 KB larger (403,864 against
    // 395,360 bytes stripped); the call costs a few instructions a call.
    #[inline(never)]
    pub(crate) fn resolve(handle: *const mpca_world) -> Result<*mut u8, mpca_status> {
        let r = registry();
        let e = r.live.get(&handle.addr()).ok_or(mpca_status::BadHandle)?;
        match e.step {
            Step::Idle => Ok(e.at.as_ptr()),
            _ => Err(mpca_status::Busy),
        }
    }

    /// Starts a parallel step on a live, idle world: every other call on
    /// it is refused with `Busy` until [`end_step`].
    pub(crate) fn begin_step(handle: *const mpca_world) -> Result<*mut u8, mpca_status> {
        let mut r = registry();
        let e = r.live.get_mut(&handle.addr()).ok_or(mpca_status::BadHandle)?;
        match e.step {
            Step::Idle => {
                e.step = Step::Busy;
                Ok(e.at.as_ptr())
            }
            _ => Err(mpca_status::Busy),
        }
    }

    /// Ends the parallel step [`begin_step`] started.
    pub(crate) fn end_step(handle: *const mpca_world) {
        if let Some(e) = registry().live.get_mut(&handle.addr()) {
            e.step = Step::Idle;
        }
    }

    /// Hands the tasks of one step to mpca_world_step_task and returns
    /// the step's ticket. [`close_tasks`] must follow before `task` is
    /// dropped.
    pub(crate) fn open_tasks(handle: *const mpca_world, count: usize, task: &(dyn Fn(usize) + Sync)) -> u64 {
        let mut r = registry();
        r.tickets += 1;
        let ticket = r.tickets;
        // SAFETY: only the lifetime is erased; close_tasks, which the caller
        // runs before `task`'s borrow ends, takes the pointer back and waits
        // until no call through it is running.
        let task: *const (dyn Fn(usize) + Sync + 'static) = unsafe { core::mem::transmute(task) };
        if let Some(e) = r.live.get_mut(&handle.addr()) {
            e.step = Step::Tasks(Tasks { ticket, count, claimed: 0, running: 0, task: TaskRef(task) });
        }
        ticket
    }

    /// Takes the step's tasks back once none is running: later calls of
    /// mpca_world_step_task with its ticket are refused.
    pub(crate) fn close_tasks(handle: *const mpca_world) {
        loop {
            {
                let mut r = registry();
                let Some(e) = r.live.get_mut(&handle.addr()) else { return };
                if !matches!(&e.step, Step::Tasks(t) if t.running > 0) {
                    e.step = Step::Busy;
                    return;
                }
            }
            crate::sys::yield_now();
        }
    }

    /// Runs task `index` of the step with `ticket`, once: `StaleTask` when
    /// that step is not in flight on this world, `TaskIndex` beyond its
    /// tasks, `TaskDone` for a task handed out before.
    pub(crate) fn run_task(handle: *const mpca_world, ticket: u64, index: u32) -> Result<(), mpca_status> {
        let task = {
            let mut r = registry();
            let e = r.live.get_mut(&handle.addr()).ok_or(mpca_status::BadHandle)?;
            let Step::Tasks(t) = &mut e.step else { return Err(mpca_status::StaleTask) };
            if t.ticket != ticket {
                return Err(mpca_status::StaleTask);
            }
            let i = index as usize;
            if i >= t.count {
                return Err(mpca_status::TaskIndex);
            }
            if t.claimed >> i & 1 != 0 {
                return Err(mpca_status::TaskDone);
            }
            t.claimed |= 1 << i;
            t.running += 1;
            t.task
        };
        /// Counts the task as returned, even if it unwinds.
        struct Returned(*const mpca_world);
        impl Drop for Returned {
            fn drop(&mut self) {
                if let Some(Entry { step: Step::Tasks(t), .. }) = registry().live.get_mut(&self.0.addr()) {
                    t.running -= 1;
                }
            }
        }
        let _returned = Returned(handle);
        // SAFETY: `running` counts this call, so close_tasks waits for it and
        // the task is alive (TaskRef).
        unsafe { (*task.0)(index as usize) };
        Ok(())
    }

    /// Ends a handle: it is refused from now on.
    pub(crate) fn revoke(handle: *const mpca_world) {
        registry().live.remove(&handle.addr());
    }

    #[cfg(test)]
    mod tests {
        use super::value;

        #[test]
        fn handle_values_of_distinct_numbers_differ_and_are_not_null() {
            // Under Miri, which runs some thousand times slower, fewer.
            let (numbers, probed) = if cfg!(miri) { (500, 4) } else { (100_000, 1000) };
            let values: std::collections::BTreeSet<usize> = (1..=numbers).map(value).collect();
            assert_eq!(values.len(), numbers);
            assert!(!values.contains(&0));
            // No handle is another plus a small offset.
            for v in (1..=probed).map(value) {
                for d in 1..=256 {
                    assert!(!values.contains(&v.wrapping_add(d)) && !values.contains(&v.wrapping_sub(d)));
                }
            }
        }
    }
}

#[cfg(not(feature = "hosted"))]
mod firmware {
    use super::{mpca_status, mpca_world, World};

    /// Nothing to set aside: the handle is the world's address.
    pub(crate) struct Reserved;

    pub(crate) fn reserve() -> Result<Reserved, mpca_status> {
        Ok(Reserved)
    }

    /// The world's address, which its header's tag is tied to.
    pub(crate) fn issue(_: Reserved, world: &mut World) -> *mut mpca_world {
        world.as_ptr().cast()
    }

    /// The handle itself; its tag is checked by the caller.
    pub(crate) fn resolve(handle: *const mpca_world) -> Result<*mut u8, mpca_status> {
        Ok(handle.cast_mut().cast())
    }

    /// Nothing to do: `World::retire` cleared the tag.
    pub(crate) fn revoke(_: *const mpca_world) {}
}
