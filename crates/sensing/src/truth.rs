//! The true geometry the simulated sensors ray-cast against.

use trust_geometry::{Shape, StaticMap, Vec3};

/// The world as it is at the sensing time: the true static map (shapes and point-cloud ESDF) and
/// the moving obstacles where they are now (boxes, cylinders or spheres).
///
/// It is `Copy` and free to build each frame.
#[derive(Debug, Clone, Copy)]
pub struct Truth<'a> {
    /// The static world.
    pub map: &'a StaticMap,
    /// The moving obstacles at the sensing time.
    pub moving: &'a [Shape],
}

impl<'a> Truth<'a> {
    /// The static map alone.
    pub fn static_only(map: &'a StaticMap) -> Self {
        Self { map, moving: &[] }
    }

    /// Distance from `origin` along the unit direction `dir` to the first obstacle within
    /// `max_range` ([`StaticMap::cast_ray`], then the moving obstacles' [`Shape::cast_ray`]);
    /// `Some(0.0)` from inside an obstacle, `None` if the ray stays clear.
    pub fn cast(&self, origin: &Vec3, dir: &Vec3, max_range: f64) -> Option<f64> {
        let mut best = self.map.cast_ray(origin, dir, max_range);
        for s in self.moving {
            let limit = best.unwrap_or(max_range);
            if let Some(t) = s.cast_ray(origin, dir, limit)
                && best.is_none_or(|b| t < b)
            {
                best = Some(t);
            }
        }
        best
    }
}
