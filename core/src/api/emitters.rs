//! Adding emitters to a world and changing their rates (M6).

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::api::edit::{MassOf, NO_TAGS};
use crate::api::checks::finite;
use crate::rules::emitter::{checked, Emitter, EmitterStats, Slot};
use crate::storage::world::World;

impl World {
    /// Adds an emitter and returns its index. A world described with no
    /// room for emitters (`emitter_capacity` 0) has none to fill:
    /// `NotEnabled`; one whose room is taken, `EmitterTableFull`.
    pub fn add_emitter(&mut self, mut e: Emitter) -> Result<usize, Error> {
        checked(&mut e, self.dim(), self.layout().n, self.head.desc.lifetimes)?;
        let used = self.head.emitters as usize;
        // The capacity the plane was sized for (`Layout::of`), without a
        // division by the slot's size.
        let capacity = self.head.desc.emitter_capacity as usize;
        if used >= capacity {
            return Err(if capacity == 0 {
                Error::new(ErrorKind::NotEnabled, c"desc.emitter_capacity is 0")
            } else {
                Error::new(ErrorKind::EmitterTableFull, c"desc.emitter_capacity")
            });
        }
        let mass_index = self.mass_index_of(e.mass, MassOf::Emitter)?;
        let (head, p) = &mut self.byte_planes();
        p.emitters[used] = Slot { emitter: e, class: u32::from(mass_index), stats: EmitterStats::default() };
        head.emitters += 1;
        Ok(used)
    }

    /// What emitter `index` asked for and placed since it was added; an
    /// index past the emitters added is `OutOfBounds`.
    pub fn emitter_stats(&self, index: usize) -> Result<EmitterStats, Error> {
        if index >= self.head.emitters as usize {
            return Err(Error::new(ErrorKind::OutOfBounds, NO_EMITTER));
        }
        Ok(self.slots()[index].stats)
    }

    /// Changes the rate of emitter `index`.
    pub fn set_emitter_rate(&mut self, index: usize, rate: f32) -> Result<(), Error> {
        finite(&[rate], c"rate")?;
        if rate < 0.0 {
            return Err(Error::new(ErrorKind::BadEmitter, c"rate"));
        }
        if index >= self.head.emitters as usize {
            return Err(Error::new(ErrorKind::OutOfBounds, NO_EMITTER));
        }
        self.byte_planes().1.emitters[index].emitter.rate = rate;
        Ok(())
    }

    /// Gives the particles emitter `index` places from now on the tag
    /// `tag` (M6b); 0 until set. Needs a world with tags.
    pub fn set_emitter_tag(&mut self, index: usize, tag: u8) -> Result<(), Error> {
        if !self.head.desc.identity_planes().tags() {
            return Err(Error::new(ErrorKind::NotEnabled, NO_TAGS));
        }
        if index >= self.head.emitters as usize {
            return Err(Error::new(ErrorKind::OutOfBounds, NO_EMITTER));
        }
        let slot = &mut self.byte_planes().1.emitters[index];
        slot.class = u32::from(slot.mass_index()) | u32::from(tag) << 8;
        Ok(())
    }
}

/// The detail of an emitter index past those added.
const NO_EMITTER: &CStr = c"index (past the emitters)";
