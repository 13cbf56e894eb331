//! What the rolling window saw before a voxel left it, kept so that the voxel comes back as it
//! left (decision 0053).
//!
//! The [`crate::LocalMap`] window is 4.8 m tall by default: a vehicle that climbs 2.5 m and comes
//! back down finds the space it saw below unknown again, and the commit check (only known free
//! space may be committed to) holds it in place until the camera sees that space anew, which a
//! forward camera never does straight above or below the body. [`Recall`] keeps each leaving
//! voxel's log-odds in blocks of [`RECALL_BLOCK`]³ voxels and hands it back when the voxel
//! re-enters. Memory stays bounded: at most the blocks asked for (the oldest block goes first;
//! [`SUGGESTED_RECALL_BLOCKS`] is 64 MiB); a voxel forgotten so comes back unknown, as without
//! the recall. Nothing is invented: a recalled voxel holds what the sensor reported of it.
//!
//! Off by default (`LocalMap::with_recall_blocks` turns it on): in flights with the 4.8 m
//! window it measured worse, not better (decision 0053).

use std::collections::{HashMap, VecDeque};
use std::hash::{BuildHasherDefault, Hasher};

use crate::traversal::VoxelKey;

/// Edge of a recall block, in voxels.
pub const RECALL_BLOCK: i64 = 8;

const BLOCK_VOXELS: usize = (RECALL_BLOCK * RECALL_BLOCK * RECALL_BLOCK) as usize;

/// A bound for an enabled recall: 32 768 blocks of 2 KiB (64 MiB, 16.8 M voxels: 16 800 m³ at
/// 0.1 m, the last 175 m of a 20 × 4.8 m window's trail).
pub const SUGGESTED_RECALL_BLOCKS: usize = 1 << 15;

/// Unknown in a block (a log-odds is always finite).
const NONE: f32 = f32::NAN;

/// A multiply-and-rotate hasher for block keys: the default SipHash costs more than the copy a
/// lookup serves.
#[derive(Default)]
pub(crate) struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(23) ^ v).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }

    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

type Block = Box<[f32; BLOCK_VOXELS]>;

/// Log-odds of the voxels that left the window (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Recall {
    blocks: HashMap<VoxelKey, Block, BuildHasherDefault<KeyHasher>>,
    /// Block keys in the order they were created (the oldest is forgotten first).
    order: VecDeque<VoxelKey>,
    max_blocks: usize,
}

/// The block of voxel `k` and the voxel's index in it.
#[inline]
fn split(k: &VoxelKey) -> (VoxelKey, usize) {
    let b = [
        k[0].div_euclid(RECALL_BLOCK),
        k[1].div_euclid(RECALL_BLOCK),
        k[2].div_euclid(RECALL_BLOCK),
    ];
    let i = k[0].rem_euclid(RECALL_BLOCK)
        + RECALL_BLOCK
            * (k[1].rem_euclid(RECALL_BLOCK) + RECALL_BLOCK * k[2].rem_euclid(RECALL_BLOCK));
    (b, i as usize)
}

impl Recall {
    /// An empty recall of at most `max_blocks` blocks (0 keeps nothing).
    pub fn new(max_blocks: usize) -> Self {
        Self {
            blocks: HashMap::default(),
            order: VecDeque::new(),
            max_blocks,
        }
    }

    /// Whether anything is kept (a bound above 0).
    pub fn is_on(&self) -> bool {
        self.max_blocks > 0
    }

    /// Blocks held.
    pub fn block_count(&self) -> usize {
        self.blocks.len()
    }

    /// Keeps voxel `k` as it leaves the window: its log-odds, or `None` if it was never
    /// observed (then a block is only written if it exists: an unobserved voxel in a new block
    /// is already unknown).
    #[inline]
    pub fn keep(&mut self, k: &VoxelKey, log_odds: Option<f32>) {
        let (b, i) = split(k);
        if let Some(block) = self.blocks.get_mut(&b) {
            block[i] = log_odds.unwrap_or(NONE);
            return;
        }
        let Some(value) = log_odds else {
            return;
        };
        if self.max_blocks == 0 {
            return;
        }
        if self.blocks.len() >= self.max_blocks
            && let Some(old) = self.order.pop_front()
        {
            self.blocks.remove(&old);
        }
        let mut block: Block = Box::new([NONE; BLOCK_VOXELS]);
        block[i] = value;
        self.blocks.insert(b, block);
        self.order.push_back(b);
    }

    /// The log-odds voxel `k` had when it last left the window, `None` if it was never kept
    /// (or was unobserved, or its block was forgotten).
    #[cfg(test)]
    pub fn recall(&self, k: &VoxelKey) -> Option<f32> {
        let (b, i) = split(k);
        let v = self.blocks.get(&b)?[i];
        (!v.is_nan()).then_some(v)
    }

    /// Every kept voxel in the box `[lo, hi]` (keys, inclusive), block by block:
    /// `f(key, log_odds)`.
    pub fn for_each_in(&self, lo: &VoxelKey, hi: &VoxelKey, mut f: impl FnMut(VoxelKey, f32)) {
        let (blo, _) = split(lo);
        let (bhi, _) = split(hi);
        let span: i64 = (0..3).map(|i| bhi[i] - blo[i] + 1).product();
        if span > 4 * self.blocks.len() as i64 {
            // Fewer blocks held than the box spans: visit the blocks.
            for (b, block) in &self.blocks {
                if (0..3).all(|i| b[i] >= blo[i] && b[i] <= bhi[i]) {
                    visit(b, block, lo, hi, &mut f);
                }
            }
            return;
        }
        for z in blo[2]..=bhi[2] {
            for y in blo[1]..=bhi[1] {
                for x in blo[0]..=bhi[0] {
                    let b = [x, y, z];
                    if let Some(block) = self.blocks.get(&b) {
                        visit(&b, block, lo, hi, &mut f);
                    }
                }
            }
        }
    }
}

/// The kept voxels of block `b` inside `[lo, hi]`.
fn visit(
    b: &VoxelKey,
    block: &Block,
    lo: &VoxelKey,
    hi: &VoxelKey,
    f: &mut impl FnMut(VoxelKey, f32),
) {
    for (i, v) in block.iter().enumerate() {
        if v.is_nan() {
            continue;
        }
        let i = i as i64;
        let k = [
            b[0] * RECALL_BLOCK + i % RECALL_BLOCK,
            b[1] * RECALL_BLOCK + (i / RECALL_BLOCK) % RECALL_BLOCK,
            b[2] * RECALL_BLOCK + i / (RECALL_BLOCK * RECALL_BLOCK),
        ];
        if (0..3).all(|a| k[a] >= lo[a] && k[a] <= hi[a]) {
            f(k, *v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kept_voxel_is_recalled_and_an_unobserved_one_is_not() {
        let mut r = Recall::new(4);
        let k = [-9, 17, 3];
        assert_eq!(r.recall(&k), None);
        r.keep(&k, Some(-0.4));
        assert_eq!(r.recall(&k), Some(-0.4));
        // Its neighbours in the block stay unknown.
        assert_eq!(r.recall(&[-10, 17, 3]), None);
        // Kept again as unobserved: unknown.
        r.keep(&k, None);
        assert_eq!(r.recall(&k), None);
        // An unobserved voxel creates no block.
        r.keep(&[100, 100, 100], None);
        assert_eq!(r.block_count(), 1);
    }

    #[test]
    fn the_oldest_block_is_forgotten_first_and_nothing_is_kept_without_room() {
        let mut r = Recall::new(2);
        r.keep(&[0, 0, 0], Some(1.0));
        r.keep(&[8, 0, 0], Some(2.0));
        r.keep(&[16, 0, 0], Some(3.0));
        assert_eq!(r.block_count(), 2);
        assert_eq!(r.recall(&[0, 0, 0]), None);
        assert_eq!(r.recall(&[8, 0, 0]), Some(2.0));
        assert_eq!(r.recall(&[16, 0, 0]), Some(3.0));
        let mut none = Recall::new(0);
        none.keep(&[0, 0, 0], Some(1.0));
        assert_eq!(none.recall(&[0, 0, 0]), None);
    }

    #[test]
    fn a_box_visits_exactly_its_kept_voxels() {
        let mut r = Recall::new(64);
        let kept: Vec<VoxelKey> = vec![[-1, -1, -1], [0, 0, 0], [7, 8, 9], [30, -20, 5]];
        for (n, k) in kept.iter().enumerate() {
            r.keep(k, Some(n as f32));
        }
        for (lo, hi) in [
            ([-1, -1, -1], [7, 8, 9]),
            ([-100, -100, -100], [100, 100, 100]),
        ] {
            let mut seen = Vec::new();
            r.for_each_in(&lo, &hi, |k, v| seen.push((k, v)));
            seen.sort_by_key(|a| a.0);
            let mut want: Vec<(VoxelKey, f32)> = kept
                .iter()
                .enumerate()
                .filter(|(_, k)| (0..3).all(|a| k[a] >= lo[a] && k[a] <= hi[a]))
                .map(|(n, k)| (*k, n as f32))
                .collect();
            want.sort_by_key(|a| a.0);
            assert_eq!(seen, want);
        }
    }
}
