//! Backing off to look (issue 34; beyond the paper): a vehicle on a sensed map stalls where
//! every plan it finds leads into space its sensor has not seen and cannot see from where it
//! is — straight down or up past a forward camera's field, back past its flank. The commit
//! check refuses them all and the braking fallback holds it there for ever. Backing off along
//! the way it came (space it committed to, so seen free) puts that space in front of the
//! sensor: the vehicle turns its sensor toward where its branches lead, and from a few metres
//! back a camera's field covers the place it stalled at, above and below.
//!
//! The manager records the path the vehicle flew ([`FlownPath`]); when it is stalled and its
//! main branch fails the commit check, the fallback's first options are short manoeuvres to
//! rest at the points back along that path `d` and `d/2` from the vehicle horizontally (`d`
//! from [`crate::CommitCheck::retreat_m`]), judged like every option (clear of the forecasts,
//! in known free space).

use std::collections::VecDeque;

use trust_core::Vec3;

/// Most points a [`FlownPath`] keeps (the oldest go first): 4096, more than a flight backs off.
pub const MAX_FLOWN_POINTS: usize = 4096;

/// The path a vehicle flew, without the stretches it flew back over: a point is recorded when
/// the vehicle is [`FlownPath::STEP_M`] from the last one, and the last points are dropped
/// while the vehicle is back nearer the one before them than they were (it retraced them).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FlownPath {
    points: VecDeque<Vec3>,
}

impl FlownPath {
    /// The spacing of recorded points (m): 0.1 m.
    pub const STEP_M: f64 = 0.1;

    /// Forgets the path (a new flight).
    pub fn clear(&mut self) {
        self.points.clear();
    }

    /// The recorded points, oldest first.
    pub fn points(&self) -> impl Iterator<Item = &Vec3> {
        self.points.iter()
    }

    /// Records the vehicle at `p` (ignored if not finite).
    pub fn record(&mut self, p: &Vec3) {
        if !p.iter().all(|x| x.is_finite()) {
            return;
        }
        while self.points.len() >= 2 {
            let n = self.points.len();
            let (before, last) = (self.points[n - 2], self.points[n - 1]);
            if (p - before).norm() < (last - before).norm() {
                self.points.pop_back();
            } else {
                break;
            }
        }
        if self
            .points
            .back()
            .is_none_or(|last| (p - last).norm() >= Self::STEP_M)
        {
            if self.points.len() == MAX_FLOWN_POINTS {
                self.points.pop_front();
            }
            self.points.push_back(*p);
        }
    }

    /// Walking back along the path from its end, the first point `distance_m` from `from`
    /// horizontally (interpolated on the path), or the path's point horizontally farthest from
    /// `from` if none is that far; `None` for an empty path or a distance that is not
    /// positive. Horizontally: a forward camera or a spinning LiDAR sees above and below a
    /// place from beside it, not from under or over it (a vehicle that climbed to where it
    /// stalled sees nothing new from lower down its path).
    pub fn behind(&self, from: &Vec3, distance_m: f64) -> Option<Vec3> {
        if distance_m.is_nan() || distance_m <= 0.0 {
            return None;
        }
        let away = |p: &Vec3| (p - from).xy().norm();
        let mut points = self.points.iter().rev();
        let mut here = *points.next()?;
        let mut farthest = here;
        if away(&here) >= distance_m {
            return Some(here);
        }
        for &p in points {
            if away(&p) >= distance_m {
                // The horizontal distance crosses `distance_m` on [here, p]: bisect.
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..40 {
                    let mid = 0.5 * (lo + hi);
                    if away(&(here + (p - here) * mid)) >= distance_m {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                return Some(here + (p - here) * hi);
            }
            if away(&p) > away(&farthest) {
                farthest = p;
            }
            here = p;
        }
        Some(farthest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn the_retreat_point_is_found_back_along_the_path_beside_the_vehicle() {
        let mut path = FlownPath::default();
        let end = v(2.0, 0.0, 1.0);
        assert_eq!(path.behind(&end, 1.0), None);
        for k in 0..=20 {
            path.record(&v(0.1 * k as f64, 0.0, 0.0));
        }
        // Round a corner: 1 m straight up from (2, 0, 0).
        for k in 1..=10 {
            path.record(&v(2.0, 0.0, 0.1 * k as f64));
        }
        // 0.5 m beside the vehicle: back down the climb and 0.5 m along the first leg.
        let p = path.behind(&end, 0.5).unwrap();
        assert!((p - v(1.5, 0.0, 0.0)).norm() < 1e-9, "{p:?}");
        // Farther than the path reaches: its farthest point.
        assert_eq!(path.behind(&end, 100.0), Some(v(0.0, 0.0, 0.0)));
        assert_eq!(path.behind(&end, 0.0), None);
        assert_eq!(path.behind(&end, f64::NAN), None);
    }

    #[test]
    fn flying_back_retracts_the_path() {
        let mut path = FlownPath::default();
        for k in 0..=30 {
            path.record(&v(0.1 * k as f64, 0.0, 0.0));
        }
        // Back 1 m, then sideways: the path is the way out to 2 m, then the new leg.
        for k in 1..=10 {
            path.record(&v(3.0 - 0.1 * k as f64, 0.0, 0.0));
        }
        let ends: Vec<Vec3> = path.points().copied().collect();
        assert!((ends.last().unwrap() - v(2.0, 0.0, 0.0)).norm() < 0.1 + 1e-9);
        assert!(ends.iter().all(|p| p.x <= 2.0 + 0.1 + 1e-9));
        path.record(&v(2.0, 0.5, 0.0));
        let back = path.behind(&v(2.0, 0.5, 0.0), 0.5).unwrap();
        assert!((back - v(2.0, 0.0, 0.0)).norm() < 0.11, "{back:?}");
        // Hovering adds nothing; a non-finite position is ignored.
        let n = path.points().count();
        path.record(&v(2.0, 0.52, 0.0));
        path.record(&v(f64::NAN, 0.0, 0.0));
        assert_eq!(path.points().count(), n);
    }

    #[test]
    fn the_path_keeps_its_newest_points() {
        let mut path = FlownPath::default();
        for k in 0..(MAX_FLOWN_POINTS + 10) {
            path.record(&v(0.25 * k as f64, 0.0, 0.0));
        }
        assert_eq!(path.points().count(), MAX_FLOWN_POINTS);
        assert!((path.points().next().unwrap().x - 2.5).abs() < 1e-9);
    }
}
