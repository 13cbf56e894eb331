//! Space the vehicle's body fills: free whatever the sensor saw.
//!
//! A vehicle of radius `R` at `c` fills the ball `B(c, R)`; nothing else is there (or it would
//! have collided). The known-free commit check ([`crate::LocalMap::segment_known_free_beside`])
//! therefore accepts a voxel it has not observed free when the part of it the vehicle's
//! clearance tube reaches lies inside that ball: a vehicle at rest may commit to its own place,
//! and a plan leaving it needs observed free space only where it pokes out of the body
//! (decision 0051). The test here is conservative: a box is split at most [`SPLIT_DEPTH`] times
//! and a piece that still straddles both the tube and the body's surface counts as outside.

use trust_geometry::Vec3;

/// How many times a voxel box is halved along each axis before a piece that straddles the
/// body's surface counts as outside it: 2 (pieces of a quarter voxel, 2.5 cm at 0.1 m).
pub const SPLIT_DEPTH: u32 = 2;

/// How far a plan's end may lie from the body's centre and still count as the vehicle's own
/// place, in voxels: 0.05 (5 mm at 0.1 m). A plan's start and the measured position differ by
/// the tracking error (1–2 mm for a hovering vehicle in the simulator), and the smallest
/// difference leaves a sliver of tube beside the body; a plan held within it moves the vehicle
/// at most this far into unseen space per cycle.
pub const HOVER_VOXELS: f64 = 0.05;

/// A ball the vehicle's body fills.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyBall {
    /// The vehicle's position (m).
    pub center: Vec3,
    /// The vehicle's radius (m).
    pub radius: f64,
}

impl BodyBall {
    /// True if the centre and the radius are finite and the radius is not negative.
    pub fn is_valid(&self) -> bool {
        self.center.iter().all(|x| x.is_finite()) && self.radius.is_finite() && self.radius >= 0.0
    }
}

/// Squared distance from `p` to the box `[lo, hi]` (0 inside).
fn dist2_to_box(p: &Vec3, lo: &Vec3, hi: &Vec3) -> f64 {
    (0..3)
        .map(|i| (lo[i] - p[i]).max(0.0).max(p[i] - hi[i]).powi(2))
        .sum()
}

/// Squared distance from `p` to the farthest corner of the box `[lo, hi]`.
fn far2_to_box(p: &Vec3, lo: &Vec3, hi: &Vec3) -> f64 {
    (0..3)
        .map(|i| (p[i] - lo[i]).abs().max((hi[i] - p[i]).abs()).powi(2))
        .sum()
}

/// Distance from `p` to the segment `[a, b]`.
fn dist_to_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + t * ab)).norm()
}

/// A lower bound on the distance from the segment `[a, b]` to the box `[lo, hi]`, tight to
/// 1e-9 of the segment's length: the distance along the segment is convex, so a ternary
/// search brackets its minimum.
fn segment_box_distance(a: &Vec3, b: &Vec3, lo: &Vec3, hi: &Vec3) -> f64 {
    let at = |t: f64| dist2_to_box(&(a + t * (b - a)), lo, hi).sqrt();
    let (mut l, mut h) = (0.0, 1.0);
    for _ in 0..60 {
        let (m1, m2) = (l + (h - l) / 3.0, h - (h - l) / 3.0);
        if at(m1) <= at(m2) {
            h = m2;
        } else {
            l = m1;
        }
    }
    (at(0.5 * (l + h)) - 0.5 * (h - l) * (b - a).norm()).max(0.0)
}

/// One piece of a segment's clearance tube: the ball round an end, or the cylinder of points
/// whose nearest point of the segment lies strictly inside it.
enum Piece {
    Ball(Vec3),
    Cylinder(Vec3, Vec3),
}

impl Piece {
    /// True if the piece (of radius `r`) surely misses the cell of centre `m` and half
    /// extents `half`.
    fn misses(&self, m: &Vec3, half: &Vec3, r: f64) -> bool {
        match self {
            Piece::Ball(p) => {
                let lo = m - half;
                let hi = m + half;
                dist2_to_box(p, &lo, &hi) > r * r
            }
            Piece::Cylinder(a, b) => {
                let ab = b - a;
                let len = ab.norm();
                let u = ab / len;
                let along = (m - a).dot(&u);
                let spread: f64 = (0..3).map(|i| half[i] * u[i].abs()).sum();
                along + spread < 0.0
                    || along - spread > len
                    || dist_to_segment(m, a, b) - half.norm() > r
            }
        }
    }
}

/// True if every point of the cell `[lo, hi]` in `piece` (radius `r`) lies in `body`: the cell
/// is halved `depth` more times where it straddles both.
fn cell_in_body(lo: &Vec3, hi: &Vec3, piece: &Piece, r: f64, body: &BodyBall, depth: u32) -> bool {
    let (m, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    if piece.misses(&m, &half, r) || far2_to_box(&body.center, lo, hi) <= body.radius.powi(2) {
        return true;
    }
    if depth == 0 || dist2_to_box(&body.center, lo, hi) >= body.radius.powi(2) {
        return false;
    }
    (0..8).all(|octant: usize| {
        let pick = |i: usize| octant >> i & 1 == 1;
        let l = Vec3::from_fn(|i, _| if pick(i) { m[i] } else { lo[i] });
        let h = Vec3::from_fn(|i, _| if pick(i) { hi[i] } else { m[i] });
        cell_in_body(&l, &h, piece, r, body, depth - 1)
    })
}

/// True if every point of the box `[lo, hi]` within `clearance` of the segment `[a, b]` lies in
/// `body`, up to `hover_m` (conservative otherwise). The tube is the balls round the ends and
/// the cylinder between them; a ball round an end within `hover_m` of the body's centre counts
/// as the body (a vehicle holding its place: the plan's start and the measured position differ
/// by the tracking error). The box is halved [`SPLIT_DEPTH`] times where a piece and the body's
/// surface both cross it.
pub fn tube_part_in_body(
    lo: &Vec3,
    hi: &Vec3,
    a: &Vec3,
    b: &Vec3,
    clearance: f64,
    body: &BodyBall,
    hover_m: f64,
) -> bool {
    let r = clearance;
    if segment_box_distance(a, b, lo, hi) > r {
        return true;
    }
    let held = |p: &Vec3| (p - body.center).norm() + r <= body.radius + hover_m;
    if held(a) && held(b) {
        return true;
    }
    if dist2_to_box(&body.center, lo, hi) >= body.radius.powi(2) {
        return false;
    }
    let mut pieces = Vec::with_capacity(3);
    for p in [a, b] {
        if !held(p) {
            pieces.push(Piece::Ball(*p));
        }
    }
    if (b - a).norm() > 0.0 {
        pieces.push(Piece::Cylinder(*a, *b));
    }
    pieces
        .iter()
        .all(|piece| cell_in_body(lo, hi, piece, r, body, SPLIT_DEPTH))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const HOVER: f64 = 1e-3;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    fn body(c: Vec3, radius: f64) -> BodyBall {
        BodyBall { center: c, radius }
    }

    /// Points of the box on a grid (its corners included).
    fn grid(lo: &Vec3, hi: &Vec3, n: usize) -> Vec<Vec3> {
        let f = |t: usize, i: usize| lo[i] + (hi[i] - lo[i]) * t as f64 / n as f64;
        let mut out = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                for k in 0..=n {
                    out.push(v(f(i, 0), f(j, 1), f(k, 2)));
                }
            }
        }
        out
    }

    #[test]
    fn a_vehicle_at_rest_fills_its_own_clearance() {
        let me = body(v(0.03, -0.02, 0.04), 0.3);
        let (lo, hi) = (v(0.2, 0.0, 0.0), v(0.3, 0.1, 0.1));
        let c = me.center;
        assert!(tube_part_in_body(&lo, &hi, &c, &c, 0.3, &me, HOVER));
        // Half a millimetre off its place: still its place.
        let near = c + v(0.0, 5e-4, 0.0);
        assert!(tube_part_in_body(&lo, &hi, &near, &near, 0.3, &me, HOVER));
        // A plan leaving it 5 cm towards the box pokes out of the body into the box.
        let toward = c + v(0.05, 0.0, 0.0);
        assert!(!tube_part_in_body(&lo, &hi, &c, &toward, 0.3, &me, HOVER));
        // Away from the box, the tube reaches the box only inside the body.
        let away = c - v(0.05, 0.0, 0.0);
        assert!(tube_part_in_body(&lo, &hi, &c, &away, 0.3, &me, HOVER));
    }

    #[test]
    fn a_plan_leaving_the_body_sweeps_beside_it() {
        // The box straddles the body's surface beside the motion: the tube's side leaves the
        // ball right where the motion starts, so a voxel there must be seen.
        let me = body(v(0.0, 0.0, 0.0), 0.2);
        let (lo, hi) = (v(-0.05, 0.15, -0.05), v(0.05, 0.25, 0.05));
        let ahead = v(0.1, 0.0, 0.0);
        assert!(!tube_part_in_body(
            &lo, &hi, &me.center, &ahead, 0.2, &me, HOVER
        ));
        assert!(tube_part_in_body(
            &lo, &hi, &me.center, &me.center, 0.2, &me, HOVER
        ));
    }

    #[test]
    fn a_box_out_of_reach_needs_no_body() {
        let far = body(v(10.0, 10.0, 10.0), 0.0);
        let (lo, hi) = (v(1.0, 1.0, 1.0), v(1.1, 1.1, 1.1));
        let o = Vec3::zeros();
        assert!(tube_part_in_body(
            &lo,
            &hi,
            &o,
            &v(0.5, 0.0, 0.0),
            0.3,
            &far,
            HOVER
        ));
        assert!(!tube_part_in_body(
            &lo,
            &hi,
            &o,
            &v(1.05, 1.05, 0.9),
            0.3,
            &far,
            HOVER
        ));
    }

    #[test]
    fn a_body_must_be_finite() {
        assert!(!body(v(f64::NAN, 0.0, 0.0), 0.1).is_valid());
        assert!(!body(Vec3::zeros(), -0.1).is_valid());
        assert!(!body(Vec3::zeros(), f64::INFINITY).is_valid());
        assert!(body(Vec3::zeros(), 0.0).is_valid());
    }

    #[test]
    fn the_segment_box_distance_is_a_tight_lower_bound() {
        let (lo, hi) = (v(1.0, 0.0, 0.0), v(2.0, 1.0, 1.0));
        let d = segment_box_distance(&v(0.0, 2.0, 0.5), &v(3.0, 2.0, 0.5), &lo, &hi);
        assert!((d - 1.0).abs() < 1e-8, "{d}");
        assert_eq!(
            segment_box_distance(&v(0.0, 0.5, 0.5), &v(3.0, 0.5, 0.5), &lo, &hi),
            0.0
        );
        let p = v(0.0, -1.0, 0.5);
        assert!((segment_box_distance(&p, &p, &lo, &hi) - 2f64.sqrt()).abs() < 1e-12);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        /// Sound: when the test accepts, no grid point of the box within the clearance of the
        /// segment lies outside the body (grown by the hover tolerance).
        #[test]
        fn an_accepted_box_has_no_point_in_the_tube_outside_the_body(
            c in prop::array::uniform3(-0.2f64..0.2),
            start in prop::array::uniform3(-0.05f64..0.05),
            d in prop::array::uniform3(-0.3f64..0.3),
            corner in prop::array::uniform3(-0.6f64..0.5),
            r in 0.05f64..0.4,
        ) {
            let me = body(v(c[0], c[1], c[2]), r);
            let a = me.center + v(start[0], start[1], start[2]);
            let b = a + v(d[0], d[1], d[2]);
            let lo = v(corner[0], corner[1], corner[2]);
            let hi = lo + v(0.1, 0.1, 0.1);
            if tube_part_in_body(&lo, &hi, &a, &b, r, &me, HOVER) {
                for p in grid(&lo, &hi, 8) {
                    prop_assert!(
                        dist_to_segment(&p, &a, &b) > r || (p - me.center).norm() <= r + HOVER,
                        "{p:?} is in the tube and outside the body"
                    );
                }
            }
        }

        /// Not too conservative: a box well clear of the tube, or wholly inside the body,
        /// passes; so does any box for a vehicle holding its place.
        #[test]
        fn a_clear_box_passes(
            c in prop::array::uniform3(-0.2f64..0.2),
            d in prop::array::uniform3(-0.3f64..0.3),
            corner in prop::array::uniform3(-0.6f64..0.5),
            r in 0.05f64..0.4,
        ) {
            let me = body(v(c[0], c[1], c[2]), r);
            let a = me.center;
            let b = a + v(d[0], d[1], d[2]);
            let lo = v(corner[0], corner[1], corner[2]);
            let hi = lo + v(0.1, 0.1, 0.1);
            let clear = grid(&lo, &hi, 8).iter().all(|p| dist_to_segment(p, &a, &b) > r + 0.1);
            let inside = far2_to_box(&me.center, &lo, &hi) <= r * r;
            if clear || inside {
                prop_assert!(tube_part_in_body(&lo, &hi, &a, &b, r, &me, HOVER));
            }
            prop_assert!(tube_part_in_body(&lo, &hi, &a, &a, r, &me, HOVER));
        }
    }
}
