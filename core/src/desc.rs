//! The scene description: what a world uses (M9), checked in full before any
//! memory is touched, and the memory layout that follows from it.

use crate::Error;
use crate::assign::Method;

/// What happens at one face of the domain (M4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Boundary {
    /// Blocks wrap around to the opposite face; both faces of the axis must
    /// say so.
    Periodic = 0,
    /// A cell beyond the face is an obstacle with the face's inward normal and
    /// the wall restitution.
    Wall = 1,
    /// A particle assigned beyond the face leaves and is counted as exited.
    Open = 2,
}

/// Bits per stored velocity component (M1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Quantization {
    /// `i8`, 127 steps per unit speed.
    Bits8 = 8,
    /// `i16`, 32767 steps per unit speed (feature `q16`).
    Bits16 = 16,
}

/// The probability of wanting a move along an axis, from that velocity
/// component (M5.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Drift {
    /// The paper's `p(v) = |v|`; a free particle drifts at `p/(2-p)`.
    Paper = 0,
    /// `p(v) = 2|v|/(1+|v|)`, so a free particle drifts at `|v|` (beyond the
    /// paper).
    Calibrated = 1,
}

/// The force terms a world sums in M5.1. Uniform acceleration needs no
/// storage; the other three need the `fields` feature.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Forces {
    /// A uniform acceleration (gravity), the same for every mass.
    pub uniform: bool,
    /// A force per cell, stored in a plane of `dim` `f32` per cell.
    pub field: bool,
    /// A potential `U` per cell; the force is `-grad U` by central differences
    /// (eq. 6).
    pub potential: bool,
    /// The analytic static Rankine vortex of the smoke scene.
    pub vortex: bool,
}

impl Forces {
    /// True if any term needs more than a uniform acceleration.
    pub const fn any_field(&self) -> bool {
        self.field || self.potential || self.vortex
    }
}

/// A static Rankine vortex (the smoke scene, paper section 4.3), evaluated at
/// cell centres. Its axis is parallel to z in 3D.
///
/// The force is tangential, counter-clockwise for positive circulation, with
/// magnitude `circulation / (2 pi) * r / core_radius^2` inside the core and
/// `circulation / (2 pi r)` outside: the Rankine velocity profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vortex {
    /// Centre in cell units (cell `(i, j)` has its centre at `(i + 0.5, j + 0.5)`).
    pub centre: [f32; 2],
    /// Radius of the solid-body core, in cells; greater than zero.
    pub core_radius: f32,
    /// Circulation; the sign sets the sense of rotation.
    pub circulation: f32,
}

/// Everything a world is built from. Start from [`Description::new_2d`] or
/// [`Description::new_3d`] and change the fields a scene needs.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Description {
    /// 2 or 3.
    pub dim: u32,
    /// Cells per axis; only the first `dim` are used. Each even and at least 2.
    pub size: [u32; 3],
    /// Per axis, the low and the high face.
    pub boundary: [[Boundary; 2]; 3],
    /// The mass of every particle, or of those added without one.
    pub mass: f32,
    /// Whether particles carry their own masses (feature `mass`): a one-byte
    /// index per cell into a table of `mass_classes` distinct masses.
    pub per_particle_mass: bool,
    /// Capacity of the mass table, 1 to 256.
    pub mass_classes: u32,
    /// Whether the world has obstacle cells (feature `obstacles`).
    pub obstacles: bool,
    /// How many obstacle surface cells (with normal and restitution) fit.
    pub surface_capacity: u32,
    /// Which force terms are summed (M5.1).
    pub forces: Forces,
    /// The uniform acceleration, used when `forces.uniform`.
    pub gravity: [f32; 3],
    /// The vortex, used when `forces.vortex`.
    pub vortex: Vortex,
    /// Particle-particle restitution `e` (eqs. 7-8), in `[0, 1]`.
    pub restitution: f32,
    /// Restitution of the domain's wall faces (M4), in `[0, 1]`.
    pub wall_restitution: f32,
    /// Time step of eqs. 4-5; finite and not negative.
    pub dt: f32,
    /// The seed of every random stream (M8).
    pub seed: u64,
    /// Stored bits per velocity component.
    pub quantization: Quantization,
    /// The move probability rule.
    pub drift: Drift,
    /// The move assignment method.
    pub method: Method,
    /// How many emitters fit.
    pub emitter_capacity: u32,
    /// Whether particles carry a remaining lifetime (a `u16` per cell), so
    /// emitters can give them one (M6).
    pub lifetimes: bool,
}

impl Description {
    /// A 2D world of `nx x ny` cells: periodic on every axis, one mass of 1,
    /// no obstacles, no force, `e = 1`, `dt = 1`, 8-bit velocities, the
    /// paper's drift rule and the exact-fast assignment.
    pub const fn new_2d(nx: u32, ny: u32) -> Self {
        Description {
            dim: 2,
            size: [nx, ny, 1],
            boundary: [[Boundary::Periodic; 2]; 3],
            mass: 1.0,
            per_particle_mass: false,
            mass_classes: 1,
            obstacles: false,
            surface_capacity: 0,
            forces: Forces { uniform: false, field: false, potential: false, vortex: false },
            gravity: [0.0; 3],
            vortex: Vortex { centre: [0.0; 2], core_radius: 1.0, circulation: 0.0 },
            restitution: 1.0,
            wall_restitution: 1.0,
            dt: 1.0,
            seed: 0,
            quantization: Quantization::Bits8,
            drift: Drift::Paper,
            method: Method::ExactFast,
            emitter_capacity: 0,
            lifetimes: false,
        }
    }

    /// A 3D world of `nx x ny x nz` cells, with the same defaults as
    /// [`Description::new_2d`].
    pub const fn new_3d(nx: u32, ny: u32, nz: u32) -> Self {
        let mut d = Self::new_2d(nx, ny);
        d.dim = 3;
        d.size[2] = nz;
        d
    }

    /// Sets every face of every axis to `b`.
    pub const fn with_boundary(mut self, b: Boundary) -> Self {
        self.boundary = [[b; 2]; 3];
        self
    }

    /// Checks the whole description; the first problem found is returned.
    pub fn validate(&self) -> Result<(), Error> {
        Layout::of(self).map(|_| ())
    }
}

pub(crate) fn finite(values: &[f32]) -> Result<(), Error> {
    if values.iter().all(|v| v.is_finite()) { Ok(()) } else { Err(Error::NotFinite) }
}

pub(crate) fn restitution(e: f32) -> Result<(), Error> {
    finite(&[e])?;
    if (0.0..=1.0).contains(&e) { Ok(()) } else { Err(Error::RestitutionRange) }
}

pub(crate) fn mass(m: f32) -> Result<(), Error> {
    finite(&[m])?;
    if m > 0.0 { Ok(()) } else { Err(Error::MassRange) }
}

/// Where one plane lies in the world's memory, in bytes from its start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Plane {
    pub off: usize,
    pub len: usize,
}

/// The memory plan of a world. Every plane starts 8-byte aligned; planes a
/// scene does not use have length 0 (M9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Layout {
    /// Cells per axis, 1 for the unused third axis of 2D.
    pub n: [usize; 3],
    pub cells: usize,
    /// 64-bit words per x-row of a bit plane (rows are padded to whole words).
    pub row_words: usize,
    pub occupancy: Plane,
    /// One byte per row `y + ny z`: 0 where the row holds no particle for
    /// sure, 1 where it may hold one (the step skips rows of 0, M3).
    pub rows: Plane,
    /// Per row, `summary_words` words with one bit per occupancy word: 0
    /// where that word holds no particle for sure (the step skips it).
    pub words: Plane,
    pub summary_words: usize,
    pub obstacle: Plane,
    pub velocity: Plane,
    pub mass_index: Plane,
    pub life: Plane,
    pub field: Plane,
    pub potential: Plane,
    pub mass_table: Plane,
    pub surface: Plane,
    pub emitters: Plane,
    pub total: usize,
}

impl Layout {
    /// Validates `d` and plans its memory. Every size computation is checked,
    /// so a description whose byte count would overflow is refused.
    pub fn of(d: &Description) -> Result<Layout, Error> {
        let dim = d.dim as usize;
        if dim != 2 && dim != 3 {
            return Err(Error::BadDimension);
        }
        if dim == 3 && !cfg!(feature = "dim3") {
            return Err(Error::Dim3Disabled);
        }
        let mut n = [1usize; 3];
        for k in 0..dim {
            let s = d.size[k];
            if s == 0 {
                return Err(Error::SizeZero);
            }
            if s % 2 != 0 {
                return Err(Error::SizeOdd);
            }
            n[k] = usize::try_from(s).map_err(|_| Error::TooLarge)?;
            if d.boundary[k][0] != d.boundary[k][1]
                && (d.boundary[k][0] == Boundary::Periodic || d.boundary[k][1] == Boundary::Periodic)
            {
                return Err(Error::PeriodicMismatch);
            }
        }
        // M1: masses, restitutions, dt and every force parameter.
        mass(d.mass)?;
        restitution(d.restitution)?;
        restitution(d.wall_restitution)?;
        finite(&[d.dt])?;
        if d.dt < 0.0 {
            return Err(Error::NegativeDt);
        }
        finite(&d.gravity)?;
        finite(&[d.vortex.centre[0], d.vortex.centre[1], d.vortex.core_radius, d.vortex.circulation])?;
        if d.forces.vortex && d.vortex.core_radius <= 0.0 {
            return Err(Error::BadVortex);
        }
        if d.quantization == Quantization::Bits16 && !cfg!(feature = "q16") {
            return Err(Error::Q16Disabled);
        }
        if (d.per_particle_mass && !cfg!(feature = "mass"))
            || (d.obstacles && !cfg!(feature = "obstacles"))
            || (d.forces.any_field() && !cfg!(feature = "fields"))
        {
            return Err(Error::FeatureDisabled);
        }
        if d.per_particle_mass && !(1..=256).contains(&d.mass_classes) {
            return Err(Error::CapacityRange);
        }

        // Cell indices are stored as u32 (surface table), so the cell count
        // must fit one; every byte count below is checked against usize.
        let cells = n[0].checked_mul(n[1]).and_then(|c| c.checked_mul(n[2])).ok_or(Error::TooLarge)?;
        if u32::try_from(cells).is_err() {
            return Err(Error::TooLarge);
        }
        let row_words = n[0].div_ceil(64);
        let bit_plane = row_words.checked_mul(n[1] * n[2]).and_then(|w| w.checked_mul(8)).ok_or(Error::TooLarge)?;
        // Bit planes are indexed by bit, so their bit count must fit too.
        bit_plane.checked_mul(8).ok_or(Error::TooLarge)?;
        let q = match d.quantization {
            Quantization::Bits8 => 1,
            Quantization::Bits16 => 2,
        };
        let per_cell = |bytes: usize, on: bool| -> Result<usize, Error> {
            if on { cells.checked_mul(bytes).ok_or(Error::TooLarge) } else { Ok(0) }
        };
        let mut b = Builder { at: 0 };
        let occupancy = b.plane(bit_plane)?;
        let rows = b.plane(n[1] * n[2])?;
        let summary_words = row_words.div_ceil(64);
        let words = b.plane(summary_words * n[1] * n[2] * 8)?;
        let obstacle = b.plane(if d.obstacles { bit_plane } else { 0 })?;
        let velocity = b.plane(per_cell(dim * q, true)?)?;
        let mass_index = b.plane(per_cell(1, d.per_particle_mass)?)?;
        let life = b.plane(per_cell(2, d.lifetimes)?)?;
        let field = b.plane(per_cell(dim * 4, d.forces.field)?)?;
        let potential = b.plane(per_cell(4, d.forces.potential)?)?;
        let mass_table = b.plane(if d.per_particle_mass { d.mass_classes as usize * 4 } else { 0 })?;
        let surface_len = if d.obstacles {
            (d.surface_capacity as usize).checked_mul(core::mem::size_of::<crate::obstacle::Surface>()).ok_or(Error::TooLarge)?
        } else {
            0
        };
        let surface = b.plane(surface_len)?;
        let emitters = b.plane(
            (d.emitter_capacity as usize).checked_mul(core::mem::size_of::<crate::emitter::Slot>()).ok_or(Error::TooLarge)?,
        )?;
        Ok(Layout {
            n,
            cells,
            row_words,
            occupancy,
            rows,
            words,
            summary_words,
            obstacle,
            velocity,
            mass_index,
            life,
            field,
            potential,
            mass_table,
            surface,
            emitters,
            total: b.at,
        })
    }
}

struct Builder {
    at: usize,
}

impl Builder {
    fn plane(&mut self, len: usize) -> Result<Plane, Error> {
        let off = self.at;
        let end = off.checked_add(len).and_then(|e| e.checked_add(7)).ok_or(Error::TooLarge)? & !7;
        // Slices may not exceed isize::MAX bytes.
        if end > isize::MAX as usize / 2 {
            return Err(Error::TooLarge);
        }
        self.at = end;
        Ok(Plane { off, len })
    }
}
