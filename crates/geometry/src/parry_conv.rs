//! Private conversions between our nalgebra types and parry/glam types. Nothing here is public.

use parry3d_f64::bounding_volume::Aabb as PAabb;
use parry3d_f64::math::{Pose, Vector as PVec};
use parry3d_f64::query;
use parry3d_f64::shape::{Cuboid, Cylinder as PCylinder, Segment};

use crate::Vec3;
use crate::aabb::Aabb;
use crate::shapes::Shape;

pub(crate) fn to_p(v: &Vec3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

pub(crate) fn to_p_aabb(b: &Aabb) -> PAabb {
    PAabb::new(to_p(&b.min), to_p(&b.max))
}

/// Euclidean distance between the segment `[a, b]` and the solid `shape` (0 if they touch or
/// overlap), computed by parry in the shape's local frame.
///
/// parry's cylinder has its axis along y; ours along z. Swapping y and z is an isometry (a
/// reflection), so the segment is expressed in the shape frame with y and z swapped.
pub(crate) fn segment_shape_distance(shape: &Shape, a: &Vec3, b: &Vec3) -> f64 {
    let id = Pose::IDENTITY;
    let result = match shape {
        Shape::Sphere(s) => {
            // Closed form: distance from the centre to the segment, minus the radius.
            let d = b - a;
            let len2 = d.norm_squared();
            let t = if len2 > 0.0 {
                ((s.center - a).dot(&d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let gap = (a + d * t - s.center).norm() - s.radius;
            // Rounding in the projection is a few ulps of the coordinates' magnitude: a gap
            // below that is reported as contact (conservative), so that a tiny sphere on a long
            // segment is never missed.
            let ulps = 8.0 * f64::EPSILON * (a.amax() + b.amax() + s.center.amax() + s.radius);
            return if gap.is_nan() || gap <= ulps {
                0.0
            } else {
                gap
            };
        }
        Shape::Cylinder(c) => {
            let swap = |p: &Vec3| {
                let q = p - c.center;
                PVec::new(q.x, q.z, q.y)
            };
            let seg = Segment::new(swap(a), swap(b));
            query::distance(
                &id,
                &seg,
                &id,
                &PCylinder::new(c.half_height.abs(), c.radius.abs()),
            )
        }
        Shape::AaBox(bx) => {
            let center = 0.5 * (bx.min + bx.max);
            let half = 0.5 * (bx.max - bx.min);
            let seg = Segment::new(to_p(&(a - center)), to_p(&(b - center)));
            query::distance(&id, &seg, &id, &Cuboid::new(to_p(&half.abs())))
        }
    };
    // Segment against ball/cylinder/cuboid is always supported by the default dispatcher; if it
    // ever were not, report contact so callers stay conservative.
    result.map(|d| d.distance).unwrap_or(0.0)
}
