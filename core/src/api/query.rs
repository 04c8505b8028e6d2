//! What a world can be asked: a cell, every particle, densities for a
//! texture, statistics (M10), and the particles and motion inside a box.

use crate::{Error, ErrorKind};
use crate::rules::quant::{with_quant, Quant};
use crate::storage::layout::Layout;
use crate::storage::world::{World, ENERGY_SCALE};

/// One particle as the queries report it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    /// Cell coordinates; the third is 0 in 2D.
    pub pos: [u32; 3],
    /// Velocity in cells per step; the third is 0 in 2D.
    pub velocity: [f32; 3],
    /// Mass.
    pub mass: f32,
    /// Steps left to live, 0 for no limit.
    pub life: u16,
    /// Its id, unique in the world's life, from 1 (M6b); 0 in a world
    /// without ids.
    pub id: u32,
    /// The steps it has taken part in (M6b); 0 in a world without ages.
    pub age: u32,
    /// The caller's tag (M6b); 0 in a world without tags.
    pub tag: u8,
}

/// What one cell holds (M1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cell {
    /// Nothing.
    Empty,
    /// An obstacle.
    Obstacle,
    /// A particle.
    Particle(Particle),
}

/// Statistics of a world (M10).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Steps taken.
    pub step: u64,
    /// Particles now; always `added + emitted - exited - expired - removed
    /// - crushed`.
    pub particles: u64,
    /// Particles placed by emitters.
    pub emitted: u64,
    /// Particles that left by open faces.
    pub exited: u64,
    /// Particles whose lifetime ended.
    pub expired: u64,
    /// Particles emitters could not place for lack of room.
    pub emit_shortfall: u64,
    /// Particles removed by bodies for want of a free cell near them
    /// (M13).
    pub crushed: u64,
    /// Total momentum `sum m v`.
    pub momentum: [f64; 3],
    /// Total kinetic energy `sum m |v|^2 / 2`.
    pub kinetic_energy: f64,
    /// Particle-particle collisions (M5.2), all steps.
    pub collisions: u64,
    /// Velocities scaled back to `|v| = 1` (M5.5), all steps.
    pub clamps: u64,
    /// Kinetic energy those clamps removed, all steps (counted in steps of
    /// 2^-32, saturating at 2^32).
    pub clamp_energy: f64,
    /// Particles not placed in their desired cell (M5.6), all steps.
    pub displaced: u64,
    /// Blocks processed in the last step.
    pub blocks_processed: u64,
    /// Blocks skipped as empty in the last step (M3).
    pub blocks_skipped: u64,
    /// Bytes of the world's memory per cell.
    pub bytes_per_cell: f64,
}

/// The particles inside a box of cells and their motion
/// ([`World::region_stats`]), for effects that trigger on what a region
/// holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RegionStats {
    /// Particles in the box.
    pub particles: u64,
    /// Their momentum `sum m v`.
    pub momentum: [f64; 3],
    /// Their kinetic energy `sum m |v|^2 / 2`.
    pub kinetic_energy: f64,
}

impl RegionStats {
    /// Adds one particle, in `f64` and in the same order of operations for
    /// [`World::stats`] and [`World::region_stats`], so a box covering the
    /// world sums to the same bits as the statistics.
    fn add(&mut self, p: &Particle) {
        let m = f64::from(p.mass);
        let mut v2 = 0.0;
        for k in 0..3 {
            let v = f64::from(p.velocity[k]);
            self.momentum[k] += m * v;
            v2 += v * v;
        }
        self.kinetic_energy += 0.5 * m * v2;
        self.particles += 1;
    }
}

impl World {
    fn velocity_at(&self, cell: usize) -> [f32; 3] {
        let d = self.dim();
        let mut v = [0.0f32; 3];
        with_quant!(self.head.desc.quantization, Q => {
            let plane: &[Q] = self.plane(self.layout().velocity());
            for (k, out) in v.iter_mut().enumerate().take(d) {
                *out = plane[cell * d + k].get();
            }
        });
        v
    }

    pub(crate) fn mass_at(&self, cell: usize) -> f32 {
        if self.head.desc.has_masses() {
            let idx: &[u8] = self.plane(self.layout().mass_index());
            let table: &[f32] = self.plane(self.layout().mass_table());
            table[usize::from(idx[cell])]
        } else {
            self.head.desc.mass
        }
    }

    /// The remaining lifetime of the particle in `cell`, 0 for none.
    pub(crate) fn life_at(&self, cell: usize) -> u16 {
        if self.head.desc.lifetimes { self.plane::<u16>(self.layout().life())[cell] } else { 0 }
    }

    /// The id, age and tag of the particle in `cell` (M6b), 0 for each
    /// plane the world does not keep. Out of line: every particle a query
    /// reads asks for them.
    #[inline(never)]
    pub(crate) fn identity_at(&self, cell: usize) -> (u32, u32, u8) {
        let (l, on) = (self.layout(), self.head.desc.identity_planes());
        let id = if on.ids() { self.plane::<u32>(l.id())[cell] } else { 0 };
        let age = if on.ages() { self.plane::<u32>(l.age())[cell] } else { 0 };
        let tag = if on.tags() { self.plane::<u8>(l.tag())[cell] } else { 0 };
        (id, age, tag)
    }

    pub(crate) fn particle_at(&self, pos: [u32; 3], cell: usize) -> Particle {
        let (id, age, tag) = self.identity_at(cell);
        Particle { pos, velocity: self.velocity_at(cell), mass: self.mass_at(cell), life: self.life_at(cell), id, age, tag }
    }

    /// What the cell at `pos` holds.
    pub fn cell(&self, pos: [u32; 3]) -> Result<Cell, Error> {
        let s = self.locate(pos)?;
        Ok(if self.occupied(s) {
            Cell::Particle(self.particle_at(pos, s.cell))
        } else if self.is_obstacle(s) {
            Cell::Obstacle
        } else {
            Cell::Empty
        })
    }

    /// Every particle, in cell order (x fastest).
    pub fn particles(&self) -> Particles<'_> {
        Particles { world: self, cells: self.occupied_cells() }
    }

    /// The cells holding a particle, in cell order (x fastest).
    pub(crate) fn occupied_cells(&self) -> Occupied<'_> {
        Occupied { layout: self.layout(), words: self.plane::<u64>(self.layout().occupancy()), word: 0, bits: 0, row: 0, row_start: 0 }
    }

    /// Fills `out` with the share of cells holding a particle in each of
    /// `res` bins per axis (x fastest; the third is 1 in 2D). Bin `i` along
    /// an axis of `n` cells covers cells `i n / r .. (i+1) n / r`.
    pub fn density(&self, res: [u32; 3], out: &mut [f32]) -> Result<(), Error> {
        self.bin(res, out.len(), &mut |i, hit, total| out[i] = hit as f32 / total as f32)
    }

    /// As [`World::density`], scaled to `0..=255` for a texture upload.
    pub fn density_u8(&self, res: [u32; 3], out: &mut [u8]) -> Result<(), Error> {
        // In u64: hit * 255 can overflow a 32-bit usize.
        self.bin(res, out.len(), &mut |i, hit, total| {
            out[i] = ((hit as u64 * 255 + total as u64 / 2) / total as u64) as u8
        })
    }

    /// The binning of both densities: `put(bin, hits, cells)` for each
    /// bin. The writer is dynamic, so one copy serves both.
    fn bin(&self, res: [u32; 3], len: usize, put: &mut dyn FnMut(usize, usize, usize)) -> Result<(), Error> {
        let l = *self.layout();
        let mut r = [1usize; 3];
        for k in 0..3 {
            r[k] = res[k] as usize;
            let used = k < self.dim();
            if r[k] == 0 || r[k] > l.n[k] || (!used && r[k] != 1) {
                return Err(Error::new(ErrorKind::BadResolution, c"res"));
            }
        }
        if r[0].checked_mul(r[1]).and_then(|v| v.checked_mul(r[2])) != Some(len) {
            return Err(Error::new(ErrorKind::BadResolution, c"out"));
        }
        let occ: &[u64] = self.plane(l.occupancy());
        // In u64: i * n can overflow a 32-bit usize; the result is <= n.
        let edge = |k: usize, i: usize| (i as u64 * l.n[k] as u64 / r[k] as u64) as usize;
        let mut i = 0;
        for bz in 0..r[2] {
            for by in 0..r[1] {
                for bx in 0..r[0] {
                    let (x0, x1) = (edge(0, bx), edge(0, bx + 1));
                    let (y0, y1) = (edge(1, by), edge(1, by + 1));
                    let (z0, z1) = (edge(2, bz), edge(2, bz + 1));
                    let mut hit = 0;
                    for z in z0..z1 {
                        for y in y0..y1 {
                            hit += count_bits(occ, l.site(x0, y, z).bit, x1 - x0);
                        }
                    }
                    put(i, hit, (x1 - x0) * (y1 - y0) * (z1 - z0));
                    i += 1;
                }
            }
        }
        Ok(())
    }

    /// Statistics now; momentum and energy are summed over the particles.
    pub fn stats(&self) -> Stats {
        let c = self.head.counters;
        let mut motion = RegionStats::default();
        for p in self.particles() {
            motion.add(&p);
        }
        let RegionStats { momentum, kinetic_energy, .. } = motion;
        Stats {
            step: self.head.step,
            particles: c.particles,
            emitted: c.emitted,
            exited: c.exited,
            expired: c.expired,
            emit_shortfall: c.shortfall,
            crushed: self.crushed(),
            momentum,
            kinetic_energy,
            collisions: c.collisions,
            clamps: c.clamps,
            clamp_energy: c.clamp_energy as f64 / ENERGY_SCALE,
            displaced: c.displaced,
            blocks_processed: c.processed,
            blocks_skipped: c.skipped,
            bytes_per_cell: self.bytes_per_cell(),
        }
    }

    /// The particles in the box of cells `min <= pos < max` (per axis; the
    /// third components are ignored in 2D), with their momentum and kinetic
    /// energy, summed in cell order as [`World::stats`] sums them. An empty
    /// or reversed box (`min >= max` on an axis) is refused with
    /// `BadShape`, one reaching beyond the world with `OutOfBounds`. The
    /// cost follows the box's rows and the particles in it, a machine word
    /// of cells at a time.
    pub fn region_stats(&self, min: [u32; 3], max: [u32; 3]) -> Result<RegionStats, Error> {
        let l = *self.layout();
        let (mut lo, mut hi) = ([0usize; 3], [1usize; 3]);
        for k in 0..self.dim() {
            if min[k] >= max[k] {
                return Err(Error::new(ErrorKind::BadShape, c"min is not below max"));
            }
            if max[k] as usize > l.n[k] {
                return Err(Error::new(ErrorKind::OutOfBounds, c"max"));
            }
            (lo[k], hi[k]) = (min[k] as usize, max[k] as usize);
        }
        let occ: &[u64] = self.plane(l.occupancy());
        let mut r = RegionStats::default();
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                // Rows start on a word, so bit x of the row is bit x % 64
                // of its word x / 64.
                let first = l.site(0, y, z).bit >> 6;
                let mut x = lo[0];
                while x < hi[0] {
                    let take = (64 - (x & 63)).min(hi[0] - x);
                    let mask = if take == 64 { u64::MAX } else { (1u64 << take) - 1 };
                    let mut bits = (occ[first + (x >> 6)] >> (x & 63)) & mask;
                    while bits != 0 {
                        let cx = x + bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let pos = [cx as u32, y as u32, z as u32];
                        r.add(&self.particle_at(pos, l.site(cx, y, z).cell));
                    }
                    x += take;
                }
            }
        }
        Ok(r)
    }

    /// Blocks processed and skipped in the last step; cheap, unlike
    /// [`World::stats`], which sums over every particle.
    pub fn last_step_blocks(&self) -> (u64, u64) {
        (self.head.counters.processed, self.head.counters.skipped)
    }

    /// Particles in the world now; cheap.
    pub fn particle_count(&self) -> u64 {
        self.head.counters.particles
    }

    /// Bytes of this world's memory (header and planes) per cell.
    pub fn bytes_per_cell(&self) -> f64 {
        self.size_in_bytes() as f64 / self.layout().cells as f64
    }
}

/// Set bits of `plane` in `bit .. bit + len`. Out of line: one copy for
/// both densities.
#[inline(never)]
fn count_bits(plane: &[u64], bit: usize, len: usize) -> usize {
    let mut n = 0;
    let mut at = bit;
    let end = bit + len;
    while at < end {
        let take = (64 - (at & 63)).min(end - at);
        let w = plane[at >> 6] >> (at & 63);
        let mask = if take == 64 { u64::MAX } else { (1u64 << take) - 1 };
        n += (w & mask).count_ones() as usize;
        at += take;
    }
    n
}

/// Iterator over a world's particles, from [`World::particles`].
pub struct Particles<'a> {
    world: &'a World,
    cells: Occupied<'a>,
}

impl Iterator for Particles<'_> {
    type Item = Particle;

    /// Out of line: one copy for every loop over the particles (the C
    /// library's exports each have one).
    #[inline(never)]
    fn next(&mut self) -> Option<Particle> {
        let (pos, cell) = self.cells.next()?;
        Some(self.world.particle_at(pos, cell))
    }
}

/// Iterator over the cells holding a particle, from
/// [`World::occupied_cells`]: each cell's coordinates and dense index.
pub(crate) struct Occupied<'a> {
    layout: &'a Layout,
    words: &'a [u64],
    /// The next word to read.
    word: usize,
    bits: u64,
    /// The row `y + ny z` of the last word read, and the number of that
    /// row's first word: counted on as words are read, with no division,
    /// which small cores call a routine for.
    row: usize,
    row_start: usize,
}

impl Iterator for Occupied<'_> {
    type Item = ([u32; 3], usize);

    fn next(&mut self) -> Option<([u32; 3], usize)> {
        let l = self.layout;
        while self.bits == 0 {
            let w = *self.words.get(self.word)?;
            self.bits = w;
            if self.word - self.row_start == l.row_words {
                self.row += 1;
                self.row_start = self.word;
            }
            self.word += 1;
        }
        // The lowest set bit's index, as 63 less the leading zeros of that
        // bit alone: where a core counts neither (the Cortex-M0), calls of
        // the library's count of leading zeros, which its soft float
        // (addition, multiplication, division) links anyway, not a table
        // of trailing zeros of its own.
        let b = 63 - (self.bits & self.bits.wrapping_neg()).leading_zeros() as usize;
        self.bits &= self.bits - 1;
        let x = (self.word - 1 - self.row_start) * 64 + b;
        // A build without 3D has one layer: the row is y.
        let (y, z) = if cfg!(feature = "dim3") { (self.row % l.n[1], self.row / l.n[1]) } else { (self.row, 0) };
        Some(([x as u32, y as u32, z as u32], l.site(x, y, z).cell))
    }
}
