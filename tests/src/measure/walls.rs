//! Obstacle fidelity (M10): reflection angles off a flat wall with e = 1
//! against the incoming angle, and particles found inside obstacles (which
//! must be none).
//!
//! Reflection: particles fly at a wall from angles of 10 to 70 degrees
//! to its normal, one per z-plane of a 3D world (planes 4 apart, no speed
//! along z, so no two share a block and only the wall changes a velocity).
//! Four walls: the domain's wall face (M4), an axis-aligned half-space
//! obstacle and half-spaces tilted by 30 and 60 degrees (M7 normals; on
//! the grid they are staircases of cells). For each
//! particle the first step that changes its velocity is the bounce:
//! - velocity angles: incoming from the stored velocity before, outgoing
//!   after (eq. 9 keeps the angle; rounding to storage, M1, moves it);
//! - trajectory angles: from the mean displacement per step over the
//!   approach and over up to 12 steps after the bounce. The drift rule
//!   (M5.3) scales each axis's mean speed separately, so under the paper's
//!   rule a path's angle differs from its velocity's.

use mpca::{Boundary, Description, Drift, Quantization, Shape, World};

use super::{memory, repeat, scale, Setting, SetupRng, Timing};

/// Incoming angles to the normal, in degrees.
pub const ANGLES: [f64; 7] = [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0];
/// Speed of the incoming particles.
pub const SPEED: f64 = 0.6;
/// Steps followed after a bounce.
const AFTER: u64 = 12;

/// Which wall.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wall {
    /// The domain's low y face.
    Face,
    /// A half-space obstacle below y = 4 with normal +y.
    Flat,
    /// A half-space through (32, 32) with normal (sin 30, cos 30).
    Tilted30,
    /// A half-space through (40, 56) with normal (sin 60, cos 60).
    Tilted60,
}

impl Wall {
    /// All four.
    pub const ALL: [Wall; 4] = [Wall::Face, Wall::Flat, Wall::Tilted30, Wall::Tilted60];
    /// The staircases.
    pub const TILTED: [Wall; 2] = [Wall::Tilted30, Wall::Tilted60];

    /// The report's name.
    pub fn name(self) -> &'static str {
        match self {
            Wall::Face => "wall face",
            Wall::Flat => "flat obstacle",
            Wall::Tilted30 => "obstacle tilted 30°",
            Wall::Tilted60 => "obstacle tilted 60°",
        }
    }

    /// The tilt from the horizontal, degrees.
    pub fn tilt(self) -> f64 {
        match self {
            Wall::Face | Wall::Flat => 0.0,
            Wall::Tilted30 => 30.0,
            Wall::Tilted60 => 60.0,
        }
    }

    fn normal(self) -> [f64; 3] {
        let a = self.tilt().to_radians();
        [a.sin(), a.cos(), 0.0]
    }

    /// A point of a tilted wall's surface, and the domain's width and
    /// height: room for every path to the wall and on along it, so that no
    /// particle meets the domain's faces or the wall's end first (the flat
    /// walls run along a periodic x axis instead).
    fn anchor(self) -> ([f64; 2], [u32; 2]) {
        match self {
            Wall::Face | Wall::Flat => ([0.0, 0.0], [64, 40]),
            Wall::Tilted30 => ([32.0, 32.0], [96, 64]),
            Wall::Tilted60 => ([40.0, 56.0], [96, 96]),
        }
    }
}

/// One (wall, setting, incoming angle).
#[derive(Clone, Debug)]
pub struct ReflectRow {
    /// The wall.
    pub wall: Wall,
    /// Storage.
    pub quant: Quantization,
    /// Move rule.
    pub drift: Drift,
    /// The requested incoming angle, degrees.
    pub angle: f64,
    /// Particles whose first velocity change happened next to the wall.
    pub bounces: usize,
    /// Particles whose first change happened elsewhere or never: they
    /// skimmed along the obstacle's staircase of cells without asking for
    /// an obstacle cell, and left its end.
    pub missed: usize,
    /// Mean `|outgoing - incoming|` of the stored velocities at the first
    /// bounce, degrees: eq. 9 and the rounding to storage.
    pub first_error: f64,
    /// Largest such difference, degrees.
    pub first_error_max: f64,
    /// Mean `|outgoing - incoming|` with the velocity the particle leaves
    /// the wall with, after any further change next to the wall (a tilted
    /// wall is a staircase of cells: a particle leaving at a grazing angle
    /// can meet the next step, whose reflection falls back to the face it
    /// came through, M5.4), degrees.
    pub net_error: f64,
    /// Largest such difference, degrees.
    pub net_error_max: f64,
    /// Share of bounces with such a further change.
    pub kicked: f64,
    /// Mean `|v_out| / |v_in| - 1` at the first bounce (0 for e = 1 but for
    /// rounding).
    pub speed_change: f64,
    /// Angle of the mean approach path, degrees.
    pub path_in: f64,
    /// Angle of the mean path after the bounce, degrees.
    pub path_out: f64,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The angle of `v` to the normal `n` on the tangent `t`'s side, degrees;
/// `into` measures an incoming direction (against `n`).
fn angle(v: [f64; 3], n: [f64; 3], t: [f64; 3], into: bool) -> f64 {
    let along = if into { -dot(v, n) } else { dot(v, n) };
    dot(v, t).atan2(along).to_degrees()
}

/// What happened to one particle at the wall.
#[derive(Clone, Copy, Debug)]
struct Bounce {
    /// Cell of the first bounce.
    at: [i64; 3],
    /// Velocity right after it.
    first: [f64; 3],
    /// Velocity now (after further changes next to the wall).
    last: [f64; 3],
    /// Changes after the first, next to the wall.
    kicks: u32,
    /// Steps followed after the first bounce, and the cell reached.
    after: u64,
    end: [i64; 3],
}

#[derive(Clone, Copy, Debug, Default)]
struct Track {
    start: [i64; 3],
    v_in: [f64; 3],
    bounce: Option<Bounce>,
    missed: bool,
    done: bool,
}

impl Wall {
    /// Whether a particle in cell `pos` touches this wall: on the first row
    /// for the wall face, next to an obstacle cell (in its z-plane)
    /// otherwise. A bounce elsewhere (the domain's faces, reached by a
    /// particle that skimmed along the obstacle's staircase without
    /// touching it) does not count, nor does one in a cell on a wall face
    /// of the domain, where the face may be what the particle met.
    fn touches(self, world: &World, pos: [i64; 3]) -> bool {
        if self == Wall::Face {
            return pos[1] == 0;
        }
        let d = world.description();
        for (k, &p) in pos.iter().enumerate().take(2) {
            if (p == 0 || p == i64::from(d.size[k]) - 1) && d.boundary[k][0] == Boundary::Wall {
                return false;
            }
        }
        let mut near = false;
        for dy in -1..=1i64 {
            for dx in -1..=1i64 {
                let (x, y) = (pos[0] + dx, pos[1] + dy);
                if x >= 0 && y >= 0 {
                    near |= world.obstacle_at([x as u32, y as u32, pos[2] as u32]);
                }
            }
        }
        near
    }
}

/// Bounces particles off one wall with one setting; returns a row per angle
/// and the step times.
pub fn reflect(wall: Wall, quant: Quantization, drift: Drift, per_angle: usize, runs: usize) -> (Vec<ReflectRow>, Timing) {
    let planes = (ANGLES.len() * per_angle) as u32;
    let (anchor, [width, height]) = wall.anchor();
    let mut desc = Description::new_3d(width, height, 4 * planes);
    let flat = matches!(wall, Wall::Face | Wall::Flat);
    desc.boundary[0] = [if flat { Boundary::Periodic } else { Boundary::Wall }; 2];
    desc.boundary[1] = [Boundary::Wall; 2];
    desc.quantization = quant;
    desc.drift = drift;
    desc.seed = 80;
    if wall != Wall::Face {
        desc.obstacles = true;
        desc.surface_capacity = width * 8 * 4 * planes;
    }
    let n = wall.normal();
    let t = [n[1], -n[0], 0.0];
    let mut mem = memory(&desc);
    // The wall is built once and saved (M12): every timed run loads it
    // back bit for bit, which costs far less than adding the shape to a
    // domain of a few million cells again.
    let image = {
        let world: &mut World = World::init(&desc, &mut mem).expect("fits");
        match wall {
            Wall::Face => Ok(()),
            Wall::Flat => world.add_shape(Shape::HalfSpace { point: [0.0, 4.0, 0.0], normal: [0.0, 1.0, 0.0] }, 1.0),
            Wall::Tilted30 | Wall::Tilted60 => {
                let nf = n.map(|c| c as f32);
                world.add_shape(Shape::HalfSpace { point: [anchor[0] as f32, anchor[1] as f32, 0.0], normal: nf }, 1.0)
            }
        }
        .expect("the wall fits");
        let mut image = vec![0u8; world.snapshot_bytes()];
        world.save(&mut image).expect("the image fits");
        image
    };
    let (tracks, timing) = repeat(runs, || {
        let world: &mut World = World::init(&desc, &mut mem).expect("fits");
        world.load(&image).expect("the world's own image");
        let mut tracks = vec![Track::default(); planes as usize];
        for (j, track) in tracks.iter_mut().enumerate() {
            let a = ANGLES[j / per_angle].to_radians();
            // Into the wall at angle a from -n, on the +t side.
            let v = [0, 1, 2].map(|k| (SPEED * (-a.cos() * n[k] + a.sin() * t[k])) as f32);
            // Start 6 cells from the wall along n (from its point at x =
            // anchor - 12 for the tilted ones), spread along the tangent
            // so both parities of every axis occur. Under the paper's rule
            // a 70 degree path covers at most 3.5 cells along the wall per
            // cell towards it: about 21 cells to the wall, 12 steps after,
            // all clear of the x faces.
            let base = match wall {
                Wall::Face => [4.0, 6.5],
                Wall::Flat => [4.0, 10.5],
                Wall::Tilted30 | Wall::Tilted60 => {
                    [anchor[0] - 12.0 + 6.0 * n[0], anchor[1] + 12.0 * n[0] / n[1] + 6.0 * n[1]]
                }
            };
            let shift = (j % per_angle) as f64 * 0.37 + (j / per_angle) as f64 * 0.11;
            let pos = [(base[0] + shift * t[0]).floor() as u32, (base[1] + shift * t[1]).floor() as u32, 4 * j as u32];
            world.add_particle(pos, v).expect("a free cell");
            track.start = pos.map(i64::from);
        }
        for p in world.particles() {
            tracks[(p.pos[2] / 4) as usize].v_in = p.velocity.map(f64::from);
        }
        let mut seconds = 0.0;
        let mut step = 0;
        while tracks.iter().any(|t| !t.done) && step < 600 {
            seconds += super::clock(|| world.step(1));
            step += 1;
            for p in world.particles() {
                let tr = &mut tracks[(p.pos[2] / 4) as usize];
                let pos = p.pos.map(i64::from);
                let v = p.velocity.map(f64::from);
                if tr.done {
                    continue;
                }
                match &mut tr.bounce {
                    None if v == tr.v_in => {}
                    None if wall.touches(world, pos) => {
                        tr.bounce = Some(Bounce { at: pos, first: v, last: v, kicks: 0, after: 0, end: pos });
                    }
                    None => (tr.missed, tr.done) = (true, true),
                    Some(b) => {
                        if v != b.last {
                            if !wall.touches(world, pos) {
                                tr.done = true;
                                continue;
                            }
                            b.kicks += 1;
                            b.last = v;
                        }
                        b.end = pos;
                        b.after += 1;
                        tr.done = b.after == AFTER;
                    }
                }
            }
        }
        assert_eq!(world.stats().collisions, 0, "the particles never meet");
        (tracks, seconds)
    });
    let mut rows = vec![];
    for (g, &deg) in ANGLES.iter().enumerate() {
        let group = &tracks[g * per_angle..(g + 1) * per_angle];
        let bounced: Vec<(&Track, Bounce)> = group.iter().filter_map(|t| t.bounce.map(|b| (t, b))).collect();
        let (mut first, mut first_max, mut net, mut net_max, mut kicked, mut speed) = (0.0, 0.0f64, 0.0, 0.0f64, 0, 0.0);
        let (mut d_in, mut d_out) = ([0.0; 3], [0.0; 3]);
        for (tr, b) in &bounced {
            let inc = angle(tr.v_in, n, t, true);
            let e1 = (angle(b.first, n, t, false) - inc).abs();
            let e2 = (angle(b.last, n, t, false) - inc).abs();
            (first, first_max) = (first + e1, first_max.max(e1));
            (net, net_max) = (net + e2, net_max.max(e2));
            kicked += usize::from(b.kicks > 0);
            speed += (dot(b.first, b.first) / dot(tr.v_in, tr.v_in)).sqrt() - 1.0;
            for k in 0..3 {
                d_in[k] += (b.at[k] - tr.start[k]) as f64;
                d_out[k] += (b.end[k] - b.at[k]) as f64;
            }
        }
        let count = bounced.len().max(1) as f64;
        rows.push(ReflectRow {
            wall,
            quant,
            drift,
            angle: deg,
            bounces: bounced.len(),
            missed: group.iter().filter(|t| t.missed || t.bounce.is_none()).count(),
            first_error: first / count,
            first_error_max: first_max,
            net_error: net / count,
            net_error_max: net_max,
            kicked: kicked as f64 / count,
            speed_change: speed / count,
            path_in: angle(d_in, n, t, true),
            path_out: angle(d_out, n, t, false),
        });
    }
    (rows, timing)
}

/// The walls of the sliding runs, as integer normals `(a, b)`: a wall of
/// cells with `(a x + b y) mod 64 < SLIDE_BAND` repeats on a periodic
/// domain of 64 cells per axis, so a particle can follow its staircase for
/// as long as the run lasts. Tilts from the horizontal: 18.4°, 26.6°, 45°,
/// 63.4° and 71.6°.
pub const SLIDE_NORMALS: [[i32; 2]; 5] = [[1, 3], [1, 2], [1, 1], [2, 1], [3, 1]];
/// Width of a sliding wall, in units of `a x + b y`.
const SLIDE_BAND: i32 = 12;
/// Directions of the sliding particles from the wall's tangent, degrees:
/// positive away from the wall, negative into it (a grazing bounce first).
pub const SLIDE_ANGLES: [f64; 6] = [-10.0, -3.0, 0.0, 3.0, 10.0, 25.0];
/// Chance allowed to the whole measurement of holding a free particle in
/// one cell for [`SlideRow::stay_bound`] steps by bad luck alone.
const STAY_RISK: f64 = 1e-9;

/// Particles sliding along and away from staircase walls for many steps.
#[derive(Clone, Debug)]
pub struct SlideRow {
    /// Storage.
    pub quant: Quantization,
    /// Move rule.
    pub drift: Drift,
    /// Particles (one per world), steps each.
    pub particles: usize,
    /// Steps each particle was followed.
    pub steps: u64,
    /// Velocity changes that are eq. 9 off the wall's normal (±n, the
    /// side the particle came from), to within the rounding to storage:
    /// every component within one quantum.
    pub reflections: u64,
    /// Velocity changes that are not: a turn off any other direction (the
    /// face a particle came through, before M5.4 kept the velocity of a
    /// particle already leaving the wall).
    pub kicks: u64,
    /// Largest angle between a stored outgoing velocity and eq. 9's exact
    /// result, over the reflections, degrees (rounding).
    pub worst_deg: f64,
    /// Largest angle between a velocity after a kick and before, degrees.
    pub worst_kick_deg: f64,
    /// Longest run of steps a particle with a velocity spent in one cell.
    pub longest_stay: u64,
    /// The run no particle that can move should reach: a particle leaving
    /// a wall always has a free cell along one axis of its velocity, which
    /// it asks for, alone or with a move that stays clear of the wall, with
    /// probability `q` or more every two steps (M5.3); the bound is the
    /// run that even the smallest `q` met makes less likely than 1e-9 over
    /// every particle and step.
    pub stay_bound: u64,
    /// Particles whose longest stay exceeded that bound.
    pub stuck: usize,
    /// Particle-steps on an obstacle cell (must be 0).
    pub inside: u64,
    /// Step times.
    pub timing: Timing,
}

/// `q` of [`SlideRow::stay_bound`] for a particle of velocity `v` leaving or
/// sliding along a wall of unit normal `n` (`v.n >= 0`): the chance that in
/// the step of the two where it can ask for its free axis `a` (the axis of
/// the largest move probability among those with `v_a n_a > 0`), it asks
/// for a move that leaves the wall side no closer: `a` alone, or `a` with
/// the other axis where that diagonal has a positive component along `n`.
fn leave_chance(drift: Drift, v: [f64; 3], n: [f64; 3]) -> f64 {
    let p = |k: usize| super::move_probability(drift, v[k].abs());
    let Some(a) = (0..2).filter(|&k| v[k] * n[k] > 0.0).max_by(|&i, &j| p(i).total_cmp(&p(j))) else {
        return 0.0;
    };
    let b = 1 - a;
    let diagonal = v[a].signum() * n[a] + if v[b] == 0.0 { 0.0 } else { v[b].signum() * n[b] };
    p(a) * (1.0 - p(b)) + if diagonal > 0.0 { p(a) * p(b) } else { 0.0 }
}

/// Sliding along staircases: per wall of [`SLIDE_NORMALS`] and direction
/// of [`SLIDE_ANGLES`], both ways along the wall, one particle at speed 0.6
/// in its own 2D periodic world of 64 x 64 cells, starting next to the
/// wall, with e = 1, followed for `steps` steps. Every velocity change is
/// checked against eq. 9 off the wall's normal; the particle crosses the
/// gap between the walls and meets the next one on the other side too.
pub fn slide(quant: Quantization, drift: Drift, steps: u64, runs: usize) -> SlideRow {
    let mut desc = Description::new_2d(64, 64);
    desc.quantization = quant;
    desc.drift = drift;
    desc.obstacles = true;
    desc.surface_capacity = 64 * 64;
    let quantum = 1.0 / scale(quant);
    let mut mem = memory(&desc);
    let (row, timing) = repeat(runs, || {
        let mut row = SlideRow {
            quant,
            drift,
            particles: 0,
            steps,
            reflections: 0,
            kicks: 0,
            worst_deg: 0.0,
            worst_kick_deg: 0.0,
            longest_stay: 0,
            stay_bound: 0,
            stuck: 0,
            inside: 0,
            timing: Timing::default(),
        };
        let (mut seconds, mut least_q, mut stays) = (0.0, 1.0f64, vec![]);
        for (w, &[a, b]) in SLIDE_NORMALS.iter().enumerate() {
            let len = f64::from(a * a + b * b).sqrt();
            let n = [f64::from(a) / len, f64::from(b) / len, 0.0];
            let t = [n[1], -n[0], 0.0];
            let band = |x: i32, y: i32| (a * x + b * y).rem_euclid(64);
            for (j, &deg) in SLIDE_ANGLES.iter().enumerate() {
                for way in [1.0, -1.0] {
                    desc.seed = 700 + 100 * w as u64 + 2 * j as u64 + u64::from(way < 0.0);
                    let world: &mut World = World::init(&desc, &mut mem).expect("fits");
                    for y in 0..64 {
                        for x in 0..64 {
                            let s = band(x, y);
                            if s < SLIDE_BAND {
                                // The nearer face's normal: +n on the side of
                                // growing a x + b y.
                                let side = if s >= SLIDE_BAND / 2 { 1.0 } else { -1.0 };
                                let nf = n.map(|c| (side * c) as f32);
                                world.add_obstacle([x as u32, y as u32, 0], nf, 1.0).expect("a wall cell");
                            }
                        }
                    }
                    // Start in the first free cell past the wall's +n face,
                    // at a column that differs from particle to particle.
                    let x0 = (7 * (j as i32 + 6 * w as i32) + if way < 0.0 { 3 } else { 0 }).rem_euclid(64);
                    let y0 = (0..64).find(|&y| (SLIDE_BAND..SLIDE_BAND + a + b).contains(&band(x0, y))).expect("a free cell");
                    let r = deg.to_radians();
                    let v = [0, 1, 2].map(|k| (0.6 * (way * r.cos() * t[k] + r.sin() * n[k])) as f32);
                    world.add_particle([x0 as u32, y0 as u32, 0], v).expect("a free cell");
                    row.particles += 1;
                    let first = world.particles().next().expect("one particle");
                    let (mut pos, mut vel) = (first.pos, first.velocity.map(f64::from));
                    let (mut stay, mut longest) = (0u64, 0u64);
                    for _ in 0..steps {
                        seconds += super::clock(|| world.step(1));
                        let p = world.particles().next().expect("a periodic world keeps its particle");
                        let now = p.velocity.map(f64::from);
                        row.inside += u64::from(world.obstacle_at(p.pos));
                        if now != vel {
                            // The side of the wall the particle came from.
                            let side = if dot(vel, n) < 0.0 { 1.0 } else { -1.0 };
                            let m = n.map(|c| side * c);
                            let vn = dot(vel, m);
                            let want = [0, 1, 2].map(|k| vel[k] - 2.0 * vn * m[k]);
                            let rounding = (0..3).all(|k| (now[k] - want[k]).abs() < quantum * (1.0 + 1e-3));
                            if vn < 0.0 && rounding {
                                row.reflections += 1;
                                row.worst_deg = row.worst_deg.max(between(now, want));
                            } else {
                                row.kicks += 1;
                                row.worst_kick_deg = row.worst_kick_deg.max(between(now, vel));
                            }
                        }
                        if p.pos == pos && now != [0.0; 3] {
                            stay += 1;
                            longest = longest.max(stay);
                        } else {
                            stay = 0;
                        }
                        // The leaving chance of the velocity now, off the
                        // wall it leaves or slides along.
                        let m = if dot(now, n) >= 0.0 { n } else { n.map(|c| -c) };
                        if now != [0.0; 3] {
                            least_q = least_q.min(leave_chance(drift, now, m));
                        }
                        (pos, vel) = (p.pos, now);
                    }
                    stays.push(longest);
                }
            }
        }
        // A bounce keeps a particle in its cell one step more than the
        // leaving chance accounts for: two steps of slack.
        let windows = (row.particles as u64 * steps) as f64;
        row.stay_bound = if least_q > 0.0 { 2 * ((STAY_RISK / windows).ln() / (1.0 - least_q).ln()).ceil() as u64 + 2 } else { u64::MAX };
        row.longest_stay = stays.iter().copied().max().unwrap_or(0);
        row.stuck = stays.iter().filter(|&&s| s > row.stay_bound).count();
        (row, seconds)
    });
    SlideRow { timing, ..row }
}

/// The angle between two vectors, degrees.
fn between(u: [f64; 3], v: [f64; 3]) -> f64 {
    let c = dot(u, v) / (dot(u, u) * dot(v, v)).sqrt();
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Particles found inside obstacles in a busy walled world.
#[derive(Clone, Debug)]
pub struct InsideRow {
    /// The switches.
    pub setting: Setting,
    /// Particles.
    pub particles: u64,
    /// Steps.
    pub steps: u64,
    /// Particle-steps checked.
    pub checked: u64,
    /// Particles found on an obstacle cell, summed over the steps.
    pub inside: u64,
    /// Clamps (the obstacles reflect fast particles).
    pub clamps: u64,
    /// Step times.
    pub timing: Timing,
    /// Bytes per cell.
    pub bytes_per_cell: f64,
}

/// A 2D 64 x 64 walled box with gravity, a disc, a box and a tilted floor,
/// filled at density 0.3 with speeds up to 1 and e = 0.9; every particle's
/// cell is checked after every step.
pub fn inside(setting: Setting, steps: u64, runs: usize) -> InsideRow {
    let mut desc = Description::new_2d(64, 64).with_boundary(Boundary::Wall);
    setting.apply(&mut desc);
    desc.obstacles = true;
    desc.surface_capacity = 1024;
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.01, 0.0];
    desc.restitution = 0.9;
    desc.seed = 90;
    let mut mem = memory(&desc);
    let (row, timing) = repeat(runs, || {
        let world: &mut World = World::init(&desc, &mut mem).expect("fits");
        world.add_shape(Shape::Disc { centre: [32.0, 30.0], radius: 8.0 }, 0.9).expect("fits");
        world.add_shape(Shape::Box { min: [8.0, 44.0, 0.0], max: [20.0, 50.0, 0.0] }, 1.0).expect("fits");
        world.add_shape(Shape::HalfSpace { point: [0.0, 6.0, 0.0], normal: [-0.3, 1.0, 0.0] }, 0.8).expect("fits");
        let mut rng = SetupRng::new(desc.seed);
        let particles = super::scatter(world, 0.3, 1.0, &mut rng);
        let (mut inside, mut checked) = (0u64, 0u64);
        let seconds = super::run_steps(world, steps, |w, _| {
            for p in w.particles() {
                checked += 1;
                inside += u64::from(w.obstacle_at(p.pos));
            }
        });
        let s = world.stats();
        assert_eq!(s.particles, particles, "walls keep every particle");
        let row = InsideRow {
            setting,
            particles,
            steps,
            checked,
            inside,
            clamps: s.clamps,
            timing: Timing::default(),
            bytes_per_cell: world.bytes_per_cell(),
        };
        (row, seconds)
    });
    InsideRow { timing, ..row }
}

/// One quantum of speed at `quant` as an angle at [`SPEED`], in degrees: the
/// scale of the rounding error of a reflected velocity.
pub fn quantum_angle(quant: Quantization) -> f64 {
    (1.0 / scale(quant) / SPEED).to_degrees()
}
