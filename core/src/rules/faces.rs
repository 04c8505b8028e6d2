//! The faces of the domain (M4): what lies beyond each face of a world,
//! periodic, wall or open, for a cell coordinate that may be outside it.

use crate::api::desc::Boundary;

/// Where a cell coordinate lands under the boundary rules of M4.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Beyond {
    /// A cell of the domain, wrapped across periodic faces.
    Inside([usize; 3]),
    /// Beyond a wall: an obstacle whose inward normal is the sum of the
    /// walls' axis normals, given here by its signs (-1, 0 or 1 per axis:
    /// an axis or a diagonal, which M1c normalises by constants). A cell
    /// beyond both a wall and an open face is wall.
    Wall([i32; 3]),
    /// Beyond open faces only: a particle sent there leaves.
    Open,
}

/// A cell's coordinates, possibly beyond a face: signed machine words,
/// wide enough for the `-n <= c < 2n` that [`resolve`] takes. On 32-bit
/// cores `Layout::of` keeps a world's bytes below 2^30 and every cell holds
/// at least two bytes of velocity, so no axis reaches 2^29 cells and `2n`
/// fits an `i32`; 64-bit integers would be pairs of registers there, and
/// library calls.
pub(crate) type Coords = [isize; 3];

/// M4: what lies at the (possibly out-of-domain) cell coordinates `c` of a
/// domain of `n` cells per axis with faces `boundary`. Axes beyond the
/// world's dimension have `n = 1` and `c = 0`. Every caller asks for a
/// neighbour of a cell, so each coordinate lies within one domain length
/// of the domain (`-n <= c < 2n`): a periodic face wraps it with one add
/// (no 64-bit division, which small cores call a library routine for).
pub(crate) fn resolve(n: [usize; 3], boundary: &[[Boundary; 2]; 3], c: Coords) -> Beyond {
    let mut out = [0usize; 3];
    let mut wall = [0i32; 3];
    let (mut is_wall, mut is_open) = (false, false);
    for k in 0..3 {
        let nk = n[k] as isize;
        if (0..nk).contains(&c[k]) {
            out[k] = c[k] as usize;
            continue;
        }
        let high = c[k] >= nk;
        match boundary[k][usize::from(high)] {
            Boundary::Periodic => {
                debug_assert!((-nk..2 * nk).contains(&c[k]), "{c:?} beyond one domain length");
                out[k] = if high { c[k] - nk } else { c[k] + nk } as usize;
            }
            Boundary::Wall => {
                is_wall = true;
                wall[k] = if high { -1 } else { 1 };
            }
            Boundary::Open => is_open = true,
        }
    }
    if is_wall {
        Beyond::Wall(wall)
    } else if is_open {
        Beyond::Open
    } else {
        Beyond::Inside(out)
    }
}
