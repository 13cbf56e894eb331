//! The sampling region of the visibility PRMs: an oriented box between the start and the (local) goal.
//!
//! Fast-Planner's topological planner samples a box centred between start and goal whose x axis points
//! from start to goal, whose y axis is horizontal, with half-sizes `0.5·‖goal − start‖ + inflate_x`,
//! `inflate_y`, `inflate_z`. Its frame is undefined when start→goal is vertical (the horizontal axis is
//! a cross product with `z`); [`SamplingBox::between`] picks world `x` as the horizontal axis in that
//! case, and world `x` as the box axis when start and goal coincide.

use rand::Rng as _;

use trust_core::{Rng, Vec3};

/// An oriented box: `center + Σ_i u_i · half[i] · axes[i]`, `u_i ∈ [−1, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplingBox {
    /// Centre of the box.
    pub center: Vec3,
    /// Orthonormal, right-handed axes: along start→goal, horizontal, and their cross product.
    pub axes: [Vec3; 3],
    /// Half-extents along `axes` (m), each `>= 0`.
    pub half: Vec3,
}

impl SamplingBox {
    /// The box between `start` and `goal` inflated by `inflate` (x along start→goal, y horizontal,
    /// z completing a right-handed frame). Negative or non-finite inflations are treated as zero.
    pub fn between(start: &Vec3, goal: &Vec3, inflate: &Vec3) -> Self {
        let axes = frame(start, goal);
        let clean = |x: f64| if x.is_finite() { x.max(0.0) } else { 0.0 };
        let half_len = 0.5 * (goal - start).norm();
        SamplingBox {
            center: 0.5 * (start + goal),
            axes,
            half: Vec3::new(
                half_len + clean(inflate.x),
                clean(inflate.y),
                clean(inflate.z),
            ),
        }
    }

    /// The point at box coordinates `u ∈ [−1, 1]³`.
    pub fn point(&self, u: &Vec3) -> Vec3 {
        self.center
            + self.axes[0] * (u.x * self.half.x)
            + self.axes[1] * (u.y * self.half.y)
            + self.axes[2] * (u.z * self.half.z)
    }

    /// A uniform random point in the box (all randomness from `rng`).
    pub fn sample(&self, rng: &mut Rng) -> Vec3 {
        let u = Vec3::new(
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
        );
        self.point(&u)
    }
}

/// An orthonormal right-handed frame whose first axis points from `start` to `goal` and whose second
/// axis is horizontal ([`trust_predict::frame_along`]). Vertical start→goal: the second axis is world
/// `x`. Coincident points: world axes.
pub fn frame(start: &Vec3, goal: &Vec3) -> [Vec3; 3] {
    trust_predict::frame_along(&(goal - start))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::SeedableRng;

    fn assert_orthonormal(f: &[Vec3; 3]) {
        for i in 0..3 {
            assert_relative_eq!(f[i].norm(), 1.0, epsilon = 1e-12);
            for j in 0..i {
                assert!(f[i].dot(&f[j]).abs() < 1e-12);
            }
        }
        assert_relative_eq!(f[0].cross(&f[1]), f[2], epsilon = 1e-12);
    }

    #[test]
    fn frame_is_orthonormal_for_general_vertical_and_degenerate_input() {
        let cases = [
            (Vec3::zeros(), Vec3::new(3.0, 4.0, 1.0)),
            (Vec3::zeros(), Vec3::new(0.0, 0.0, 5.0)),
            (Vec3::zeros(), Vec3::new(0.0, 0.0, -5.0)),
            (Vec3::new(1.0, 1.0, 1.0), Vec3::new(1.0, 1.0, 1.0)),
            (Vec3::zeros(), Vec3::new(1e-12, 0.0, 1.0)),
        ];
        for (a, b) in cases {
            let f = frame(&a, &b);
            assert_orthonormal(&f);
            assert!(f[1].z.abs() < 1e-12, "second axis must be horizontal");
            if (b - a).norm() > 0.0 {
                assert_relative_eq!(f[0], (b - a).normalize(), epsilon = 1e-9);
            }
        }
    }

    #[test]
    fn samples_stay_in_the_box() {
        let b = SamplingBox::between(
            &Vec3::zeros(),
            &Vec3::new(0.0, 0.0, 4.0),
            &Vec3::new(1.0, 3.5, 1.0),
        );
        assert_relative_eq!(b.half, Vec3::new(3.0, 3.5, 1.0));
        let mut rng = Rng::seed_from_u64(3);
        for _ in 0..200 {
            let p = b.sample(&mut rng);
            let r = p - b.center;
            for i in 0..3 {
                assert!(r.dot(&b.axes[i]).abs() <= b.half[i] + 1e-9);
            }
        }
    }

    #[test]
    fn bad_inflation_is_clamped() {
        let b = SamplingBox::between(
            &Vec3::zeros(),
            &Vec3::new(2.0, 0.0, 0.0),
            &Vec3::new(-1.0, f64::NAN, 2.0),
        );
        assert_relative_eq!(b.half, Vec3::new(1.0, 0.0, 2.0));
    }
}
