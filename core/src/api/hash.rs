//! The state hash: equal worlds hash equal on every target (M8), so the
//! tests and the cross-target check compare worlds through it.

use crate::rules::quant::{with_quant, Quant};
use crate::storage::world::World;

impl World {
    /// A 64-bit FNV-1a hash over every particle's cell, stored velocity,
    /// mass and lifetime, and its id, age and tag where the world keeps
    /// them (M6b), in cell order. Equal worlds hash equal on every
    /// target.
    pub fn state_hash(&self) -> u64 {
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        let d = self.dim();
        let l = self.layout();
        // Sizes and cell indices are hashed as 64-bit values; both fit 32
        // bits (`Layout::of` keeps the cell count within a u32), so the
        // high four bytes are zeros.
        h.eat(self.head.desc.dim, 4);
        for k in 0..3 {
            h.eat(l.n[k] as u32, 8);
        }
        for (_, cell) in self.occupied_cells() {
            h.eat(cell as u32, 8);
            with_quant!(self.head.desc.quantization, Q => {
                let plane: &[Q] = self.plane(l.velocity());
                for k in 0..d {
                    h.eat(plane[cell * d + k].to_int() as u32, 4);
                }
            });
            h.eat(self.mass_at(cell).to_bits(), 4);
            h.eat(u32::from(self.life_at(cell)), 2);
            // M6b, where the world keeps them: a world without these planes
            // hashes as before they existed.
            let on = self.head.desc.identity_planes();
            if on.any() {
                // No byte of a plane the world does not keep.
                let (id, age, tag) = self.identity_at(cell);
                h.eat(id, 4 * u32::from(on.ids()));
                h.eat(age, 4 * u32::from(on.ages()));
                h.eat(u32::from(tag), u32::from(on.tags()));
            }
        }
        h.0
    }
}

struct Fnv(u64);

impl Fnv {
    /// Hashes the `bytes` low bytes of `v` zero-extended, little-endian
    /// first: `v` in a register, not bytes in memory (every call a store
    /// and two addresses on a small core), and every value hashed fits 32
    /// bits.
    fn eat(&mut self, mut v: u32, bytes: u32) {
        for _ in 0..bytes {
            self.0 = (self.0 ^ u64::from(v & 0xff)).wrapping_mul(0x0000_0100_0000_01b3);
            v >>= 8;
        }
    }
}
