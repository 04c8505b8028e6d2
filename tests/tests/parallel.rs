//! The parallel step (M11): a step split into tasks that the host runs, in
//! any order and on any threads, gives the serial step's world bit for bit,
//! and a host that runs a task twice or not at all cannot change that.

use mpca::{Host, Method, World, MAX_TASKS};
use mpca_tests::scenes::{self, Scene};
use mpca_tests::setup::SetupRng;

/// Task counts the issue names; 64 is [`MAX_TASKS`].
const COUNTS: [usize; 6] = [1, 2, 3, 4, 7, 64];

/// The order a host calls the tasks in.
#[derive(Clone, Copy, Debug)]
enum Order {
    Forward,
    Reverse,
    Shuffled(u64),
}

fn indices(count: usize, order: Order) -> Vec<usize> {
    let mut v: Vec<usize> = (0..count).collect();
    match order {
        Order::Forward => {}
        Order::Reverse => v.reverse(),
        Order::Shuffled(seed) => {
            let mut rng = SetupRng::new(seed);
            for i in (1..count).rev() {
                v.swap(i, rng.below(i as u32 + 1) as usize);
            }
        }
    }
    v
}

/// A host on the calling thread that runs the tasks in `order`.
fn in_order(order: Order) -> impl FnMut(usize, &(dyn Fn(usize) + Sync)) {
    move |count, task| indices(count, order).into_iter().for_each(task)
}

/// A host on two threads: one takes the even positions of `order`, the
/// other the odd ones.
fn two_threads(order: Order) -> impl FnMut(usize, &(dyn Fn(usize) + Sync)) {
    move |count, task| {
        let all = indices(count, order);
        std::thread::scope(|s| {
            for parity in 0..2 {
                let all = &all;
                s.spawn(move || all.iter().skip(parity).step_by(2).for_each(|&i| task(i)));
            }
        });
    }
}

/// The world's hash after `steps` serial steps.
fn serial(scene: &Scene, steps: u64) -> (u64, mpca::Stats) {
    let mut memory = Vec::new();
    let w = scenes::build(scene, &mut memory).unwrap();
    w.step(steps);
    (w.state_hash(), w.stats())
}

/// The world's hash after `steps` steps of `tasks` tasks each run by
/// `host`.
fn parallel(scene: &Scene, steps: u64, tasks: usize, host: Host<'_>) -> (u64, mpca::Stats) {
    let mut memory = Vec::new();
    let w = scenes::build(scene, &mut memory).unwrap();
    for _ in 0..steps {
        w.step_parallel(tasks, host);
    }
    (w.state_hash(), w.stats())
}

fn check_scene(scene: &Scene, steps: u64) {
    let want = serial(scene, steps);
    for tasks in COUNTS {
        for order in [Order::Forward, Order::Reverse, Order::Shuffled(tasks as u64)] {
            let got = parallel(scene, steps, tasks, &mut in_order(order));
            assert_eq!(got, want, "{}: {tasks} tasks, {order:?}, one thread", scene.name);
        }
        let got = parallel(scene, steps, tasks, &mut two_threads(Order::Shuffled(99)));
        assert_eq!(got, want, "{}: {tasks} tasks, shuffled, two threads", scene.name);
    }
}

#[test]
fn paper_scenes_equal_the_serial_step_at_any_task_count_order_and_thread() {
    // Steps enough for both partition offsets, collisions and (water) the
    // 3D sweep; the stats compare the counters the tasks merge.
    for scene in scenes::paper_scenes() {
        check_scene(&scene, 24);
    }
}

#[test]
fn a_1024_world_equals_the_serial_step() {
    check_scene(&scenes::wide_gas(), 4);
}

#[test]
fn every_part_equals_the_serial_step() {
    // Obstacles, emitters, lifetimes, masses, fields, open faces, 3D.
    for method in [Method::ExactFast, Method::Greedy] {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let serial = scenes::every_part(&mut a, method);
        let split = scenes::every_part(&mut b, method);
        for step in 0..30 {
            serial.step(1);
            let tasks = COUNTS[step % COUNTS.len()];
            split.step_parallel(tasks, &mut two_threads(Order::Shuffled(step as u64)));
            assert_eq!(split.state_hash(), serial.state_hash(), "{method:?}: step {step}, {tasks} tasks");
            assert_eq!(split.stats(), serial.stats(), "{method:?}: step {step}");
        }
    }
}

#[test]
fn std_threads_equal_the_serial_step() {
    let scene = scenes::aggregation();
    let want = serial(&scene, 20);
    for threads in [1, 2, 3] {
        let mut memory = Vec::new();
        let w = scenes::build(&scene, &mut memory).unwrap();
        w.step_threads(20, threads);
        assert_eq!((w.state_hash(), w.stats()), want, "{threads} threads");
    }
}

/// Steps `scene` with a host that misbehaves as `host` does, and checks the
/// world equals the serial one.
fn survives(name: &str, host: Host<'_>) {
    let scene = scenes::aggregation();
    let want = serial(&scene, 12);
    let got = parallel(&scene, 12, 8, host);
    assert_eq!(got, want, "{name}");
}

#[test]
fn a_host_that_runs_tasks_twice_changes_nothing() {
    survives("every task twice", &mut |count, task| {
        (0..count).for_each(task);
        (0..count).rev().for_each(task);
    });
    // Twice at the same time, on two threads.
    survives("every task on two threads", &mut |count, task| {
        std::thread::scope(|s| {
            s.spawn(|| (0..count).for_each(task));
            (0..count).for_each(task);
        })
    });
}

#[test]
fn a_host_that_skips_tasks_or_calls_others_changes_nothing() {
    // The tasks it left out run before the step ends.
    survives("no task at all", &mut |_, _| {});
    survives("odd tasks only", &mut |count, task| (1..count).step_by(2).for_each(task));
    // Indices beyond the count are ignored.
    survives("indices beyond the count", &mut |count, task| {
        (count..count + 100).for_each(task);
        task(usize::MAX);
        (0..count).for_each(task);
    });
}

#[test]
fn task_counts_are_bounded() {
    // More tasks than rows of blocks, or than MAX_TASKS, are fewer tasks;
    // 0 is one.
    let scene = scenes::cluster();
    let want = serial(&scene, 6);
    for tasks in [0, MAX_TASKS + 1, usize::MAX] {
        let mut seen = 0;
        let mut host = |count: usize, task: &(dyn Fn(usize) + Sync)| {
            seen = seen.max(count);
            (0..count).for_each(task);
        };
        assert_eq!(parallel(&scene, 6, tasks, &mut host), want, "{tasks} tasks");
        assert!((1..=MAX_TASKS).contains(&seen), "{tasks}: {seen}");
    }
}

#[test]
fn an_empty_world_steps_in_tasks() {
    let desc = mpca::Description::new_2d(16, 16);
    let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
    let w = World::init(&desc, &mut memory).unwrap();
    w.step_parallel(3, &mut in_order(Order::Forward));
    assert_eq!(w.stats().step, 1);
    assert_eq!(w.stats().particles, 0);
}
