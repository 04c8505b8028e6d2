//! The scene description: what a world uses (M9), and its checks
//! ([`Description::check`]), made in full before any memory is touched;
//! the memory plan that follows from it is `storage/layout.rs`'s.

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::rules::assign::Method;
use crate::api::checks::{finite, mass, negative, positive, restitution, size};

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

/// How a collision picks its direction `R` (M5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Collisions {
    /// The paper's: `R` uniform. Eqs. 7-8 can then give a speed above 1,
    /// which the clamp (M5.5) cuts, losing energy.
    Paper = 0,
    /// M5.2b (beyond the paper): `R` uniform among the directions for which
    /// both outgoing speeds are at most 1, so a collision never needs the
    /// clamp and keeps momentum and the `e`-scaled energy.
    SpeedLimited = 1,
}

/// M5.1b flow drag (beyond the paper): after the forces of M5.1, each
/// velocity relaxes towards the flow velocity `u` at its cell at `rate` per
/// unit time, `v <- (v + dt rate u) / (1 + dt rate)` (backward Euler: stable
/// for any `dt rate`, never past `u`). The flow is `wind` plus, if `field`,
/// the cell's value in the wind plane ([`crate::World::set_wind_field`]),
/// plus, if `vortex`, the Rankine vortex of the description read as a
/// velocity field (`G r / (2 pi R^2)` inside the core, `G / (2 pi r)`
/// outside, tangential). A rate of 0 is off. Needs the `fields` feature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drag {
    /// The relaxation rate per step, times `dt`: finite and not negative.
    pub rate: f32,
    /// A uniform flow velocity in cells per step, `|wind| <= 1`.
    pub wind: [f32; 3],
    /// Add a flow velocity per cell to the flow: a plane of `dim` `f32` per
    /// cell, each cell's `|u| <= 1`, zero until set.
    pub field: bool,
    /// Add the vortex's velocity field to the flow.
    pub vortex: bool,
    /// Add turbulence to the flow (M5.1c); off where its amplitude is 0.
    pub turbulence: Turbulence,
}

impl Drag {
    /// No drag: a rate of 0, no wind, no plane, no vortex, no turbulence.
    pub const OFF: Drag = Drag { rate: 0.0, wind: [0.0; 3], field: false, vortex: false, turbulence: Turbulence::OFF };
}

/// M5.1c turbulence (beyond the paper): a part of the drag's flow that
/// varies in space and time and has no divergence, the curl of a smooth
/// noise potential computed in the step from integers, so smoke carried by
/// it breaks up and curls without a flow from the caller. It acts through
/// drag ([`Drag::rate`] > 0) and needs the `fields` feature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turbulence {
    /// The largest any component of the turbulent flow gets, in cells per
    /// step, `0 <= amplitude <= 1`; 0 is off.
    pub amplitude: f32,
    /// The size of the eddies in cells: a power of two from 1 to 1024,
    /// dividing the size of every periodic axis.
    pub scale: u32,
    /// How fast the flow changes, per step, `0 <= rate <= 1`: a new random
    /// flow every `1 / rate` steps, blended smoothly; 0 is a steady flow.
    pub rate: f32,
}

impl Turbulence {
    /// No turbulence.
    pub const OFF: Turbulence = Turbulence { amplitude: 0.0, scale: 0, rate: 0.0 };
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

/// The identity planes a world keeps (M6b), each paid for only where it
/// is on (M9): a 32-bit id unique in the world's life, the age in steps
/// and a one-byte tag of the caller's, carried with every particle. A set
/// of flags: [`Identity::IDS`], [`Identity::AGES`], [`Identity::TAGS`],
/// joined with `|`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Identity(u8);

impl Identity {
    /// No plane.
    pub const NONE: Identity = Identity(0);
    /// Each particle gets an id when it is added or emitted, counting up
    /// from 1, never given again (4 bytes a cell).
    pub const IDS: Identity = Identity(1);
    /// Each particle counts the steps it has taken part in (4 bytes a
    /// cell).
    pub const AGES: Identity = Identity(2);
    /// Each particle carries a byte the caller gives it: at
    /// [`World::set_tag`](crate::World::set_tag) or from its emitter (1
    /// byte a cell).
    pub const TAGS: Identity = Identity(4);
    /// Every plane.
    pub const ALL: Identity = Identity(7);

    /// The planes of `bits` (ids 1, ages 2, tags 4, as the C ABI's
    /// `MPCA_IDENTITY_*`), or `None` where another bit is set.
    pub const fn from_bits(bits: u32) -> Option<Identity> {
        if bits & !7 == 0 { Some(Identity(bits as u8)) } else { None }
    }

    /// Ids 1, ages 2, tags 4.
    pub const fn bits(self) -> u32 {
        self.0 as u32
    }

    /// Whether every plane of `other` is in this set.
    pub const fn contains(self, other: Identity) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether particles carry ids.
    #[inline(always)]
    pub const fn ids(self) -> bool {
        self.0 & 1 != 0
    }

    /// Whether particles carry ages.
    #[inline(always)]
    pub const fn ages(self) -> bool {
        self.0 & 2 != 0
    }

    /// Whether particles carry tags.
    #[inline(always)]
    pub const fn tags(self) -> bool {
        self.0 & 4 != 0
    }

    /// Whether any plane is on.
    #[inline(always)]
    pub const fn any(self) -> bool {
        self.0 != 0
    }
}

impl core::ops::BitOr for Identity {
    type Output = Identity;
    fn bitor(self, other: Identity) -> Identity {
        Identity(self.0 | other.0)
    }
}

/// An effect a description can start from ([`Description::preset`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Preset {
    /// Rising, fading smoke: buoyancy against flow drag, open sides and top.
    Smoke,
    /// Water in a box: lively, levelling, and at rest where it lies.
    Water,
    /// Sand in a box: grains that barely bounce and rest in a pile.
    Sand,
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
    /// Capacity of the mass table, 1 to 256. Sixteen bits: the description
    /// then stays small enough for a step to copy with inline moves, not a
    /// call of `memcpy` on the world's memory (a C program's
    /// ThreadSanitizer sees such calls, but not the handle's ordering of
    /// them).
    pub mass_classes: u16,
    /// Whether the world has obstacle cells (feature `obstacles`).
    pub obstacles: bool,
    /// How many obstacle surface cells (with normal and restitution) fit;
    /// [`Description::surface_entries`] says how many a shape takes.
    pub surface_capacity: u32,
    /// How many bodies, obstacles the caller moves (M13, with `obstacles`),
    /// fit.
    pub body_capacity: u32,
    /// How many body surface cells fit (M13): every body cell with a free
    /// neighbour takes one; [`Description::surface_entries`] of a body's
    /// shape is an upper bound for it.
    pub body_surface_capacity: u32,
    /// Which force terms are summed (M5.1).
    pub forces: Forces,
    /// The uniform acceleration, used when `forces.uniform`, in cells per
    /// step per step (times `dt`; `docs/model.md`, Units, maps it to m/s²).
    pub gravity: [f32; 3],
    /// The vortex, used when `forces.vortex`.
    pub vortex: Vortex,
    /// Particle-particle restitution `e` (eqs. 7-8), in `[0, 1]`.
    pub restitution: f32,
    /// Restitution of the domain's wall faces (M4), in `[0, 1]`.
    pub wall_restitution: f32,
    /// Time step of eqs. 4-5, the factor a step scales every acceleration
    /// and drag rate by; finite and not negative.
    pub dt: f32,
    /// The seed of every random stream (M8).
    pub seed: u64,
    /// Stored bits per velocity component.
    pub quantization: Quantization,
    /// The move probability rule.
    pub drift: Drift,
    /// Flow drag towards a wind and the vortex (M5.1b); rate 0 is off.
    pub drag: Drag,
    /// The move assignment method.
    pub method: Method,
    /// How collisions pick their direction.
    pub collisions: Collisions,
    /// M5.7 (beyond the paper): a particle refused the cell it wanted meets
    /// the particle that holds it, head on, with restitution `e`, so piles
    /// come to rest. Off: the paper's rules, where a refused particle keeps
    /// its velocity.
    pub contacts: bool,
    /// M5.7b (beyond the paper): a particle that rests on a full support
    /// (walls, obstacles, particles at rest) loses its velocity into the
    /// support along the uniform force and takes no push from it, so a pool
    /// or a pile comes to rest exactly. Off: the paper's rules.
    pub rest: bool,
    /// M1b (beyond the paper): each collision and contact shrinks its
    /// pair's relative velocity by the kinetic energy the stochastic
    /// rounding of its results adds on average, so an elastic world keeps
    /// its energy. Off: unbiased rounding, which heats an elastic world.
    pub energy_neutral: bool,
    /// How many emitters fit.
    pub emitter_capacity: u32,
    /// Whether particles carry a remaining lifetime (a `u16` per cell), so
    /// emitters can give them one (M6).
    pub lifetimes: bool,
    /// Ids, ages and tags carried with the particles (M6b, feature
    /// `identity`); none by default.
    pub identity: Identity,
}

impl Description {
    /// A 2D world of `nx x ny` cells: periodic on every axis, one mass of 1,
    /// no obstacles, no force, `e = 1`, `dt = 1`, 8-bit velocities, the
    /// calibrated drift rule (a free particle drifts at its velocity; set
    /// `Drift::Paper` to reproduce the paper), the paper's collisions and
    /// the exact-fast assignment.
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
            body_capacity: 0,
            body_surface_capacity: 0,
            forces: Forces { uniform: false, field: false, potential: false, vortex: false },
            gravity: [0.0; 3],
            vortex: Vortex { centre: [0.0; 2], core_radius: 1.0, circulation: 0.0 },
            restitution: 1.0,
            wall_restitution: 1.0,
            dt: 1.0,
            seed: 0,
            quantization: Quantization::Bits8,
            drift: Drift::Calibrated,
            drag: Drag::OFF,
            method: Method::ExactFast,
            collisions: Collisions::Paper,
            contacts: false,
            rest: false,
            energy_neutral: false,
            emitter_capacity: 0,
            lifetimes: false,
            identity: Identity::NONE,
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

    /// A `dim`-dimensional world of `size` cells (the third ignored in 2D)
    /// set up for an effect: its faces, forces and rules, with +y up
    /// (docs/model.md, Presets, says what each sets and why). Room for
    /// emitters, obstacles and bodies is the caller's to add.
    pub const fn preset(preset: Preset, dim: u32, size: [u32; 3]) -> Self {
        let mut d = if dim == 3 { Self::new_3d(size[0], size[1], size[2]) } else { Self::new_2d(size[0], size[1]) };
        d.dim = dim;
        d.boundary = [[Boundary::Wall; 2]; 3];
        d.forces.uniform = true;
        d.contacts = true;
        match preset {
            Preset::Smoke => {
                // Rises from a floor through open sides and top, at the
                // speed buoyancy and drag settle on, and fades.
                d.boundary = [[Boundary::Open; 2]; 3];
                d.boundary[1][0] = Boundary::Wall;
                d.gravity = [0.0, 0.0069, 0.0];
                d.drag.rate = 0.033;
                // Eddies faster than the rise, changing about once a
                // second at the units' 60 steps a second, so that the
                // column wavers and breaks up (docs/model.md, Presets).
                d.drag.turbulence = Turbulence { amplitude: 0.5, scale: 16, rate: 0.02 };
                d.collisions = Collisions::SpeedLimited;
                d.contacts = false;
                d.lifetimes = true;
                d.identity = Identity(Identity::IDS.0 | Identity::AGES.0);
            }
            Preset::Water => {
                // Lively where it falls, levelled by its bounces, at rest
                // where it lies.
                d.gravity = [0.0, -0.005, 0.0];
                d.restitution = 0.95;
                d.wall_restitution = 0.95;
                d.rest = true;
                d.identity = Identity::IDS;
            }
            Preset::Sand => {
                // Grains that barely bounce and come to rest in a pile.
                d.gravity = [0.0, -0.0136, 0.0];
                d.restitution = 0.1;
                d.wall_restitution = 0.1;
                d.rest = true;
                d.identity = Identity(Identity::IDS.0 | Identity::TAGS.0);
            }
        }
        d
    }

    /// Sets every face of every axis to `b`.
    pub const fn with_boundary(mut self, b: Boundary) -> Self {
        self.boundary = [[b; 2]; 3];
        self
    }

    /// Every check of a description but its memory plan, in the order
    /// they are made ([`Description::validate`] adds the plan): dimension,
    /// sizes and faces (M1, M4), then masses, restitutions, `dt` and every
    /// force parameter, then the parts this build leaves out. What passes
    /// is what a plan is made from.
    pub(crate) fn check(&self) -> Result<Checked<'_>, Error> {
        use ErrorKind as K;
        let dim = self.dim as usize;
        if dim != 2 && dim != 3 {
            return Err(Error::new(K::BadDimension, c"desc.dim"));
        }
        if dim == 3 && !cfg!(feature = "dim3") {
            return Err(Error::new(K::Dim3Disabled, c"desc.dim"));
        }
        for k in 0..dim {
            // Each axis named: the details are static text.
            let axis = |x: &'static CStr, y: &'static CStr, z: &'static CStr| match k {
                0 => x,
                1 => y,
                _ => z,
            };
            let s = self.size[k];
            if s == 0 || s % 2 != 0 {
                let kind = if s == 0 { K::SizeZero } else { K::SizeOdd };
                return Err(Error::new(kind, axis(c"desc.size[0]", c"desc.size[1]", c"desc.size[2]")));
            }
            if self.boundary[k][0] != self.boundary[k][1]
                && (self.boundary[k][0] == Boundary::Periodic || self.boundary[k][1] == Boundary::Periodic)
            {
                return Err(Error::new(K::PeriodicMismatch, axis(c"desc.boundary[0]", c"desc.boundary[1]", c"desc.boundary[2]")));
            }
        }
        // M1: masses, restitutions, dt and every force parameter.
        mass(self.mass, c"desc.mass")?;
        restitution(self.restitution, c"desc.restitution")?;
        restitution(self.wall_restitution, c"desc.wall_restitution")?;
        finite(&[self.dt], c"desc.dt")?;
        if negative(self.dt) {
            return Err(Error::new(K::NegativeDt, c"desc.dt"));
        }
        finite(&self.gravity, c"desc.gravity")?;
        finite(&[self.vortex.centre[0], self.vortex.centre[1], self.vortex.core_radius, self.vortex.circulation], c"desc.vortex")?;
        if self.forces.vortex && !positive(self.vortex.core_radius) {
            return Err(Error::new(K::BadVortex, c"desc.vortex.core_radius"));
        }
        // M5.1b: a rate of 0 is off, and the wind is a velocity.
        finite(&[self.drag.rate], c"desc.drag.rate")?;
        finite(&self.drag.wind, c"desc.drag.wind")?;
        if negative(self.drag.rate) {
            return Err(Error::new(K::BadDrag, c"desc.drag.rate"));
        }
        if !crate::api::speed::slow(&self.drag.wind[..dim]) {
            return Err(Error::new(K::SpeedRange, c"desc.drag.wind"));
        }
        if self.drag.vortex && positive(self.drag.rate) && !positive(self.vortex.core_radius) {
            return Err(Error::new(K::BadVortex, c"desc.vortex.core_radius"));
        }
        self.check_turbulence(dim)?;
        if self.quantization == Quantization::Bits16 && !cfg!(feature = "q16") {
            return Err(Error::new(K::Q16Disabled, c"desc.quantization"));
        }
        // A part the build left out: the step reads the description through
        // accessors that give what the build keeps (`has_masses`,
        // `built_forces`, `assignment`, ...), so a description they would
        // change asks for something missing. One map of features to parts;
        // which part, only once one is missing.
        let kept = self.has_masses() == self.per_particle_mass
            && self.has_obstacles() == self.obstacles
            && self.built_forces() == self.forces
            && self.has_drag() == positive(self.drag.rate)
            && (cfg!(feature = "fields") || !self.drag.field && !positive(self.drag.turbulence.amplitude))
            && self.assignment() == self.method
            && self.collision_rule() == self.collisions
            && self.has_contacts() == self.contacts
            && self.has_rest() == self.rest
            && self.has_energy_neutral() == self.energy_neutral
            && self.identity_planes().any() == self.identity.any();
        if !kept {
            return Err(Error::computed(K::FeatureDisabled, || self.left_out()));
        }
        if self.per_particle_mass && !(1..=256).contains(&self.mass_classes) {
            return Err(Error::new(K::CapacityRange, c"desc.mass_classes"));
        }
        Ok(Checked(self))
    }

    /// M5.1c's settings, where the amplitude is above 0: each in its
    /// range, the scale dividing every periodic axis, and drag on to carry
    /// it. Compared through the floats' bits, as every check.
    fn check_turbulence(&self, dim: usize) -> Result<(), Error> {
        // Without `fields` any turbulence is refused as a part left out.
        if !cfg!(feature = "fields") {
            return Ok(());
        }
        let t = &self.drag.turbulence;
        finite(&[t.amplitude, t.rate], c"desc.drag.turbulence")?;
        // 0 (or -0) is off.
        if !positive(t.amplitude) && !negative(t.amplitude) {
            return Ok(());
        }
        let problem = if negative(t.amplitude) || size(t.amplitude) > size(1.0) {
            c"desc.drag.turbulence.amplitude (0 to 1)"
        } else if !t.scale.is_power_of_two() || t.scale > 1024 {
            c"desc.drag.turbulence.scale (a power of two, 1 to 1024)"
        } else if (0..dim).any(|k| self.boundary[k][0] == Boundary::Periodic && self.size[k] % t.scale != 0) {
            c"desc.drag.turbulence.scale (must divide the size of every periodic axis)"
        } else if negative(t.rate) || size(t.rate) > size(1.0) {
            c"desc.drag.turbulence.rate (0 to 1)"
        } else if !positive(self.drag.rate) {
            c"desc.drag.turbulence (needs desc.drag.rate above 0)"
        } else {
            return Ok(());
        };
        Err(Error::new(ErrorKind::BadDrag, problem))
    }

    /// The field that asks for a part this build left out, and the feature
    /// that builds it in, for [`Description::check`]'s refusal: the same
    /// map as its, field by field. Out of line and apart, so the check
    /// itself stays one test.
    #[inline(never)]
    #[cold]
    fn left_out(&self) -> &'static CStr {
        let f = self.forces;
        if self.has_masses() != self.per_particle_mass {
            c"desc.per_particle_mass needs feature `mass`"
        } else if self.has_obstacles() != self.obstacles {
            c"desc.obstacles needs feature `obstacles`"
        } else if self.built_forces().vortex != f.vortex {
            c"desc.forces.vortex needs feature `vortex`"
        } else if self.built_forces().field != f.field {
            c"desc.forces.field needs feature `fields`"
        } else if self.built_forces().potential != f.potential {
            c"desc.forces.potential needs feature `fields`"
        } else if self.has_drag() != positive(self.drag.rate) {
            c"desc.drag.rate needs feature `fields`"
        } else if !cfg!(feature = "fields") && self.drag.field {
            c"desc.drag.field needs feature `fields`"
        } else if !cfg!(feature = "fields") && positive(self.drag.turbulence.amplitude) {
            c"desc.drag.turbulence needs feature `fields`"
        } else if self.assignment() != self.method {
            c"desc.method needs feature `all-methods`"
        } else if self.collision_rule() != self.collisions {
            c"desc.collisions needs feature `collision-rules`"
        } else if self.has_contacts() != self.contacts {
            c"desc.contacts needs feature `collision-rules`"
        } else if self.has_rest() != self.rest {
            c"desc.rest needs feature `collision-rules`"
        } else if self.has_energy_neutral() != self.energy_neutral {
            c"desc.energy_neutral needs feature `collision-rules`"
        } else {
            c"desc.identity needs feature `identity`"
        }
    }

    /// `per_particle_mass`, false by construction in a build without the
    /// feature `mass` ([`Description::check`] refuses it there): the step
    /// and the edits test this, so such a build holds no code for masses.
    #[inline(always)]
    pub(crate) const fn has_masses(&self) -> bool {
        cfg!(feature = "mass") && self.per_particle_mass
    }

    /// `identity`, none by construction in a build without the feature
    /// `identity`, as [`Description::has_masses`].
    #[inline(always)]
    pub(crate) const fn identity_planes(&self) -> Identity {
        if cfg!(feature = "identity") { self.identity } else { Identity::NONE }
    }

    /// `obstacles`, false by construction in a build without the feature
    /// `obstacles`, as [`Description::has_masses`].
    #[inline(always)]
    pub(crate) const fn has_obstacles(&self) -> bool {
        cfg!(feature = "obstacles") && self.obstacles
    }

    /// Whether the world keeps a body table (M13): obstacles, and room for
    /// a body.
    #[cfg(feature = "obstacles")]
    #[inline(always)]
    pub(crate) const fn has_bodies(&self) -> bool {
        self.has_obstacles() && self.body_capacity > 0
    }

    /// `forces` with the terms this build leaves out false, as they are by
    /// construction ([`Description::check`] refuses them): the vortex needs
    /// the feature `vortex`, the force field and the potential `fields`.
    /// The step reads this, so a build without them holds no code for them.
    #[inline(always)]
    pub(crate) const fn built_forces(&self) -> Forces {
        let fields = cfg!(feature = "fields");
        let f = self.forces;
        Forces { uniform: f.uniform, field: fields && f.field, potential: fields && f.potential, vortex: cfg!(feature = "vortex") && f.vortex }
    }

    /// Whether flow drag is on (M5.1b: a rate above 0), false by
    /// construction without the feature `fields`.
    #[inline(always)]
    pub(crate) fn has_drag(&self) -> bool {
        cfg!(feature = "fields") && positive(self.drag.rate)
    }

    /// `method`, [`Method::ExactFast`] by construction in a build without
    /// the feature `all-methods` ([`Description::check`] refuses the others
    /// there): the step reads this, so such a build holds no code for the
    /// others.
    #[inline(always)]
    pub(crate) const fn assignment(&self) -> Method {
        if cfg!(feature = "all-methods") { self.method } else { Method::ExactFast }
    }

    /// `collisions`, [`Collisions::Paper`] by construction in a build
    /// without the feature `collision-rules` ([`Description::check`]
    /// refuses M5.2b there), as [`Description::assignment`].
    #[inline(always)]
    pub(crate) const fn collision_rule(&self) -> Collisions {
        if cfg!(feature = "collision-rules") { self.collisions } else { Collisions::Paper }
    }

    /// `contacts` (M5.7), false by construction without the feature
    /// `collision-rules`, as [`Description::has_masses`].
    #[inline(always)]
    pub(crate) const fn has_contacts(&self) -> bool {
        cfg!(feature = "collision-rules") && self.contacts
    }

    /// `rest` (M5.7b), false by construction without the feature
    /// `collision-rules`, as [`Description::has_masses`].
    #[inline(always)]
    pub(crate) const fn has_rest(&self) -> bool {
        cfg!(feature = "collision-rules") && self.rest
    }

    /// `energy_neutral` (M1b), false by construction without the feature
    /// `collision-rules`, as [`Description::has_masses`].
    #[inline(always)]
    pub(crate) const fn has_energy_neutral(&self) -> bool {
        cfg!(feature = "collision-rules") && self.energy_neutral
    }
}

/// A description that passed [`Description::check`]: what a memory plan
/// ([`Layout::of`](crate::storage::layout::Layout::of)) is made from, so
/// that no plan is made of a description nobody checked.
#[derive(Clone, Copy)]
pub(crate) struct Checked<'a>(&'a Description);

impl core::ops::Deref for Checked<'_> {
    type Target = Description;

    fn deref(&self) -> &Description {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_a_build_left_out_are_refused() {
        // Expect: a description asking for an assignment method, a
        // collision rule or a force the build left out (without the
        // features `all-methods`, `collision-rules`, `vortex`, `fields`) is
        // refused with FeatureDisabled, its detail naming the field that
        // asks for it and the feature, and accepted by a build that has it
        // (the default); the paper's rules and exact-fast are accepted by
        // every build.
        let check = |d: Description, left_out: bool, detail: &str| match d.validate() {
            Ok(()) => assert!(!left_out, "{detail}: accepted"),
            Err(e) => {
                assert!(left_out, "{detail}: refused, {e}");
                assert_eq!(e.kind(), ErrorKind::FeatureDisabled);
                if cfg!(feature = "details") {
                    assert_eq!(e.detail(), detail);
                }
            }
        };
        let plain = Description::new_2d(8, 8);
        for method in [Method::Exhaustive, Method::Greedy] {
            check(Description { method, ..plain }, !cfg!(feature = "all-methods"), "desc.method needs feature `all-methods`");
        }
        let paper_only = !cfg!(feature = "collision-rules");
        check(Description { collisions: Collisions::SpeedLimited, ..plain }, paper_only, "desc.collisions needs feature `collision-rules`");
        check(Description { contacts: true, ..plain }, paper_only, "desc.contacts needs feature `collision-rules`");
        check(Description { rest: true, ..plain }, paper_only, "desc.rest needs feature `collision-rules`");
        check(Description { energy_neutral: true, ..plain }, paper_only, "desc.energy_neutral needs feature `collision-rules`");
        // The vortex needs `vortex` (which `fields` implies), the other
        // summed forces and drag need `fields`.
        let vortex = Forces { vortex: true, ..plain.forces };
        check(Description { forces: vortex, ..plain }, !cfg!(feature = "vortex"), "desc.forces.vortex needs feature `vortex`");
        let field = Forces { field: true, ..plain.forces };
        check(Description { forces: field, ..plain }, !cfg!(feature = "fields"), "desc.forces.field needs feature `fields`");
        let wind_field = Drag { field: true, ..plain.drag };
        check(Description { drag: wind_field, ..plain }, !cfg!(feature = "fields"), "desc.drag.field needs feature `fields`");
        assert_eq!(plain.validate(), Ok(()));
    }
}
