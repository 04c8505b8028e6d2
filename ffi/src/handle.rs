//! Handles: how the `mpca_world *` C holds reaches its world, and how it
//! stops reaching it.
//!
//! Hosted builds (`hosted`): a handle is a number this library issued, never
//! the world's address, and no number is issued twice in a process. A
//! registry maps the live ones to their worlds, and is asked before any
//! memory is read, so a handle whose world ended is refused whatever has
//! since happened to that memory. The registry also knows who is inside
//! each world, and refuses with `Busy` a call that would share it with a
//! call that changes it: every export enters its world for the call's
//! length (`Call::world`), and mpca_world_init claims the memory it
//! builds in ([`claim`]). That is the rule for threads `mpca_world` states.
//!
//! Firmware builds (no `hosted`, so no registry): the handle is the world's
//! address, and only the tag in the world's header tells a live world from
//! anything else (`mpca_world` in the header says what that promises).

use mpca_core::World;

use crate::{mpca_status, mpca_world};

#[cfg(feature = "hosted")]
pub(crate) use hosted::{claim, close_tasks, enter, issue, issue_owned, last_detail, leave, open_tasks, reserve, revoke, run_task};

#[cfg(not(feature = "hosted"))]
pub(crate) use firmware::{claim, enter, issue, reserve, revoke};

/// What a call does to the world it names, which decides what it may
/// share the world with (hosted builds; the rule `mpca_world` states).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Access {
    /// Reads it only (the exports taking `const mpca_world *`): any number
    /// of these at once.
    Read,
    /// Changes it, alone: waits for the reading calls inside to return.
    Write,
    /// Ends or replaces it (deinit, destroy, load), alone: refused while
    /// any call is inside, as a world built over its memory is.
    End,
}

#[cfg(feature = "hosted")]
mod hosted {
    use alloc::vec::Vec;
    use core::ffi::c_char;
    use core::ptr::NonNull;

    use crate::sys::{Held, Lock};

    use super::{mpca_status, mpca_world, Access, World};

    /// A live world: where it starts, how many bytes it spans, whether the
    /// library allocated it, who is inside it, and the detail of the last
    /// call to enter it (NULL: it succeeded, or none was made;
    /// mpca_world_last_error).
    struct Entry {
        at: NonNull<u8>,
        bytes: usize,
        owned: bool,
        using: Use,
        last: *const c_char,
    }

    impl Entry {
        /// Whether its memory shares a byte with `start..end`.
        fn overlaps(&self, start: usize, end: usize) -> bool {
            let s = self.at.as_ptr() as usize;
            s < end && start < s + self.bytes
        }
    }

    /// Who is inside a world. A call the state does not admit is refused
    /// with `Busy` at once. The one wait: a changing call waits for the
    /// reading calls inside to return, and those wait for nothing and call
    /// nothing of the program's, so the wait ends, whatever thread or task
    /// the changing call comes from.
    enum Use {
        /// Calls that only read it, this many (0: no call at all).
        Read(u32),
        /// A changing call waits for this many reading calls to return;
        /// new calls are refused.
        Draining(u32),
        /// One call that changes it: an edit, a step, a load, its end, a
        /// world being built over its memory, or mpca_world_step_parallel
        /// between the host's task runs.
        Write,
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
    // reads or writes the world through it. Which calls reach the world at
    // once is what `Use` decides, under the registry's lock. The task
    // pointer is called only as `TaskRef` says, and the task is `Sync`.
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
    /// building a world; a BTreeMap's code made libmpca.so larger for it.
    struct Live(Vec<(usize, Entry)>);

    impl Live {
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

        /// The entries whose memory shares a byte with `start..end`.
        fn overlapping(&mut self, start: usize, end: usize) -> impl Iterator<Item = &mut Entry> {
            self.0.iter_mut().map(|(_, e)| e).filter(move |e| e.overlaps(start, end))
        }
    }

    static REGISTRY: Lock<Registry> = Lock::new(Registry { taken: 0, tickets: 0, live: Live(Vec::new()) });

    fn registry() -> Held<'static, Registry> {
        // Every change below is one insert, remove, retain or state change,
        // so a panic while the lock was held (caught with catch-panics; the
        // lock is freed as it unwinds) left nothing half-done.
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

    /// Caller memory a world is about to be built in, held from the check
    /// until the world is registered ([`issue`]) or the call is refused
    /// (dropped): the live worlds in it are held as a changing call holds
    /// its world, so no call reaches them meanwhile.
    pub(crate) struct Claim {
        start: usize,
        end: usize,
    }

    /// Claims the `len` bytes at `at` for a new world. Refused, claiming
    /// nothing: with `Busy` when a live world there is in use (a call is
    /// inside it, or a parallel step), whichever thread or task asks; with
    /// `Overlap` when the library allocated a world there (caller memory
    /// never holds one: that memory is the library's until
    /// mpca_world_destroy).
    pub(crate) fn claim(at: *mut u8, len: usize) -> Result<Claim, mpca_status> {
        let (start, end) = (at as usize, (at as usize).saturating_add(len));
        let mut r = registry();
        let mut refusal = None;
        for e in r.live.overlapping(start, end) {
            if !matches!(e.using, Use::Read(0)) {
                return Err(mpca_status::Busy);
            }
            if e.owned {
                refusal = Some(mpca_status::Overlap);
            }
        }
        if let Some(s) = refusal {
            return Err(s);
        }
        for e in r.live.overlapping(start, end) {
            e.using = Use::Write;
        }
        Ok(Claim { start, end })
    }

    impl Drop for Claim {
        /// The world was not built: the worlds in the memory live on,
        /// unchanged (every refusal comes before the memory is written).
        fn drop(&mut self) {
            for e in registry().live.overlapping(self.start, self.end) {
                e.using = Use::Read(0);
            }
        }
    }

    /// Registers a world just built in claimed caller memory and returns
    /// its handle. The live worlds that memory held end: their handles are
    /// refused from now on.
    pub(crate) fn issue(number: Reserved, claim: Claim, world: &mut World) -> *mut mpca_world {
        let entry = Entry { at: NonNull::from(&mut *world).cast(), bytes: world.size_in_bytes(), owned: false, using: Use::Read(0), last: core::ptr::null() };
        let handle = value(number.0);
        let mut r = registry();
        r.live.0.retain(|(_, e)| !e.overlaps(claim.start, claim.end));
        r.live.insert(handle, entry);
        // Nothing is left to release: the claimed entries are gone.
        core::mem::forget(claim);
        core::ptr::without_provenance_mut(handle)
    }

    /// Registers a world the library allocated, by the pointer
    /// `WorldBox::into_raw` gives: the allocation's own, which
    /// mpca_world_destroy frees through (one derived from the `&mut World`
    /// would not reach the allocation's alignment slack). Worlds the
    /// registry still knows in that memory were freed by the caller
    /// without mpca_world_deinit: they end.
    pub(crate) fn issue_owned(number: Reserved, world: mpca_core::WorldBox) -> *mut mpca_world {
        let bytes = world.size_in_bytes();
        let at = NonNull::new(world.into_raw()).expect("an allocation is not NULL");
        let handle = value(number.0);
        let mut r = registry();
        let start = at.as_ptr() as usize;
        r.live.0.retain(|(_, e)| !e.overlaps(start, start + bytes));
        r.live.insert(handle, Entry { at, bytes, owned: true, using: Use::Read(0), last: core::ptr::null() });
        core::ptr::without_provenance_mut(handle)
    }

    /// Enters the world of a live handle for a call that does `access` to
    /// it and returns where the world is; [`leave`] must follow when the
    /// call ends. `BadHandle` for anything but a live handle, found without
    /// reading any memory `handle` might point to. `Busy` when the world's
    /// state does not admit the call: a changing call or a parallel step is
    /// inside (or waiting to be), or, for a call that ends the world, any
    /// call is. A changing call finding reading calls inside waits for them.
    // Not inlined: every export calls it, and the lock and the map search
    // inlined into each made libmpca.so much larger; the call costs a few
    // instructions a call.
    #[inline(never)]
    pub(crate) fn enter(handle: *const mpca_world, access: Access) -> Result<*mut u8, mpca_status> {
        {
            let mut r = registry();
            let e = r.live.get_mut(&handle.addr()).ok_or(mpca_status::BadHandle)?;
            e.using = match (&e.using, access) {
                (&Use::Read(n), Access::Read) => Use::Read(n.checked_add(1).ok_or(mpca_status::Busy)?),
                (Use::Read(0), Access::Write | Access::End) => Use::Write,
                (&Use::Read(n), Access::Write) => Use::Draining(n),
                _ => return Err(mpca_status::Busy),
            };
            if !matches!(e.using, Use::Draining(_)) {
                return Ok(e.at.as_ptr());
            }
        }
        // Draining: the readers leave without waiting, and nothing else
        // enters, ends or claims the world meanwhile.
        loop {
            crate::sys::yield_now();
            let mut r = registry();
            let e = r.live.get_mut(&handle.addr()).ok_or(mpca_status::BadHandle)?;
            if let Use::Draining(0) = e.using {
                e.using = Use::Write;
                return Ok(e.at.as_ptr());
            }
        }
    }

    /// Ends a call's [`enter`], recording its detail (NULL: it succeeded)
    /// as the world's last. A handle the call ended (deinit, destroy) is
    /// gone from the registry, and nothing is left to do.
    #[inline(never)]
    pub(crate) fn leave(handle: *const mpca_world, access: Access, detail: *const c_char) {
        if let Some(e) = registry().live.get_mut(&handle.addr()) {
            e.last = detail;
            match (&mut e.using, access) {
                (Use::Read(n) | Use::Draining(n), Access::Read) => *n = n.saturating_sub(1),
                (Use::Write, Access::Write | Access::End) => e.using = Use::Read(0),
                // Not reached: a call's state is what its enter made it, or
                // Write again after close_tasks.
                _ => {}
            }
        }
    }

    /// Hands the tasks of one step to mpca_world_step_task and returns
    /// the step's ticket. The world must be entered for `Write` by this
    /// call; [`close_tasks`] must follow before `task` is dropped.
    pub(crate) fn open_tasks(handle: *const mpca_world, count: usize, task: &(dyn Fn(usize) + Sync)) -> u64 {
        let mut r = registry();
        r.tickets += 1;
        let ticket = r.tickets;
        // SAFETY: only the lifetime is erased; close_tasks, which the caller
        // runs before `task`'s borrow ends, takes the pointer back and waits
        // until no call through it is running.
        let task: *const (dyn Fn(usize) + Sync + 'static) = unsafe { core::mem::transmute(task) };
        if let Some(e) = r.live.get_mut(&handle.addr()) {
            e.using = Use::Tasks(Tasks { ticket, count, claimed: 0, running: 0, task: TaskRef(task) });
        }
        ticket
    }

    /// Takes the step's tasks back once none is running: later calls of
    /// mpca_world_step_task with its ticket are refused, and the world is
    /// the stepping call's alone again (`Write`).
    pub(crate) fn close_tasks(handle: *const mpca_world) {
        loop {
            {
                let mut r = registry();
                let Some(e) = r.live.get_mut(&handle.addr()) else { return };
                if !matches!(&e.using, Use::Tasks(t) if t.running > 0) {
                    e.using = Use::Write;
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
            let Use::Tasks(t) = &mut e.using else { return Err(mpca_status::StaleTask) };
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
                if let Some(Entry { using: Use::Tasks(t), .. }) = registry().live.get_mut(&self.0.addr()) {
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

    /// The detail of the last call to enter the world of `handle` (NULL:
    /// it succeeded, or none was made); `None` for a handle that is not
    /// live. It does not enter the world, so it answers during a parallel
    /// step too.
    pub(crate) fn last_detail(handle: *const mpca_world) -> Option<*const c_char> {
        registry().live.get_mut(&handle.addr()).map(|e| e.last)
    }

    /// Ends a handle: it is refused from now on. Called by the call that
    /// holds the world for `Write`, so no other call is inside it.
    pub(crate) fn revoke(handle: *const mpca_world) {
        registry().live.remove(&handle.addr());
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use crate::*;

        #[test]
        fn memory_in_use_or_the_librarys_own_is_not_claimed() {
            use core::ptr::null_mut;
            // SAFETY, for every export below: each pointer is a live local
            // of the size the header asks for.
            unsafe {
                let mut d = core::mem::MaybeUninit::<mpca_desc>::uninit();
                assert_eq!(mpca_desc_defaults(d.as_mut_ptr(), 2, 8, 6, 0), mpca_status::Ok);
                let d = d.assume_init();
                let mut owned = null_mut();
                assert_eq!(mpca_world_create(&d, &mut owned), mpca_status::Ok);
                let (at, bytes) = {
                    let mut r = registry();
                    let e = r.live.get_mut(&owned.addr()).expect("a live world");
                    (e.at.as_ptr(), e.bytes)
                };
                // No caller owns the library's allocation: refused, whole or
                // in part, and the world lives on.
                assert!(matches!(claim(at, bytes), Err(mpca_status::Overlap)));
                assert!(matches!(claim(at.wrapping_add(bytes / 2), 16), Err(mpca_status::Overlap)));
                // A call inside: every claim and every end is refused.
                assert!(enter(owned, Access::Read).is_ok());
                assert!(matches!(claim(at, bytes), Err(mpca_status::Busy)));
                assert_eq!(enter(owned, Access::End).err(), Some(mpca_status::Busy));
                assert_eq!(mpca_world_destroy(owned), mpca_status::Busy);
                leave(owned, Access::Read, core::ptr::null());
                assert_eq!(mpca_world_destroy(owned), mpca_status::Ok);

                // Caller memory: a claim holds the world in it, refusing its
                // calls, until the claim is dropped (the init refused).
                let mut memory = std::vec![0u8; bytes + 64];
                let mut w = null_mut();
                assert_eq!(mpca_world_init(&d, memory.as_mut_ptr().cast(), memory.len(), &mut w), mpca_status::Ok);
                let claimed = claim(memory.as_mut_ptr().wrapping_add(32), 8).expect("no call inside");
                assert_eq!(enter(w, Access::Read).err(), Some(mpca_status::Busy));
                drop(claimed);
                assert!(enter(w, Access::Read).is_ok());
                leave(w, Access::Read, core::ptr::null());
                assert_eq!(mpca_world_deinit(w), mpca_status::Ok);
            }
        }

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
    use super::{mpca_status, mpca_world, Access, World};

    /// Nothing to set aside: the handle is the world's address.
    pub(crate) struct Reserved;

    pub(crate) fn reserve() -> Result<Reserved, mpca_status> {
        Ok(Reserved)
    }

    /// Nothing to hold: without a registry the library knows no world's
    /// memory, and a firmware program calls from one thread.
    pub(crate) struct Claim;

    pub(crate) fn claim(_: *mut u8, _: usize) -> Result<Claim, mpca_status> {
        Ok(Claim)
    }

    /// The world's address, which its header's tag is tied to.
    pub(crate) fn issue(_: Reserved, _: Claim, world: &mut World) -> *mut mpca_world {
        world.as_ptr().cast()
    }

    /// The handle itself; its tag is checked by the caller.
    pub(crate) fn enter(handle: *const mpca_world, _: Access) -> Result<*mut u8, mpca_status> {
        Ok(handle.cast_mut().cast())
    }

    /// Nothing to do: `World::retire` cleared the tag.
    pub(crate) fn revoke(_: *const mpca_world) {}
}
