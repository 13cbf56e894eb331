//! Where one planning horizon reaches toward the goal: the goal guidance surface's radius `r_des`
//! (paper Algorithm 2, line 1) shared by the frontend (DEV-PRM's GGS) and the backend
//! (UTF-MINCO's terminal surface), and the end of the straight guide shared by the straight-line
//! frontend and the manager's fallback guide.

use crate::Vec3;

/// Radius `r_des = max(0, ‖p_s − p_g‖ − T_h·v_max)` (m) of the goal guidance surface
/// `‖p − p_g‖ = r_des` for a vehicle at `start` with horizon `horizon_s` (s) and speed limit
/// `v_max` (m/s) (paper Algorithm 2, line 1): the part of the distance to the goal that one
/// horizon at full speed does not cover. 0 when the goal is within reach, and 0 for non-finite
/// input.
///
/// ```
/// use trust_core::{Vec3, guidance_radius};
/// // Fig. Sim-A-1-1(a): a goal 65 m away, T_h = 4 s, v_max = 10 m/s.
/// let r = guidance_radius(&Vec3::zeros(), &Vec3::new(65.0, 0.0, 0.0), 4.0, 10.0);
/// assert_eq!(r, 25.0);
/// ```
pub fn guidance_radius(start: &Vec3, goal: &Vec3, horizon_s: f64, v_max: f64) -> f64 {
    let r = (start - goal).norm() - horizon_s * v_max;
    if r.is_finite() { r.max(0.0) } else { 0.0 }
}

/// The end of the straight guide from `start` toward `goal` truncated to the distance `reach`
/// (m): `start + (goal − start)·min(1, reach / ‖goal − start‖)`. The goal itself when it is
/// within reach, when `start = goal`, or for non-finite distances.
///
/// ```
/// use trust_core::{Vec3, straight_end};
/// let end = straight_end(&Vec3::zeros(), &Vec3::new(10.0, 0.0, 0.0), 4.0);
/// assert_eq!(end, Vec3::new(4.0, 0.0, 0.0));
/// ```
pub fn straight_end(start: &Vec3, goal: &Vec3, reach: f64) -> Vec3 {
    let d = (goal - start).norm();
    if !d.is_finite() || !reach.is_finite() || d <= reach || d <= 0.0 {
        *goal
    } else {
        start + (goal - start) * (reach / d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guidance_radius_is_clamped_and_finite() {
        let (s, g) = (Vec3::zeros(), Vec3::new(30.0, 40.0, 0.0));
        assert_eq!(guidance_radius(&s, &g, 2.0, 10.0), 30.0);
        assert_eq!(guidance_radius(&s, &g, 10.0, 10.0), 0.0);
        assert_eq!(guidance_radius(&s, &g, f64::INFINITY, 10.0), 0.0);
        assert_eq!(guidance_radius(&s, &Vec3::repeat(f64::NAN), 2.0, 10.0), 0.0);
    }

    #[test]
    fn straight_end_stops_at_the_reach_or_the_goal() {
        let (s, g) = (Vec3::new(1.0, 1.0, 1.0), Vec3::new(1.0, 11.0, 1.0));
        assert_eq!(straight_end(&s, &g, 4.0), Vec3::new(1.0, 5.0, 1.0));
        assert_eq!(straight_end(&s, &g, 20.0), g);
        assert_eq!(straight_end(&g, &g, 4.0), g);
        assert_eq!(straight_end(&s, &g, f64::NAN), g);
    }
}
