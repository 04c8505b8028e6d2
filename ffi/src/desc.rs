//! `mpca_desc`: the scene description (M9), as C sees it.

use mpca_core::{Boundary, Collisions, Description, Drag, Drift, Forces, Identity, Method, Preset, Quantization, Turbulence, Vortex};

use core::ffi::CStr;

use crate::{check_size, guard, mpca_status, Refusal};

/// What happens at one face of the domain (M4). Values of `mpca_desc.boundary`.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_boundary {
    /// Wrap around to the opposite face; set it on both faces of the axis.
    Periodic = 0,
    /// An obstacle beyond the face, with the wall restitution.
    Wall = 1,
    /// Particles leave and are counted as exited.
    Open = 2,
}

/// The move probability rule (M5.3). Values of `mpca_desc.drift`.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_drift {
    /// The paper's p = |v|; a free particle drifts at p/(2-p).
    Paper = 0,
    /// p = 2|v|/(1+|v|); a free particle drifts at |v|.
    Calibrated = 1,
}

/// The move assignment method (M5.6). Values of `mpca_desc.method`.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_method {
    /// Every permutation: the paper's method, the reference.
    Exhaustive = 0,
    /// Always the exhaustive optimum, far faster.
    ExactFast = 1,
    /// The paper's 3D approximation: fastest particles choose first.
    Greedy = 2,
}

/// How a collision picks its direction (M5.2). Values of
/// `mpca_desc.collisions`.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_collisions {
    /// The paper's: a uniform direction; a speed above 1 is clamped.
    Paper = 0,
    /// M5.2b: a uniform direction among those that leave both speeds at
    /// most 1, so collisions keep their energy (e = 1) and never clamp.
    SpeedLimited = 1,
}

/// Bits of `mpca_desc.forces` (M5.1); the force is the sum of those set.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_force {
    /// A uniform acceleration (gravity), `mpca_desc.gravity`.
    Uniform = 1,
    /// A force per cell: mpca_world_set_force_field.
    Field = 2,
    /// A potential per cell, F = -grad U: mpca_world_set_potential.
    Potential = 4,
    /// The static Rankine vortex, `mpca_desc.vortex_*`.
    Vortex = 8,
}

/// Bits of `mpca_desc.identity` (M6b): the planes carried with every
/// particle.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_identity {
    /// A 32-bit id, unique in the world's life, from 1 (4 bytes a cell).
    Ids = 1,
    /// The steps each particle has taken part in (4 bytes a cell).
    Ages = 2,
    /// A byte of the caller's: mpca_world_set_tag, mpca_world_set_emitter_tag
    /// (1 byte a cell).
    Tags = 4,
}

// The C bits are the core's flags, which `to_core` takes as they are.
const _: () = assert!(
    mpca_identity::Ids as u32 == Identity::IDS.bits()
        && mpca_identity::Ages as u32 == Identity::AGES.bits()
        && mpca_identity::Tags as u32 == Identity::TAGS.bits()
);

/// A scene description. Fill it with mpca_desc_defaults, then change the
/// fields the scene needs. Flags are 0 or 1.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct mpca_desc {
    /// `sizeof(mpca_desc)`; set by mpca_desc_defaults.
    pub struct_size: u32,
    /// 2 or 3.
    pub dim: u32,
    /// The seed of every random stream.
    pub seed: u64,
    /// Cells per axis, each even and at least 2; the third is ignored in 2D.
    pub size: [u32; 3],
    /// Per axis, the low and the high face: `mpca_boundary` values.
    pub boundary: [[u32; 2]; 3],
    /// The mass of every particle, or of those added without one.
    pub mass: f32,
    /// 1: particles carry their own masses (a table of `mass_classes`).
    pub per_particle_mass: u32,
    /// Capacity of the mass table, 1 to 256; with per-particle masses off it
    /// is not used, but above 65,535 it is refused all the same
    /// (MPCA_STATUS_CAPACITY_RANGE), so a world reports the description it
    /// was given.
    pub mass_classes: u32,
    /// 1: the world has obstacles.
    pub obstacles: u32,
    /// How many obstacle surface cells fit; mpca_desc_surface_entries says
    /// how many a shape takes.
    pub surface_capacity: u32,
    /// `mpca_force` bits.
    pub forces: u32,
    /// The uniform acceleration, in cells per step per step (times `dt`):
    /// each step adds `dt * gravity` to every velocity (M5.1).
    pub gravity: [f32; 3],
    /// Vortex centre, in cells.
    pub vortex_centre: [f32; 2],
    /// Vortex core radius, in cells, greater than zero.
    pub vortex_core_radius: f32,
    /// Vortex circulation; its sign sets the sense of rotation.
    pub vortex_circulation: f32,
    /// Particle-particle restitution, in [0, 1].
    pub restitution: f32,
    /// Restitution of wall faces, in [0, 1].
    pub wall_restitution: f32,
    /// The factor every acceleration and drag rate is scaled by in a step
    /// (M5.1), finite and not negative; 1 by default.
    pub dt: f32,
    /// Bits per stored velocity component: 8 or 16.
    pub quantization: u32,
    /// An `mpca_drift` value.
    pub drift: u32,
    /// An `mpca_method` value.
    pub method: u32,
    /// How many emitters fit.
    pub emitter_capacity: u32,
    /// 1: particles carry a lifetime, so emitters can give them one.
    pub lifetimes: u32,
    /// An `mpca_collisions` value.
    pub collisions: u32,
    /// 1: a particle refused the cell it wanted meets the particle holding
    /// it, head on (M5.7), so piles come to rest. 0: the paper's rules.
    pub contacts: u32,
    /// 1: collisions and contacts give back the kinetic energy rounding
    /// adds on average (M1b), so an elastic world keeps its energy. 0:
    /// unbiased rounding only.
    pub energy_neutral: u32,
    /// Flow drag rate per step, times `dt` (M5.1b), not negative; 0 is
    /// off. Each velocity relaxes towards the flow: v <- (v + dt rate u) /
    /// (1 + dt rate).
    pub drag_rate: f32,
    /// The uniform part of the flow `u`, in cells per step, |drag_wind| <=
    /// 1 (decided exactly for the floats given).
    pub drag_wind: [f32; 3],
    /// 1: the vortex (`vortex_*`) read as a velocity field adds to the flow.
    pub drag_vortex: u32,
    /// 1: a flow velocity per cell adds to the flow (the wind plane, `dim`
    /// floats a cell, zero until mpca_world_set_wind_field or
    /// mpca_world_set_cell_wind sets it).
    pub drag_wind_field: u32,
    /// `mpca_identity` bits: ids, ages and tags carried with the particles
    /// (M6b); 0, none, by default.
    pub identity: u32,
    /// How many bodies, obstacles the caller moves (M13, with `obstacles`),
    /// fit; 0 by default.
    pub body_capacity: u32,
    /// How many body surface cells fit (M13): every body cell with a free
    /// neighbour takes one; mpca_desc_surface_entries of a body's shape is
    /// an upper bound for it.
    pub body_surface_capacity: u32,
    /// 1: a particle resting on a full support (walls, obstacles,
    /// particles at rest) loses its velocity into the support along the
    /// uniform force and takes no push from it (M5.7b), so a pool or a pile
    /// comes to rest exactly. 0: the paper's rules.
    pub rest: u32,
    /// Turbulence in the flow (M5.1c): the largest any component of the
    /// turbulent flow gets, in cells per step, 0 to 1; 0 is off. It acts
    /// through drag (`drag_rate` above 0).
    pub drag_turbulence_amplitude: f32,
    /// The size of the turbulence's eddies in cells: a power of two from 1
    /// to 1024, dividing the size of every periodic axis.
    pub drag_turbulence_scale: u32,
    /// How fast the turbulence changes, per step, 0 to 1: a new random flow
    /// every 1 / rate steps, blended smoothly; 0 is a steady flow.
    pub drag_turbulence_rate: f32,
}

/// Description::new_2d's defaults as C sees them (the sizes aside), built
/// at compile time: mpca_desc_defaults copies them.
const DEFAULTS: mpca_desc = mpca_desc::from_core(&BASE);

/// A core description to start from where every field is set after: a
/// copy of a constant, less code than a call of new_2d.
const BASE: Description = Description::new_2d(0, 0);

const FORCE_BITS: u32 = mpca_force::Uniform as u32 | mpca_force::Field as u32 | mpca_force::Potential as u32 | mpca_force::Vortex as u32;

/// `term`'s bit of `mpca_desc.forces` where it is `on`, else 0.
const fn force_bit(on: bool, term: mpca_force) -> u32 {
    on as u32 * term as u32
}

const fn boundary_to_c(b: Boundary) -> u32 {
    match b {
        Boundary::Periodic => mpca_boundary::Periodic as u32,
        Boundary::Wall => mpca_boundary::Wall as u32,
        Boundary::Open => mpca_boundary::Open as u32,
    }
}

fn boundary_from_c(v: u32) -> Result<Boundary, Refusal> {
    Ok(match v {
        0 => Boundary::Periodic,
        1 => Boundary::Wall,
        2 => Boundary::Open,
        _ => return Err(Refusal::new(mpca_status::BadEnum, c"desc.boundary")),
    })
}

impl mpca_desc {
    /// A constant function, so that [`DEFAULTS`] is built at compile time.
    /// Out of line where it runs: one copy for the exports that call it.
    #[inline(never)]
    pub(crate) const fn from_core(d: &Description) -> mpca_desc {
        let f = d.forces;
        let mut boundary = [[0; 2]; 3];
        let mut k = 0;
        while k < 3 {
            boundary[k] = [boundary_to_c(d.boundary[k][0]), boundary_to_c(d.boundary[k][1])];
            k += 1;
        }
        mpca_desc {
            struct_size: core::mem::size_of::<mpca_desc>() as u32,
            dim: d.dim,
            seed: d.seed,
            size: d.size,
            boundary,
            mass: d.mass,
            per_particle_mass: d.per_particle_mass as u32,
            mass_classes: d.mass_classes as u32,
            obstacles: d.obstacles as u32,
            surface_capacity: d.surface_capacity,
            forces: force_bit(f.uniform, mpca_force::Uniform)
                | force_bit(f.field, mpca_force::Field)
                | force_bit(f.potential, mpca_force::Potential)
                | force_bit(f.vortex, mpca_force::Vortex),
            gravity: d.gravity,
            vortex_centre: d.vortex.centre,
            vortex_core_radius: d.vortex.core_radius,
            vortex_circulation: d.vortex.circulation,
            restitution: d.restitution,
            wall_restitution: d.wall_restitution,
            dt: d.dt,
            quantization: d.quantization as u32,
            drift: d.drift as u32,
            method: d.method as u32,
            emitter_capacity: d.emitter_capacity,
            lifetimes: d.lifetimes as u32,
            collisions: d.collisions as u32,
            contacts: d.contacts as u32,
            energy_neutral: d.energy_neutral as u32,
            drag_rate: d.drag.rate,
            drag_wind: d.drag.wind,
            drag_vortex: d.drag.vortex as u32,
            drag_wind_field: d.drag.field as u32,
            identity: d.identity.bits(),
            body_capacity: d.body_capacity,
            body_surface_capacity: d.body_surface_capacity,
            rest: d.rest as u32,
            drag_turbulence_amplitude: d.drag.turbulence.amplitude,
            drag_turbulence_scale: d.drag.turbulence.scale,
            drag_turbulence_rate: d.drag.turbulence.rate,
        }
    }

    /// The core description; unknown enum values and flags are refused
    /// here, everything else by the core's own validation. Out of line:
    /// every export that takes a description calls it.
    #[inline(never)]
    pub(crate) fn to_core(self) -> Result<Description, Refusal> {
        check_size::<mpca_desc>(self.struct_size, c"desc.struct_size")?;
        // Every field is set below: the constant only gives the
        // non-exhaustive structure a start.
        let mut d = BASE;
        // The flags, and the enumerations of two values, are converted as
        // read, and all checked at the end at once: valid when none is
        // above 1, that is when they or'ed together are at most 1 (a test
        // and a branch of its own for each cost flash for every field on a
        // small core). `d` is a local: what a refusal leaves in it is
        // dropped.
        let mut ones = 0;
        // The flag is the value's low bit: a value above 1 is refused
        // below whatever it converted to, and the bit alone is a masking
        // and a store where `v != 0` takes a comparison and a select each.
        let mut one = |v: u32| {
            ones |= v;
            v & 1 != 0
        };
        d.per_particle_mass = one(self.per_particle_mass);
        d.obstacles = one(self.obstacles);
        d.drift = if one(self.drift) { Drift::Calibrated } else { Drift::Paper };
        d.collisions = if one(self.collisions) { Collisions::SpeedLimited } else { Collisions::Paper };
        d.contacts = one(self.contacts);
        d.rest = one(self.rest);
        d.energy_neutral = one(self.energy_neutral);
        let turbulence = Turbulence { amplitude: self.drag_turbulence_amplitude, scale: self.drag_turbulence_scale, rate: self.drag_turbulence_rate };
        d.drag = Drag { rate: self.drag_rate, wind: self.drag_wind, field: one(self.drag_wind_field), vortex: one(self.drag_vortex), turbulence };
        d.lifetimes = one(self.lifetimes);
        if ones > 1 || self.forces & !FORCE_BITS != 0 || self.identity > Identity::ALL.bits() {
            return Err(Refusal::computed(mpca_status::BadEnum, || self.bad_flag()));
        }
        // The core's flags are the C ABI's bits (checked at the top).
        d.identity = Identity::from_bits(self.identity).unwrap_or_default();
        d.dim = self.dim;
        d.seed = self.seed;
        d.size = self.size;
        for k in 0..3 {
            for f in 0..2 {
                d.boundary[k][f] = boundary_from_c(self.boundary[k][f])?;
            }
        }
        d.mass = self.mass;
        // The core keeps 16 bits: a value beyond them would come back
        // changed, so it is refused, masses on or off.
        d.mass_classes = u16::try_from(self.mass_classes).map_err(|_| Refusal::new(mpca_status::CapacityRange, c"desc.mass_classes"))?;
        d.surface_capacity = self.surface_capacity;
        (d.body_capacity, d.body_surface_capacity) = (self.body_capacity, self.body_surface_capacity);
        d.forces = Forces {
            uniform: self.forces & mpca_force::Uniform as u32 != 0,
            field: self.forces & mpca_force::Field as u32 != 0,
            potential: self.forces & mpca_force::Potential as u32 != 0,
            vortex: self.forces & mpca_force::Vortex as u32 != 0,
        };
        d.gravity = self.gravity;
        d.vortex = Vortex { centre: self.vortex_centre, core_radius: self.vortex_core_radius, circulation: self.vortex_circulation };
        d.restitution = self.restitution;
        d.wall_restitution = self.wall_restitution;
        d.dt = self.dt;
        d.quantization = match self.quantization {
            8 => Quantization::Bits8,
            16 => Quantization::Bits16,
            _ => return Err(Refusal::new(mpca_status::BadEnum, c"desc.quantization")),
        };
        d.method = match self.method {
            0 => Method::Exhaustive,
            1 => Method::ExactFast,
            2 => Method::Greedy,
            _ => return Err(Refusal::new(mpca_status::BadEnum, c"desc.method")),
        };
        d.emitter_capacity = self.emitter_capacity;
        Ok(d)
    }

    /// The field [`mpca_desc::to_core`]'s test of the flags and bits
    /// refused, asked only then, so that the test stays one.
    #[cold]
    #[inline(never)]
    fn bad_flag(&self) -> &'static CStr {
        if self.per_particle_mass > 1 {
            c"desc.per_particle_mass"
        } else if self.obstacles > 1 {
            c"desc.obstacles"
        } else if self.drift > 1 {
            c"desc.drift"
        } else if self.collisions > 1 {
            c"desc.collisions"
        } else if self.contacts > 1 {
            c"desc.contacts"
        } else if self.rest > 1 {
            c"desc.rest"
        } else if self.energy_neutral > 1 {
            c"desc.energy_neutral"
        } else if self.drag_wind_field > 1 {
            c"desc.drag_wind_field"
        } else if self.drag_vortex > 1 {
            c"desc.drag_vortex"
        } else if self.lifetimes > 1 {
            c"desc.lifetimes"
        } else if self.forces & !FORCE_BITS != 0 {
            c"desc.forces"
        } else {
            c"desc.identity"
        }
    }
}

/// Fills `out` with the defaults for a `dim`-dimensional world of
/// `nx x ny (x nz)` cells: periodic faces, one mass of 1, no obstacles, no
/// force, e = 1, dt = 1, seed 0, 8-bit velocities, the calibrated drift
/// rule (MPCA_DRIFT_PAPER reproduces the paper), the paper's collisions,
/// the exact-fast assignment, no emitters. Sets `struct_size`. Sizes are
/// checked later, by mpca_world_bytes and mpca_world_init.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_desc_defaults(out: *mut mpca_desc, dim: u32, nx: u32, ny: u32, nz: u32) -> mpca_status {
    guard(|c| {
        let out = c.out(out)?;
        // Description::new_3d is new_2d with the dimension and nz set.
        let mut desc = DEFAULTS;
        desc.dim = dim;
        desc.size = [nx, ny, if dim == 3 { nz } else { 1 }];
        out.set(desc);
        Ok(())
    })
}

/// An effect a description can start from: values of mpca_desc_preset's
/// `preset`.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_preset {
    /// Rising, fading smoke: buoyancy against flow drag, open sides and
    /// top, lifetimes, ids and ages.
    Smoke = 0,
    /// Water in a box: lively, levelling, and at rest where it lies
    /// (contacts and resting contact), ids.
    Water = 1,
    /// Sand in a box: grains that barely bounce and rest in a pile, ids and
    /// tags.
    Sand = 2,
}

/// Fills `out` for an effect (`mpca_preset`) in a `dim`-dimensional world
/// of `nx x ny (x nz)` cells, +y up: its faces, forces and rules, as
/// docs/model.md's Presets gives them. Room for emitters, obstacles and
/// bodies is the caller's to add. Sets `struct_size`. An unknown preset is
/// MPCA_STATUS_BAD_ENUM and leaves `out` as it was; sizes are checked
/// later, as for mpca_desc_defaults.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_desc_preset(out: *mut mpca_desc, preset: u32, dim: u32, nx: u32, ny: u32, nz: u32) -> mpca_status {
    guard(|c| {
        let out = c.out(out)?;
        let preset = match preset {
            0 => Preset::Smoke,
            1 => Preset::Water,
            2 => Preset::Sand,
            _ => return Err(Refusal::new(mpca_status::BadEnum, c"preset")),
        };
        out.set(mpca_desc::from_core(&Description::preset(preset, dim, [nx, ny, if dim == 3 { nz } else { 1 }])));
        Ok(())
    })
}

/// Checks a description in full without building anything.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_desc_validate(desc: *const mpca_desc) -> mpca_status {
    guard(|c| Ok(c.get(desc)?.to_core()?.validate()?))
}

/// Bytes of memory a world built from `desc` needs with mpca_world_init,
/// alignment slack included (any alignment of the memory is accepted).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_bytes(desc: *const mpca_desc, out_bytes: *mut usize) -> mpca_status {
    guard(|c| {
        // Read inside the result (moved out, it would be copied).
        let d = c.get(desc)?.to_core();
        let d = d.as_ref().map_err(|&s| s)?;
        let out = c.out(out_bytes)?;
        out.set(mpca_core::world_bytes(d)?);
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_core_descriptions() {
        // Expect: mpca_desc_defaults writes the core's new_2d and new_3d
        // as C sees them, with the dimension it was given (any, even one
        // the validation refuses later), and the core description back.
        let mut four = Description::new_2d(6, 8);
        four.dim = 4;
        for (dim, core) in [(2, Description::new_2d(6, 8)), (3, Description::new_3d(6, 8, 10)), (4, four)] {
            let mut out = DEFAULTS;
            out.seed = 99;
            // SAFETY: `out` is a valid, writable mpca_desc.
            assert_eq!(unsafe { mpca_desc_defaults(&mut out, dim, 6, 8, 10) }, mpca_status::Ok);
            assert_eq!(out, mpca_desc::from_core(&core), "dim {dim}");
            assert_eq!(out.to_core().ok(), Some(core), "dim {dim}");
        }
    }
}
