//! A hasher for the motion sweep's caches, keyed by a stretch's middle and half-width as `f64`
//! bits (and a target's index). The default SipHash cost 11 % of a motion check on the wall
//! benchmark: these keys are not chosen by an adversary, so FxHash's multiply-rotate mix per word
//! and MurmurHash3's finaliser do (a few nanoseconds a key).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// FxHash's mix over 64-bit words.
#[derive(Default, Clone, Copy)]
pub(super) struct StretchHasher(u64);

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl Hasher for StretchHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(SEED);
    }

    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        // The low bits of a product of dyadic fractions' bits are mostly zeros: MurmurHash3's
        // finaliser spreads the high bits, where the multiplication carried them, over all.
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}

/// A map keyed by stretches.
pub(super) type StretchMap<K, V> = HashMap<K, V, BuildHasherDefault<StretchHasher>>;

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::BuildHasher;

    /// The keys the sweep uses (dyadic midpoints and half-widths, target indices) spread over
    /// the buckets of a map of that size: no bucket of 4,096 holds more than a handful (with
    /// FxHash's own finish, 36 keys fell in one).
    #[test]
    fn dyadic_stretch_keys_spread() {
        let build = BuildHasherDefault::<StretchHasher>::default();
        let mut buckets = vec![0u32; 4096];
        let mut keys = 0;
        for depth in 1..=8u32 {
            let half = 0.5f64.powi(depth as i32 + 1);
            for k in 0..(1u32 << depth) {
                let mid = (2 * k + 1) as f64 * half;
                for ti in 0..8usize {
                    buckets[(build.hash_one((ti, mid.to_bits(), half.to_bits())) % 4096) as usize] += 1;
                    keys += 1;
                }
            }
        }
        let fullest = buckets.iter().copied().max().unwrap_or(0);
        eprintln!("{keys} keys, fullest bucket {fullest}");
        assert!(keys > 4000 && fullest <= 10, "{keys} keys, fullest bucket {fullest}");
    }
}
