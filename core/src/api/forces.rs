//! Setting a world's forces (M5.1) and its wind plane (M5.1b): the
//! uniform acceleration, the vortex, the force field, the potential and
//! the flow that drag relaxes towards, each checked before anything is
//! written.

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::api::checks::{all_finite, finite};
use crate::api::speed::slow;
use crate::api::desc::{Boundary, Vortex};
use crate::storage::layout::Planes;
use crate::storage::world::World;

impl World {
    /// The checks of a whole plane's values: a plane the world has
    /// (`enabled`), `per_cell` values a cell, finite. The details name
    /// the plane.
    fn force_plane_check(&self, enabled: bool, values: &[f32], per_cell: usize, plane: Plane) -> Result<(), Error> {
        if !enabled {
            return Err(Error::computed(ErrorKind::NotEnabled, || plane.off()));
        }
        if values.len() != self.layout().cells * per_cell {
            return Err(Error::computed(ErrorKind::BadLength, || plane.values()));
        }
        if !all_finite(values) {
            return Err(Error::computed(ErrorKind::NotFinite, || plane.values()));
        }
        Ok(())
    }

    /// Sets the uniform acceleration (M5.1). Needs `forces.uniform`.
    pub fn set_gravity(&mut self, g: [f32; 3]) -> Result<(), Error> {
        if !self.head.desc.forces.uniform {
            return Err(Error::new(ErrorKind::NotEnabled, c"desc.forces.uniform"));
        }
        finite(&g, c"gravity")?;
        self.head.desc.gravity = g;
        if self.dim() == 2 {
            self.head.desc.gravity[2] = 0.0;
        }
        Ok(())
    }

    /// Sets the Rankine vortex. Needs `forces.vortex`.
    pub fn set_vortex(&mut self, v: Vortex) -> Result<(), Error> {
        if !self.head.desc.forces.vortex {
            return Err(Error::new(ErrorKind::NotEnabled, c"desc.forces.vortex"));
        }
        finite(&[v.centre[0], v.centre[1], v.core_radius, v.circulation], c"vortex")?;
        if v.core_radius <= 0.0 {
            return Err(Error::new(ErrorKind::BadVortex, c"vortex.core_radius"));
        }
        self.head.desc.vortex = v;
        Ok(())
    }

    /// Replaces the per-cell force field: `dim` components per cell, cells in
    /// dense order (x fastest). Needs `forces.field`.
    pub fn set_force_field(&mut self, forces: &[f32]) -> Result<(), Error> {
        self.force_plane_check(self.head.desc.forces.field, forces, self.dim(), Plane::Field)?;
        self.byte_planes().1.field.copy_from_slice(forces);
        Ok(())
    }

    /// Sets the force on one cell. Needs `forces.field`.
    pub fn set_cell_force(&mut self, pos: [u32; 3], f: [f32; 3]) -> Result<(), Error> {
        self.set_cell_vector(pos, Plane::Field, f, |p| p.field)
    }

    /// Writes the first `dim` components of `v` at the cell `pos` of a
    /// plane of `dim` floats a cell, `which` (the force field or the wind
    /// plane), that `plane` picks, after the checks such a setter makes: a
    /// cell of the world, a plane the world has, finite values and, for a
    /// velocity (the wind), a speed of at most 1.
    fn set_cell_vector(&mut self, pos: [u32; 3], which: Plane, v: [f32; 3], plane: fn(Planes<'_, u8>) -> &mut [f32]) -> Result<(), Error> {
        let s = self.locate(pos)?;
        let wind = matches!(which, Plane::Wind);
        let enabled = if wind { self.head.desc.drag.field } else { self.head.desc.forces.field };
        if !enabled {
            return Err(Error::computed(ErrorKind::NotEnabled, || which.off()));
        }
        if !all_finite(&v) {
            return Err(Error::computed(ErrorKind::NotFinite, || which.cell()));
        }
        let d = self.dim();
        if wind && !slow(&v[..d]) {
            return Err(Error::new(ErrorKind::SpeedRange, c"wind"));
        }
        plane(self.byte_planes().1)[s.cell * d..s.cell * d + d].copy_from_slice(&v[..d]);
        Ok(())
    }

    /// Replaces the potential: one value per cell, dense order. Needs
    /// `forces.potential`.
    pub fn set_potential(&mut self, u: &[f32]) -> Result<(), Error> {
        self.force_plane_check(self.head.desc.forces.potential, u, 1, Plane::Potential)?;
        self.byte_planes().1.potential.copy_from_slice(u);
        Ok(())
    }

    /// Sets the potential of one cell. Needs `forces.potential`.
    pub fn set_cell_potential(&mut self, pos: [u32; 3], u: f32) -> Result<(), Error> {
        let s = self.locate(pos)?;
        if !self.head.desc.forces.potential {
            return Err(Error::computed(ErrorKind::NotEnabled, || Plane::Potential.off()));
        }
        finite(&[u], c"potential")?;
        self.byte_planes().1.potential[s.cell] = u;
        Ok(())
    }

    /// Replaces the wind plane of M5.1b: `dim` flow velocity components per
    /// cell, cells in dense order (x fastest). Each cell's `|u|` must be at
    /// most 1 (`SpeedRange`); the sum with the uniform wind and the vortex
    /// is not bounded, the clamp (M5.5) is. Needs `drag.field`.
    pub fn set_wind_field(&mut self, wind: &[f32]) -> Result<(), Error> {
        let d = self.dim();
        self.force_plane_check(self.head.desc.drag.field, wind, d, Plane::Wind)?;
        if wind.chunks_exact(d).any(|u| !slow(u)) {
            return Err(Error::new(ErrorKind::SpeedRange, c"wind"));
        }
        self.byte_planes().1.wind.copy_from_slice(wind);
        Ok(())
    }

    /// Sets the flow velocity of one cell in the wind plane, `|u| <= 1`.
    /// Needs `drag.field`.
    pub fn set_cell_wind(&mut self, pos: [u32; 3], u: [f32; 3]) -> Result<(), Error> {
        self.set_cell_vector(pos, Plane::Wind, u, |p| p.wind)
    }

    pub(crate) fn periodic(&self) -> [bool; 3] {
        let b = self.head.desc.boundary;
        [0, 1, 2].map(|k| b[k][0] == Boundary::Periodic)
    }
}

/// A plane a setter writes, which the details of its refusals name: a tag
/// rather than the texts, so that a build without details references
/// none of them.
#[derive(Clone, Copy)]
enum Plane {
    Field,
    Potential,
    Wind,
}

impl Plane {
    /// The description's switch for the plane, off.
    fn off(self) -> &'static CStr {
        match self {
            Plane::Field => c"desc.forces.field",
            Plane::Potential => c"desc.forces.potential",
            Plane::Wind => c"desc.drag.field",
        }
    }

    /// A whole plane's values (their length, or one not finite).
    fn values(self) -> &'static CStr {
        match self {
            Plane::Field => c"forces",
            Plane::Potential => c"potential",
            Plane::Wind => c"wind",
        }
    }

    /// One cell's value, not finite.
    fn cell(self) -> &'static CStr {
        match self {
            Plane::Field => c"force",
            Plane::Potential => c"potential",
            Plane::Wind => c"wind",
        }
    }
}
