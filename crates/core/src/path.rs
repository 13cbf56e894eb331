//! Guide paths: the polylines a [`crate::PathFrontend`] hands to a [`crate::TrajectoryBackend`].

use serde::{Deserialize, Serialize};

use trust_geometry::scale::{self, Quantity};

use crate::error::check_scaled_vec;
use crate::{PlanError, Vec3};

/// A polyline from the start (first point) toward the goal (last point), untimed.
///
/// A path may have a single point (start on the goal) and may contain repeated points; every query is
/// well defined for those degenerate cases (zero length, all fractions map to the first point).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GuidePath {
    /// The vertices, start first. Never empty (guaranteed by [`GuidePath::new`]).
    pub points: Vec<Vec3>,
}

impl GuidePath {
    /// A validated path: at least one point and at most [`scale::MAX_VERTEX_COUNT`], every point a
    /// position inside the scale policy ([`crate::scale`]).
    pub fn new(points: Vec<Vec3>) -> Result<Self, PlanError> {
        let path = GuidePath { points };
        path.validate("path")?;
        Ok(path)
    }

    /// Re-checks the invariants of [`GuidePath::new`] (the `points` field is public); `field`
    /// prefixes the names in the error. Every API that takes a path calls it.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] for an empty path, [`PlanError::Count`] for too many points,
    /// [`PlanError`] naming the first bad point otherwise.
    pub fn validate(&self, field: &str) -> Result<(), PlanError> {
        if self.points.is_empty() {
            return Err(PlanError::invalid(
                format!("{field}.points"),
                "[]",
                "at least one point",
            ));
        }
        scale::check_count(
            &format!("{field}.points.len()"),
            self.points.len() as u128,
            scale::MAX_VERTEX_COUNT,
        )?;
        for (i, p) in self.points.iter().enumerate() {
            check_scaled_vec(&format!("{field}.points[{i}]"), p, Quantity::Position)?;
        }
        Ok(())
    }

    /// First point (the origin for an empty path, which [`GuidePath::new`] never builds).
    pub fn start(&self) -> Vec3 {
        self.points.first().copied().unwrap_or_else(Vec3::zeros)
    }

    /// Last point (the origin for an empty path, which [`GuidePath::new`] never builds).
    pub fn end(&self) -> Vec3 {
        self.points.last().copied().unwrap_or_else(Vec3::zeros)
    }

    /// Total length (m).
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
    }

    /// The point at arc-length fraction `s` ∈ [0, 1] (clamped). A zero-length path returns its start.
    pub fn point_at_fraction(&self, s: f64) -> Vec3 {
        let total = self.length();
        if total <= 0.0 || !s.is_finite() {
            return self.start();
        }
        let target = s.clamp(0.0, 1.0) * total;
        let mut walked = 0.0;
        for w in self.points.windows(2) {
            let seg = (w[1] - w[0]).norm();
            if walked + seg >= target && seg > 0.0 {
                let u = ((target - walked) / seg).clamp(0.0, 1.0);
                return w[0] + (w[1] - w[0]) * u;
            }
            walked += seg;
        }
        self.end()
    }

    /// `count` points (at least 2, at most [`scale::MAX_SAMPLE_COUNT`]: larger counts are capped)
    /// evenly spaced by arc length, start and end included, appended to `out` after clearing it.
    /// One pass over the polyline. Writes nothing for an empty path.
    pub fn resample_into(&self, count: usize, out: &mut Vec<Vec3>) {
        out.clear();
        if self.points.is_empty() {
            return;
        }
        let count = count.clamp(2, scale::MAX_SAMPLE_COUNT);
        let total = self.length();
        if total <= 0.0 {
            out.resize(count, self.start());
            return;
        }
        let step = total / (count - 1) as f64;
        let mut seg_index = 0;
        let mut seg_start_len = 0.0;
        for k in 0..count {
            let target = if k + 1 == count {
                total
            } else {
                k as f64 * step
            };
            // Advance to the segment that contains `target`.
            while seg_index + 1 < self.points.len() - 1 {
                let seg = (self.points[seg_index + 1] - self.points[seg_index]).norm();
                if seg_start_len + seg >= target {
                    break;
                }
                seg_start_len += seg;
                seg_index += 1;
            }
            let a = self.points[seg_index];
            let b = self.points[(seg_index + 1).min(self.points.len() - 1)];
            let seg = (b - a).norm();
            let u = if seg > 0.0 {
                ((target - seg_start_len) / seg).clamp(0.0, 1.0)
            } else {
                0.0
            };
            out.push(a + (b - a) * u);
        }
    }

    /// [`GuidePath::resample`] that rejects a count above [`scale::MAX_SAMPLE_COUNT`] instead of
    /// capping it.
    ///
    /// # Errors
    /// [`PlanError::Count`] naming `count`.
    pub fn try_resample(&self, count: usize) -> Result<Vec<Vec3>, PlanError> {
        scale::check_count("count", count as u128, scale::MAX_SAMPLE_COUNT)?;
        Ok(self.resample(count))
    }

    /// Convenience wrapper around [`GuidePath::resample_into`].
    pub fn resample(&self, count: usize) -> Vec<Vec3> {
        let mut out = Vec::with_capacity(count.clamp(2, scale::MAX_SAMPLE_COUNT));
        self.resample_into(count, &mut out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    #[test]
    fn rejects_empty_and_non_finite() {
        assert!(GuidePath::new(vec![]).is_err());
        let e = GuidePath::new(vec![Vec3::zeros(), Vec3::new(f64::NAN, 0.0, 0.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("path.points[1]"), "{e}");
    }

    #[test]
    fn single_point_path_is_well_defined() {
        let p = GuidePath::new(vec![Vec3::new(1.0, 2.0, 3.0)]).unwrap();
        assert_eq!(p.length(), 0.0);
        assert_eq!(p.point_at_fraction(0.7), p.start());
        let r = p.resample(5);
        assert_eq!(r.len(), 5);
        assert!(r.iter().all(|q| *q == p.start()));
    }

    #[test]
    fn fraction_on_an_l_shape() {
        let p = GuidePath::new(vec![
            Vec3::zeros(),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ])
        .unwrap();
        assert_relative_eq!(p.length(), 2.0);
        assert_relative_eq!(p.point_at_fraction(0.25), Vec3::new(0.5, 0.0, 0.0));
        assert_relative_eq!(p.point_at_fraction(0.75), Vec3::new(1.0, 0.5, 0.0));
        assert_eq!(p.point_at_fraction(2.0), p.end());
    }

    proptest! {
        #[test]
        fn resample_is_uniform_and_matches_point_at_fraction(
            pts in prop::collection::vec(prop::array::uniform3(-10.0..10.0f64), 1..8),
            count in 2usize..40,
        ) {
            let path = GuidePath::new(pts.iter().map(|a| Vec3::new(a[0], a[1], a[2])).collect()).unwrap();
            let r = path.resample(count);
            prop_assert_eq!(r.len(), count);
            prop_assert!((r[0] - path.start()).norm() < 1e-9);
            prop_assert!((r[count - 1] - path.end()).norm() < 1e-9);
            for (k, q) in r.iter().enumerate() {
                let s = k as f64 / (count - 1) as f64;
                prop_assert!((q - path.point_at_fraction(s)).norm() < 1e-7 * (1.0 + path.length()));
            }
        }
    }
}
