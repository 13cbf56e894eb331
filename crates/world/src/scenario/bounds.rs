//! The axis-aligned boxes of a scenario file (`world.bounds`, the `region`s): below the sections
//! and the generators, which both use them.

use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Vec3};

/// An axis-aligned box `{ min = [x, y, z], max = [x, y, z] }`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundsSpec {
    /// Lower corner (m).
    pub min: [f64; 3],
    /// Upper corner (m).
    pub max: [f64; 3],
}

impl BoundsSpec {
    /// The box, without checks.
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: Vec3::from(self.min),
            max: Vec3::from(self.max),
        }
    }

    /// From a box.
    pub fn from_aabb(a: &Aabb) -> Self {
        BoundsSpec {
            min: a.min.into(),
            max: a.max.into(),
        }
    }

    /// Finite corners with `min < max` on every axis.
    pub fn is_valid(&self) -> bool {
        self.min.iter().chain(&self.max).all(|x| x.is_finite())
            && (0..3).all(|i| self.min[i] < self.max[i])
    }
}
