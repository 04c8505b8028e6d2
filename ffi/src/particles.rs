//! Particles: adding, removing, reading cells, and export into caller arrays
//! for vertex buffers and textures.

use mpca_core::{Cell, Particle, World};

use crate::snapshot::overlap;
use crate::{check_size, guard, mpca_status, mpca_world, Call, Refusal};

/// One particle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct mpca_particle {
    /// Cell coordinates; the third is 0 in 2D.
    pub pos: [u32; 3],
    /// Velocity in cells per step; the third is 0 in 2D.
    pub velocity: [f32; 3],
    /// Mass.
    pub mass: f32,
    /// Steps left to live, 0 for no limit.
    pub life: u32,
    /// Its id, unique in the world's life, from 1 (M6b); 0 in a world
    /// without MPCA_IDENTITY_IDS.
    pub id: u32,
    /// The steps it has taken part in; 0 without MPCA_IDENTITY_AGES.
    pub age: u32,
    /// The caller's tag, 0 to 255; 0 without MPCA_IDENTITY_TAGS.
    pub tag: u32,
}

/// What a cell holds. Values of `mpca_cell.kind`.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_cell_kind {
    /// Nothing.
    Empty = 0,
    /// A particle, described in `mpca_cell.particle`.
    Particle = 1,
    /// An obstacle.
    Obstacle = 2,
}

/// One cell.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct mpca_cell {
    /// An `mpca_cell_kind` value.
    pub kind: u32,
    /// The particle, when `kind` is MPCA_CELL_KIND_PARTICLE; zero otherwise.
    pub particle: mpca_particle,
}

fn particle_to_c(p: Particle) -> mpca_particle {
    mpca_particle { pos: p.pos, velocity: p.velocity, mass: p.mass, life: u32::from(p.life), id: p.id, age: p.age, tag: u32::from(p.tag) }
}

/// Adds a particle of the world's mass at `pos` (3 values) with velocity
/// `velocity` (3 values; the third is ignored in 2D), stored rounded to
/// nearest. Accepted: components in [-1, 1] that round to a velocity the
/// step itself can store, one within a quantum per axis (1/127 at 8 bits)
/// of a velocity of length at most 1. That is every |v| <= 1 and every
/// velocity mpca_world_cell and the exports report, so a world can be
/// rebuilt from its own export; anything else is `MPCA_STATUS_SPEED_RANGE`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_particle(world: *mut mpca_world, pos: *const u32, velocity: *const f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let (pos, v) = (c.array(pos)?, c.array(velocity)?);
        Ok(w.add_particle(pos, v)?)
    })
}

/// Adds a particle of mass `mass` (velocity as for mpca_world_add_particle);
/// worlds without per-particle masses accept only their own mass.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_particle_mass(
    world: *mut mpca_world,
    pos: *const u32,
    velocity: *const f32,
    mass: f32,
) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let (pos, v) = (c.array(pos)?, c.array(velocity)?);
        Ok(w.add_particle_with_mass(pos, v, mass)?)
    })
}

/// Removes the particle at `pos`, writing it to `out` (which may not be
/// NULL).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_remove_particle(world: *mut mpca_world, pos: *const u32, out: *mut mpca_particle) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let pos = c.array(pos)?;
        let out = c.out(out)?;
        out.set(particle_to_c(w.remove_particle(pos)?));
        Ok(())
    })
}

/// Gives the particle at `pos` the tag `tag`, at most 255 (M6b). Needs a
/// world with MPCA_IDENTITY_TAGS.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_tag(world: *mut mpca_world, pos: *const u32, tag: u32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let pos = c.array(pos)?;
        let tag = u8::try_from(tag).map_err(|_| mpca_status::TagRange)?;
        Ok(w.set_tag(pos, tag)?)
    })
}

/// What the cell at `pos` holds.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_cell(world: *const mpca_world, pos: *const u32, out: *mut mpca_cell) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let pos = c.array(pos)?;
        let out = c.out(out)?;
        out.set(match w.cell(pos)? {
            Cell::Empty => mpca_cell { kind: mpca_cell_kind::Empty as u32, ..Default::default() },
            Cell::Obstacle => mpca_cell { kind: mpca_cell_kind::Obstacle as u32, ..Default::default() },
            Cell::Particle(p) => mpca_cell { kind: mpca_cell_kind::Particle as u32, particle: particle_to_c(p) },
        });
        Ok(())
    })
}

/// The number of particles now.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_particle_count(world: *const mpca_world, out_count: *mut usize) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        c.out(out_count)?.set(w.particle_count() as usize);
        Ok(())
    })
}

/// Writes `per` floats of each particle, in cell order, into `out`, which
/// has room for `capacity` particles; the particle count goes to
/// `out_count`. Too small a buffer writes nothing but the count. `out`
/// NULL with `capacity` 0 asks for the count alone (the size query every
/// export of the header answers); NULL with room claimed is refused.
/// The body of the three exports below, inside their `guard`.
fn export(
    c: &Call<'_>,
    world: *const mpca_world,
    out: *mut f32,
    capacity: usize,
    out_count: *mut usize,
    per: usize,
    put: impl Fn(&Particle, &mut [f32]),
) -> Result<(), Refusal> {
    let w = c.world_ref(world)?;
    let Some(n) = counted(c, w, !out.is_null(), capacity, out_count)? else {
        return Ok(()); // the size query
    };
    let floats = n.checked_mul(per).ok_or(mpca_status::OutputTooSmall)?;
    let dst = c.slice_mut(out, floats, mpca_status::OutputTooSmall)?;
    for (p, chunk) in w.particles().zip(dst.chunks_exact_mut(per)) {
        put(&p, chunk);
    }
    Ok(())
}

/// What every export does before it writes: the particle count to
/// `out_count`, and `Some` of it where there is somewhere to write
/// (`has_output`) with room for it; `None` for the size query (nowhere to
/// write, `capacity` 0); NULL with room claimed refused before the count
/// is written, a capacity below the count after.
fn counted(c: &Call<'_>, w: &World, has_output: bool, capacity: usize, out_count: *mut usize) -> Result<Option<usize>, Refusal> {
    let count = c.out(out_count)?;
    if !has_output && capacity != 0 {
        return Err(Refusal::new(mpca_status::NullPointer, c"out (NULL, capacity not 0)"));
    }
    let n = w.particle_count() as usize;
    count.set(n);
    if !has_output {
        return Ok(None);
    }
    if capacity < n {
        return Err(Refusal::new(mpca_status::OutputTooSmall, c"capacity"));
    }
    Ok(Some(n))
}

/// Particle positions as 3 floats each (cell centres: x + 0.5, y + 0.5,
/// z + 0.5; z is 0.5 in 2D), ready for a vertex buffer. `capacity` counts
/// particles (the buffer holds 3 * capacity floats); the particle count
/// goes to `out_count`.
///
/// Size query: `out` NULL with `capacity` 0 writes the count and returns
/// `MPCA_STATUS_OK`; call again with a buffer that large. A buffer too
/// small (capacity 0 included) returns `MPCA_STATUS_OUTPUT_TOO_SMALL`,
/// writing the count and nothing else; NULL with a capacity above 0 is
/// `MPCA_STATUS_NULL_POINTER`. The same holds for every export with an
/// `out_count`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_export_positions(
    world: *const mpca_world,
    out: *mut f32,
    capacity: usize,
    out_count: *mut usize,
) -> mpca_status {
    guard(|c| export(c, world, out, capacity, out_count, 3, |p, o| o.copy_from_slice(&p.pos.map(|x| x as f32 + 0.5))))
}

/// Particle velocities as 3 floats each, in the order of
/// mpca_world_export_positions; buffer, count and size query as there.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_export_velocities(
    world: *const mpca_world,
    out: *mut f32,
    capacity: usize,
    out_count: *mut usize,
) -> mpca_status {
    guard(|c| export(c, world, out, capacity, out_count, 3, |p, o| o.copy_from_slice(&p.velocity)))
}

/// Particle masses, one float each, in the order of
/// mpca_world_export_positions; buffer, count and size query as there.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_export_masses(
    world: *const mpca_world,
    out: *mut f32,
    capacity: usize,
    out_count: *mut usize,
) -> mpca_status {
    guard(|c| export(c, world, out, capacity, out_count, 1, |p, o| o[0] = p.mass))
}

/// Where mpca_world_export_particles writes, a column per quantity: each
/// NULL or an array with room for `capacity` particles. Set `struct_size`
/// to `sizeof(mpca_particle_columns)`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct mpca_particle_columns {
    /// `sizeof(mpca_particle_columns)`.
    pub struct_size: u32,
    /// 0: room a later version may give a meaning (no padding before the
    /// pointers). Anything else is refused with MPCA_STATUS_BAD_ENUM.
    pub reserved: u32,
    /// 3 floats a particle: the cell's centre, as
    /// mpca_world_export_positions writes.
    pub positions: *mut f32,
    /// 3 floats a particle: the velocity in cells per step.
    pub velocities: *mut f32,
    /// One a particle: its id (needs MPCA_IDENTITY_IDS).
    pub ids: *mut u32,
    /// One a particle: its age in steps (needs MPCA_IDENTITY_AGES).
    pub ages: *mut u32,
    /// One a particle: its tag (needs MPCA_IDENTITY_TAGS).
    pub tags: *mut u8,
}

/// Writes every particle, in cell order (the order of every export), into
/// the columns of `columns` that are not NULL, in one pass: entry `i` of
/// each column is the same particle, so that an engine can match ids,
/// ages and tags (M6b) to positions and velocities. `capacity` counts
/// particles; the count goes to `out_count`, with the size query and the
/// refusals of mpca_world_export_positions (every column NULL and
/// `capacity` 0 asks for the count alone). A column of a plane the world
/// does not keep is refused with MPCA_STATUS_NOT_ENABLED before anything
/// is written.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_export_particles(
    world: *const mpca_world,
    columns: *const mpca_particle_columns,
    capacity: usize,
    out_count: *mut usize,
) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let cols = c.get(columns)?;
        check_size::<mpca_particle_columns>(cols.struct_size, c"columns.struct_size")?;
        if cols.reserved != 0 {
            return Err(Refusal::new(mpca_status::BadEnum, c"columns.reserved"));
        }
        let on = w.description().identity;
        let missing = |column_set: bool, kept: bool| column_set && !kept;
        if missing(!cols.ids.is_null(), on.ids()) || missing(!cols.ages.is_null(), on.ages()) || missing(!cols.tags.is_null(), on.tags()) {
            return Err(Refusal::new(mpca_status::NotEnabled, c"columns.ids, ages or tags"));
        }
        let some = !(cols.positions.is_null() && cols.velocities.is_null() && cols.ids.is_null() && cols.ages.is_null() && cols.tags.is_null());
        let Some(n) = counted(c, w, some, capacity, out_count)? else {
            return Ok(()); // the size query
        };
        let too_small = mpca_status::OutputTooSmall;
        let triples = n.checked_mul(3).ok_or(too_small)?;
        // Each column is its own array: two that share a byte are refused
        // before a slice is formed over either.
        let spans = [
            (cols.positions.cast::<u8>(), triples.saturating_mul(4)),
            (cols.velocities.cast::<u8>(), triples.saturating_mul(4)),
            (cols.ids.cast::<u8>(), n.saturating_mul(4)),
            (cols.ages.cast::<u8>(), n.saturating_mul(4)),
            (cols.tags, n),
        ];
        for (i, &(a, a_len)) in spans.iter().enumerate() {
            if spans[i + 1..].iter().any(|&(b, b_len)| overlap(a, a_len, b, b_len)) {
                return Err(Refusal::new(mpca_status::Overlap, c"columns (two overlap)"));
            }
        }
        let mut positions = c.slice_mut_or_null(cols.positions, triples, too_small)?;
        let mut velocities = c.slice_mut_or_null(cols.velocities, triples, too_small)?;
        let mut ids = c.slice_mut_or_null(cols.ids, n, too_small)?;
        let mut ages = c.slice_mut_or_null(cols.ages, n, too_small)?;
        let mut tags = c.slice_mut_or_null(cols.tags, n, too_small)?;
        for (i, p) in w.particles().enumerate() {
            if let Some(out) = positions.as_deref_mut() {
                out[3 * i..3 * i + 3].copy_from_slice(&p.pos.map(|x| x as f32 + 0.5));
            }
            if let Some(out) = velocities.as_deref_mut() {
                out[3 * i..3 * i + 3].copy_from_slice(&p.velocity);
            }
            if let Some(out) = ids.as_deref_mut() {
                out[i] = p.id;
            }
            if let Some(out) = ages.as_deref_mut() {
                out[i] = p.age;
            }
            if let Some(out) = tags.as_deref_mut() {
                out[i] = p.tag;
            }
        }
        Ok(())
    })
}

/// The share of occupied cells in each of `res` (3 values; the third 1 in
/// 2D) bins per axis, x fastest, into `out` of `len` floats (the product of
/// `res`). With `res` equal to the world size this is the occupancy.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_density(world: *const mpca_world, res: *const u32, out: *mut f32, len: usize) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let res = c.array(res)?;
        let out = c.slice_mut(out, len, mpca_status::BadResolution)?;
        Ok(w.density(res, out)?)
    })
}

/// As mpca_world_density, scaled to 0..255 bytes for a texture upload.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_density_u8(world: *const mpca_world, res: *const u32, out: *mut u8, len: usize) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let res = c.array(res)?;
        let out = c.slice_mut(out, len, mpca_status::BadResolution)?;
        Ok(w.density_u8(res, out)?)
    })
}
