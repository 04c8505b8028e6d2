//! Edits of a world's particles: adding one (with the world's mass or its
//! own), removing one, and the placement the emitters share (M1, M6, M9).
//! Every edit checks everything before it changes anything.

use crate::cells::Cells;
use crate::layout::{mark, put_bit, Site};
use crate::quant::{with_quant, Quant};
use crate::query::Particle;
use crate::world::World;
use crate::Error;

impl World {
    /// Checks a velocity a caller hands in: finite, `|v| <= 1`, and zero on
    /// the unused axis of 2D.
    pub(crate) fn check_velocity(&self, v: [f32; 3]) -> Result<[f32; 3], Error> {
        crate::desc::finite(&v)?;
        let mut v = v;
        if self.dim() == 2 {
            v[2] = 0.0;
        }
        if v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > 1.0 {
            return Err(Error::SpeedRange);
        }
        Ok(v)
    }

    /// The mass table index of `m`, adding it if new. Nothing is changed on
    /// error.
    pub(crate) fn mass_index_of(&mut self, m: f32) -> Result<u8, Error> {
        crate::desc::mass(m)?;
        if !self.head.desc.per_particle_mass {
            return if m == self.head.desc.mass { Ok(0) } else { Err(Error::NotEnabled) };
        }
        let used = self.head.masses as usize;
        let (head, p) = self.planes::<u8>();
        if let Some(i) = p.mass_table[..used].iter().position(|&t| t.to_bits() == m.to_bits()) {
            return Ok(i as u8);
        }
        if used >= p.mass_table.len() {
            return Err(Error::MassTableFull);
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
            return Err(Error::CellOccupied);
        }
        if self.is_obstacle(s) {
            return Err(Error::CellObstacle);
        }
        crate::desc::mass(m)?;
        // Last fallible step; it changes the world only when it succeeds.
        let index = self.mass_index_of(m)?;
        self.place(s, v, index, 0, None);
        self.head.counters.particles += 1;
        Ok(())
    }

    /// Writes a particle into a free cell. Components are rounded
    /// stochastically from `stream` when one is given (M1), else to nearest.
    pub(crate) fn place(&mut self, s: Site, v: [f32; 3], mass_index: u8, life: u16, stream: Option<&mut crate::rng::Stream>) {
        let d = self.dim();
        let summary_words = self.layout().summary_words;
        let per_mass = self.head.desc.per_particle_mass;
        let lifetimes = self.head.desc.lifetimes;
        with_quant!(self.head.desc.quantization, Q => {
            let (_, p) = self.planes::<Q>();
            put_bit(Cells::new(p.occupancy), s.bit, true);
            mark(Cells::new(p.rows), Cells::new(p.words), summary_words, s.row, s.x);
            let r = stream.map(|rng| rng.next_u64());
            for k in 0..d {
                p.velocity[s.cell * d + k] = match r {
                    Some(r) => Q::from_int(Q::stochastic(v[k] * Q::SCALE, (r >> (16 * k)) as u32)),
                    None => Q::nearest(v[k]),
                };
            }
            if per_mass {
                p.mass_index[s.cell] = mass_index;
            }
            if lifetimes {
                p.life[s.cell] = life;
            }
        });
    }

    /// Removes the particle at `pos` and returns it.
    pub fn remove_particle(&mut self, pos: [u32; 3]) -> Result<Particle, Error> {
        let s = self.locate(pos)?;
        if !self.occupied(s) {
            return Err(Error::NoParticle);
        }
        let p = self.particle_at(pos, s.cell);
        let (head, planes) = self.planes::<u8>();
        put_bit(Cells::new(planes.occupancy), s.bit, false);
        head.counters.particles -= 1;
        Ok(p)
    }
}
