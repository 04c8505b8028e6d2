//! The paper's four scenes (section 4; MODEL.md, "The paper's scenes and
//! figures"), as descriptions plus a function that fills a fresh world.
//! Where the paper gives no figure (the smoke domain, the water emitter), the
//! choice is written next to it.

use mpca::{Boundary, Description, Emitter, Error, Shape, Vortex, World};
use rand_core::Rng;
use rand_pcg::Pcg32;

/// One of the paper's scenes.
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    /// Short name, also used for file names.
    pub name: &'static str,
    /// Section of the paper.
    pub section: &'static str,
    /// The world's description.
    pub desc: Description,
    /// Steps the paper ran.
    pub steps: u64,
    /// The paper's wall time for those steps on a Sun SPARCstation 2GS, s.
    pub paper_seconds: f64,
    /// Places the scene's particles and obstacles in a fresh world.
    pub setup: fn(&mut World) -> Result<(), Error>,
}

/// A stream for placing the initial particles; the world's own streams are
/// separate (M8).
fn setup_rng(world: &World) -> Pcg32 {
    Pcg32::new(world.description().seed ^ 0x5ce7_e500, 0x0dd)
}

/// 4.1 aggregation: 2D 128 x 128, density 0.3, random velocities, no force,
/// e = 0.5, 800 steps. Periodic. Speeds uniform in [0, 1), directions
/// uniform.
pub fn aggregation() -> Scene {
    let mut desc = Description::new_2d(128, 128);
    desc.restitution = 0.5;
    desc.seed = 41;
    Scene { name: "aggregation", section: "4.1", desc, steps: 800, paper_seconds: 800.0, setup: fill_aggregation }
}

fn fill_aggregation(w: &mut World) -> Result<(), Error> {
    let mut rng = setup_rng(w);
    let [nx, ny, _] = w.description().size;
    for y in 0..ny {
        for x in 0..nx {
            if unit(&mut rng) < 0.3 {
                let speed = unit(&mut rng);
                let a = core::f32::consts::TAU * unit(&mut rng);
                w.add_particle([x, y, 0], [speed * a.cos(), speed * a.sin(), 0.0])?;
            }
        }
    }
    Ok(())
}

/// 4.2 cluster collision: 2D 128 x 128, two discs of radius 10 cells
/// (about 300 particles each), velocities (+-0.8, 0), e = 1, m = 1, 130 steps.
/// Walls all round, so nothing leaves.
pub fn cluster() -> Scene {
    let mut desc = Description::new_2d(128, 128).with_boundary(Boundary::Wall);
    desc.restitution = 1.0;
    desc.mass = 1.0;
    desc.seed = 42;
    Scene { name: "cluster", section: "4.2", desc, steps: 130, paper_seconds: 70.0, setup: fill_cluster }
}

fn fill_cluster(w: &mut World) -> Result<(), Error> {
    for (cx, vx) in [(40.0f32, 0.8f32), (88.0, -0.8)] {
        for y in 0..128u32 {
            for x in 0..128u32 {
                let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - 64.0);
                if dx * dx + dy * dy <= 100.0 {
                    w.add_particle([x, y, 0], [vx, 0.0, 0.0])?;
                }
            }
        }
    }
    Ok(())
}

/// 4.3 smoke: 2D 128 x 128 (the paper gives no size), about one particle per
/// step emitted at the bottom with a rising velocity, a static Rankine vortex
/// force, e = 1, one mass, 120 steps. A wall below, open on the other faces.
pub fn smoke() -> Scene {
    let mut desc = Description::new_2d(128, 128).with_boundary(Boundary::Open);
    desc.boundary[1][0] = Boundary::Wall;
    desc.restitution = 1.0;
    desc.forces.vortex = true;
    desc.vortex = Vortex { centre: [64.0, 72.0], core_radius: 10.0, circulation: 2.0 };
    desc.emitter_capacity = 1;
    desc.seed = 43;
    Scene { name: "smoke", section: "4.3", desc, steps: 120, paper_seconds: 8.0, setup: fill_smoke }
}

fn fill_smoke(w: &mut World) -> Result<(), Error> {
    w.add_emitter(Emitter {
        min: [60, 0, 0],
        max: [68, 2, 1],
        rate: 1.0,
        velocity: [0.0, 0.6, 0.0],
        spread: 0.2,
        mass: 1.0,
        lifetime: 0,
    })?;
    Ok(())
}

/// 4.4 water: 3D 64^3, emitted at the top, gravity, a sphere obstacle in the
/// middle, e = 1, 130 steps. y is up; walls all round. The emitter (the paper
/// gives no rate) pours 16 particles a step from an 8 x 8 patch.
pub fn water() -> Scene {
    let mut desc = Description::new_3d(64, 64, 64).with_boundary(Boundary::Wall);
    desc.restitution = 1.0;
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.02, 0.0];
    desc.obstacles = true;
    desc.surface_capacity = 4096;
    desc.emitter_capacity = 1;
    desc.seed = 44;
    Scene { name: "water", section: "4.4", desc, steps: 130, paper_seconds: 270.0, setup: fill_water }
}

fn fill_water(w: &mut World) -> Result<(), Error> {
    w.add_shape(Shape::Sphere { centre: [32.0, 28.0, 32.0], radius: 10.0 }, 1.0)?;
    w.add_emitter(Emitter {
        min: [28, 60, 28],
        max: [36, 62, 36],
        rate: 16.0,
        velocity: [0.0, -0.3, 0.0],
        spread: 0.05,
        mass: 1.0,
        lifetime: 0,
    })?;
    Ok(())
}

/// All four, in the paper's order.
pub fn paper_scenes() -> [Scene; 4] {
    [aggregation(), cluster(), smoke(), water()]
}

/// Builds a scene's world in `memory` (resized to fit) and fills it.
pub fn build<'a>(scene: &Scene, memory: &'a mut Vec<u8>) -> Result<&'a mut World, Error> {
    memory.clear();
    memory.resize(mpca::world_bytes(&scene.desc)?, 0);
    let world = World::init(&scene.desc, memory)?;
    (scene.setup)(world)?;
    Ok(world)
}

fn unit(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / 16_777_216.0
}
