//! MIT-ACL's dynamic-forest benchmark (the obstacle field of MADER, PANTHER, DYNUS and SANDO):
//! a corridor from `(0, 0, 2)` to `(105, 0, 2)` among `N` obstacles, the first `int(0.65 N)` of
//! them 0.8 m cubes moving on trefoil knots, the rest static pillars and horizontal bars.
//!
//! Facts of record (read from mit-acl/sando, April 2026: `launch/dyn_obstacles.launch.py`,
//! `scripts/run_sim.py`, `scripts/run_benchmark.py`; summarized in `docs/dynamic-forest.md`):
//!
//! - each obstacle draws, in this order, `x0 ~ U[5, 100]`, `y0 ~ U[−6, 6]`, `z0 ~ U[0.5, 4.5]`
//!   ([`FOREST_RANGES`]); a moving one then draws `sx, sy, sz ~ U[2, 4]`, `offset ~ U[0, 3]`,
//!   `slower ~ U[4, 6]` and follows the trefoil knot of [`Trefoil::position`];
//! - of the `S` static ones, the first `ceil(0.35 S)` (index `< 0.35 S`) are 0.4 × 0.4 × 4 m
//!   pillars standing on the ground (centre height 2 m; their drawn `z0` is unused), the others
//!   0.4 (x) × 4 (y) × 0.4 (z) m bars centred at `(x0, y0, z0)` (the launch file's orientation;
//!   `run_sim.py` turns half of them along x, not done here).
//!
//! The draws follow those distributions from our own seeded stream (`trust_core::Rng`), not
//! Python's `random` stream: a seed gives the same world every time, but not the world the
//! peers' seed of the same number gives.

use std::f64::consts::TAU;

use rand::Rng as _;
use trust_core::{Rng, Vec3};

/// Side of a moving cube (m).
pub const CUBE_SIDE_M: f64 = 0.8;
/// Size of a static pillar, x × y × z (m); it stands on the ground `z = 0`.
pub const PILLAR_SIZE_M: [f64; 3] = [0.4, 0.4, 4.0];
/// Size of a static horizontal bar, x × y × z (m), long along y.
pub const BAR_SIZE_M: [f64; 3] = [0.4, 4.0, 0.4];
/// Fraction of the obstacles that move (the first `floor(0.65 N)`).
pub const MOVING_FRACTION: f64 = 0.65;
/// Fraction of the static obstacles that are pillars (the first `ceil(0.35 S)`).
pub const PILLAR_FRACTION: f64 = 0.35;

/// The uniform ranges of the draws, each `[lo, hi]` (drawn as `lo + (hi − lo) u`, `u ∈ [0, 1)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForestRanges {
    /// Centre x (m).
    pub x0_m: [f64; 2],
    /// Centre y (m).
    pub y0_m: [f64; 2],
    /// Centre z (m).
    pub z0_m: [f64; 2],
    /// Each of the trefoil's scales `sx`, `sy`, `sz` (m).
    pub scale_m: [f64; 2],
    /// The trefoil's phase `offset` (rad of the curve parameter).
    pub offset: [f64; 2],
    /// The trefoil's time scale `slower` (s per rad of the curve parameter).
    pub slower_s: [f64; 2],
}

/// The benchmark's ranges (`scripts/run_sim.py`: positions 5–100 × ±6 × 0.5–4.5 m, scales 2–4 m,
/// offset 0–3, slower 4–6).
pub const FOREST_RANGES: ForestRanges = ForestRanges {
    x0_m: [5.0, 100.0],
    y0_m: [-6.0, 6.0],
    z0_m: [0.5, 4.5],
    scale_m: [2.0, 4.0],
    offset: [0.0, 3.0],
    slower_s: [4.0, 6.0],
};

impl ForestRanges {
    /// The box every moving cube stays inside at all times (m): the centre ranges widened by the
    /// largest excursion of the knot (`|sin u + 2 sin 2u| ≤ 3` scaled by `s/6`, `|cos u −
    /// 2 cos 2u| ≤ 3` by `s/5`, `|sin 3u| ≤ 1` by `s/2`) and half a cube. For
    /// [`FOREST_RANGES`]: x 2.6–102.4, y −8.8–8.8, z −1.9–6.9 (the cubes pass through the
    /// ground and above the 6 m ceiling, as in the peers' simulation).
    pub fn reach(&self) -> (Vec3, Vec3) {
        let s = self.scale_m[1].max(0.0);
        let h = 0.5 * CUBE_SIDE_M;
        let ex = Vec3::new(s / 6.0 * 3.0 + h, s / 5.0 * 3.0 + h, s / 2.0 + h);
        (
            Vec3::new(self.x0_m[0], self.y0_m[0], self.z0_m[0]) - ex,
            Vec3::new(self.x0_m[1], self.y0_m[1], self.z0_m[1]) + ex,
        )
    }
}

/// A trefoil knot: with `u = t / slower + offset`,
/// `x = x0 + sx/6 (sin u + 2 sin 2u)`, `y = y0 + sy/5 (cos u − 2 cos 2u)`,
/// `z = z0 − sz/2 sin 3u`. Period `2π · slower`; as a Fourier curve in time
/// `p(t) = c + Σ a_k cos(k ω τ) + b_k sin(k ω τ)` with `ω = 1/slower` and `τ = t + offset ·
/// slower` ([`Trefoil::fourier`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trefoil {
    /// `(x0, y0, z0)` (m).
    pub center: Vec3,
    /// `(sx, sy, sz)` (m).
    pub scale: Vec3,
    /// `offset` (rad of the curve parameter).
    pub offset: f64,
    /// `slower` (s per rad), `> 0`.
    pub slower: f64,
}

/// A trefoil as Fourier coefficients: period, phase and the `cos` / `sin` coefficient vectors
/// of harmonics 1–3 (the fields of a scenario's `motion = { kind = "fourier", … }`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrefoilFourier {
    /// Period (s): `2π · slower`.
    pub period_s: f64,
    /// Time shift (s): `offset · slower`.
    pub phase_s: f64,
    /// Centre `(x0, y0, z0)`.
    pub center: [f64; 3],
    /// `a_1, a_2, a_3`.
    pub cos: [[f64; 3]; 3],
    /// `b_1, b_2, b_3`.
    pub sin: [[f64; 3]; 3],
}

impl Trefoil {
    fn u(&self, t: f64) -> f64 {
        t / self.slower + self.offset
    }

    /// Position at time `t` (s), the closed form.
    pub fn position(&self, t: f64) -> Vec3 {
        let u = self.u(t);
        let s = self.scale;
        self.center
            + Vec3::new(
                s.x / 6.0 * (u.sin() + 2.0 * (2.0 * u).sin()),
                s.y / 5.0 * (u.cos() - 2.0 * (2.0 * u).cos()),
                -s.z / 2.0 * (3.0 * u).sin(),
            )
    }

    /// Velocity at time `t` (m/s), the derivative of [`Trefoil::position`].
    pub fn velocity(&self, t: f64) -> Vec3 {
        let u = self.u(t);
        let s = self.scale;
        Vec3::new(
            s.x / 6.0 * (u.cos() + 4.0 * (2.0 * u).cos()),
            s.y / 5.0 * (-u.sin() + 4.0 * (2.0 * u).sin()),
            -1.5 * s.z * (3.0 * u).cos(),
        ) / self.slower
    }

    /// Period (s): `2π · slower`.
    pub fn period_s(&self) -> f64 {
        TAU * self.slower
    }

    /// The same curve as Fourier coefficients in time.
    pub fn fourier(&self) -> TrefoilFourier {
        let s = self.scale;
        TrefoilFourier {
            period_s: self.period_s(),
            phase_s: self.offset * self.slower,
            center: [self.center.x, self.center.y, self.center.z],
            cos: [
                [0.0, s.y / 5.0, 0.0],
                [0.0, -2.0 * s.y / 5.0, 0.0],
                [0.0, 0.0, 0.0],
            ],
            sin: [
                [s.x / 6.0, 0.0, 0.0],
                [2.0 * s.x / 6.0, 0.0, 0.0],
                [0.0, 0.0, -s.z / 2.0],
            ],
        }
    }
}

/// One obstacle of the forest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ForestObstacle {
    /// A [`CUBE_SIDE_M`] cube whose centre follows the knot.
    Moving(Trefoil),
    /// A [`PILLAR_SIZE_M`] pillar standing on the ground at `(x, y)`.
    Pillar {
        /// Centre x (m).
        x: f64,
        /// Centre y (m).
        y: f64,
    },
    /// A [`BAR_SIZE_M`] bar centred at `center`.
    Bar {
        /// Centre (m).
        center: Vec3,
    },
}

impl ForestObstacle {
    /// The static box `(min, max)` of a pillar or bar; `None` for a moving cube.
    pub fn static_box(&self) -> Option<(Vec3, Vec3)> {
        let (c, size) = match *self {
            ForestObstacle::Moving(_) => return None,
            ForestObstacle::Pillar { x, y } => {
                (Vec3::new(x, y, 0.5 * PILLAR_SIZE_M[2]), PILLAR_SIZE_M)
            }
            ForestObstacle::Bar { center } => (center, BAR_SIZE_M),
        };
        let h = Vec3::from(size) * 0.5;
        Some((c - h, c + h))
    }
}

/// How many of `n` obstacles move: `floor(0.65 n)`, in integers (`65 n / 100`).
pub fn moving_count(n: usize) -> usize {
    n.saturating_mul(65) / 100
}

/// How many of `s` static obstacles are pillars: those of index `< 0.35 s`, i.e. `ceil(0.35 s)`,
/// in integers (`(35 s + 99) / 100`).
pub fn pillar_count(s: usize) -> usize {
    s.saturating_mul(35).saturating_add(99) / 100
}

fn draw(rng: &mut Rng, [lo, hi]: [f64; 2]) -> f64 {
    lo + (hi - lo) * rng.random::<f64>()
}

/// The `n` obstacles of one forest, drawn from `rng` in the benchmark's order (module docs): the
/// first [`moving_count`] move, then [`pillar_count`] pillars, then bars.
pub fn generate(n: usize, ranges: &ForestRanges, rng: &mut Rng) -> Vec<ForestObstacle> {
    let moving = moving_count(n);
    let pillars = pillar_count(n - moving);
    (0..n)
        .map(|i| {
            let center = Vec3::new(
                draw(rng, ranges.x0_m),
                draw(rng, ranges.y0_m),
                draw(rng, ranges.z0_m),
            );
            if i < moving {
                let scale = Vec3::new(
                    draw(rng, ranges.scale_m),
                    draw(rng, ranges.scale_m),
                    draw(rng, ranges.scale_m),
                );
                let offset = draw(rng, ranges.offset);
                let slower = draw(rng, ranges.slower_s);
                ForestObstacle::Moving(Trefoil {
                    center,
                    scale,
                    offset,
                    slower,
                })
            } else if i - moving < pillars {
                ForestObstacle::Pillar {
                    x: center.x,
                    y: center.y,
                }
            } else {
                ForestObstacle::Bar { center }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn counts_follow_the_benchmark() {
        // easy / medium / hard: 50 / 100 / 200 obstacles.
        assert_eq!((moving_count(50), pillar_count(18)), (32, 7));
        assert_eq!((moving_count(100), pillar_count(35)), (65, 13));
        assert_eq!((moving_count(200), pillar_count(70)), (130, 25));
        assert_eq!((moving_count(0), pillar_count(0)), (0, 0));
        assert_eq!(pillar_count(20), 7);
    }

    #[test]
    fn same_seed_same_forest() {
        let a = generate(100, &FOREST_RANGES, &mut Rng::seed_from_u64(3));
        let b = generate(100, &FOREST_RANGES, &mut Rng::seed_from_u64(3));
        let c = generate(100, &FOREST_RANGES, &mut Rng::seed_from_u64(4));
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn velocity_is_the_derivative() {
        let k = Trefoil {
            center: Vec3::new(50.0, 1.0, 2.5),
            scale: Vec3::new(3.0, 2.5, 3.5),
            offset: 1.2,
            slower: 4.5,
        };
        for t in [0.0, 3.3, 17.0, 40.1] {
            let h = 1e-5;
            let fd = trust_numdiff::central_difference(|s| k.position(s), t, h);
            assert!((fd - k.velocity(t)).norm() < 1e-6, "t = {t}");
        }
        assert!((k.position(0.7) - k.position(0.7 + k.period_s())).norm() < 1e-9);
    }
}
