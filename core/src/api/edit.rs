//! Edits of a world's particles: adding one (with the world's mass or its
//! own), removing one, and the placement the emitters share (M1, M6, M9).
//! Every edit checks everything before it changes anything.

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::api::query::Particle;
use crate::rules::quant::{with_quant, Quant, Width};
use crate::storage::cells::Cells;
use crate::storage::layout::{mark, put_bit, view, Site};
use crate::storage::world::World;

/// Whether stored components `q`, in quanta (`scale` to a cell per step),
/// lie within one quantum per axis of a velocity of length at most 1. Those
/// are the velocities the step stores: it clamps to `|v| <= 1` (M5.5), then
/// rounds each component to one of the two integers around it (M1), which
/// can leave `|q|` above `scale`. Also every `|v| <= 1` rounded to nearest,
/// which moves a component by half a quantum at most. The point of the box
/// `|x_k - q_k| <= 1` nearest the origin has `|x_k| = max(|q_k| - 1, 0)`; in
/// integers, so the test is exact.
pub(crate) fn storable(q: [i32; 3], scale: i32) -> bool {
    let nearest: i64 = q
        .iter()
        .map(|&c| {
            let x = i64::from(c.unsigned_abs().saturating_sub(1));
            x * x
        })
        .sum();
    nearest <= i64::from(scale) * i64::from(scale)
}

impl World {
    /// Checks a velocity a caller hands in: finite, zero on the unused axis
    /// of 2D, each component in `[-1, 1]`, and, rounded to nearest as it will
    /// be stored, a velocity the step itself can store (M1): see
    /// [`storable`]. That takes every `|v| <= 1` and every velocity a world
    /// reports, so a world can be rebuilt from what it reports.
    pub(crate) fn check_velocity(&self, v: [f32; 3]) -> Result<[f32; 3], Error> {
        crate::api::checks::finite(&v, c"velocity")?;
        let mut v = v;
        if self.dim() == 2 {
            v[2] = 0.0;
        }
        if v.iter().any(|c| c.abs() > 1.0) {
            return Err(Error::new(ErrorKind::SpeedRange, c"velocity"));
        }
        let width = Width::of_quantization(self.head.desc.quantization);
        if !storable(v.map(|c| width.nearest(c)), width.scale()) {
            return Err(Error::new(ErrorKind::SpeedRange, c"velocity"));
        }
        Ok(v)
    }

    /// The mass table index of `m`, adding it if new. Nothing is changed on
    /// error. `of` says where the mass came from, for the details.
    pub(crate) fn mass_index_of(&mut self, m: f32, of: MassOf) -> Result<u8, Error> {
        crate::api::checks::mass(m, of.field())?;
        if !self.head.desc.has_masses() {
            // Both positive (checked): equal exactly where their bits are.
            return if m.to_bits() == self.head.desc.mass.to_bits() { Ok(0) } else { Err(Error::computed(ErrorKind::NotEnabled, || of.not_one())) };
        }
        let used = self.head.masses as usize;
        let (head, p) = &mut self.byte_planes();
        if let Some(i) = p.mass_table[..used].iter().position(|&t| t.to_bits() == m.to_bits()) {
            return Ok(i as u8);
        }
        // The plane holds the step's classes after the table (`mass_plane`).
        if used >= head.desc.mass_classes as usize {
            return Err(Error::new(ErrorKind::MassTableFull, c"desc.mass_classes"));
        }
        p.mass_table[used] = m;
        head.masses += 1;
        Ok(used as u8)
    }

    /// Adds a particle of the world's mass at `pos` with velocity `v`
    /// (rounded to the nearest stored value).
    pub fn add_particle(&mut self, pos: [u32; 3], v: [f32; 3]) -> Result<(), Error> {
        let m = self.head.desc.mass;
        self.add_particle_with_mass(pos, v, m)
    }


    /// Adds a particle of mass `m`. Worlds without per-particle masses accept
    /// only their own mass.
    pub fn add_particle_with_mass(&mut self, pos: [u32; 3], v: [f32; 3], m: f32) -> Result<(), Error> {
        let s = self.locate(pos)?;
        let v = self.check_velocity(v)?;
        if self.occupied(s) {
            return Err(Error::new(ErrorKind::CellOccupied, c"pos"));
        }
        if self.is_obstacle(s) {
            return Err(Error::new(ErrorKind::CellObstacle, c"pos"));
        }
        if self.ids_left() == 0 {
            return Err(Error::new(ErrorKind::IdsExhausted, c"ids"));
        }
        // Last fallible step (it checks the mass first); it changes the
        // world only when it succeeds.
        let index = self.mass_index_of(m, MassOf::Particle)?;
        self.place_added(s, v, index);
        self.head.counters.particles += 1;
        Ok(())
    }

    /// Writes an emitted particle into a free cell, its components rounded
    /// stochastically from `rng` (M1), with the mass index and tag of its
    /// emitter's `class` ([`Slot::class`](crate::rules::emitter::Slot))
    /// and lifetime `life`. Not inlined into the step, whose frame would
    /// grow by it, on firmware stacks too.
    #[inline(never)]
    pub(crate) fn place_emitted(&mut self, s: Site, x: [i32; 3], class: u32, life: u16, rng: &mut crate::rules::rng::Stream) {
        self.place(s, Velocity::Fine(x), class as u8, life, (class >> 8) as u8, Some(rng));
    }

    /// Writes a particle a caller adds into a free cell, its components
    /// rounded to nearest. Apart from [`World::place_emitted`], so that a
    /// firmware that only emits does not carry this rounding.
    fn place_added(&mut self, s: Site, v: [f32; 3], mass_index: u8) {
        self.place(s, Velocity::Float(v), mass_index, 0, 0, None);
    }

    /// Writes a particle into a free cell, with the next id where the
    /// world gives ids (the caller made sure one is left), age 0 and `tag`
    /// (M6b). Components in fine units are rounded stochastically from
    /// `stream` (M1, M1c), floats to nearest.
    #[inline(always)]
    fn place(&mut self, s: Site, v: Velocity, mass_index: u8, life: u16, tag: u8, stream: Option<&mut crate::rules::rng::Stream>) {
        let d = self.dim();
        let summary_words = self.layout().summary_words;
        let per_mass = self.head.desc.has_masses();
        let lifetimes = self.head.desc.lifetimes;
        let identity = self.head.desc.identity_planes();
        if identity.any() {
            self.identify(s.cell, tag);
        }
        let quantization = self.head.desc.quantization;
        let (_, p) = self.planes::<u8>();
        put_bit(Cells::new(p.occupancy), s.bit, true);
        mark(Cells::new(p.rows), Cells::new(p.words), summary_words, s.row, s.x);
        let r = stream.map(|rng| rng.next_u64());
        // The velocity alone in the world's type: the rest is one copy for
        // both widths.
        with_quant!(quantization, Q => {
            let (width, velocity) = (Width::of::<Q>(), view::<Q>(p.velocity));
            for k in 0..d {
                velocity[s.cell * d + k] = Q::from_int(match (v, r) {
                    (Velocity::Fine(x), r) => width.stochastic(x[k], (r.unwrap_or(0) >> (16 * k)) as u32),
                    (Velocity::Float(v), _) => width.nearest(v[k]),
                });
            }
        });
        if per_mass {
            p.mass_index[s.cell] = mass_index;
        }
        if lifetimes {
            p.life[s.cell] = life;
        }
    }

    /// Gives the particle just placed in `cell` the next id, age 0 and
    /// `tag`, in the planes the world keeps (M6b; the caller made sure an
    /// id is left). Out of line: every way of placing a particle shares it.
    #[inline(never)]
    fn identify(&mut self, cell: usize, tag: u8) {
        #[cfg(feature = "identity")]
        {
            let identity = self.head.desc.identity_planes();
            let (head, p) = self.planes::<u8>();
            if identity.ids() {
                head.ids_given += 1;
                p.id[cell] = head.ids_given;
            }
            if identity.ages() {
                p.age[cell] = 0;
            }
            if identity.tags() {
                p.tag[cell] = tag;
            }
        }
        // Never called without the feature (no world has the planes).
        #[cfg(not(feature = "identity"))]
        let _ = (cell, tag);
    }

    /// How many ids are left to give (M6b): `u32::MAX` in a world without
    /// ids, which never runs out.
    pub(crate) fn ids_left(&self) -> u32 {
        if self.head.desc.identity_planes().ids() { u32::MAX - self.head.ids_given } else { u32::MAX }
    }

    /// Gives the particle at `pos` the tag `tag` (M6b). Needs a world with
    /// tags.
    pub fn set_tag(&mut self, pos: [u32; 3], tag: u8) -> Result<(), Error> {
        let s = self.locate(pos)?;
        if !self.head.desc.identity_planes().tags() {
            return Err(Error::new(ErrorKind::NotEnabled, NO_TAGS));
        }
        if !self.occupied(s) {
            return Err(Error::new(ErrorKind::NoParticle, NO_PARTICLE));
        }
        #[cfg(feature = "identity")]
        {
            self.byte_planes().1.tag[s.cell] = tag;
        }
        #[cfg(not(feature = "identity"))]
        let _ = tag; // refused above: no world has tags
        Ok(())
    }

    /// Removes the particle at `pos` and returns it.
    pub fn remove_particle(&mut self, pos: [u32; 3]) -> Result<Particle, Error> {
        let s = self.locate(pos)?;
        if !self.occupied(s) {
            return Err(Error::new(ErrorKind::NoParticle, NO_PARTICLE));
        }
        let p = self.particle_at(pos, s.cell);
        let (head, planes) = &mut self.byte_planes();
        put_bit(Cells::new(planes.occupancy), s.bit, false);
        head.counters.particles -= 1;
        Ok(p)
    }
}

/// Where a mass came from, which the details of its refusal name: a tag
/// rather than the texts, so that a build without details, where the
/// texts go unused, references none of them.
#[derive(Clone, Copy)]
pub(crate) enum MassOf {
    Particle,
    Emitter,
}

impl MassOf {
    /// The field: not finite, or not above 0.
    fn field(self) -> &'static CStr {
        match self {
            MassOf::Particle => c"mass",
            MassOf::Emitter => c"emitter.mass",
        }
    }

    /// Another mass than the world's, in a world of one.
    fn not_one(self) -> &'static CStr {
        match self {
            MassOf::Particle => c"mass is not desc.mass (desc.per_particle_mass is off)",
            MassOf::Emitter => c"emitter.mass is not desc.mass (desc.per_particle_mass is off)",
        }
    }
}

/// The detail of a cell a call needs a particle in.
const NO_PARTICLE: &CStr = c"pos";

/// The detail of a world without tags asked to set one.
pub(crate) const NO_TAGS: &CStr = c"desc.identity (no tags)";

/// A velocity as [`World::place`] takes it: a caller's floats (rounded to
/// nearest), or an emitter's fine units (rounded stochastically, M1c).
#[derive(Clone, Copy)]
enum Velocity {
    Float([f32; 3]),
    Fine([i32; 3]),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Description;

    #[test]
    fn storable_takes_what_the_step_stores_and_refuses_more() {
        for scale in [127, 32767] {
            // Every rounding of a velocity of length 1, in 2D and 3D.
            for i in (0..1000).step_by(crate::sized(1, 20)) {
                let a = i as f64 * 0.0062832;
                let b = i as f64 * 0.0391;
                let (ca, sa, cb, sb) = (libm::cos(a), libm::sin(a), libm::cos(b), libm::sin(b));
                let dirs = [[ca, sa, 0.0], [ca * sb, sa * sb, cb]];
                for u in dirs {
                    let x = u.map(|c| c * f64::from(scale));
                    for pick in 0..8 {
                        let q: [i32; 3] =
                            core::array::from_fn(|k| if pick >> k & 1 == 1 { libm::ceil(x[k]) as i32 } else { libm::floor(x[k]) as i32 });
                        assert!(storable(q, scale), "{q:?} rounds {x:?}");
                    }
                }
            }
        }
        assert!(storable([90, 90, 0], 127)); // (1, 1) / sqrt(2) rounded: |q| = 1.0022 * 127
        assert!(!storable([102, 89, 0], 127)); // (0.8, 0.7)
        assert!(!storable([76, 76, 76], 127)); // (0.6, 0.6, 0.6)
        assert!(!storable([127, 127, 0], 127));
    }

    #[test]
    fn a_velocity_read_back_is_accepted_again() {
        let mut memory = [0u64; 512];
        // SAFETY: the array's bytes, borrowed for this test only.
        let bytes = unsafe { core::slice::from_raw_parts_mut(memory.as_mut_ptr().cast::<u8>(), 4096) };
        let w = World::init(&Description::new_2d(8, 8), bytes).unwrap();
        let h = core::f32::consts::FRAC_1_SQRT_2; // stored as 90/127, |v| = 1.0022
        w.add_particle([1, 1, 0], [h, h, 0.0]).unwrap();
        let p = w.remove_particle([1, 1, 0]).unwrap();
        assert!(p.velocity[0] * p.velocity[0] + p.velocity[1] * p.velocity[1] > 1.0);
        w.add_particle([1, 1, 0], p.velocity).unwrap();
        assert_eq!(w.remove_particle([1, 1, 0]).unwrap(), p);
        assert_eq!(w.add_particle([1, 1, 0], [1.0001, 0.0, 0.0]).map_err(Error::kind), Err(ErrorKind::SpeedRange));
        assert_eq!(w.add_particle([1, 1, 0], [0.8, 0.7, 0.0]).map_err(Error::kind), Err(ErrorKind::SpeedRange));
    }
}
