//! The state hash: equal worlds hash equal on every target (M8), so the
//! tests and the cross-target check compare worlds through it.

use crate::quant::{with_quant, Quant};
use crate::world::World;

impl World {
    /// A 64-bit FNV-1a hash over every particle's cell, stored velocity,
    /// mass and lifetime, in cell order. Equal worlds hash equal on every
    /// target.
    pub fn state_hash(&self) -> u64 {
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        let d = self.dim();
        let l = self.layout();
        h.eat(&(self.head.desc.dim).to_le_bytes());
        for k in 0..3 {
            h.eat(&(l.n[k] as u64).to_le_bytes());
        }
        for (_, cell) in self.occupied_cells() {
            h.eat(&(cell as u64).to_le_bytes());
            with_quant!(self.head.desc.quantization, Q => {
                let plane: &[Q] = self.plane(l.velocity());
                for k in 0..d {
                    h.eat(&plane[cell * d + k].to_int().to_le_bytes());
                }
            });
            h.eat(&self.mass_at(cell).to_bits().to_le_bytes());
            h.eat(&self.life_at(cell).to_le_bytes());
        }
        h.0
    }
}

struct Fnv(u64);

impl Fnv {
    fn eat(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}
