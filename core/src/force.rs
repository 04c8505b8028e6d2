//! External forces (M5.1, eqs. 4-6): `v <- v + dt F / m`, with `F` the sum of
//! the terms the description enables. A uniform acceleration is the same for
//! every mass; the other terms are forces, divided by the particle's mass.
//! And the flow that drag relaxes velocities towards (M5.1b).

use crate::desc::{finite, Boundary, Vortex};
use crate::layout::Planes;
use crate::world::World;
use crate::Error;

/// The force terms of one step, read-only, for the general force path.
pub(crate) struct ForceTerms<'a> {
    pub gravity: [f32; 3],
    pub field: Option<&'a [f32]>,
    pub potential: Option<&'a [f32]>,
    pub vortex: Option<Vortex>,
    pub n: [usize; 3],
    pub periodic: [bool; 3],
    pub dim: usize,
}

impl ForceTerms<'_> {
    /// Acceleration of a particle of mass `m` at cell `pos` (dense index
    /// `cell`).
    #[inline]
    pub fn accel(&self, pos: [usize; 3], cell: usize, m: f32) -> [f32; 3] {
        let mut f = [0.0f32; 3];
        // Without the feature `fields` a world has neither term
        // (`Layout::of`), and the build no code for them.
        if cfg!(feature = "fields") {
            if let Some(field) = self.field {
                for k in 0..self.dim {
                    f[k] += field[cell * self.dim + k];
                }
            }
            if let Some(u) = self.potential {
                let g = self.grad(u, pos, cell);
                for k in 0..self.dim {
                    f[k] -= g[k]; // eq. 6: F = -grad U
                }
            }
        }
        if let Some(v) = self.vortex {
            let t = vortex_force(&v, centre_of(pos));
            f[0] += t[0];
            f[1] += t[1];
        }
        let mut a = self.gravity;
        for k in 0..self.dim {
            a[k] += crate::vector::div(f[k], m);
        }
        a
    }

    /// Central differences of `u` (eq. 6) on the grid; one-sided at a face
    /// that is not periodic.
    fn grad(&self, u: &[f32], pos: [usize; 3], cell: usize) -> [f32; 3] {
        let mut g = [0.0f32; 3];
        let mut stride = 1usize;
        for k in 0..self.dim {
            let n = self.n[k];
            let x = pos[k];
            let lo_in = x > 0 || self.periodic[k];
            let hi_in = x + 1 < n || self.periodic[k];
            let lo = if x > 0 { cell - stride } else { cell + (n - 1) * stride };
            let hi = if x + 1 < n { cell + stride } else { cell - (n - 1) * stride };
            g[k] = match (lo_in, hi_in) {
                (true, true) => 0.5 * (u[hi] - u[lo]),
                (false, true) => u[hi] - u[cell],
                (true, false) => u[cell] - u[lo],
                (false, false) => 0.0, // an axis of one cell has no gradient
            };
            stride *= n;
        }
        g
    }
}

/// The flow of M5.1b drag, read-only, for the general path: `u` at a cell
/// is the uniform wind, plus the wind plane's value there, plus the vortex
/// read as a velocity, in quanta per step.
pub(crate) struct Flow<'a> {
    /// The uniform wind, in quanta.
    pub wind: [f32; 3],
    pub field: Option<&'a [f32]>,
    pub vortex: Option<Vortex>,
    /// Quanta per unit speed.
    pub scale: f32,
    pub dim: usize,
    /// `dt * rate`.
    pub rate: f32,
}

impl Flow<'_> {
    /// The flow at cell `pos` (dense index `cell`), in quanta.
    #[inline]
    pub fn at(&self, pos: [usize; 3], cell: usize) -> [f32; 3] {
        let mut u = self.wind;
        if let Some(field) = self.field {
            for k in 0..self.dim {
                u[k] += field[cell * self.dim + k] * self.scale;
            }
        }
        if let Some(v) = self.vortex {
            let t = vortex_force(&v, centre_of(pos));
            u[0] += t[0] * self.scale;
            u[1] += t[1] * self.scale;
        }
        u
    }
}

/// The centre of cell `pos` in the plane, for [`vortex_force`]. The
/// coordinates are below 2^31: a grid holds fewer than 2^32 cells
/// (`Layout::of`), and each axis at least 2.
#[inline(always)]
fn centre_of(pos: [usize; 3]) -> [f32; 2] {
    [crate::vector::small_to_f32(pos[0] as u32) + 0.5, crate::vector::small_to_f32(pos[1] as u32) + 0.5]
}

/// The static Rankine vortex force at point `p`: tangential, of magnitude
/// `G/(2 pi) * r/R^2` inside the core and `G/(2 pi r)` outside, which is
/// `G/(2 pi) * (-dy, dx) / max(r^2, R^2)`: no square root needed.
///
/// A component whose offset is zero is zero, whatever the factor: a core
/// too small to square in `f32` (`R^2 = 0`) makes the factor infinite at the
/// centre, or 0/0 without circulation, and `0 * inf` would be NaN, which the
/// clamp (M5.5) counts as a stopped component. The force at the centre is
/// zero for every core.
#[inline]
pub(crate) fn vortex_force(v: &Vortex, p: [f32; 2]) -> [f32; 2] {
    let dx = p[0] - v.centre[0];
    let dy = p[1] - v.centre[1];
    // Neither is NaN: squares of finite numbers (Layout::of, set_vortex).
    let r2 = crate::vector::larger(dx * dx + dy * dy, v.core_radius * v.core_radius);
    let s = crate::vector::div(v.circulation, core::f32::consts::TAU * r2);
    let along = |d: f32| if d == 0.0 { 0.0 } else { d * s };
    [-along(dy), along(dx)]
}

impl World {
    fn force_plane_check(&self, enabled: bool, values: &[f32], per_cell: usize) -> Result<(), Error> {
        if !enabled {
            return Err(Error::NotEnabled);
        }
        if values.len() != self.layout().cells * per_cell {
            return Err(Error::BadLength);
        }
        finite(values)
    }

    /// Sets the uniform acceleration (M5.1). Needs `forces.uniform`.
    pub fn set_gravity(&mut self, g: [f32; 3]) -> Result<(), Error> {
        if !self.head.desc.forces.uniform {
            return Err(Error::NotEnabled);
        }
        finite(&g)?;
        self.head.desc.gravity = g;
        if self.dim() == 2 {
            self.head.desc.gravity[2] = 0.0;
        }
        Ok(())
    }

    /// Sets the Rankine vortex. Needs `forces.vortex`.
    pub fn set_vortex(&mut self, v: Vortex) -> Result<(), Error> {
        if !self.head.desc.forces.vortex {
            return Err(Error::NotEnabled);
        }
        finite(&[v.centre[0], v.centre[1], v.core_radius, v.circulation])?;
        if v.core_radius <= 0.0 {
            return Err(Error::BadVortex);
        }
        self.head.desc.vortex = v;
        Ok(())
    }

    /// Replaces the per-cell force field: `dim` components per cell, cells in
    /// dense order (x fastest). Needs `forces.field`.
    pub fn set_force_field(&mut self, forces: &[f32]) -> Result<(), Error> {
        self.force_plane_check(self.head.desc.forces.field, forces, self.dim())?;
        self.planes::<u8>().1.field.copy_from_slice(forces);
        Ok(())
    }

    /// Sets the force on one cell. Needs `forces.field`.
    pub fn set_cell_force(&mut self, pos: [u32; 3], f: [f32; 3]) -> Result<(), Error> {
        self.set_cell_vector(pos, self.head.desc.forces.field, f, false, |p| p.field)
    }

    /// Writes the first `dim` components of `v` at the cell `pos` of a
    /// plane of `dim` floats a cell, which `plane` picks, after the checks
    /// such a setter makes: a cell of the world, a plane the world has
    /// (`enabled`), finite values and, for a velocity, a speed of at most 1.
    fn set_cell_vector(
        &mut self,
        pos: [u32; 3],
        enabled: bool,
        v: [f32; 3],
        velocity: bool,
        plane: fn(Planes<'_, u8>) -> &mut [f32],
    ) -> Result<(), Error> {
        let s = self.locate(pos)?;
        if !enabled {
            return Err(Error::NotEnabled);
        }
        finite(&v)?;
        let d = self.dim();
        if velocity && !crate::speed::slow(&v[..d]) {
            return Err(Error::SpeedRange);
        }
        plane(self.planes::<u8>().1)[s.cell * d..s.cell * d + d].copy_from_slice(&v[..d]);
        Ok(())
    }

    /// Replaces the potential: one value per cell, dense order. Needs
    /// `forces.potential`.
    pub fn set_potential(&mut self, u: &[f32]) -> Result<(), Error> {
        self.force_plane_check(self.head.desc.forces.potential, u, 1)?;
        self.planes::<u8>().1.potential.copy_from_slice(u);
        Ok(())
    }

    /// Sets the potential of one cell. Needs `forces.potential`.
    pub fn set_cell_potential(&mut self, pos: [u32; 3], u: f32) -> Result<(), Error> {
        let s = self.locate(pos)?;
        if !self.head.desc.forces.potential {
            return Err(Error::NotEnabled);
        }
        finite(&[u])?;
        self.planes::<u8>().1.potential[s.cell] = u;
        Ok(())
    }

    /// Replaces the wind plane of M5.1b: `dim` flow velocity components per
    /// cell, cells in dense order (x fastest). Each cell's `|u|` must be at
    /// most 1 (`SpeedRange`); the sum with the uniform wind and the vortex
    /// is not bounded, the clamp (M5.5) is. Needs `drag.field`.
    pub fn set_wind_field(&mut self, wind: &[f32]) -> Result<(), Error> {
        let d = self.dim();
        self.force_plane_check(self.head.desc.drag.field, wind, d)?;
        if wind.chunks_exact(d).any(|u| !crate::speed::slow(u)) {
            return Err(Error::SpeedRange);
        }
        self.planes::<u8>().1.wind.copy_from_slice(wind);
        Ok(())
    }

    /// Sets the flow velocity of one cell in the wind plane, `|u| <= 1`.
    /// Needs `drag.field`.
    pub fn set_cell_wind(&mut self, pos: [u32; 3], u: [f32; 3]) -> Result<(), Error> {
        self.set_cell_vector(pos, self.head.desc.drag.field, u, true, |p| p.wind)
    }

    pub(crate) fn periodic(&self) -> [bool; 3] {
        let b = self.head.desc.boundary;
        [0, 1, 2].map(|k| b[k][0] == Boundary::Periodic)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rankine_profile() {
        let v = Vortex { centre: [0.0, 0.0], core_radius: 2.0, circulation: core::f32::consts::TAU };
        // Inside the core: |F| = r / R^2; outside: 1 / r; tangential, CCW.
        let f = vortex_force(&v, [1.0, 0.0]);
        assert!((f[0]).abs() < 1e-7 && (f[1] - 0.25).abs() < 1e-6);
        let f = vortex_force(&v, [0.0, 4.0]);
        assert!((f[0] + 0.25).abs() < 1e-6 && f[1].abs() < 1e-7);
        assert_eq!(vortex_force(&v, [0.0, 0.0]), [0.0, 0.0]);
    }

    #[test]
    fn a_core_too_small_to_square_gives_no_force_at_the_centre() {
        for circulation in [0.0, 1.0, -3e38] {
            let v = Vortex { centre: [4.5, 4.5], core_radius: 1e-30, circulation };
            let f = vortex_force(&v, [4.5, 4.5]);
            assert!(f[0] == 0.0 && f[1] == 0.0, "{circulation}: {f:?}");
            // On an axis through the centre: no component across it.
            let f = vortex_force(&v, [4.5, 5.5]);
            assert!(f[1] == 0.0 && !f[0].is_nan(), "{circulation}: {f:?}");
        }
    }
}
