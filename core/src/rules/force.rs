//! External forces (M5.1, eqs. 4-6): `v <- v + dt F / m`, with `F` the sum of
//! the terms the description enables. A uniform acceleration is the same for
//! every mass; the other terms are forces, divided by the particle's mass.
//! And the flow that drag relaxes velocities towards (M5.1b).

use crate::api::desc::Vortex;

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
            a[k] += crate::rules::vector::div(f[k], m);
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
    [crate::rules::vector::small_to_f32(pos[0] as u32) + 0.5, crate::rules::vector::small_to_f32(pos[1] as u32) + 0.5]
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
    let r2 = crate::rules::vector::larger(dx * dx + dy * dy, v.core_radius * v.core_radius);
    let s = crate::rules::vector::div(v.circulation, core::f32::consts::TAU * r2);
    let along = |d: f32| if d == 0.0 { 0.0 } else { d * s };
    [-along(dy), along(dx)]
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
