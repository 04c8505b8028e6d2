//! What a second implementation of the step needs from this one: the
//! integers a step converts its settings to (M1c: per world, per mass
//! class, per emitter, per surface entry), the tables of the rule (M5.2's
//! turns, M5.3's move limits, M5.6's 2D assignments), the planes a step
//! reads (obstacles, force fields, potentials, wind) and those it changes
//! (occupancy, velocities, lifetimes, mass indices, ids, ages and tags) to
//! copy out and, checked, back in, with the counters and step number it
//! hands back. The GPU backend (`mpca-gpu`) is one: it runs
//! the block rule in a shader and keeps this crate's worlds, so that both
//! give the same world bit for bit (M8b). Nothing here is needed to use a
//! world.

use crate::api::desc::Drift;
use crate::api::error::{Error, ErrorKind};
use crate::rules::emitter::{split_rate, EmitterStats};
use crate::rules::fixed::{csqrt, divr, magnitude, parts, scaled, scaled_by, to_fine, unit_scale};
use crate::rules::force::Swirl;
use crate::rules::obstacle::{normal_q30, Surface};
use crate::rules::quant::unit_of;
use crate::step::convert_class;
use crate::step::partition::Partition;
use crate::storage::layout::stored;
pub use crate::rules::turbulence::TurbulenceConstants;
pub use crate::step::rest::RestConstants;
use crate::step::rest::Support;
use crate::storage::world::{Counters, World};

/// The integers one step of a world reads, converted from its description
/// as the step converts them (M1c, M8).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepConstants {
    /// M5.1's uniform push `G` per axis in fine units, 0 where the force
    /// is off (M1c).
    pub push: [i64; 3],
    /// M5.2's restitution `E` in Q16.
    pub restitution: i32,
    /// M5.4's restitution of the walls in Q16.
    pub wall_restitution: i32,
    /// M5.2b's limit on an outgoing speed in fine units: the unit speed
    /// less `sqrt(D)` quanta, rounded up.
    pub speed_limit: i32,
    /// The world's unit speed `W` in fine units (M1c).
    pub unit: i32,
    /// Fine bits per quantum, `F` (M1c).
    pub fine: u32,
    /// M5.3: per stored 8-bit component (as a byte), the largest 16
    /// random bits that say "move".
    pub moves: &'static [u16; 256],
    /// M5.1's Rankine vortex, where the force or the flow of M5.1b reads
    /// it (M1c); its strength as a force is each mass class's
    /// ([`World::port_class`]).
    pub vortex: Option<VortexConstants>,
    /// M5.1b's drag, where its rate is not 0.
    pub drag: Option<DragConstants>,
    /// M5.7b's support, where resting contact is on and the uniform push
    /// is not 0.
    pub rest: Option<RestConstants>,
}

/// M5.1's vortex as the step reads it (M1c): its centre and core radius
/// in `2^-8` cells, and, where the drag's flow holds it, its strength as a
/// flow `top(Γ'')`: a 16-bit significand `g` (signed) and an exponent `e`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VortexConstants {
    /// See the type.
    pub centre: [i64; 2],
    /// See the type.
    pub core: u32,
    /// `(g, e)` of `Γ''`, where the drag's flow holds the vortex.
    pub flow: Option<(i32, i32)>,
}

/// A surface entry of an obstacle cell as M5.4 reads it (M1c): its
/// cell, its normal in Q30 and its restitution in Q16.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceConstants {
    /// Dense cell index `x + nx (y + ny z)`.
    pub cell: u32,
    /// `conv(n_k, 1, 30)`, within `±2^30`.
    pub normal: [i32; 3],
    /// `conv(e, 1, 16)`.
    pub restitution: i32,
}

/// M5.1b's drag as the step reads it (M1c).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DragConstants {
    /// `C = 2^16 / (1 + dt rate)`, rounded: the weight of the velocity.
    pub keep: i32,
    /// The uniform wind `U` in fine units.
    pub wind: [i32; 3],
    /// The flow adds the wind plane.
    pub field: bool,
    /// The flow adds turbulence (M5.1c).
    pub turbulence: Option<TurbulenceConstants>,
}

/// An emitter as a step reads it (M6, M1c).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmitterConstants {
    /// Its region: cells `min[k] <= x_k < max[k]`.
    pub min: [u32; 3],
    /// See `min`.
    pub max: [u32; 3],
    /// The whole part of its rate (`u64::MAX` for an absurd one).
    pub whole: u64,
    /// One more particle where 24 random bits fall below this.
    pub threshold: u32,
    /// Its velocity in fine units, `conv(v_k, W, 0)`.
    pub velocity: [i32; 3],
    /// Its spread in fine units, `conv(spread, W, 0)`.
    pub radius: i32,
    /// Steps its particles live, 0 for ever.
    pub lifetime: u32,
    /// The mass index its particles get (M9).
    pub mass_index: u8,
    /// The tag its particles get (M6b).
    pub tag: u8,
}

/// What steps run elsewhere counted (the fields of [`crate::Stats`] of the
/// same names), handed back by [`World::port_finish_steps`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepCounts {
    /// Steps run.
    pub steps: u64,
    /// Over those steps.
    pub collisions: u64,
    /// Over those steps.
    pub clamps: u64,
    /// Over those steps, saturating.
    pub clamp_energy: u64,
    /// Over those steps.
    pub displaced: u64,
    /// Over those steps.
    pub exited: u64,
    /// Over those steps.
    pub expired: u64,
    /// Over those steps.
    pub emitted: u64,
    /// Over those steps (`Stats::emit_shortfall`).
    pub shortfall: u64,
    /// In the last of those steps.
    pub blocks_processed: u64,
    /// The last id given after those steps (M6b; the world's own where it
    /// keeps no ids).
    pub ids_given: u32,
}

/// A world's occupancy and velocity planes, as the step reads them.
pub struct PortPlanes<'a> {
    /// One bit a cell, `row_words` 64-bit words a row of `nx` cells (the
    /// last padded with zeros), rows in `y + ny z` order.
    pub occupancy: &'a [u64],
    /// 64-bit words a row of the occupancy.
    pub row_words: usize,
    /// The stored velocity components, `dim` a cell in dense cell order,
    /// one byte each (8-bit worlds) or two (16-bit, in the machine's byte
    /// order, as every plane here). What an empty cell holds is never read.
    pub velocity: &'a [u8],
    /// The steps each particle has left to live (M6), two bytes a cell (0
    /// for no limit); empty in a world without lifetimes.
    pub life: &'a [u8],
    /// Each particle's mass class (M9), a byte a cell; empty in a world
    /// of one mass.
    pub mass_index: &'a [u8],
    /// M6b's ids (four bytes a cell), ages (four) and tags (one), each
    /// empty where the world keeps none.
    pub id: &'a [u8],
    /// See `id`.
    pub age: &'a [u8],
    /// See `id`.
    pub tag: &'a [u8],
}

/// A mass class as a step reads it (M1c).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClassConstants {
    /// `M`: the mass relative to the largest in use, `2^24` for that one.
    pub relative: u32,
    /// M5.5's energy factor `h = m 2^e`: the clamp's counter adds
    /// `floor(n h)` for `n` cut to its top 40 bits.
    pub energy: (u32, i32),
    /// `K = quot(dt, m)`, as the bits of its `f32`.
    pub push: u32,
    /// The vortex force's strength for this class, `top(Γ')` as `(g, e)`,
    /// where the force is on.
    pub swirl: Option<(i32, i32)>,
}

/// A world's planes of `f32` settings per cell (M5.1, M5.1b), as their
/// bytes: `dim` values a cell for the force field and the wind, one for
/// the potential; each empty where the world has none. A step reads them
/// and writes none.
pub struct PortFields<'a> {
    /// M5.1's force field.
    pub force: &'a [u8],
    /// M5.1's potential.
    pub potential: &'a [u8],
    /// M5.1b's wind plane.
    pub wind: &'a [u8],
}

impl World {
    /// The integers of the step this world takes next (M1c, M8).
    pub fn port_constants(&self) -> StepConstants {
        let desc = &self.head.desc;
        let unit = unit_of(desc.quantization);
        let (s, fine) = unit_scale(unit);
        let push = if desc.forces.uniform { desc.gravity.map(|g| scaled_by(desc.dt, g, s, fine)) } else { [0; 3] };
        StepConstants {
            push,
            restitution: scaled(desc.restitution, 1.0, 16) as i32,
            wall_restitution: scaled(desc.wall_restitution, 1.0, 16) as i32,
            speed_limit: unit - csqrt(u64::from(desc.dim) << (2 * fine), 1 << fine) as i32,
            unit,
            fine: fine as u32,
            moves: crate::rules::quant::move_table_8(desc.drift),
            vortex: {
                let force = cfg!(feature = "vortex") && desc.forces.vortex;
                let flow = desc.has_drag() && desc.drag.vortex;
                (force || flow).then(|| {
                    let swirl = Swirl::of(&desc.vortex);
                    let (centre, core) = swirl.integers();
                    let top = swirl.gamma(1.0, (s, fine));
                    VortexConstants { centre, core, flow: flow.then_some((top.g, top.e)) }
                })
            },
            drag: desc.has_drag().then(|| DragConstants {
                keep: divr(1 << 48, (1 << 32) + scaled(desc.dt, desc.drag.rate, 32) as u64) as i32,
                wind: desc.drag.wind.map(|u| to_fine(u, (s, fine))),
                field: desc.drag.field,
                turbulence: TurbulenceConstants::of(desc, (s, fine)),
            }),
            rest: Support::of(desc, push, fine as u32).map(|s| s.constants()),
        }
    }

    /// Emitter `i` as a step reads it (M6, M1c), `None` past the last.
    pub fn port_emitter(&self, i: usize) -> Option<EmitterConstants> {
        let slot = self.slots().get(i)?;
        let e = slot.emitter;
        let scale = unit_scale(unit_of(self.head.desc.quantization));
        let (whole, threshold) = split_rate(e.rate);
        Some(EmitterConstants {
            min: e.min,
            max: e.max,
            whole,
            threshold,
            velocity: e.velocity.map(|v| to_fine(v, scale)),
            radius: to_fine(e.spread, scale),
            lifetime: e.lifetime,
            mass_index: slot.mass_index(),
            tag: slot.tag(),
        })
    }

    /// The occupancy, velocity and lifetime planes, to copy a world out.
    pub fn port_planes(&self) -> PortPlanes<'_> {
        let l = self.layout();
        PortPlanes {
            occupancy: self.plane(l.occupancy()),
            row_words: l.row_words,
            velocity: self.plane_bytes(l.velocity()),
            life: self.plane_bytes(l.life()),
            mass_index: self.plane_bytes(l.mass_index()),
            id: self.identity_plane(0),
            age: self.identity_plane(1),
            tag: self.identity_plane(2),
        }
    }

    /// Mass class `i` as a step reads it (M1c): a class in use, or, for an
    /// index the world has no class for, the class a step gives such a
    /// particle (the first).
    pub fn port_class(&self, i: u8) -> ClassConstants {
        let desc = &self.head.desc;
        let table: &[f32] = self.plane(self.layout().mass_table());
        let used = if desc.has_masses() { &table[..(self.head.masses as usize).min(desc.mass_classes as usize).min(table.len())] } else { &[] };
        // As the step converts them: the classes in use against the
        // largest of them (masses are positive, checked: their bits order
        // them as numbers), or the world's one mass.
        let (mass, largest) = match used.iter().map(|m| m.to_bits()).max() {
            Some(largest) => (used.get(usize::from(i)).unwrap_or(&used[0]).to_bits(), largest),
            None => (desc.mass.to_bits(), desc.mass.to_bits()),
        };
        let swirl = (cfg!(feature = "vortex") && desc.forces.vortex).then(|| Swirl::of(&desc.vortex));
        let class = convert_class(magnitude(f32::from_bits(mass)), magnitude(f32::from_bits(largest)), desc.dt, unit_scale(unit_of(desc.quantization)), swirl);
        let (_, m, e) = parts(class.energy);
        ClassConstants {
            relative: class.relative,
            energy: (m as u32, e),
            push: class.push.to_bits(),
            swirl: swirl.map(|_| (class.swirl.g, class.swirl.e)),
        }
    }

    /// M6b's plane `which` (0 ids, 1 ages, 2 tags) as bytes; empty in a
    /// build without them.
    fn identity_plane(&self, which: usize) -> &[u8] {
        #[cfg(feature = "identity")]
        {
            let l = self.layout();
            self.plane_bytes([l.id(), l.age(), l.tag()][which])
        }
        #[cfg(not(feature = "identity"))]
        {
            let _ = which;
            &[]
        }
    }

    /// The ids given so far (M6b): the last one given.
    pub fn port_ids_given(&self) -> u32 {
        self.head.ids_given
    }

    /// The obstacle cells (M7), one bit a cell laid out as the occupancy
    /// ([`World::port_planes`]); empty in a world without obstacles.
    pub fn port_obstacles(&self) -> &[u64] {
        self.plane(self.layout().obstacle())
    }

    /// Surface entry `i` of the obstacles (M7), in increasing cell order,
    /// as M5.4 reads it; `None` past the last.
    pub fn port_surface(&self, i: usize) -> Option<SurfaceConstants> {
        let l = self.layout();
        let table: &[Surface] = self.plane(l.surface());
        let entry = table[..(self.head.surfaces as usize).min(table.len())].get(i)?;
        Some(SurfaceConstants { cell: entry.cell, normal: normal_q30(entry.normal), restitution: scaled(entry.restitution, 1.0, 16) as i32 })
    }

    /// The force field, potential and wind planes (M5.1, M5.1b).
    pub fn port_fields(&self) -> PortFields<'_> {
        let l = self.layout();
        PortFields { force: self.plane_bytes(l.field()), potential: self.plane_bytes(l.potential()), wind: self.plane_bytes(l.wind()) }
    }

    /// Takes the world `c.steps` steps that ran elsewhere left: its
    /// planes as [`World::port_planes`] lays them out, and what those steps
    /// counted (their counters added, the last step's processed and
    /// skipped blocks set, the step number advanced), with what each
    /// emitter asked for and placed in them (`emitters`, one entry an
    /// emitter).
    ///
    /// Refused, with the world unchanged: planes of the wrong length
    /// (`BadLength`); fewer ids given than before, an id of a particle
    /// that was never given, a mass index the world has no class for, a bit set beyond a row's end, a
    /// particle on an obstacle, a stored component beyond the storage's
    /// range, or a particle count other than the world's with the emitted
    /// and without the exits and expiries (`ImageInvalid`).
    pub fn port_finish_steps(&mut self, planes: &PortPlanes<'_>, c: &StepCounts, emitters: &[EmitterStats]) -> Result<(), Error> {
        let l = *self.layout();
        let desc = self.head.desc;
        let PortPlanes { occupancy, velocity, life, mass_index, id, age, tag, .. } = *planes;
        let own = self.port_planes();
        let lengths = [(occupancy.len() * 8, own.occupancy.len() * 8), (velocity.len(), own.velocity.len()), (life.len(), own.life.len()), (mass_index.len(), own.mass_index.len()), (id.len(), own.id.len()), (age.len(), own.age.len()), (tag.len(), own.tag.len()), (emitters.len(), self.slots().len())];
        if let Some(i) = lengths.iter().position(|(a, b)| a != b) {
            let part = match i {
                0 => c"planes.occupancy is not the world's length",
                1 => c"planes.velocity is not the world's length",
                2 => c"planes.life is not the world's length",
                3 => c"planes.mass_index is not the world's length",
                4 => c"planes.id is not the world's length",
                5 => c"planes.age is not the world's length",
                6 => c"planes.tag is not the world's length",
                _ => c"emitters: not one entry an emitter",
            };
            return Err(Error::new(ErrorKind::BadLength, part));
        }
        // The last id given only grows (M6b).
        if c.ids_given < self.head.ids_given {
            return Err(Error::new(ErrorKind::ImageInvalid, c"counts.ids_given is below the world's"));
        }
        let classes = self.head.masses as usize;
        let obstacle: &[u64] = self.plane(l.obstacle());
        let padding = match l.n[0] % 64 {
            0 => 0,
            used => u64::MAX << used,
        };
        let wide = desc.quantization == crate::api::desc::Quantization::Bits16;
        let limit = if wide { 32767 } else { 127 };
        let dim = self.dim();
        let mut count = 0u64;
        for (i, &word) in occupancy.iter().enumerate() {
            if i % l.row_words == l.row_words - 1 && word & padding != 0 {
                return Err(Error::new(ErrorKind::ImageInvalid, c"planes.occupancy has a bit past a row's end"));
            }
            if obstacle.get(i).is_some_and(|o| o & word != 0) {
                return Err(Error::new(ErrorKind::ImageInvalid, c"planes.occupancy has a particle on an obstacle"));
            }
            count += u64::from(word.count_ones());
            let mut bits = word;
            while bits != 0 {
                let x = (i % l.row_words) * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let cell = (i / l.row_words) * l.n[0] + x;
                if mass_index.get(cell).is_some_and(|&m| usize::from(m) >= classes) {
                    return Err(Error::new(ErrorKind::ImageInvalid, c"planes.mass_index names a class the world has not"));
                }
                if id.len() >= 4 * (cell + 1) && !(1..=c.ids_given).contains(&u32::from_ne_bytes([id[4 * cell], id[4 * cell + 1], id[4 * cell + 2], id[4 * cell + 3]])) {
                    return Err(Error::new(ErrorKind::ImageInvalid, c"planes.id holds an id never given"));
                }
                for k in 0..dim {
                    let at = cell * dim + k;
                    let q = stored(velocity, at, if wide { 2 } else { 1 });
                    if q.abs() > limit {
                        return Err(Error::new(ErrorKind::ImageInvalid, c"planes.velocity holds a component out of range"));
                    }
                }
            }
        }
        if Some(count) != self.head.counters.particles.checked_add(c.emitted).and_then(|n| n.checked_sub(c.exited)).and_then(|n| n.checked_sub(c.expired)) {
            return Err(Error::new(ErrorKind::ImageInvalid, c"planes.occupancy does not hold the particles counts says"));
        }
        let (head, p) = &mut self.byte_planes();
        head.ids_given = c.ids_given;
        for (slot, more) in p.emitters.iter_mut().zip(emitters) {
            slot.stats.requested = slot.stats.requested.saturating_add(more.requested);
            slot.stats.delivered = slot.stats.delivered.saturating_add(more.delivered);
        }
        p.occupancy.copy_from_slice(occupancy);
        p.velocity.copy_from_slice(velocity);
        for (to, from) in p.life.iter_mut().zip(life.chunks_exact(2)) {
            *to = u16::from_ne_bytes([from[0], from[1]]);
        }
        p.mass_index.copy_from_slice(mass_index);
        #[cfg(feature = "identity")]
        {
            for (to, from) in p.id.iter_mut().zip(id.chunks_exact(4)) {
                *to = u32::from_ne_bytes([from[0], from[1], from[2], from[3]]);
            }
            for (to, from) in p.age.iter_mut().zip(age.chunks_exact(4)) {
                *to = u32::from_ne_bytes([from[0], from[1], from[2], from[3]]);
            }
            p.tag.copy_from_slice(tag);
        }
        #[cfg(not(feature = "identity"))]
        let _ = (age, tag);
        // The step's summaries of empty rows and words (M3): "may hold a
        // particle" everywhere, so that the next step sweeps what came in.
        p.rows.fill(1);
        p.words.fill(u64::MAX);
        self.count_steps(c);
        Ok(())
    }

    /// [`World::port_finish_steps`]' counting, once its planes are in.
    fn count_steps(&mut self, c: &StepCounts) {
        if c.steps == 0 {
            return;
        }
        let last = self.head.step.wrapping_add(c.steps - 1);
        let part = Partition::new(self.layout(), &self.head.desc.boundary, self.dim(), last);
        let total = part.total_blocks();
        let h = &mut self.head.counters;
        h.add_step(&Counters {
            exited: c.exited,
            expired: c.expired,
            collisions: c.collisions,
            clamps: c.clamps,
            clamp_energy: c.clamp_energy,
            displaced: c.displaced,
            ..Counters::default()
        });
        h.emitted = h.emitted.saturating_add(c.emitted);
        h.shortfall = h.shortfall.saturating_add(c.shortfall);
        h.particles = h.particles.saturating_add(c.emitted).saturating_sub(c.exited).saturating_sub(c.expired);
        h.processed = c.blocks_processed;
        h.skipped = total.saturating_sub(c.blocks_processed);
        self.head.step = self.head.step.wrapping_add(c.steps);
    }
}

/// M5.2 in 2D: the turn `j` of 1,024 as `(round(2^30 cos), round(2^30 sin))`.
pub fn turn(j: u32) -> (i32, i32) {
    crate::rules::fixed::turn(j & (crate::rules::fixed::TURNS - 1))
}

/// M5.6 in 2D, exact-fast: the optimal assignments of the block state
/// `key` (one digit of six a cell, place values 1, 6, 36, 216: 0 free, 1
/// blocked, `2 + m` a particle that wants to cross the axes `m`), each
/// packed as bits `2c, 2c + 1` the cell the particle in cell `c` goes to
/// and bits 12-14 how many do not get the cell they want; `None` for a
/// state the step never poses (a wish for a blocked cell).
pub fn optimal_moves_2d(key: usize) -> Option<&'static [u16]> {
    crate::rules::assign::moves_of_key_2d(key)
}

/// M5.3's table for 8-bit storage under `drift`, as [`StepConstants::moves`].
pub fn move_table_8(drift: Drift) -> &'static [u16; 256] {
    crate::rules::quant::move_table_8(drift)
}
