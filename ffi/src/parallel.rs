//! The parallel step (M11): a step split into tasks that the host's own
//! threads run. Hosted builds only: the registry of handles keeps the step's
//! state, refuses every other call on the world while it runs (the step
//! enters its world as every changing call does), and hands out each task
//! once.

use core::ffi::c_void;

use crate::{guard, handle, mpca_status, mpca_world};

/// The most tasks mpca_world_step_parallel splits one step into.
pub const MPCA_MAX_TASKS: u32 = 64;
const _: () = assert!(MPCA_MAX_TASKS as usize == mpca_core::MAX_TASKS);

/// The host's parallel-for, called once per step by
/// mpca_world_step_parallel: it must call `mpca_world_step_task(world,
/// ticket, i)` once for each `i` in `[0, count)`, in any order, on any of
/// its threads (a job system, a thread pool, OpenMP, or a plain loop), and
/// return once every call has returned.
pub type mpca_run_tasks = Option<unsafe extern "C" fn(world: *mut mpca_world, ticket: u64, count: u32, user_data: *mut c_void)>;

/// Advances `steps` steps, each split into at most `max_tasks` tasks (0 and
/// 1 mean one; at most MPCA_MAX_TASKS) that `run_tasks` runs, passing it
/// `user_data`. The world is the one mpca_world_step gives, bit for bit,
/// whatever the task count, the order or the threads.
///
/// What may run concurrently (the rule at `mpca_world`): the step waits
/// for the calls reading the world to return, refusing new ones, and
/// returns `MPCA_STATUS_BUSY` at once, stepping nothing, when another
/// changing call or a parallel step is inside. While it
/// runs, only mpca_world_step_task may be called on this world, from any
/// thread and concurrently for distinct tasks; any other call on it (this
/// one included, from another thread or from inside a task; mpca_world_init
/// or mpca_world_init_from_image over its memory too) returns
/// `MPCA_STATUS_BUSY` and changes nothing. So a call on the world completes
/// before the step begins, or is refused. Other worlds are unaffected.
///
/// A task the host did not run is run on this thread before the step ends,
/// so a `run_tasks` that returns early still completes the step. Hosted
/// builds only (the default `hosted` feature).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_step_parallel(
    world: *mut mpca_world,
    steps: u64,
    max_tasks: u32,
    run_tasks: mpca_run_tasks,
    user_data: *mut c_void,
) -> mpca_status {
    guard(|c| {
        let run_tasks = run_tasks.ok_or(mpca_status::NullPointer)?;
        // Entered for Write: refused with Busy while any other call is
        // inside the world, and every call but the tasks' is refused until
        // this one returns.
        let w = c.world(world)?;
        for _ in 0..steps {
            w.step_parallel(max_tasks as usize, &mut |count, task| {
                let ticket = handle::open_tasks(world, count, task);
                /// Takes the tasks back (waiting for running ones) even if
                /// the host unwinds.
                struct Close(*mut mpca_world);
                impl Drop for Close {
                    fn drop(&mut self) {
                        handle::close_tasks(self.0);
                    }
                }
                let _close = Close(world);
                // SAFETY: the C contract for `run_tasks`; count <= 64.
                unsafe { run_tasks(world, ticket, count as u32, user_data) };
            });
        }
        Ok(())
    })
}

/// Runs task `index` of the parallel step with `ticket` (as `run_tasks`
/// received them). Safe to call concurrently for distinct tasks of the
/// step, from any threads. Refused, changing nothing: a task run already
/// (`MPCA_STATUS_TASK_DONE`), an index not below the step's count
/// (`MPCA_STATUS_TASK_INDEX`), a ticket of another step or a call when no
/// step is in flight (`MPCA_STATUS_STALE_TASK`). Hosted builds only.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_step_task(world: *mut mpca_world, ticket: u64, index: u32) -> mpca_status {
    guard(|_| {
        if world.is_null() {
            return Err(mpca_status::NullPointer.into());
        }
        Ok(handle::run_task(world, ticket, index)?)
    })
}
