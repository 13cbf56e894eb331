//! Private conversions between our nalgebra types and parry/glam types. Nothing here is public.

use parry3d_f64::bounding_volume::Aabb as PAabb;
use parry3d_f64::math::{Pose, Vector as PVec};
use parry3d_f64::query::{self, Ray, RayCast};
use parry3d_f64::shape::{Ball, Cuboid, Cylinder as PCylinder, Segment};

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

/// Distance along the ray `origin + t * dir` (`dir` a unit vector, `t` in `[0, max_t]`) to the
/// first point of the solid `shape`, by parry's ray casts in the shape's frame (the cylinder with
/// y and z swapped, as in [`segment_shape_distance`]); `Some(0)` if `origin` is inside.
pub(crate) fn ray_shape_hit(shape: &Shape, origin: &Vec3, dir: &Vec3, max_t: f64) -> Option<f64> {
    match shape {
        Shape::Sphere(s) => {
            let ray = Ray::new(to_p(&(origin - s.center)), to_p(dir));
            Ball::new(s.radius.abs()).cast_local_ray(&ray, max_t, true)
        }
        Shape::Cylinder(c) => ray_cylinder_hit(c, origin, dir, max_t),
        Shape::AaBox(bx) => {
            let center = 0.5 * (bx.min + bx.max);
            let half = 0.5 * (bx.max - bx.min);
            let ray = Ray::new(to_p(&(origin - center)), to_p(dir));
            Cuboid::new(to_p(&half.abs())).cast_local_ray(&ray, max_t, true)
        }
    }
}

/// Ray cast against a solid vertical cylinder in closed form (the first of the side's entry and
/// the caps' entries that lies on the surface): parry casts cylinders by GJK, which took half of
/// a depth frame's time in a forest (`trust-sensing`'s bench). Agrees with parry's cast (property
/// test `closed_form_ray_cylinder_agrees_with_parry`).
pub(crate) fn ray_cylinder_hit(
    c: &crate::shapes::Cylinder,
    origin: &Vec3,
    dir: &Vec3,
    max_t: f64,
) -> Option<f64> {
    let (r, h) = (c.radius.abs(), c.half_height.abs());
    let q = origin - c.center;
    let r2 = r * r;
    let radial2 = q.x * q.x + q.y * q.y;
    if radial2 <= r2 && q.z.abs() <= h {
        return Some(0.0);
    }
    let mut best = f64::INFINITY;
    // The side: |q_xy + t d_xy| = r, entering (the smaller root), within the height.
    let a = dir.x * dir.x + dir.y * dir.y;
    if a > 0.0 {
        let b = q.x * dir.x + q.y * dir.y;
        let disc = b * b - a * (radial2 - r2);
        if disc >= 0.0 {
            let t = (-b - disc.sqrt()) / a;
            if t >= 0.0 && (q.z + t * dir.z).abs() <= h {
                best = t;
            }
        }
    }
    // The caps: z = ±h, inside the disc.
    if dir.z != 0.0 {
        for cap in [-h, h] {
            let t = (cap - q.z) / dir.z;
            let (x, y) = (q.x + t * dir.x, q.y + t * dir.y);
            if t >= 0.0 && t < best && x * x + y * y <= r2 {
                best = t;
            }
        }
    }
    (best <= max_t).then_some(best)
}

/// parry's (GJK) ray cast against a cylinder, as the reference of [`ray_cylinder_hit`].
#[cfg(test)]
pub(crate) fn parry_ray_cylinder_hit(
    c: &crate::shapes::Cylinder,
    origin: &Vec3,
    dir: &Vec3,
    max_t: f64,
) -> Option<f64> {
    let o = origin - c.center;
    let ray = Ray::new(PVec::new(o.x, o.z, o.y), PVec::new(dir.x, dir.z, dir.y));
    PCylinder::new(c.half_height.abs(), c.radius.abs()).cast_local_ray(&ray, max_t, true)
}

/// Whether the segment `[a, b]` comes closer than `clearance` to `shape` or touches it — the
/// negation of `d > 0 && d >= clearance` with `d` = [`segment_shape_distance`] — deciding
/// vertical cylinders and boxes in closed form where a margin of `1e-9` relative to the shape's
/// size separates the two answers, and asking GJK only in the rest (a segment grazing a
/// cylinder's rim band or a box's rounded edges). The closed-form answers agree with GJK's
/// (property test `closed_form_segment_tests_agree_with_gjk`); they are ~10× cheaper.
pub(crate) fn segment_blocked(shape: &Shape, a: &Vec3, b: &Vec3, clearance: f64) -> bool {
    // An end point closer than the clearance, or touching, decides at once and exactly (the
    // segment's distance is at most its ends'): a segment of any length from a point on the
    // surface is blocked at clearance 0, like the zero-length segment at that point, although
    // GJK stops up to ~1e-8 m above 0 for a segment leaving a cylinder tangentially.
    let end = shape.signed_distance(a).min(shape.signed_distance(b));
    let tol = contact_tolerance(shape, a, b);
    if end.is_nan() || end <= tol || end < clearance {
        return true;
    }
    if a == b {
        // A point: its exact distance decides (GJK on a degenerate segment could err either way
        // within its tolerance, and then a segment from this point could be clearer than it).
        return false;
    }
    let decided = match shape {
        Shape::Cylinder(c) => cylinder_verdict(c, a, b, clearance),
        Shape::AaBox(bx) => box_verdict(bx, a, b, clearance),
        Shape::Sphere(_) => None,
    };
    decided.unwrap_or_else(|| {
        let d = segment_shape_distance(shape, a, b);
        // GJK converges slowly on a segment tangent to a curved surface and stops a little
        // above 0: a distance within `1e-9` of the shape's size is contact, as in the closed
        // forms, so that a segment touching a shape at clearance 0 is blocked whatever its
        // length and direction.
        !(d > contact_tolerance(shape, a, b) && d >= clearance)
    })
}

/// Distances at or below this count as contact: `1e-9` relative to the shape's size and the
/// magnitude of the coordinates (GJK's own accuracy is about `1e-10` relative).
fn contact_tolerance(shape: &Shape, a: &Vec3, b: &Vec3) -> f64 {
    let bx = shape.aabb();
    let size = (bx.max - bx.min).amax();
    let coords = a.amax().max(b.amax()).max(bx.min.amax()).max(bx.max.amax());
    1e-9 * (1.0 + size) + 8.0 * f64::EPSILON * coords
}

/// Squared distance from the origin to the 2-D segment `[(ax, ay), (bx, by)]`.
fn origin_segment_distance2(ax: f64, ay: f64, bx: f64, by: f64) -> f64 {
    let (dx, dy) = (bx - ax, by - ay);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (-(ax * dx + ay * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (x, y) = (ax + dx * t, ay + dy * t);
    x * x + y * y
}

/// Closed-form verdict for a vertical cylinder: `Some(false)` if the segment stays horizontally
/// farther than `radius + clearance` from the axis (every point of the cylinder is within
/// `radius` of it), `Some(true)` if its part between the caps comes horizontally closer than
/// `radius + clearance` (such a point is within `clearance` of the cylinder), `None` otherwise.
fn cylinder_verdict(
    c: &crate::shapes::Cylinder,
    a: &Vec3,
    b: &Vec3,
    clearance: f64,
) -> Option<bool> {
    let (p, q) = (a - c.center, b - c.center);
    let tol = 1e-9 * (1.0 + c.radius + c.half_height + clearance);
    let reach = c.radius + clearance;
    let far = reach + tol;
    if origin_segment_distance2(p.x, p.y, q.x, q.y) > far * far {
        return Some(false);
    }
    // The part of the segment between the caps.
    let (z0, z1) = (-c.half_height, c.half_height);
    let dz = q.z - p.z;
    let (lo, hi) = if dz == 0.0 {
        if p.z < z0 || p.z > z1 {
            return None;
        }
        (0.0, 1.0)
    } else {
        let (t0, t1) = ((z0 - p.z) / dz, (z1 - p.z) / dz);
        let (t0, t1) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        let (lo, hi) = (t0.max(0.0), t1.min(1.0));
        if lo.is_nan() || hi.is_nan() || lo > hi {
            return None;
        }
        (lo, hi)
    };
    let (u, v) = (p + (q - p) * lo, p + (q - p) * hi);
    let near = reach - tol;
    (near > 0.0 && origin_segment_distance2(u.x, u.y, v.x, v.y) < near * near).then_some(true)
}

/// Closed-form verdict for a box: `Some(true)` if the segment meets the box grown by less than
/// `clearance` along one axis (a point of it is closer than `clearance`, or touches). `None`
/// otherwise; the caller has already skipped boxes whose `clearance`-grown box the segment
/// misses.
fn box_verdict(bx: &crate::shapes::AaBox, a: &Vec3, b: &Vec3, clearance: f64) -> Option<bool> {
    let tol = 1e-9 * (1.0 + (bx.max - bx.min).amax() + clearance);
    let grow = (clearance - tol).max(0.0);
    let base = bx.aabb();
    if base.clip_segment(a, b).is_some() {
        return Some(true);
    }
    for axis in 0..3 {
        let mut grown = base;
        grown.min[axis] -= grow;
        grown.max[axis] += grow;
        if grown.clip_segment(a, b).is_some() {
            return Some(true);
        }
    }
    None
}

/// Longest ray a cast follows, in metres: twice the largest distance within the scale policy.
const MAX_RAY_M: f64 = 4.0 * crate::scale::MAX_COORD_M;

/// The unit direction and the range of a ray cast, or `Err` for input answered "blocked at once"
/// (see [`crate::StaticMap::cast_ray`]).
pub(crate) fn ray_input(origin: &Vec3, dir: &Vec3, max_range: f64) -> Result<(Vec3, f64), ()> {
    let len = dir.norm();
    if !crate::scale::position_in_scale(origin)
        || !len.is_finite()
        || len == 0.0
        || max_range.is_nan()
    {
        return Err(());
    }
    Ok((dir / len, max_range.clamp(0.0, MAX_RAY_M)))
}

impl Shape {
    /// Ray cast against the solid shape: the distance in metres from `origin` along `dir` (any
    /// non-zero length; it is normalized) to the first point of the shape within `max_range`,
    /// `Some(0.0)` if `origin` is inside or on it, `None` if the ray stays clear. parry's ray
    /// casts do the work (closed forms for the ball and the box, GJK for the cylinder).
    ///
    /// Invalid input answers conservatively, as the other queries do ([`crate::scale`]): a
    /// non-finite or out-of-scale `origin`, a zero or non-finite `dir` or a NaN `max_range` gives
    /// `Some(0.0)` ("blocked at once"); a negative `max_range` counts as 0.
    pub fn cast_ray(&self, origin: &Vec3, dir: &Vec3, max_range: f64) -> Option<f64> {
        match ray_input(origin, dir, max_range) {
            Ok((unit, max_t)) => ray_shape_hit(self, origin, &unit, max_t),
            Err(()) => Some(0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{AaBox, Cylinder};
    use proptest::prelude::*;

    fn gjk_blocked(shape: &Shape, a: &Vec3, b: &Vec3, clearance: f64) -> bool {
        let d = segment_shape_distance(shape, a, b);
        !(d > 0.0 && d >= clearance)
    }

    #[test]
    fn closed_form_verdicts_on_hand_made_cases() {
        let c = Cylinder::new(Vec3::new(0.0, 0.0, 1.0), 0.5, 1.0).unwrap();
        let v = |x, y, z| Vec3::new(x, y, z);
        // Passing at 0.7 m from the axis: clear for a 0.1 m clearance, blocked for 0.3 m.
        assert_eq!(
            cylinder_verdict(&c, &v(-2.0, 0.7, 1.0), &v(2.0, 0.7, 1.0), 0.1),
            Some(false)
        );
        assert_eq!(
            cylinder_verdict(&c, &v(-2.0, 0.7, 1.0), &v(2.0, 0.7, 1.0), 0.3),
            Some(true)
        );
        // Above the cap within the clearance band: left to GJK.
        assert_eq!(
            cylinder_verdict(&c, &v(-2.0, 0.0, 2.2), &v(2.0, 0.0, 2.2), 0.3),
            None
        );
        assert!(segment_blocked(
            &Shape::Cylinder(c),
            &v(-2.0, 0.0, 2.2),
            &v(2.0, 0.0, 2.2),
            0.3
        ));
        assert!(!segment_blocked(
            &Shape::Cylinder(c),
            &v(-2.0, 0.0, 2.4),
            &v(2.0, 0.0, 2.4),
            0.3
        ));
        let bx = AaBox::new(v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0)).unwrap();
        assert_eq!(
            box_verdict(&bx, &v(-1.0, 0.5, 1.2), &v(2.0, 0.5, 1.2), 0.3),
            Some(true)
        );
        // Past an edge, 0.2 m from it along both y and z (0.28 m away): GJK decides.
        assert_eq!(
            box_verdict(&bx, &v(-1.0, 1.2, 1.2), &v(2.0, 1.2, 1.2), 0.3),
            None
        );
        assert!(segment_blocked(
            &Shape::AaBox(bx),
            &v(-1.0, 1.2, 1.2),
            &v(2.0, 1.2, 1.2),
            0.3
        ));
        assert!(!segment_blocked(
            &Shape::AaBox(bx),
            &v(-1.0, 1.2, 1.2),
            &v(2.0, 1.2, 1.2),
            0.25
        ));
    }

    proptest! {
        /// Wherever the closed forms decide, they give GJK's verdict.
        #[test]
        fn closed_form_segment_tests_agree_with_gjk(
            a in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64),
            b in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64),
            radius in 0.0..1.5f64, half_height in 0.0..1.5f64,
            lo in (-1.0..0.0f64, -1.0..0.0f64, -1.0..0.0f64),
            size in (0.0..2.0f64, 0.0..2.0f64, 0.0..2.0f64),
            clearance in prop_oneof![Just(0.0), 0.0..0.8f64],
        ) {
            let (a, b) = (Vec3::new(a.0, a.1, a.2), Vec3::new(b.0, b.1, b.2));
            let c = Cylinder::new(Vec3::new(0.1, -0.2, 0.3), radius, half_height).unwrap();
            if let Some(v) = cylinder_verdict(&c, &a, &b, clearance) {
                prop_assert_eq!(v, gjk_blocked(&Shape::Cylinder(c), &a, &b, clearance));
            }
            let lo = Vec3::new(lo.0, lo.1, lo.2);
            let bx = AaBox::new(lo, lo + Vec3::new(size.0, size.1, size.2)).unwrap();
            if let Some(v) = box_verdict(&bx, &a, &b, clearance) {
                prop_assert_eq!(v, gjk_blocked(&Shape::AaBox(bx), &a, &b, clearance));
            }
        }
    }
}
