//! Adding obstacles to a world (M7): cells, shapes and masks, their
//! surface entries kept sorted, and the checks that leave a world unchanged
//! when an addition is refused.

use crate::Error;
use crate::api::checks::{finite, restitution};
use crate::rules::faces::{resolve, Beyond};
use crate::rules::obstacle::{centre, in_plane, surface_at, Shape, Surface};
use crate::rules::vector::normalise;
use crate::storage::cells::Cells;
use crate::storage::layout::put_bit;
use crate::storage::world::World;

/// A set of cells, as a predicate on coordinates.
type Mask<'a> = &'a dyn Fn([usize; 3]) -> bool;

/// Gives a surface cell's outward normal, unnormalised, given the set of
/// cells that will be obstacles.
type NormalFn<'a> = &'a dyn Fn(&World, [usize; 3], Mask<'_>) -> [f32; 3];

impl World {
    /// The neighbour of `c` at offset `off`, after the boundary rules (M4).
    fn beyond(&self, c: [usize; 3], off: [i32; 3]) -> Beyond {
        let at = [0, 1, 2].map(|k| c[k] as isize + off[k] as isize);
        resolve(self.layout().n, &self.head.desc.boundary, at)
    }

    /// Whether the neighbour of `c` at `off` is free once the cells for which
    /// `obstacle` holds are obstacles: inside and not an obstacle, or beyond
    /// an open face.
    fn free_after(&self, c: [usize; 3], off: [i32; 3], obstacle: Mask<'_>) -> bool {
        match self.beyond(c, off) {
            Beyond::Inside(nb) => !obstacle(nb),
            Beyond::Wall(_) => false,
            Beyond::Open => true,
        }
    }

    /// Calls `f` with every offset of the `3^D - 1` neighbourhood.
    fn for_neighbours(&self, mut f: impl FnMut([i32; 3])) {
        let zr = if self.dim() == 3 { -1..=1 } else { 0..=0 };
        for dz in zr {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if (dx, dy, dz) != (0, 0, 0) {
                        f([dx, dy, dz]);
                    }
                }
            }
        }
    }

    /// Whether cell `c` has a free neighbour once the cells for which
    /// `obstacle` holds are obstacles.
    fn is_surface(&self, c: [usize; 3], obstacle: Mask<'_>) -> bool {
        let mut free = false;
        self.for_neighbours(|off| free |= self.free_after(c, off, obstacle));
        free
    }

    /// M7's normal for an arbitrary mask: the sum of the unit directions to
    /// the free neighbours (not normalised; zero where it is undefined).
    fn mask_normal(&self, c: [usize; 3], obstacle: Mask<'_>) -> [f32; 3] {
        let mut sum = [0.0f32; 3];
        self.for_neighbours(|off| {
            if self.free_after(c, off, obstacle) {
                let d = normalise(off.map(|o| o as f32)).unwrap_or([0.0; 3]);
                for k in 0..3 {
                    sum[k] += d[k];
                }
            }
        });
        sum
    }

    fn surfaces_used(&self) -> &[Surface] {
        &self.plane::<Surface>(self.layout().surface())[..self.head.surfaces as usize]
    }

    /// Inserts or replaces the entry of `entry.cell`; the caller checked that
    /// the table has room.
    fn put_surface(&mut self, entry: Surface) {
        let (head, p) = self.planes::<u8>();
        let used = head.surfaces as usize;
        match p.surface[..used].binary_search_by_key(&entry.cell, |t| t.cell) {
            Ok(i) => p.surface[i] = entry,
            Err(i) => {
                p.surface.copy_within(i..used, i + 1);
                p.surface[i] = entry;
                head.surfaces += 1;
            }
        }
    }

    fn drop_surface(&mut self, cell: u32) {
        let (head, p) = self.planes::<u8>();
        let used = head.surfaces as usize;
        if let Ok(i) = p.surface[..used].binary_search_by_key(&cell, |t| t.cell) {
            p.surface.copy_within(i + 1..used, i);
            head.surfaces -= 1;
        }
    }

    /// Adds the cells in `lo..hi` for which `inside` holds as obstacles of
    /// restitution `e`; `normal` gives each new surface cell's outward normal
    /// (normalised here), `from_mask` says it is M7's free-neighbour normal.
    ///
    /// Existing obstacle cells next to the new ones are kept up to date: an
    /// entry whose cell no longer has a free neighbour is dropped, and a
    /// free-neighbour normal is computed again. Two passes: the first checks
    /// everything against the obstacles as they will be, the second writes.
    fn add_obstacles(
        &mut self,
        lo: [usize; 3],
        hi: [usize; 3],
        e: f32,
        inside: Mask<'_>,
        normal: NormalFn<'_>,
        from_mask: bool,
    ) -> Result<(), Error> {
        if !self.head.desc.obstacles {
            return Err(Error::NotEnabled);
        }
        restitution(e)?;
        let l = *self.layout();
        let site = |c: [usize; 3]| l.site(c[0], c[1], c[2]);
        let each = |f: &mut dyn FnMut([usize; 3]) -> Result<(), Error>| -> Result<(), Error> {
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        if inside([x, y, z]) {
                            f([x, y, z])?;
                        }
                    }
                }
            }
            Ok(())
        };
        // Existing obstacle cells next to new cell `c`, outside the new set.
        let old_neighbours = |w: &World, c: [usize; 3], f: &mut dyn FnMut([usize; 3]) -> Result<(), Error>| {
            let mut result = Ok(());
            w.for_neighbours(|off| {
                if let (Ok(()), Beyond::Inside(nb)) = (result, w.beyond(c, off)) {
                    if w.is_obstacle(site(nb)) && !inside(nb) {
                        result = f(nb);
                    }
                }
            });
            result
        };

        // Pass 1: check, and count the entries to add.
        let mut new_entries = 0usize;
        {
            let w: &World = self;
            let after = |c: [usize; 3]| w.is_obstacle(site(c)) || inside(c);
            let table = w.surfaces_used();
            each(&mut |c| {
                if w.occupied(site(c)) {
                    return Err(Error::CellOccupied);
                }
                if w.is_surface(c, &after) {
                    normalise(normal(w, c, &after)).ok_or(Error::UndefinedNormal)?;
                    new_entries += usize::from(surface_at(table, site(c).cell as u32).is_none());
                }
                old_neighbours(w, c, &mut |nb| {
                    let old = surface_at(table, site(nb).cell as u32);
                    if old.is_some_and(|s| s.from_mask != 0) && w.is_surface(nb, &after) {
                        normalise(w.mask_normal(nb, &after)).ok_or(Error::UndefinedNormal)?;
                    }
                    Ok(())
                })
            })?;
        }
        let capacity = l.surface().len / core::mem::size_of::<Surface>();
        if self.head.surfaces as usize + new_entries > capacity {
            return Err(Error::SurfaceTableFull);
        }

        // Pass 2: the bits, then the entries, read off the plane as it now is.
        // Nothing here can fail: pass 1 checked every cell.
        each(&mut |c| {
            put_bit(Cells::new(self.planes::<u8>().1.obstacle), site(c).bit, true);
            Ok(())
        })?;
        each(&mut |c| {
            let w: &World = self;
            let plane = |q: [usize; 3]| w.is_obstacle(site(q));
            let cell = site(c).cell as u32;
            let entry = w
                .is_surface(c, &plane)
                .then(|| normalise(normal(w, c, &plane)))
                .flatten()
                .map(|n| Surface { cell, normal: n, restitution: e, from_mask: u32::from(from_mask) });
            match entry {
                Some(entry) => self.put_surface(entry),
                None => self.drop_surface(cell),
            }
            let mut stale = [[0usize; 3]; 26];
            let mut count = 0;
            let _ = old_neighbours(self, c, &mut |nb| {
                stale[count] = nb;
                count += 1;
                Ok(())
            });
            for &nb in &stale[..count] {
                let w: &World = self;
                let plane = |q: [usize; 3]| w.is_obstacle(site(q));
                let cell = site(nb).cell as u32;
                let Some(old) = surface_at(w.surfaces_used(), cell).copied() else { continue };
                if !w.is_surface(nb, &plane) {
                    self.drop_surface(cell);
                } else if old.from_mask != 0 {
                    if let Some(n) = normalise(w.mask_normal(nb, &plane)) {
                        self.put_surface(Surface { normal: n, ..old });
                    }
                }
            }
            Ok(())
        })
    }

    /// Makes one cell an obstacle with the given outward normal (normalised
    /// here) and restitution.
    pub fn add_obstacle(&mut self, pos: [u32; 3], normal: [f32; 3], e: f32) -> Result<(), Error> {
        self.locate(pos)?;
        finite(&normal)?;
        let nrm = in_plane(normal, self.dim());
        normalise(nrm).ok_or(Error::UndefinedNormal)?;
        let c = pos.map(|v| v as usize);
        self.add_obstacles(c, c.map(|v| v + 1), e, &|q| q == c, &|_, _, _| nrm, false)
    }

    /// Adds a shape's cells as obstacles with restitution `e`, normals from
    /// the shape's exact geometry (M7).
    pub fn add_shape(&mut self, shape: Shape, e: f32) -> Result<(), Error> {
        let dim = self.dim();
        shape.check(dim)?;
        let shape = shape.in_dim(dim);
        let (lo, hi) = shape.bounds(self.layout().n, dim);
        let normal = |_: &World, c, _: Mask<'_>| shape.normal(centre(c), dim);
        self.add_obstacles(lo, hi, e, &|c| shape.contains(centre(c), dim), &normal, false)
    }

    /// Adds every cell whose byte in `mask` (one per cell, x fastest) is not
    /// zero as an obstacle with restitution `e`. A surface cell's normal is
    /// the normalised sum of the unit directions to its free neighbours (M7);
    /// a mask where that sum vanishes for some surface cell (a wall one cell
    /// thick, say) is refused with `UndefinedNormal`.
    pub fn add_obstacle_mask(&mut self, mask: &[u8], e: f32) -> Result<(), Error> {
        let l = *self.layout();
        if mask.len() != l.cells {
            return Err(Error::BadLength);
        }
        let inside = |c: [usize; 3]| mask[l.site(c[0], c[1], c[2]).cell] != 0;
        let normal = |w: &World, c, obstacle: Mask<'_>| w.mask_normal(c, obstacle);
        self.add_obstacles([0; 3], l.n, e, &inside, &normal, true)
    }

    /// Whether `pos` is an obstacle (false outside the world).
    pub fn obstacle_at(&self, pos: [u32; 3]) -> bool {
        self.locate(pos).is_ok_and(|s| self.is_obstacle(s))
    }

    /// The surface entry of the obstacle at `pos`, if it is a surface cell.
    pub fn surface(&self, pos: [u32; 3]) -> Option<Surface> {
        let s = self.locate(pos).ok()?;
        let table: &[Surface] = self.plane(self.layout().surface());
        surface_at(&table[..self.head.surfaces as usize], s.cell as u32).copied()
    }
}
