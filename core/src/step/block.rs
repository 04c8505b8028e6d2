//! What the block pipeline works with: the data every block of a step
//! reads, the planes the step writes, the pipeline's parameters (the parts
//! it has code for, the velocity width it reads), where a block lies and
//! what its particles carry, and one block's particles as the stages of M5
//! see them.

use crate::api::desc::Description;
#[cfg(not(feature = "small-step"))]
use crate::api::desc::{Boundary, Collisions, Drift, Identity};
#[cfg(not(feature = "small-step"))]
use crate::rules::assign::Method;
use crate::rules::assign::{bits, Bits};
use crate::rules::class::Class;
use crate::rules::faces::Coords;
use crate::rules::force::{Flow, ForceTerms};
use crate::rules::obstacle::Surface;
use crate::rules::quant::{Quant, Width};
use crate::rules::rng::StepKey;
use crate::step::partition::{BlockRow, Partition};
use crate::storage::cells::Cells;
use crate::storage::layout::{groups, view};
use crate::storage::world::Counters;

/// What a step's blocks read of the description, copied beside the other
/// shared data once a step: the few settings the block rule branches on,
/// not the whole description, whose copy grows with every setting a world
/// has (a large copy is a library call, which ThreadSanitizer sees apart
/// from the registry's atomics that order it).
///
/// Each switch a feature builds out reads false here as it does in
/// [`Description`]'s own accessor, so that such a build holds no code for
/// the part.
///
/// With `small-step` the blocks read the description where it lies in the
/// world's header instead ([`StepRules`]): no copy to set up, less flash.
#[cfg(not(feature = "small-step"))]
#[derive(Clone, Copy)]
pub(crate) struct BlockRules {
    pub boundary: [[Boundary; 2]; 3],
    pub wall_restitution: f32,
    pub drift: Drift,
    pub lifetimes: bool,
    masses: bool,
    obstacles: bool,
    contacts: bool,
    energy_neutral: bool,
    collisions: Collisions,
    method: Method,
    identity: Identity,
}

/// The description's settings as the blocks read them: [`BlockRules`], or
/// with `small-step` the description itself, which has the same fields and
/// accessors.
#[cfg(feature = "small-step")]
pub(crate) type StepRules<'a> = &'a Description;
#[cfg(not(feature = "small-step"))]
pub(crate) type StepRules<'a> = BlockRules;

#[cfg(not(feature = "small-step"))]
impl BlockRules {
    pub(crate) fn of(d: &Description) -> BlockRules {
        BlockRules {
            boundary: d.boundary,
            wall_restitution: d.wall_restitution,
            drift: d.drift,
            lifetimes: d.lifetimes,
            masses: d.has_masses(),
            obstacles: d.has_obstacles(),
            contacts: d.has_contacts(),
            energy_neutral: d.has_energy_neutral(),
            collisions: d.collision_rule(),
            method: d.assignment(),
            identity: d.identity_planes(),
        }
    }

    /// As [`Description::has_masses`].
    #[inline(always)]
    pub(crate) const fn has_masses(&self) -> bool {
        cfg!(feature = "mass") && self.masses
    }

    /// As [`Description::has_obstacles`].
    #[inline(always)]
    pub(crate) const fn has_obstacles(&self) -> bool {
        cfg!(feature = "obstacles") && self.obstacles
    }

    /// As [`Description::has_contacts`].
    #[inline(always)]
    pub(crate) const fn has_contacts(&self) -> bool {
        cfg!(feature = "collision-rules") && self.contacts
    }

    /// As [`Description::has_energy_neutral`].
    #[inline(always)]
    pub(crate) const fn has_energy_neutral(&self) -> bool {
        cfg!(feature = "collision-rules") && self.energy_neutral
    }

    /// As [`Description::collision_rule`].
    #[inline(always)]
    pub(crate) const fn collision_rule(&self) -> Collisions {
        if cfg!(feature = "collision-rules") { self.collisions } else { Collisions::Paper }
    }

    /// As [`Description::assignment`].
    #[inline(always)]
    pub(crate) const fn assignment(&self) -> Method {
        if cfg!(feature = "all-methods") { self.method } else { Method::ExactFast }
    }

    /// As [`Description::identity_planes`].
    #[inline(always)]
    pub(crate) const fn identity_planes(&self) -> Identity {
        if cfg!(feature = "identity") { self.identity } else { Identity::NONE }
    }
}

impl Shared<'_> {
    /// The class of mass index `i`: the first where the index names none
    /// (no index an API call writes does; an image's are checked).
    #[inline(always)]
    pub(crate) fn class(&self, i: u8) -> Class {
        match self.classes.get(usize::from(i)) {
            Some(c) => *c,
            None => self.one,
        }
    }
}

/// The block pipeline (`step/kernel.rs`), specialised once per step (M9)
/// on the dimension `D` (with `CELLS = 2^D` cells a block); its methods
/// take the velocity width ([`Widths`]) as a parameter. Summed forces,
/// obstacles, per-particle masses and lifetimes are per-step switches:
/// each costs a predictable branch per block or per particle where the
/// pipeline has code for [`Every`] part, and sends every block there when
/// it is on ([`Shared::plain`]), so the plain instantiations never test
/// them.
pub(crate) struct Kernel<'a, const D: usize, const CELLS: usize> {
    pub shared: &'a Shared<'a>,
    pub planes: Writable<'a, D>,
    pub counters: Counters,
}

/// The parts of a step an instantiation of the pipeline has code for (M9).
pub(crate) trait Parts {
    /// Every part, each read from the step's description: the faces,
    /// obstacles, masses, lifetimes, summed forces and drag. Without it
    /// the block is a plain world's ([`Shared::plain`]), away from the
    /// faces and the block that wraps round x, and holds no obstacle
    /// ([`RowPlan`](crate::step::kernel::RowPlan)); its cells are unrolled.
    const ALL: bool;
    /// M5.7 may be on (read from the description).
    const CONTACTS: bool;
}

/// Every part: the blocks on the faces, with obstacles, and every block
/// of a world that is not plain.
pub(crate) struct Every;
/// A plain world's block away from the faces and obstacles.
pub(crate) struct Plain;
/// [`Plain`] in a world without contacts ([`Shared::lanes`]).
pub(crate) struct Bare;

impl Parts for Every {
    const ALL: bool = true;
    const CONTACTS: bool = true;
}
impl Parts for Plain {
    const ALL: bool = false;
    const CONTACTS: bool = true;
}
impl Parts for Bare {
    const ALL: bool = false;
    const CONTACTS: bool = false;
}

/// The stored velocity width (M1) an instantiation of the pipeline has
/// code for: a stored type's ([`Typed`]), which folds at compile time, or
/// the step's, read at run time ([`AnyWidth`]).
pub(crate) trait Widths {
    /// The width as values.
    fn width(sh: &Shared<'_>) -> Width;
    /// The block of occupancy `occ` whose block rows lie in `row`, its
    /// cells at x `xs` ([`Block::load`]).
    fn load<const D: usize, const CELLS: usize>(velocity: &Velocity<'_, D>, sh: &Shared<'_>, row: &BlockRow, xs: [usize; 2], occ: u8) -> Block<D, CELLS>;
    /// Makes `q` (in quanta, within the stored range) the stored velocity
    /// of cell `at`. By reference: the components are read in place (a
    /// copy first takes more flash in the firmware).
    fn store<const D: usize>(velocity: &Velocity<'_, D>, sh: &Shared<'_>, at: usize, q: &[i32; D]);
}

/// A stored velocity type, with its plane among the step's.
pub(crate) trait Typed: Quant {
    /// The velocity plane of a world of this type.
    fn plane<'a, const D: usize>(velocity: &Velocity<'a, D>) -> Cells<'a, [Self; D]>;
}

impl Typed for i8 {
    #[inline(always)]
    fn plane<'a, const D: usize>(velocity: &Velocity<'a, D>) -> Cells<'a, [i8; D]> {
        velocity.narrow
    }
}

#[cfg(feature = "q16")]
impl Typed for i16 {
    #[inline(always)]
    fn plane<'a, const D: usize>(velocity: &Velocity<'a, D>) -> Cells<'a, [i16; D]> {
        velocity.wide
    }
}

impl<Q: Typed> Widths for Q {
    #[inline(always)]
    fn width(_: &Shared<'_>) -> Width {
        Width::of::<Q>()
    }

    #[inline(always)]
    fn load<const D: usize, const CELLS: usize>(velocity: &Velocity<'_, D>, _: &Shared<'_>, row: &BlockRow, xs: [usize; 2], occ: u8) -> Block<D, CELLS> {
        Block::load(Q::plane(velocity), row, xs, occ)
    }

    #[inline(always)]
    fn store<const D: usize>(velocity: &Velocity<'_, D>, _: &Shared<'_>, at: usize, q: &[i32; D]) {
        // Component by component: an array's `map` is a call at opt-level z.
        let mut v = [Q::from_int(0); D];
        for k in 0..D {
            v[k] = Q::from_int(q[k]);
        }
        Q::plane(velocity).set(at, v);
    }
}

/// The width of the step's world, read from its shared data
/// ([`Shared::width`]): the pipeline with every part, one copy of which
/// serves both widths (not with `small-step`: `Sink::every`).
#[cfg(not(feature = "small-step"))]
pub(crate) struct AnyWidth;

#[cfg(not(feature = "small-step"))]
impl Widths for AnyWidth {
    #[inline(always)]
    fn width(sh: &Shared<'_>) -> Width {
        sh.width
    }

    #[inline(always)]
    fn load<const D: usize, const CELLS: usize>(velocity: &Velocity<'_, D>, sh: &Shared<'_>, row: &BlockRow, xs: [usize; 2], occ: u8) -> Block<D, CELLS> {
        #[cfg(feature = "q16")]
        if sh.width.wide() {
            return <i16 as Widths>::load(velocity, sh, row, xs, occ);
        }
        <i8 as Widths>::load(velocity, sh, row, xs, occ)
    }

    #[inline(always)]
    fn store<const D: usize>(velocity: &Velocity<'_, D>, sh: &Shared<'_>, at: usize, q: &[i32; D]) {
        #[cfg(feature = "q16")]
        if sh.width.wide() {
            return <i16 as Widths>::store(velocity, sh, at, q);
        }
        <i8 as Widths>::store(velocity, sh, at, q);
    }
}

/// Where a block lies (M3, M4): its cells in the planes, and the cells
/// beyond a face or blocked.
pub(crate) struct Site<'r> {
    pub row: &'r BlockRow,
    /// The x of the block's lowest corner (-1 for the half block on a low
    /// face).
    pub x0: isize,
    /// Cell `c` lies at x `xs[c & 1]` of block row `c >> 1` (y, then z).
    pub xs: [usize; 2],
    /// Cells beyond a wall face, and beyond an open one (their sites mean
    /// nothing).
    pub wall: u8,
    pub open: u8,
    /// Cells no particle may enter: beyond a wall, or an obstacle's.
    pub blocked: u8,
}

impl<'r> Site<'r> {
    /// A plain block's site: block `x0` of `row`, whose cells are all
    /// inside the domain and none blocked.
    #[inline(always)]
    pub(crate) fn plain(row: &'r BlockRow, x0: usize) -> Self {
        Site { row, x0: x0 as isize, xs: [x0, x0 + 1], wall: 0, open: 0, blocked: 0 }
    }

    /// The dense index of cell `c` in the planes.
    #[inline(always)]
    pub(crate) fn cell(&self, c: usize) -> usize {
        // A choice, not an index: the two x stay in registers.
        (if c & 1 == 0 { self.xs[0] } else { self.xs[1] }) + self.row.cell[c >> 1]
    }

    /// The raw coordinates of cell `c` (beyond a face where it lies there).
    #[inline(always)]
    pub(crate) fn at(&self, c: usize) -> Coords {
        [self.x0 + (c & 1) as isize, self.row.origin[0] + ((c >> 1) & 1) as isize, self.row.origin[1] + ((c >> 2) & 1) as isize]
    }
}

/// What the particles of a block carry besides their velocity (M9): their
/// mass indices and lifetimes, read where the world has them.
pub(crate) struct Carried<const CELLS: usize> {
    /// Read through [`Carried::masses`].
    masses: bool,
    pub lifetimes: bool,
    pub mass_index: [u8; CELLS],
    /// 0 (none) in worlds without lifetimes.
    pub life: [u16; CELLS],
}

impl<const CELLS: usize> Carried<CELLS> {
    /// The particles carry mass indices: never in a build without the
    /// feature `mass`, where this folds to false (the switch alone, kept
    /// in the struct, does not always).
    #[inline(always)]
    pub(crate) fn masses(&self) -> bool {
        cfg!(feature = "mass") && self.masses
    }

    /// Nothing: a plain world's particles carry no mass index and no
    /// lifetime.
    #[inline(always)]
    pub(crate) fn none() -> Self {
        Carried::new(false, false)
    }

    /// Particles that carry mass indices where `masses`, lifetimes where
    /// `lifetimes`, all 0 until read.
    #[inline(always)]
    pub(crate) fn new(masses: bool, lifetimes: bool) -> Self {
        Carried { masses, lifetimes, mass_index: [0; CELLS], life: [0; CELLS] }
    }

    /// The mass class of the particle in cell `c`: the world's one where
    /// particles carry none (no array read, so no bounds check, in a build
    /// without masses).
    #[inline(always)]
    pub(crate) fn class(&self, sh: &Shared<'_>, c: usize) -> Class {
        if self.masses() {
            sh.class(self.mass_index[c])
        } else {
            sh.one
        }
    }
}

/// What every block of a step reads and none writes.
pub(crate) struct Shared<'a> {
    pub rules: StepRules<'a>,
    pub n: [usize; 3],
    pub part: Partition,
    /// The width of the world's stored velocities, which the pipeline with
    /// every part reads ([`AnyWidth`]); not with `small-step`, whose
    /// pipeline takes the width as a type.
    #[cfg(not(feature = "small-step"))]
    pub width: Width,
    pub key: StepKey,
    pub obstacle: &'a [u64],
    pub surface: &'a [Surface],
    /// The mass classes in use in a world of masses, converted for this
    /// step (M1c); none in a world of one mass, which reads `one`.
    pub classes: &'a [Class],
    /// The class of every particle of a world of one mass (class 0 in a
    /// world of masses), where the plain instantiations read it without a
    /// bounds check.
    pub one: Class,
    pub terms: ForceTerms<'a>,
    /// The uniform force's velocity change per step in fine units (M1c's
    /// `G`), where it changes anything (the summed force path includes it
    /// in `terms`).
    pub push: Option<[i64; 3]>,
    /// `push` where every component is below `2^29`, so that a velocity
    /// and the push add up within the bound in 32 bits: what M5.1 adds
    /// where the force is uniform (a world whose push is larger is not
    /// plain).
    pub lean_push: Option<[i32; 3]>,
    /// M5.2's restitution in Q16 (M1c's `E`).
    pub restitution: i32,
    /// M5.7b's support, where it is on and the uniform push is not zero.
    pub rest: Option<crate::step::rest::Support>,
    /// M5.1b flow drag, where its rate is not 0.
    pub drag: Option<Flow<'a>>,
    /// The 8-bit move table of the drift rule (M5.3).
    pub moves: &'static [u16; 256],
    /// The high bytes of `moves`' entries, which M5.3 reads first for
    /// 8-bit velocities (`Kernel::crosses`; not built with `small-step`,
    /// which reads `moves` alone).
    #[cfg(not(feature = "small-step"))]
    pub tops: &'static [u8; 256],
    /// Forces other than a uniform one (fields, potentials, the vortex,
    /// drag) are summed per particle, where the pipeline has every part
    /// (`kernel::Every`).
    pub summed: bool,
    /// One mass, no lifetimes, no summed force: blocks away from the faces
    /// and without an obstacle take a plain instantiation of the pipeline
    /// (`kernel::Plain`, or lanes).
    pub plain: bool,
    /// `plain` without contacts (M5.7): what the lanes representation
    /// (`lanes::Lanes`) needs of the step, tested once a row.
    pub lanes: bool,
    /// The identity planes (M6b), which only the blocks with every part
    /// write: here rather than beside the other planes in [`Writable`],
    /// whose size the plain blocks' sweep feels. Not in a build without
    /// `identity` (firmware), whose setup would store it for nothing.
    #[cfg(feature = "identity")]
    pub identity: Identified<'a>,
    /// The bodies (M13): empty in a world without them.
    #[cfg(feature = "obstacles")]
    pub bodies: Moving<'a>,
}

/// What the step reads of the bodies (M13), and the tallies its
/// reflections write, one per body surface entry: a block writes only the
/// entries of its own cells, so blocks on different threads never write
/// the same one.
#[cfg(feature = "obstacles")]
#[derive(Clone, Copy)]
pub(crate) struct Moving<'a> {
    pub surface: &'a [crate::rules::body::BodySurface],
    pub table: &'a [crate::rules::body::Body],
    pub tally: Cells<'a, crate::rules::body::Tally>,
}

/// The planes a step writes. Copies go to the tasks of a parallel step,
/// which write disjoint elements ([`Cells`]).
#[derive(Clone, Copy)]
pub(crate) struct Writable<'a, const D: usize> {
    pub occupancy: Cells<'a, u64>,
    pub rows: Cells<'a, u8>,
    pub words: Cells<'a, u64>,
    pub velocity: Velocity<'a, D>,
    pub mass_index: Cells<'a, u8>,
    pub life: Cells<'a, u16>,
}

/// The velocity plane, a cell's `D` components together, as the type the
/// world stores ([`Typed::plane`]): the plane of the other width is empty.
#[derive(Clone, Copy)]
pub(crate) struct Velocity<'a, const D: usize> {
    pub narrow: Cells<'a, [i8; D]>,
    #[cfg(feature = "q16")]
    pub wide: Cells<'a, [i16; D]>,
}

impl<'a, const D: usize> Velocity<'a, D> {
    /// The plane `bytes` of velocities of `width`.
    pub(crate) fn new(bytes: &'a mut [u8], width: Width) -> Self {
        if width.wide() {
            #[cfg(feature = "q16")]
            return Velocity { narrow: Cells::new(&mut []), wide: Cells::new(groups(view(bytes))) };
        }
        Velocity {
            narrow: Cells::new(groups(view(bytes))),
            #[cfg(feature = "q16")]
            wide: Cells::new(&mut []),
        }
    }
}

/// The identity planes a step writes (M6b, `step/identity.rs`), to
/// disjoint cells from each task as [`Writable`]'s; empty where the world
/// has none.
#[cfg(feature = "identity")]
#[derive(Clone, Copy)]
pub(crate) struct Identified<'a> {
    pub id: Cells<'a, u32>,
    pub age: Cells<'a, u32>,
    pub tag: Cells<'a, u8>,
}

/// A block's stored velocities (in quanta) as the pipeline holds them
/// (M5): per-cell arrays ([`Block`]) or, for the plain 2D block of 8-bit
/// velocities, one word of byte lanes
/// ([`Lanes`](crate::step::lanes::Lanes)). The stages read and write a
/// block through this alone, so each is written once for both.
pub(crate) trait Stored<const D: usize> {
    /// Cells holding a particle.
    fn occ(&self) -> u8;
    /// Cells whose velocity differs from what the plane holds.
    fn dirty(&self) -> u8;
    /// The stored velocity of the particle in cell `c`, in quanta.
    fn stored(&self, c: usize) -> [i32; D];
    /// Makes `q` (in quanta, within the stored range) the stored velocity of
    /// the particle in cell `c`: M1's result.
    fn put(&mut self, c: usize, q: [i32; D]);

    /// Component `i % D` of the stored velocity of cell `i / D`.
    #[inline(always)]
    fn component(&self, i: usize) -> i32 {
        self.stored(i / D)[i % D]
    }

    /// M5.3's first test, in 2D: bit `2c + k` set where cell `c` holds a
    /// particle whose component `k` points inward, across the block's
    /// middle (positive on the low side of the axis, negative on the high).
    #[inline(always)]
    fn inward(&self) -> u8 {
        let mut inward = 0u8;
        for c in cells_of(self.occ()) {
            inward |= inward_axes::<D>(self.stored(c), c) << (D * c);
        }
        inward
    }

    /// The velocity of the particle in cell `c` as stored, in fine units of
    /// `2^-fine` quanta (M1c).
    #[inline(always)]
    fn fine(&self, c: usize, fine: u32) -> [i32; 3] {
        let q = self.stored(c);
        let mut x = [0; 3];
        for k in 0..D {
            x[k] = q[k] << fine;
        }
        x
    }
}

/// The axes `k` (bit `k`) along which the particle in cell `c`, of stored
/// velocity `q`, points inward: towards +k from the low side of the block,
/// towards -k from the high (M5.3). Only such a move stays inside the
/// block.
#[inline(always)]
pub(crate) fn inward_axes<const D: usize>(q: [i32; D], c: usize) -> u8 {
    let mut inward = 0u8;
    for k in 0..D {
        let low = (c >> k) & 1 == 0;
        inward |= u8::from(if low { q[k] > 0 } else { q[k] < 0 }) << k;
    }
    inward
}

/// A block's particles as per-cell arrays: the representation of every
/// block but the plain 2D ones of 8-bit worlds.
pub(crate) struct Block<const D: usize, const CELLS: usize> {
    /// Cells holding a particle.
    pub(crate) occ: u8,
    /// Velocities as stored, in quanta; what an empty cell holds is never
    /// read.
    pub(crate) v: [[i32; D]; CELLS],
    /// Cells whose velocity differs from what the plane holds.
    pub(crate) dirty: u8,
}

impl<const D: usize, const CELLS: usize> Block<D, CELLS> {
    /// The block's stored velocities as per-cell arrays, read a block row
    /// (two neighbouring cells) at a time where the row does not wrap.
    #[inline(always)]
    pub(crate) fn load<Q: Quant>(velocity: Cells<'_, [Q; D]>, row: &BlockRow, xs: [usize; 2], occ: u8) -> Self {
        let mut b = Block { occ, v: [[0; D]; CELLS], dirty: 0 };
        // With `small-step` a cell at a time always: one loop, less flash.
        if !cfg!(feature = "small-step") && xs[1] == xs[0] + 1 {
            for r in 0..CELLS / 2 {
                if occ >> (2 * r) & 3 != 0 {
                    let at = xs[0] + row.cell[r];
                    let pair = velocity.pair(at);
                    b.v[2 * r] = ints(pair[0]);
                    b.v[2 * r + 1] = ints(pair[1]);
                }
            }
        } else {
            for c in cells_of(occ) {
                b.v[c] = ints(velocity.get(xs[c & 1] + row.cell[c >> 1]));
            }
        }
        b
    }
}

impl<const D: usize, const CELLS: usize> Stored<D> for Block<D, CELLS> {
    #[inline(always)]
    fn occ(&self) -> u8 {
        self.occ
    }

    #[inline(always)]
    fn dirty(&self) -> u8 {
        self.dirty
    }

    #[inline(always)]
    fn stored(&self, c: usize) -> [i32; D] {
        self.v[c]
    }

    #[inline(always)]
    fn put(&mut self, c: usize, q: [i32; D]) {
        self.v[c] = q;
        self.dirty |= 1 << c;
    }

    /// The default's value, read in place: through `stored` the cell's
    /// array is copied first, which takes more flash in the firmware.
    #[inline(always)]
    fn component(&self, i: usize) -> i32 {
        self.v[i / D][i % D]
    }
}

/// Stored components as integers (quanta), component by component: an
/// array's `map` is a call at opt-level z.
#[inline(always)]
pub(crate) fn ints<Q: Quant, const D: usize>(q: [Q; D]) -> [i32; D] {
    let mut v = [0; D];
    for k in 0..D {
        v[k] = q[k].to_int();
    }
    v
}

/// The cells of a block mask (its set bits), lowest first.
#[inline]
pub(crate) fn cells_of(mask: u8) -> Bits {
    bits(mask)
}

/// Runs `$body` once for each cell of a block of `$cells` cells, with `$c`
/// bound to the cell's number as a constant: every index, side and table
/// entry derived from the cell folds at compile time, where a loop over the
/// cells would be left rolled.
macro_rules! each_cell {
    ($cells:expr, $c:ident => $body:block) => {{
        { let $c: usize = 0; $body }
        { let $c: usize = 1; $body }
        { let $c: usize = 2; $body }
        { let $c: usize = 3; $body }
        if $cells > 4 {
            { let $c: usize = 4; $body }
            { let $c: usize = 5; $body }
            { let $c: usize = 6; $body }
            { let $c: usize = 7; $body }
        }
    }};
}
pub(crate) use each_cell;

/// Runs `$body` for each cell `$c` set in `$occ` (of a block of `$cells`
/// cells): unrolled as [`each_cell`] where `$unroll`, else a loop over the
/// set cells, which is a little slower and far smaller.
macro_rules! each_occupied {
    ($unroll:expr, $cells:expr, $occ:expr, $c:ident => $body:block) => {{
        if $unroll {
            $crate::step::block::each_cell!($cells, $c => {
                if $occ >> $c & 1 != 0 $body
            });
        } else {
            for $c in $crate::step::block::cells_of($occ) $body
        }
    }};
}
pub(crate) use each_occupied;
