//! Seeds of the independent random streams of one trial.
//!
//! One trial seed (the scenario's `seed`) determines everything random in a flight. The world
//! layout, the obstacle maneuvers, the sensor noise and the planner each get their own stream,
//! derived by [`mix_seed`], so that a change in one (another planner drawing more samples) never
//! shifts the others: the same trial seed gives the same world, the same obstacle trajectories
//! and the same sensor noise whatever the planner does.

use serde::{Deserialize, Serialize};

/// SplitMix64's finalizer (Steele, Lea & Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014): a bijective 64-bit mix.
fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A seed for sub-stream `stream` of `seed`: distinct streams of one seed and the same stream of
/// distinct seeds give unrelated values (two rounds of SplitMix64). Portable and stable across
/// versions (the mix is written out here, not taken from a library).
pub fn mix_seed(seed: u64, stream: u64) -> u64 {
    splitmix64(splitmix64(seed) ^ splitmix64(stream.wrapping_add(0x5851_F42D_4C95_7F2D)))
}

/// The seeds of one trial's random streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Seeds {
    /// World generation (static layout, initial moving obstacles).
    pub world: u64,
    /// True obstacle maneuvers ([`crate::traffic::Traffic`]).
    pub traffic: u64,
    /// Sensor noise and dropouts ([`crate::sensing::Sensing`]).
    pub sensing: u64,
    /// The planner's own randomness (`ManagerParams::seed`, handed to the frontend).
    pub planner: u64,
}

impl Seeds {
    /// The streams of trial seed `seed`.
    pub fn from_trial(seed: u64) -> Self {
        Seeds {
            world: mix_seed(seed, 1),
            traffic: mix_seed(seed, 2),
            sensing: mix_seed(seed, 3),
            planner: mix_seed(seed, 4),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_differ_and_are_stable() {
        let s = Seeds::from_trial(7);
        let all = [s.world, s.traffic, s.sensing, s.planner];
        for i in 0..4 {
            for j in 0..i {
                assert_ne!(all[i], all[j]);
            }
        }
        assert_eq!(Seeds::from_trial(7), s);
        assert_ne!(Seeds::from_trial(8).world, s.world);
        assert_ne!(mix_seed(0, 0), mix_seed(0, 1));
    }
}
