//! Adversarial input generation: ordinary values most of the time, the edges of `f64` and of
//! `usize` the rest.

use rand::{Rng as _, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_core::Vec3;

/// The edges of f64 every API must survive.
pub const SPECIAL: [f64; 26] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    f64::MIN_POSITIVE,
    1e-300,
    1e-12,
    1e-9,
    1.0,
    -1.0,
    0.5,
    1e6,
    -1e6,
    1e7,
    1e8,
    -1e8,
    1e155,
    -1e155,
    1e300,
    -1e300,
    f64::MAX,
    f64::MIN,
    1e-6,
];

/// Counts at the edges: empty, one, a few, huge.
pub const SPECIAL_COUNTS: [usize; 10] = [
    0,
    1,
    2,
    3,
    1_000,
    100_000,
    1_000_000,
    1_000_000_000,
    usize::MAX / 2,
    usize::MAX,
];

/// One case's random source.
pub struct Gen {
    rng: ChaCha8Rng,
    /// Probability of an adversarial value.
    p_special: f64,
}

impl Gen {
    /// A generator for one case.
    pub fn new(seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Some cases are entirely ordinary, some entirely hostile, most mixed.
        let p_special = [0.0, 0.05, 0.2, 0.5][rng.random_range(0..4)];
        Gen { rng, p_special }
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.rng.random_bool(p.clamp(0.0, 1.0))
    }

    fn special(&mut self) -> Option<f64> {
        if self.chance(self.p_special) {
            Some(SPECIAL[self.rng.random_range(0..SPECIAL.len())])
        } else {
            None
        }
    }

    /// Any value: ordinary in `[lo, hi)`, sometimes a power-of-ten magnitude, sometimes special.
    pub fn num(&mut self, lo: f64, hi: f64) -> f64 {
        if let Some(s) = self.special() {
            return s;
        }
        if self.chance(0.05) {
            let e = self.rng.random_range(-15..15);
            let sign = if self.chance(0.5) { 1.0 } else { -1.0 };
            return sign * 10f64.powi(e) * self.rng.random_range(1.0..10.0);
        }
        self.rng.random_range(lo..hi)
    }

    /// A coordinate (m).
    pub fn coord(&mut self) -> f64 {
        self.num(-25.0, 25.0)
    }

    /// A size (m), usually positive.
    pub fn size(&mut self) -> f64 {
        self.num(0.0, 3.0)
    }

    /// A time (s).
    pub fn time(&mut self) -> f64 {
        self.num(-1.0, 10.0)
    }

    /// A point.
    pub fn v3(&mut self) -> Vec3 {
        Vec3::new(self.coord(), self.coord(), self.coord())
    }

    /// A point inside `b` most of the time (adversarial otherwise).
    pub fn in_box(&mut self, b: &trust_core::Aabb) -> Vec3 {
        if self.chance(0.85) {
            let mut p = Vec3::zeros();
            for i in 0..3 {
                p[i] = self.rng.random_range(b.min[i]..=b.max[i]);
            }
            p
        } else {
            self.v3()
        }
    }

    /// A velocity.
    pub fn vel(&mut self) -> Vec3 {
        Vec3::new(
            self.num(-5.0, 5.0),
            self.num(-5.0, 5.0),
            self.num(-1.0, 1.0),
        )
    }

    /// A count below `ordinary_max` most of the time, an edge count otherwise.
    pub fn count(&mut self, ordinary_max: usize) -> usize {
        if self.chance(self.p_special) {
            SPECIAL_COUNTS[self.rng.random_range(0..SPECIAL_COUNTS.len())]
        } else {
            self.rng.random_range(0..=ordinary_max)
        }
    }

    /// A list of points: empty, one, repeated points, or a few random ones.
    pub fn points(&mut self, ordinary_max: usize) -> Vec<Vec3> {
        let n = self.rng.random_range(0..=ordinary_max);
        let mut out: Vec<Vec3> = Vec::with_capacity(n);
        for _ in 0..n {
            if !out.is_empty() && self.chance(0.1) {
                let i = self.rng.random_range(0..out.len());
                out.push(out[i]);
            } else {
                out.push(self.v3());
            }
        }
        out
    }

    /// An index in `0..n` (`n > 0`).
    pub fn index(&mut self, n: usize) -> usize {
        self.rng.random_range(0..n)
    }
}
