//! The page's scenes, 128 x 128 cells each: smoke rising from the floor
//! into a vortex's flow, and water poured over a disc into a walled box.
//! A click on the page adds an emitter where it lands ([`emit`]).

use mpca::{Boundary, Collisions, Description, Drag, Drift, Emitter, Error, ErrorKind, Shape, Vortex, World};

/// Cells along each side.
pub const SIZE: u32 = 128;

/// Emitters a world holds: its own and those clicks add.
pub const EMITTERS: u32 = 16;

/// Water stops pouring (every emitter's rate 0) above this many particles,
/// so the box does not fill up.
pub const WATER_CAP: u64 = 6000;

/// The two scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Smoke: buoyancy and drag towards a vortex's flow, open sides and top.
    Smoke,
    /// Water: gravity, walls, contacts, a disc.
    Water,
}

impl Kind {
    /// The scene numbered `n` (0 smoke, 1 water), as the page numbers them.
    pub fn from_index(n: u32) -> Option<Kind> {
        match n {
            0 => Some(Kind::Smoke),
            1 => Some(Kind::Water),
            _ => None,
        }
    }

    /// The scene called `name` (`smoke`, `water`).
    pub fn from_name(name: &str) -> Option<Kind> {
        match name {
            "smoke" => Some(Kind::Smoke),
            "water" => Some(Kind::Water),
            _ => None,
        }
    }
}

/// The scene's description with seed `seed`.
pub fn description(kind: Kind, seed: u64) -> Description {
    let mut d = Description::new_2d(SIZE, SIZE);
    d.seed = seed;
    d.drift = Drift::Calibrated;
    d.collisions = Collisions::SpeedLimited;
    d.forces.uniform = true;
    d.emitter_capacity = EMITTERS;
    match kind {
        Kind::Smoke => {
            d.boundary = [[Boundary::Open; 2]; 3];
            d.boundary[1][0] = Boundary::Wall;
            d.restitution = 1.0;
            d.gravity = [0.0, 0.004, 0.0];
            d.vortex = Vortex { centre: [64.0, 72.0], core_radius: 10.0, circulation: 8.0 };
            d.drag = Drag { rate: 0.05, wind: [0.0; 3], field: false, vortex: true, ..Drag::OFF };
        }
        Kind::Water => {
            d.boundary = [[Boundary::Wall; 2]; 3];
            d.restitution = 0.5;
            d.wall_restitution = 0.5;
            d.gravity = [0.0, -0.01, 0.0];
            d.contacts = true;
            d.obstacles = true;
            d.surface_capacity = 512;
        }
    }
    d
}

/// A source at cell (x, y): smoke puffs upwards, water pours down and to
/// the right.
fn source(kind: Kind, x: u32, y: u32) -> Emitter {
    let (rate, velocity, spread, r) = match kind {
        Kind::Smoke => (2.0, [0.0, 0.4, 0.0], 0.1, 3),
        Kind::Water => (2.0, [0.25, -0.2, 0.0], 0.05, 2),
    };
    let span = |c: u32| (c.saturating_sub(r), (c + r).min(SIZE - 1));
    let ((x0, x1), (y0, y1)) = (span(x), span(y));
    Emitter { min: [x0, y0, 0], max: [x1, y1, 0], rate, velocity, spread, mass: 1.0, lifetime: 0 }
}

/// Builds the scene in `memory` (at least `mpca::world_bytes` of its
/// description): the obstacles and the scene's own emitter.
pub fn build(kind: Kind, seed: u64, memory: &mut [u8]) -> Result<&mut World, Error> {
    let world = World::init(&description(kind, seed), memory)?;
    match kind {
        Kind::Smoke => {
            world.add_emitter(source(kind, 64, 2))?;
        }
        Kind::Water => {
            world.add_shape(Shape::Disc { centre: [64.0, 44.0], radius: 14.0 }, 0.5)?;
            world.add_emitter(source(kind, 48, 112))?;
        }
    }
    Ok(world)
}

/// One step, and for water the cap on its particles.
pub fn step(kind: Kind, world: &mut World) {
    world.step(1);
    if kind == Kind::Water && world.particle_count() > WATER_CAP {
        for i in 0..EMITTERS as usize {
            let _ = world.set_emitter_rate(i, 0.0);
        }
    }
}

/// A click at cell (x, y): one more emitter there. Refused when the table
/// is full or the cell lies outside.
pub fn emit(kind: Kind, world: &mut World, x: u32, y: u32) -> Result<usize, Error> {
    if x >= SIZE || y >= SIZE {
        return Err(Error::new(ErrorKind::OutOfBounds, c"the click is outside the scene"));
    }
    world.add_emitter(source(kind, x, y))
}

/// The world drawn into `pixels` (RGBA, `SIZE` x `SIZE`, the top row
/// first): background, obstacles grey, particles coloured by speed (smoke
/// grey to white, water deep to light blue). Returns how many pixels hold a
/// particle.
pub fn render(kind: Kind, world: &World, pixels: &mut [u8]) -> u32 {
    let n = SIZE as usize;
    for y in 0..n {
        for x in 0..n {
            let at = ((n - 1 - y) * n + x) * 4;
            let solid = matches!(world.cell([x as u32, y as u32, 0]), Ok(mpca::Cell::Obstacle));
            let rgb = if solid { [96, 100, 110] } else { [14, 16, 22] };
            pixels[at..at + 4].copy_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
        }
    }
    let mut drawn = 0;
    for p in world.particles() {
        let v = p.velocity;
        // Brighter with speed; most move slower than a quarter cell a step.
        let s = ((v[0] * v[0] + v[1] * v[1]) * 16.0).min(1.0);
        let rgb = match kind {
            Kind::Smoke => {
                let g = 140.0 + 115.0 * s;
                [g as u8, g as u8, g as u8]
            }
            Kind::Water => [(30.0 + 120.0 * s) as u8, (90.0 + 120.0 * s) as u8, 230],
        };
        let (x, y) = (p.pos[0] as usize, p.pos[1] as usize);
        let at = ((n - 1 - y) * n + x) * 4;
        pixels[at..at + 4].copy_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
        drawn += 1;
    }
    drawn
}
