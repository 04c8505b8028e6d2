//! The paper's four scenes (tests/src/scenes.rs) under every setting, with
//! the M10 errors that apply to each, and M9's "leave out what the scene
//! does not need": each scene in its own description against one that
//! enables every part with values that change nothing.

use mpca::{Description, World};

use super::cooling::{fit_haff, HaffFit};
use super::{repeat, Setting, Timing};
use crate::scenes::{build, Scene};

/// One scene under one setting.
#[derive(Clone, Debug)]
pub struct SceneRow {
    /// The scene's name.
    pub scene: &'static str,
    /// The switches.
    pub setting: Setting,
    /// Steps run.
    pub steps: u64,
    /// Particles at the end.
    pub particles: u64,
    /// Particle-steps (the particles present at each step, summed).
    pub particle_steps: u64,
    /// Particles not placed in their desired cell (M5.6), over
    /// `particle_steps`.
    pub displaced: f64,
    /// Collisions.
    pub collisions: u64,
    /// Clamps (M5.5).
    pub clamps: u64,
    /// Energy the clamps removed.
    pub clamp_energy: f64,
    /// Kinetic energy at the start and at the end.
    pub energy: (f64, f64),
    /// Momentum at the start and at the end.
    pub momentum: ([f64; 3], [f64; 3]),
    /// Particles that left by open faces.
    pub exited: u64,
    /// Particles found on obstacle cells, summed over the steps.
    pub inside: u64,
    /// Haff's law fitted to the scene's temperature (the aggregation scene,
    /// a cooling gas with e = 0.5).
    pub haff: Option<HaffFit>,
    /// Step times.
    pub timing: Timing,
    /// Bytes per cell.
    pub bytes_per_cell: f64,
    /// The state hash at the end.
    pub hash: u64,
}

impl SceneRow {
    /// Median nanoseconds per particle-step.
    pub fn ns_per_particle_step(&self) -> f64 {
        self.timing.median() * 1e9 / self.particle_steps.max(1) as f64
    }
}

/// Runs `scene` for `steps` steps under `setting`.
pub fn measure(scene: &Scene, setting: Setting, steps: u64, runs: usize) -> SceneRow {
    let mut sc = *scene;
    setting.apply(&mut sc.desc);
    let mut mem = vec![];
    let (row, timing) = repeat(runs, || {
        let world: &mut World = build(&sc, &mut mem).expect("the scene builds");
        let start = world.stats();
        let mut series = vec![start.kinetic_energy / start.particles.max(1) as f64];
        let (mut inside, mut particle_steps) = (0u64, 0u64);
        let obstacles = sc.desc.obstacles;
        let want_series = sc.name == "aggregation";
        let mut gone = 0u64;
        let seconds = super::run_steps(world, steps, |w, _| {
            // Particles present during the step: those left after it plus
            // those that left during it (emitted ones are placed at its start).
            let s = w.stats();
            particle_steps += s.particles + (s.exited + s.expired - gone);
            gone = s.exited + s.expired;
            if obstacles {
                inside += w.particles().filter(|p| w.obstacle_at(p.pos)).count() as u64;
            }
            if want_series {
                series.push(s.kinetic_energy / s.particles.max(1) as f64);
            }
        });
        let end = world.stats();
        let row = SceneRow {
            scene: sc.name,
            setting,
            steps,
            particles: end.particles,
            particle_steps,
            displaced: end.displaced as f64 / particle_steps.max(1) as f64,
            collisions: end.collisions,
            clamps: end.clamps,
            clamp_energy: end.clamp_energy,
            energy: (start.kinetic_energy, end.kinetic_energy),
            momentum: (start.momentum, end.momentum),
            exited: end.exited,
            inside,
            haff: want_series.then(|| fit_haff(&series)),
            timing: Timing::default(),
            bytes_per_cell: world.bytes_per_cell(),
            hash: world.state_hash(),
        };
        (row, seconds)
    });
    SceneRow { timing, ..row }
}

/// `desc` with every part switched on, each with a value that changes
/// nothing: per-particle masses (16 classes; every particle keeps the
/// scene's mass), obstacles (none placed), all four forces (the scene's
/// gravity or none, a zero field and potential, the scene's vortex or one of
/// zero circulation), lifetimes (particles added by hand and the scenes'
/// emitters live for ever) and room for 4 emitters.
pub fn every_part(desc: &Description) -> Description {
    let mut d = *desc;
    d.per_particle_mass = true;
    d.mass_classes = 16;
    d.obstacles = true;
    d.surface_capacity = d.surface_capacity.max(1024);
    d.forces.uniform = true;
    d.forces.field = true;
    d.forces.potential = true;
    if !desc.forces.vortex {
        d.forces.vortex = true;
        d.vortex.circulation = 0.0;
    }
    d.lifetimes = true;
    d.emitter_capacity = d.emitter_capacity.max(4);
    d
}

/// One variant of a scene's description.
#[derive(Clone, Debug)]
pub struct LeaveOutRow {
    /// The scene's name.
    pub scene: &'static str,
    /// "as needed", "every part", "every part but unused forces", "every
    /// part, 16-bit".
    pub variant: &'static str,
    /// Step times.
    pub timing: Timing,
    /// Bytes per cell.
    pub bytes_per_cell: f64,
    /// The state hash at the end.
    pub hash: u64,
    /// Particles at the end.
    pub particles: u64,
    /// Clamps (M5.5) during the run.
    pub clamps: u64,
}

/// The scene in its own description, with every part, with every part but
/// the force terms the scene does not use, and with every part and 16-bit
/// velocities (the default setting otherwise).
pub fn leave_out(scene: &Scene, steps: u64, runs: usize) -> Vec<LeaveOutRow> {
    let mut full16 = every_part(&scene.desc);
    full16.quantization = mpca::Quantization::Bits16;
    let mut no_forces = every_part(&scene.desc);
    no_forces.forces = scene.desc.forces;
    let variants = [
        ("as needed", scene.desc),
        ("every part", every_part(&scene.desc)),
        ("every part but unused forces", no_forces),
        ("every part, 16-bit", full16),
    ];
    let mut mem = vec![];
    variants
        .into_iter()
        .map(|(variant, desc)| {
            let sc = Scene { desc, ..*scene };
            let (row, timing) = repeat(runs, || {
                let world: &mut World = build(&sc, &mut mem).expect("the scene builds");
                let seconds = super::clock(|| world.step(steps));
                let row = LeaveOutRow {
                    scene: sc.name,
                    variant,
                    timing: Timing::default(),
                    bytes_per_cell: world.bytes_per_cell(),
                    hash: world.state_hash(),
                    particles: world.particle_count(),
                    clamps: world.stats().clamps,
                };
                (row, seconds)
            });
            LeaveOutRow { timing, ..row }
        })
        .collect()
}
