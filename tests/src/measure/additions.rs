//! The rules beyond the paper (docs/model.md, "Additions"), each against
//! the paper's rule on the scene where the difference shows (M10): flow
//! drag on the smoke, turbulence on the smoke preset's plume,
//! speed-limited collisions on the e = 1 cluster,
//! contacts and resting contact on the poured water pool, energy-neutral
//! rounding in an
//! elastic 8-bit box. The figures are those the tests of
//! `tests/tests/effects.rs` hold to their bounds, here with run times.

use mpca::{Boundary, Collisions, Description, Error, World};

use super::{memory, plume, repeat, run_steps, Timing};
use crate::scenes::{self, Scene};

/// One figure of one rule: its value under the paper's rule and under the
/// addition, and the run times of both.
pub struct AdditionRow {
    /// The rule, as docs/model.md names it.
    pub rule: &'static str,
    /// The paper's scene (or world) and the one with the addition.
    pub scenes: String,
    /// What is measured.
    pub measure: &'static str,
    /// The figure under the paper's rule.
    pub paper: f64,
    /// The figure with the addition.
    pub addition: f64,
    /// Steps of each run: the paper's, the addition's.
    pub steps: (u64, u64),
    /// Run time of the steps under the paper's rule.
    pub paper_timing: Timing,
    /// Run time of the steps with the addition.
    pub addition_timing: Timing,
}

/// What a run of a scene ends with.
struct Ended {
    clamps_per_particle_step: f64,
    mean_speed: f64,
    energy_change: f64,
    clamps: f64,
    /// The share of the cells holding a particle that hold none a step
    /// later, in one more step (untimed) after the run.
    changing: f64,
}

/// Builds `scene`, steps it `steps` times one at a time (only the steps
/// are timed) and reads what [`Ended`] holds.
fn run(scene: &Scene, steps: u64, runs: usize) -> (Ended, Timing) {
    repeat(runs, || {
        let mut mem = Vec::new();
        let w = scenes::build(scene, &mut mem).expect("the scene builds");
        step_and_read(w, steps)
    })
}

/// Steps `w` `steps` times, one at a time (only the steps timed), and reads
/// what [`Ended`] holds; the seconds spent stepping.
fn step_and_read(w: &mut World, steps: u64) -> (Ended, f64) {
    let e0 = w.stats().kinetic_energy;
    let mut particle_steps = 0u64;
    let seconds = run_steps(w, steps, |w, _| particle_steps += w.particle_count());
    let s = w.stats();
    let n = w.particle_count().max(1) as f64;
    let mean_speed = w.particles().map(|p| f64::from(p.velocity.iter().map(|c| c * c).sum::<f32>().sqrt())).sum::<f64>() / n;
    let before: std::collections::HashSet<[u32; 3]> = w.particles().map(|p| p.pos).collect();
    w.step(1);
    let changing = before.len() - w.particles().filter(|p| before.contains(&p.pos)).count();
    let ended = Ended {
        clamps_per_particle_step: s.clamps as f64 / particle_steps.max(1) as f64,
        mean_speed,
        energy_change: s.kinetic_energy / e0 - 1.0,
        clamps: s.clamps as f64,
        changing: changing as f64 / n,
    };
    (ended, seconds)
}

/// A figure of a run that ends with a `T`: its name and how it is read.
type Figure<T> = (&'static str, fn(&T) -> f64);

/// The figures `figures` of the pair of runs `(paper, addition)`, whatever
/// a run ends with (`T`).
fn rows<T>(
    rule: &'static str,
    scenes: String,
    figures: &[Figure<T>],
    paper: (T, Timing),
    addition: (T, Timing),
    steps: (u64, u64),
) -> Vec<AdditionRow> {
    figures
        .iter()
        .map(|&(measure, f)| AdditionRow {
            rule,
            scenes: scenes.clone(),
            measure,
            paper: f(&paper.0),
            addition: f(&addition.0),
            steps,
            paper_timing: paper.1.clone(),
            addition_timing: addition.1.clone(),
        })
        .collect()
}

fn elastic_run(energy_neutral: bool, steps: u64, runs: usize) -> (Ended, Timing) {
    let desc = scenes::elastic_box(energy_neutral, Boundary::Wall);
    let mut mem = memory(&desc);
    repeat(runs, || {
        let w = World::init(&desc, &mut mem).expect("fits");
        scenes::fill_elastic(w);
        step_and_read(w, steps)
    })
}

/// Every rule, `share` of each scene's steps (the elastic box `box_steps`),
/// each run timed `runs` times.
pub fn measure(share: f64, box_steps: u64, runs: usize) -> Vec<AdditionRow> {
    let steps = |n: u64| ((n as f64 * share).round() as u64).max(1);
    let mut out = vec![];

    // M5.1b: the paper's vortex force against drag towards the flow.
    let (smoke, flow) = (scenes::smoke(), scenes::smoke_flow());
    let (a, b) = (steps(480), steps(flow.steps));
    out.extend(rows::<Ended>(
        "M5.1b flow drag",
        format!("{} / {}", smoke.name, flow.name),
        &[("clamps per particle-step", |e| e.clamps_per_particle_step), ("mean speed at the end", |e| e.mean_speed)],
        run(&smoke, a, runs),
        run(&flow, b, runs),
        (a, b),
    ));

    // M5.1c: the smoke preset's plume with drag alone against drag with
    // its turbulence (the figures tests/tests/turbulence.rs holds).
    let (calm, stirred) = (scenes::plume(false, 1), scenes::plume(true, 1));
    let n = steps(calm.steps);
    let plume_run = |scene: &Scene| {
        let scene = Scene { steps: n, ..*scene };
        repeat(runs, || plume::measure(&scene))
    };
    let (calm_run, stirred_run) = (plume_run(&calm), plume_run(&stirred));
    let figures: [Figure<plume::Plume>; 4] = [
        ("plume width 8 to 24 cells up, cells", |p| p.width[0]),
        ("plume width 104 to 120 cells up, cells", |p| p.width[3]),
        ("r.m.s. sideways velocity", |p| p.sideways),
        ("clamps per particle-step", |p| p.clamps),
    ];
    out.extend(rows("M5.1c turbulence", "plume of the smoke preset, 128²".into(), &figures, calm_run, stirred_run, (n, n)));

    // M5.2b: the e = 1 cluster collision, paper collisions against
    // speed-limited ones.
    let paper = scenes::cluster();
    let mut limited = scenes::cluster();
    limited.desc.collisions = Collisions::SpeedLimited;
    let n = steps(paper.steps);
    out.extend(rows::<Ended>(
        "M5.2b speed-limited collisions",
        format!("{} (e = 1)", paper.name),
        &[("kinetic energy, relative change", |e| e.energy_change), ("clamps", |e| e.clamps)],
        run(&paper, n, runs),
        run(&limited, n, runs),
        (n, n),
    ));

    // M5.7: the poured water pool without and with contacts.
    let with = scenes::water_pool();
    let mut without = scenes::water_pool();
    without.desc.contacts = false;
    let n = steps(with.steps);
    out.extend(rows::<Ended>(
        "M5.7 contacts",
        format!("{} (e = 0.5)", with.name),
        &[("mean speed at the end", |e| e.mean_speed), ("clamps per particle-step", |e| e.clamps_per_particle_step)],
        run(&without, n, runs),
        run(&with, n, runs),
        (n, n),
    ));

    // M5.7b: the same pool with contacts, without and with resting contact.
    let mut resting = scenes::water_pool();
    resting.desc.rest = true;
    out.extend(rows::<Ended>(
        "M5.7b resting contact",
        format!("{} (e = 0.5, contacts)", with.name),
        &[
            ("mean speed at the end", |e| e.mean_speed),
            ("share of occupied cells emptied in a step, at the end", |e| e.changing),
            ("clamps per particle-step", |e| e.clamps_per_particle_step),
        ],
        run(&with, n, runs),
        run(&resting, n, runs),
        (n, n),
    ));

    // M5.7b on the pile: 8 rows under g = 0.02 (tests/tests/rest.rs).
    for e in [0.0, 0.5] {
        let (off, on) = (pile(e, false), pile(e, true));
        let n = steps(off.steps);
        out.extend(rows::<Ended>(
            "M5.7b resting contact",
            format!("{} (e = {e}, contacts)", off.name),
            &[
                ("mean speed at the end", |e| e.mean_speed),
                ("share of occupied cells emptied in a step, at the end", |e| e.changing),
                ("clamps per particle-step", |e| e.clamps_per_particle_step),
            ],
            run(&off, n, runs),
            run(&on, n, runs),
            (n, n),
        ));
    }

    // M1b: the elastic box, unbiased rounding against energy-neutral.
    out.extend(rows::<Ended>(
        "M1b energy-neutral rounding",
        "elastic 8-bit box, 128² (e = 1)".into(),
        &[("kinetic energy, relative change", |e| e.energy_change)],
        elastic_run(false, box_steps, runs),
        elastic_run(true, box_steps, runs),
        (box_steps, box_steps),
    ));
    out
}

/// The pile of tests/tests/rest.rs: a 64 x 48 box with walls, gravity 0.02
/// down, restitution `e` for particles and walls, contacts on, resting
/// contact as `rest` says, and 8 full rows dropped from 12 cells up;
/// 1,500 steps.
fn pile(e: f32, rest: bool) -> Scene {
    let mut desc = Description::new_2d(64, 48).with_boundary(Boundary::Wall);
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.02, 0.0];
    desc.restitution = e;
    desc.wall_restitution = e;
    desc.contacts = true;
    desc.rest = rest;
    desc.seed = 11;
    Scene { name: "8-row pile, 64 × 48", section: "-", desc, steps: 1500, paper_seconds: f64::NAN, setup: fill_pile }
}

fn fill_pile(w: &mut World) -> Result<(), Error> {
    for y in 12..20 {
        for x in 0..64 {
            w.add_particle([x, y, 0], [0.0; 3])?;
        }
    }
    Ok(())
}
