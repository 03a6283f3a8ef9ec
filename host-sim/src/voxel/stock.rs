//! The workpiece: a voxel grid stored as dexels (run-length z-columns).
//!
//! # Design
//! A voxel is a cube of edge `m`; voxel `(ix, iy, k)` has its centre at
//! `origin + ((ix + 0.5) m, (iy + 0.5) m, (k + 0.5) m)` and is either material or air.
//! Each XY cell holds its column of voxels as a sorted list of occupied intervals
//! `[lo, hi)` of voxel indices along z. This is the same set of voxels a 3-D bit grid holds
//! (paper 004 counts removed voxels; so does this), but a block costs one interval per
//! column, and removing a slab from a column is a comparison of two intervals instead of
//! a walk over its bits.
//!
//! A column keeps up to two intervals inline in 8 bytes (`[u16; 4]`): a block has one, and
//! while a helical flute cuts a column the slabs below the cut are gone before those above
//! (helix lag), which leaves a second interval for a step or two. A third interval (rare:
//! runout, odd toolpaths) moves the column to an overflow map. 200 x 150 mm at 0.09 mm is
//! 3.7e6 columns, 30 MB.
//!
//! The z index is a `u16`: a column may be at most 65534 voxels tall (5.9 m at 0.09 mm).

use anyhow::{bail, Result};
use std::collections::HashMap;

/// Marks a column whose intervals live in the overflow map (`a = [OVF, 0]`: `lo > hi`,
/// which no real interval has).
const OVF: u16 = u16::MAX;
/// Largest number of voxels along z (`OVF` must never be a valid bound).
pub const MAX_NZ: usize = (u16::MAX - 1) as usize;

/// Up to two occupied intervals `a` below `b`; an empty interval is `[0, 0]` and `a` is
/// empty only if `b` is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Column {
    a: [u16; 2],
    b: [u16; 2],
}

const EMPTY: [u16; 2] = [0, 0];

/// What one `subtract` removed: `n` voxels, the lowest at `lo`, the highest at `hi - 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Removed {
    /// Voxels removed.
    pub n: u32,
    /// Lowest removed voxel index (valid if `n > 0`).
    pub lo: u16,
    /// One above the highest removed voxel index (valid if `n > 0`).
    pub hi: u16,
}

impl Removed {
    const NONE: Removed = Removed { n: 0, lo: 0, hi: 0 };
}

/// A block of stock on a voxel grid.
pub struct Stock {
    origin: [f64; 3],
    voxel_mm: f64,
    nx: usize,
    ny: usize,
    nz: usize,
    cols: Vec<Column>,
    overflow: HashMap<u32, Vec<[u16; 2]>>,
}

impl Stock {
    /// A full block from corner `min` to corner `max` [mm] in voxels of `voxel_mm`. The
    /// grid covers the block with whole voxels (the far faces round to the nearest voxel).
    pub fn block(min: [f64; 3], max: [f64; 3], voxel_mm: f64) -> Result<Stock> {
        if !(voxel_mm.is_finite() && voxel_mm > 0.0) {
            bail!("voxel size must be a positive number of mm, got {voxel_mm}");
        }
        let mut n = [0usize; 3];
        for (axis, name) in ["x", "y", "z"].iter().enumerate() {
            let len = max[axis] - min[axis];
            if !(min[axis].is_finite() && max[axis].is_finite()) || len <= 0.0 {
                bail!(
                    "stock: {name}1 must be greater than {name}0 (got {} .. {})",
                    min[axis],
                    max[axis]
                );
            }
            let cells = (len / voxel_mm).round();
            if cells < 1.0 {
                bail!("stock: {name} extent {len} mm is less than one voxel of {voxel_mm} mm");
            }
            n[axis] = cells as usize;
        }
        if n[2] > MAX_NZ {
            bail!(
                "stock: {} voxels along z, at most {MAX_NZ} (use a larger voxel)",
                n[2]
            );
        }
        let count = n[0].checked_mul(n[1]).filter(|&c| c <= u32::MAX as usize);
        let Some(count) = count else {
            bail!("stock: {} x {} columns is too many", n[0], n[1]);
        };
        let full = Column {
            a: [0, n[2] as u16],
            b: EMPTY,
        };
        let mut cols = Vec::new();
        if cols.try_reserve_exact(count).is_err() {
            bail!(
                "stock: cannot allocate {} MB for {} x {} columns",
                (count * std::mem::size_of::<Column>()) >> 20,
                n[0],
                n[1]
            );
        }
        cols.resize(count, full);
        Ok(Stock {
            origin: min,
            voxel_mm,
            nx: n[0],
            ny: n[1],
            nz: n[2],
            cols,
            overflow: HashMap::new(),
        })
    }

    /// Voxel edge length [mm].
    #[inline]
    pub fn voxel_mm(&self) -> f64 {
        self.voxel_mm
    }

    /// Grid corner (the block's minimum corner) [mm].
    #[inline]
    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }

    /// Cells along x, y, z.
    #[inline]
    pub fn dims(&self) -> [usize; 3] {
        [self.nx, self.ny, self.nz]
    }

    /// z of the grid's top face [mm].
    #[inline]
    pub fn z_top(&self) -> f64 {
        self.origin[2] + self.nz as f64 * self.voxel_mm
    }

    /// Index of the first voxel whose centre is at or above `z` (clamped to `0..=nz`):
    /// the voxels with centres in `[za, zb)` are `z_index(za)..z_index(zb)`.
    #[inline]
    pub fn z_index(&self, z: f64) -> u16 {
        // ceil without the libm call (see sim.rs `fast_ceil`); clamped first so the cast
        // cannot overflow.
        let x = ((z - self.origin[2]) / self.voxel_mm - 0.5).clamp(-1.0, self.nz as f64);
        let t = x as i64;
        let k = if (t as f64) < x { t + 1 } else { t };
        k.clamp(0, self.nz as i64) as u16
    }

    /// Centre of cell `i` along `axis` [mm].
    #[inline]
    pub fn cell_centre(&self, axis: usize, i: usize) -> f64 {
        self.origin[axis] + (i as f64 + 0.5) * self.voxel_mm
    }

    /// Flat index of column `(ix, iy)`.
    #[inline]
    pub fn col_index(&self, ix: usize, iy: usize) -> usize {
        iy * self.nx + ix
    }

    /// Removes the voxels `[k0, k1)` of column `idx`; returns what was there.
    #[inline]
    pub fn subtract(&mut self, idx: usize, k0: u16, k1: u16) -> Removed {
        let c = &mut self.cols[idx];
        if c.b == EMPTY && c.a[0] != OVF {
            // One interval (or none): the case of nearly every call.
            let [lo, hi] = c.a;
            let s = lo.max(k0);
            let e = hi.min(k1);
            if s >= e {
                return Removed::NONE;
            }
            match (lo < s, e < hi) {
                (false, false) => c.a = EMPTY,
                (true, false) => c.a[1] = s,
                (false, true) => c.a[0] = e,
                (true, true) => {
                    c.a = [lo, s];
                    c.b = [e, hi];
                }
            }
            return Removed {
                n: u32::from(e - s),
                lo: s,
                hi: e,
            };
        }
        self.subtract_general(idx, k0, k1)
    }

    /// `subtract` for a column with two intervals or in the overflow map.
    fn subtract_general(&mut self, idx: usize, k0: u16, k1: u16) -> Removed {
        let c = self.cols[idx];
        if c.a[0] != OVF {
            // Two inline intervals (the second one left by helix lag): no allocation.
            let mut kept = [EMPTY; 4];
            let mut n_kept = 0;
            let out = cut(&[c.a, c.b], k0, k1, |iv| {
                kept[n_kept] = iv;
                n_kept += 1;
            });
            if out.n > 0 {
                self.store(idx, &kept[..n_kept]);
            }
            return out;
        }
        let ivs = self.intervals(idx);
        let mut kept = Vec::with_capacity(ivs.len() + 1);
        let out = cut(&ivs, k0, k1, |iv| kept.push(iv));
        if out.n > 0 {
            self.store(idx, &kept);
        }
        out
    }

    /// The occupied intervals of column `idx`, bottom up.
    fn intervals(&self, idx: usize) -> Vec<[u16; 2]> {
        let c = self.cols[idx];
        if c.a[0] == OVF {
            return self
                .overflow
                .get(&(idx as u32))
                .cloned()
                .unwrap_or_default();
        }
        [c.a, c.b].into_iter().filter(|iv| iv[0] < iv[1]).collect()
    }

    /// Stores `ivs` (sorted, disjoint, non-empty) as column `idx`.
    fn store(&mut self, idx: usize, ivs: &[[u16; 2]]) {
        let c = &mut self.cols[idx];
        if c.a[0] == OVF && ivs.len() <= 2 {
            self.overflow.remove(&(idx as u32));
        }
        match ivs.len() {
            0 => *c = Column { a: EMPTY, b: EMPTY },
            1 => {
                *c = Column {
                    a: ivs[0],
                    b: EMPTY,
                }
            }
            2 => {
                *c = Column {
                    a: ivs[0],
                    b: ivs[1],
                }
            }
            _ => {
                *c = Column {
                    a: [OVF, 0],
                    b: EMPTY,
                };
                self.overflow.insert(idx as u32, ivs.to_vec());
            }
        }
    }

    /// Whether column `idx` has material anywhere in `[k0, k1)`.
    #[inline]
    pub fn occupied_in(&self, idx: usize, k0: u16, k1: u16) -> bool {
        let c = self.cols[idx];
        let hit = |iv: [u16; 2]| iv[0].max(k0) < iv[1].min(k1);
        if c.a[0] == OVF {
            return self
                .overflow
                .get(&(idx as u32))
                .is_some_and(|v| v.iter().any(|&iv| hit(iv)));
        }
        hit(c.a) || hit(c.b)
    }

    /// One above the highest material voxel of column `(ix, iy)`, 0 if the column is empty.
    pub fn top(&self, ix: usize, iy: usize) -> u16 {
        let idx = self.col_index(ix, iy);
        self.intervals(idx).last().map_or(0, |iv| iv[1])
    }

    /// Material voxels in the whole stock (walks every column: for tests and summaries).
    pub fn count_voxels(&self) -> u64 {
        (0..self.cols.len())
            .map(|i| {
                self.intervals(i)
                    .iter()
                    .map(|iv| u64::from(iv[1] - iv[0]))
                    .sum::<u64>()
            })
            .sum()
    }

    /// Columns stored in the overflow map (more than two intervals).
    pub fn overflow_columns(&self) -> usize {
        self.overflow.len()
    }

    /// Bytes held by the column array and the overflow map (approximately).
    pub fn memory_bytes(&self) -> usize {
        self.cols.len() * std::mem::size_of::<Column>()
            + self
                .overflow
                .values()
                .map(|v| 32 + v.len() * 4)
                .sum::<usize>()
    }
}

/// Removes `[k0, k1)` from the sorted intervals `ivs` (empty ones skipped), passing what is
/// kept, in order, to `keep`; returns what was removed.
#[inline]
fn cut(ivs: &[[u16; 2]], k0: u16, k1: u16, mut keep: impl FnMut([u16; 2])) -> Removed {
    let mut out = Removed::NONE;
    for &[lo, hi] in ivs {
        if lo >= hi {
            continue;
        }
        let s = lo.max(k0);
        let e = hi.min(k1);
        if s >= e {
            keep([lo, hi]);
            continue;
        }
        if out.n == 0 {
            out.lo = s;
        }
        out.n += u32::from(e - s);
        out.hi = e;
        if lo < s {
            keep([lo, s]);
        }
        if e < hi {
            keep([e, hi]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_column(nz: f64) -> Stock {
        Stock::block([0.0; 3], [1.0, 1.0, nz], 1.0).expect("block")
    }

    #[test]
    fn subtract_every_case_and_count() {
        let mut s = one_column(20.0);
        assert_eq!(s.count_voxels(), 20);
        // Interior slab: splits into two intervals.
        assert_eq!(s.subtract(0, 5, 8), Removed { n: 3, lo: 5, hi: 8 });
        assert_eq!(s.intervals(0), vec![[0, 5], [8, 20]]);
        // Again: nothing left there.
        assert_eq!(s.subtract(0, 5, 8).n, 0);
        // A third interval goes to the overflow map and back.
        assert_eq!(s.subtract(0, 12, 14).n, 2);
        assert_eq!(s.intervals(0), vec![[0, 5], [8, 12], [14, 20]]);
        assert_eq!(s.overflow_columns(), 1);
        assert!(s.occupied_in(0, 13, 15));
        assert!(!s.occupied_in(0, 12, 14));
        // Spanning two intervals and the gap between them.
        assert_eq!(
            s.subtract(0, 10, 16),
            Removed {
                n: 4,
                lo: 10,
                hi: 16
            }
        );
        assert_eq!(s.intervals(0), vec![[0, 5], [8, 10], [16, 20]]);
        assert_eq!(s.subtract(0, 0, 9).n, 6);
        assert_eq!(s.intervals(0), vec![[9, 10], [16, 20]]);
        assert_eq!(s.overflow_columns(), 0);
        assert_eq!(s.top(0, 0), 20);
        assert_eq!(s.subtract(0, 0, 20).n, 5);
        assert_eq!(s.count_voxels(), 0);
        assert_eq!(s.top(0, 0), 0);
        assert_eq!(s.subtract(0, 0, 20).n, 0);
    }

    #[test]
    fn z_index_takes_voxel_centres() {
        let s = Stock::block([0.0, 0.0, -2.0], [1.0, 1.0, 0.0], 0.5).expect("block");
        // Centres at -1.75, -1.25, -0.75, -0.25.
        assert_eq!(s.z_index(-2.0), 0);
        assert_eq!(s.z_index(-1.75), 0);
        assert_eq!(s.z_index(-1.7), 1);
        assert_eq!(s.z_index(-0.25), 3);
        assert_eq!(s.z_index(5.0), 4);
        assert_eq!(s.z_index(-9.0), 0);
    }

    #[test]
    fn bad_blocks_are_refused() {
        assert!(Stock::block([0.0; 3], [1.0, 1.0, 1.0], 0.0).is_err());
        assert!(Stock::block([0.0; 3], [-1.0, 1.0, 1.0], 0.1).is_err());
        assert!(Stock::block([0.0; 3], [1.0, 1.0, f64::NAN], 0.1).is_err());
        assert!(Stock::block([0.0; 3], [1.0, 1.0, 1e5], 0.1).is_err());
    }
}
