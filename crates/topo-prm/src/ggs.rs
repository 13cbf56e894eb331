//! Where the paths end: the goal point (V-PRM) or the goal guidance surface (GGS, paper Sec. III-B).
//!
//! The GGS is the sphere `‖p − p_g‖ = r_des` with `r_des = ‖p_s − p_g‖ − T_h·v_max`: the place the
//! vehicle can reach within the horizon while heading for the goal. It acts as one guard that a point
//! sees when it sees some point of the sphere. When `r_des <= 0` (the goal is within reach) it
//! degenerates to the goal point and DEV-PRM behaves like V-PRM.

use trust_core::Vec3;

/// Candidate directions tried on the sphere besides the nearest point (tilted by up to this angle, rad).
const GGS_TILT_RAD: f64 = 0.35;

/// The end of the paths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Terminal {
    /// A fixed goal point.
    Point(Vec3),
    /// The goal guidance surface: sphere of `radius > 0` around `center` (the global goal).
    Surface {
        /// The global goal.
        center: Vec3,
        /// `r_des` (m), strictly positive.
        radius: f64,
    },
}

impl Terminal {
    /// The GGS for this query ([`trust_core::guidance_radius`]), or the goal point when
    /// `r_des = 0` (the goal within reach, or non-finite input).
    pub fn goal_guidance_surface(start: &Vec3, goal: &Vec3, horizon_s: f64, v_max: f64) -> Self {
        let r = trust_core::guidance_radius(start, goal, horizon_s, v_max);
        if r > 0.0 {
            Terminal::Surface {
                center: *goal,
                radius: r,
            }
        } else {
            Terminal::Point(*goal)
        }
    }

    /// The point of the terminal nearest to `p` (the goal itself for a point terminal; the goal when
    /// `p` is the centre).
    pub fn nearest_point(&self, p: &Vec3) -> Vec3 {
        match *self {
            Terminal::Point(g) => g,
            Terminal::Surface { center, radius } => {
                let d = p - center;
                let n = d.norm();
                if n > 0.0 {
                    center + d * (radius / n)
                } else {
                    center
                }
            }
        }
    }

    /// Distance from `p` to the terminal (0 inside the GGS ball): an admissible heuristic for the
    /// remaining path length.
    pub fn distance_from(&self, p: &Vec3) -> f64 {
        match *self {
            Terminal::Point(g) => (p - g).norm(),
            Terminal::Surface { center, radius } => ((p - center).norm() - radius).max(0.0),
        }
    }

    /// True if `p` lies strictly inside the GGS ball (samples there are beyond the surface). Always
    /// false for a point terminal.
    pub fn is_beyond(&self, p: &Vec3) -> bool {
        match *self {
            Terminal::Point(_) => false,
            Terminal::Surface { center, radius } => (p - center).norm() < radius,
        }
    }

    /// True if `q` is on the terminal: the goal point, or on the sphere (within `tol` metres).
    pub fn reaches(&self, q: &Vec3, tol: f64) -> bool {
        match *self {
            Terminal::Point(g) => (q - g).norm() <= tol,
            Terminal::Surface { center, radius } => ((q - center).norm() - radius).abs() <= tol,
        }
    }

    /// Candidate end points on the terminal seen from `p`, best first: the nearest point, then points
    /// tilted around it (only directions whose segment from `p` stays outside the ball). Written to
    /// `out` (cleared first).
    pub fn candidates(&self, p: &Vec3, out: &mut Vec<Vec3>) {
        out.clear();
        match *self {
            Terminal::Point(g) => out.push(g),
            Terminal::Surface { center, radius } => {
                let d = p - center;
                let n = d.norm();
                if n.is_nan() || n <= radius {
                    out.push(self.nearest_point(p));
                    return;
                }
                let d0 = d / n;
                out.push(center + d0 * radius);
                // Points beyond the tangent cone would need a segment through the ball.
                let tilt = GGS_TILT_RAD.min(0.5 * (radius / n).clamp(-1.0, 1.0).acos());
                if tilt <= 1e-6 {
                    return;
                }
                let [_, e1, e2] = crate::sampling::frame(&Vec3::zeros(), &d0);
                for e in [e1, -e1, e2, -e2] {
                    out.push(center + (d0 * tilt.cos() + e * tilt.sin()) * radius);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn degenerates_to_the_goal_near_the_goal() {
        let s = Vec3::zeros();
        let g = Vec3::new(30.0, 0.0, 0.0);
        assert_eq!(
            Terminal::goal_guidance_surface(&s, &g, 2.0, 10.0),
            Terminal::Surface {
                center: g,
                radius: 10.0
            }
        );
        assert_eq!(
            Terminal::goal_guidance_surface(&s, &g, 3.0, 10.0),
            Terminal::Point(g)
        );
        assert_eq!(
            Terminal::goal_guidance_surface(&g, &g, 3.0, 10.0),
            Terminal::Point(g)
        );
    }

    #[test]
    fn candidates_lie_on_the_sphere_and_face_the_point() {
        let t = Terminal::Surface {
            center: Vec3::zeros(),
            radius: 5.0,
        };
        let p = Vec3::new(0.0, 0.0, 9.0);
        let mut out = Vec::new();
        t.candidates(&p, &mut out);
        assert_eq!(out.len(), 5);
        assert_relative_eq!(out[0], Vec3::new(0.0, 0.0, 5.0));
        for q in &out {
            assert_relative_eq!(q.norm(), 5.0, epsilon = 1e-9);
            assert!(t.reaches(q, 1e-9));
            // The segment p→q does not enter the ball: q is in front of the tangent plane.
            assert!((q - p).dot(q) <= 1e-9);
        }
        assert_relative_eq!(t.distance_from(&p), 4.0);
        assert!(t.is_beyond(&Vec3::new(1.0, 0.0, 0.0)));
    }
}
