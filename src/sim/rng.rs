//! Seeded random streams: one ChaCha stream per (scenario seed, run, lap, purpose).
//!
//! The 32-byte ChaCha key is the little-endian bytes of the four numbers, in that order:
//! `seed ‖ run ‖ lap ‖ purpose` (each as a `u64`). No hashing, no global or OS generator, so a
//! stream depends only on those four numbers: results are identical whatever the thread count
//! and whatever order runs are simulated in. Draws that belong to a run rather than a lap (the
//! laser's fixed per-beam angle errors) use lap [`RUN_WIDE`].

use rand::SeedableRng;
use rand_chacha::ChaCha12Rng;

/// The generator every simulated draw comes from.
pub type SimRng = ChaCha12Rng;

/// Lap number used for draws made once per run (per robot).
pub const RUN_WIDE: u64 = u64::MAX;

/// What a stream is used for; the value is part of the key, so never renumber these.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u64)]
pub enum Purpose {
    /// Door states of a lap under `doors_random`.
    Doors = 1,
    /// Pedestrian paths, phases and speeds of a lap.
    Pedestrians = 2,
    /// Laser range noise.
    LaserNoise = 3,
    /// Fixed per-beam angle errors (with lap [`RUN_WIDE`]).
    LaserAngles = 4,
    /// Odometry noise.
    Odometry = 5,
    /// The robot's sideways wander from the route in a lap.
    PathWander = 6,
    /// `placewords world generate` (with run and lap 0).
    WorldGenerator = 8,
    /// The lap's variation plan: lanes, speeds, stops, turns on the spot.
    LapVariation = 7,
}

/// The stream for (seed, run, lap, purpose).
pub fn stream(seed: u64, run: u64, lap: u64, purpose: Purpose) -> SimRng {
    let mut key = [0u8; 32];
    key[0..8].copy_from_slice(&seed.to_le_bytes());
    key[8..16].copy_from_slice(&run.to_le_bytes());
    key[16..24].copy_from_slice(&lap.to_le_bytes());
    key[24..32].copy_from_slice(&(purpose as u64).to_le_bytes());
    ChaCha12Rng::from_seed(key)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    #[test]
    fn streams_differ_by_every_key_part() {
        let base = stream(1, 2, 3, Purpose::Doors).next_u64();
        assert_eq!(base, stream(1, 2, 3, Purpose::Doors).next_u64());
        assert_ne!(base, stream(9, 2, 3, Purpose::Doors).next_u64());
        assert_ne!(base, stream(1, 9, 3, Purpose::Doors).next_u64());
        assert_ne!(base, stream(1, 2, 9, Purpose::Doors).next_u64());
        assert_ne!(base, stream(1, 2, 3, Purpose::Odometry).next_u64());
    }
}
