//! Axis-aligned bounding boxes (broad phase, map bounds).

use serde::{Deserialize, Serialize};

use crate::Vec3;
use crate::error::{GeometryError, check_non_negative, check_vec};

/// An axis-aligned bounding box `[min, max]` (closed). Invariant: finite and `min <= max` per axis.
///
/// A degenerate (zero-extent) box is a valid `Aabb` (e.g. the box of a point); map bounds
/// additionally require a positive volume (see [`Aabb::check_volume`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawAabb", into = "RawAabb")]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAabb {
    min: Vec3,
    max: Vec3,
}

impl TryFrom<RawAabb> for Aabb {
    type Error = GeometryError;
    fn try_from(r: RawAabb) -> Result<Self, GeometryError> {
        Aabb::new(r.min, r.max)
    }
}

impl From<Aabb> for RawAabb {
    fn from(b: Aabb) -> Self {
        RawAabb {
            min: b.min,
            max: b.max,
        }
    }
}

pub(crate) const AXES: [char; 3] = ['x', 'y', 'z'];

/// Validates `min <= max` (finite) for a box named `field`.
pub(crate) fn check_box(field: &str, min: &Vec3, max: &Vec3) -> Result<(), GeometryError> {
    check_vec(&format!("{field}.min"), min)?;
    check_vec(&format!("{field}.max"), max)?;
    for (i, axis) in AXES.into_iter().enumerate() {
        if min[i] > max[i] {
            return Err(GeometryError::InvertedBox {
                field: field.into(),
                axis,
                min: min[i],
                max: max[i],
            });
        }
    }
    Ok(())
}

impl Aabb {
    /// Creates a box; errors if a coordinate is non-finite or `min > max` along an axis.
    pub fn new(min: Vec3, max: Vec3) -> Result<Self, GeometryError> {
        check_box("aabb", &min, &max)?;
        Ok(Self { min, max })
    }

    /// The smallest box containing both segment end points.
    ///
    /// Non-finite input yields a box with non-finite corners (no validation, for speed in
    /// inner loops); use [`Aabb::new`] when the input is untrusted.
    pub fn from_segment(a: &Vec3, b: &Vec3) -> Self {
        Self {
            min: a.inf(b),
            max: a.sup(b),
        }
    }

    /// The smallest box containing all `points`, or `None` if `points` is empty.
    pub fn from_points(points: &[Vec3]) -> Option<Self> {
        let (first, rest) = points.split_first()?;
        let mut b = Self {
            min: *first,
            max: *first,
        };
        for p in rest {
            b.min = b.min.inf(p);
            b.max = b.max.sup(p);
        }
        Some(b)
    }

    /// Errors with [`GeometryError::EmptyBounds`] if the box has zero extent along some axis.
    pub fn check_volume(&self, field: &str) -> Result<(), GeometryError> {
        for (i, axis) in AXES.into_iter().enumerate() {
            if self.max[i] <= self.min[i] {
                return Err(GeometryError::EmptyBounds {
                    field: field.into(),
                    axis,
                    value: self.min[i],
                });
            }
        }
        Ok(())
    }

    /// The part of the segment `[a, b]` inside the closed box, as its end points, or `None` if the
    /// segment misses the box (slab method). A degenerate segment gives its point if inside.
    pub fn clip_segment(&self, a: &Vec3, b: &Vec3) -> Option<(Vec3, Vec3)> {
        let d = b - a;
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        for i in 0..3 {
            if d[i] == 0.0 {
                if a[i] < self.min[i] || a[i] > self.max[i] {
                    return None;
                }
                continue;
            }
            let t0 = (self.min[i] - a[i]) / d[i];
            let t1 = (self.max[i] - a[i]) / d[i];
            let (t0, t1) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
            lo = lo.max(t0);
            hi = hi.min(t1);
            // Also false for NaN bounds.
            if lo.is_nan() || hi.is_nan() || lo > hi {
                return None;
            }
        }
        let at = |t: f64| {
            if t <= 0.0 {
                *a
            } else if t >= 1.0 {
                *b
            } else {
                a + d * t
            }
        };
        Some((at(lo), at(hi)))
    }

    /// True if `p` lies in the closed box.
    pub fn contains(&self, p: &Vec3) -> bool {
        (0..3).all(|i| p[i] >= self.min[i] && p[i] <= self.max[i])
    }

    /// True if `other` lies inside this closed box (false if either has a NaN coordinate).
    pub fn contains_box(&self, other: &Aabb) -> bool {
        (0..3).all(|i| self.min[i] <= other.min[i] && other.max[i] <= self.max[i])
    }

    /// True if the closed boxes overlap (touching counts).
    pub fn intersects(&self, other: &Aabb) -> bool {
        (0..3).all(|i| self.min[i] <= other.max[i] && other.min[i] <= self.max[i])
    }

    /// The box grown by `r` on every side. A negative `r` shrinks it, clamping each axis at its
    /// centre so the result is never inverted.
    pub fn inflated(&self, r: f64) -> Aabb {
        let mut min = self.min.add_scalar(-r);
        let mut max = self.max.add_scalar(r);
        for i in 0..3 {
            if min[i] > max[i] {
                let c = 0.5 * (self.min[i] + self.max[i]);
                min[i] = c;
                max[i] = c;
            }
        }
        Aabb { min, max }
    }

    /// Validating variant of [`Aabb::inflated`]: errors if `r` is negative or non-finite.
    pub fn try_inflated(&self, r: f64) -> Result<Aabb, GeometryError> {
        check_non_negative("inflation", r)?;
        Ok(self.inflated(r))
    }

    /// The smallest box containing both boxes.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&other.min),
            max: self.max.sup(&other.max),
        }
    }

    /// `max - min`.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Midpoint of the box.
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// The point of the box nearest to `p` (`p` itself if inside).
    pub fn clamp(&self, p: &Vec3) -> Vec3 {
        p.sup(&self.min).inf(&self.max)
    }

    /// Euclidean distance from `p` to the box (0 inside).
    pub fn distance_to_point(&self, p: &Vec3) -> f64 {
        (p - self.clamp(p)).norm()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn new_rejects_inverted_and_non_finite() {
        let e = Aabb::new(v(0.0, 2.0, 0.0), v(1.0, 1.0, 1.0)).unwrap_err();
        assert!(
            matches!(e, GeometryError::InvertedBox { axis: 'y', .. }),
            "{e}"
        );
        assert!(e.to_string().contains("min.y = 2"), "{e}");
        let e = Aabb::new(v(0.0, 0.0, f64::NAN), v(1.0, 1.0, 1.0)).unwrap_err();
        assert!(e.to_string().contains("aabb.min.z"), "{e}");
    }

    #[test]
    fn queries() {
        let a = Aabb::new(v(0.0, 0.0, 0.0), v(1.0, 2.0, 3.0)).unwrap();
        assert!(a.contains(&v(1.0, 2.0, 3.0)));
        assert!(!a.contains(&v(1.1, 2.0, 3.0)));
        assert_eq!(a.extent(), v(1.0, 2.0, 3.0));
        assert_eq!(a.center(), v(0.5, 1.0, 1.5));
        let b = Aabb::from_segment(&v(1.0, 5.0, 1.0), &v(2.0, -1.0, 0.0));
        assert!(a.intersects(&b));
        assert_eq!(a.union(&b).max, v(2.0, 5.0, 3.0));
        let c = Aabb::new(v(1.5, 0.0, 0.0), v(2.0, 1.0, 1.0)).unwrap();
        assert!(!a.intersects(&c));
        assert!(a.inflated(0.5).intersects(&c));
        let s = a.inflated(-0.75);
        assert!(s.min.x <= s.max.x && s.min.y <= s.max.y);
        assert!((a.distance_to_point(&v(2.0, 2.0, 3.0)) - 1.0).abs() < 1e-12);
        assert!(a.check_volume("b").is_ok());
        let flat = Aabb::new(v(0.0, 0.0, 1.0), v(1.0, 1.0, 1.0)).unwrap();
        assert!(matches!(
            flat.check_volume("bounds"),
            Err(GeometryError::EmptyBounds { axis: 'z', .. })
        ));
    }
}
