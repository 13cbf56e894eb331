//! The static-map obstacle penalty (part of `I_o`).

use trust_core::{Aabb, StaticMap, Vec3};
use trust_geometry::Shape;

use super::integrand::{Integrand, SampleGrad, SampleState};
use super::smooth::SmoothedL1;

/// Static-map penalty `L_s = Σ_shapes f_max(c − d_shape(p)) + f_max(c − d_esdf(p)) +
/// Σ_faces f_max(c − d_face(p))`: the smoothed violation of the clearance `c` by each analytic
/// shape of the [`StaticMap`], by its voxel ESDF (if any) and by the six faces of its bounds
/// (the map ends there: a trajectory leaving it has left the known world, and the manager's
/// safety check rejects it), with the closed-form signed distances of `trust-geometry`.
///
/// Summing over shapes (instead of penalizing the map's minimum distance) keeps the cost smooth
/// where two shapes are equally near; where only one shape violates the clearance — the usual
/// case — both agree. Broad phase: per piece, the map's BVH ([`StaticMap::shapes_near`]) lists
/// the shapes whose boxes meet the samples' box inflated by `c`; the others cannot violate the
/// clearance at any sample.
#[derive(Debug, Clone)]
pub struct StaticObstacleTerm<'a> {
    map: &'a StaticMap,
    clearance: f64,
    smoothing: SmoothedL1,
    near: Vec<usize>,
    use_esdf: bool,
    near_bounds: bool,
}

impl<'a> StaticObstacleTerm<'a> {
    /// The penalty against `map` with `clearance` (m) and smoothing `μ`.
    pub fn new(map: &'a StaticMap, clearance: f64, smoothing: f64) -> Self {
        Self {
            map,
            clearance,
            smoothing: SmoothedL1::new(smoothing),
            near: Vec::new(),
            use_esdf: false,
            near_bounds: false,
        }
    }

    /// Broad phase for one piece; `true` if anything may be violated.
    pub(crate) fn begin_piece_impl(&mut self, samples_box: &Aabb) -> bool {
        self.near.clear();
        self.use_esdf = false;
        let b = self.map.bounds();
        self.near_bounds = (0..3).any(|k| {
            !(samples_box.min[k] - b.min[k] >= self.clearance
                && b.max[k] - samples_box.max[k] >= self.clearance)
        });
        if self.map.has_no_obstacles() {
            return self.near_bounds;
        }
        if !(samples_box.min.iter().chain(samples_box.max.iter())).all(|x| x.is_finite()) {
            // Non-finite samples: let the sample evaluation report a non-finite cost.
            self.near.extend(0..self.map.shapes().len());
            self.use_esdf = self.map.esdf().is_some();
            return true;
        }
        self.map
            .shapes_near(&samples_box.inflated(self.clearance), &mut self.near);
        // The ESDF matters only where its coarse lower bound over the samples' box is below
        // the clearance (exact: elsewhere every sample's penalty is 0).
        self.use_esdf = self.map.esdf().is_some_and(|e| {
            e.occupied_count() > 0 && e.lower_bound_in(samples_box) < self.clearance
        });
        self.use_esdf || self.near_bounds || !self.near.is_empty()
    }

    /// Unweighted `L_s` at `p`; adds `weight · ∂L_s/∂p` into `grad_p`.
    #[inline(always)]
    pub(crate) fn at(&self, p: &Vec3, weight: f64, grad_p: &mut Vec3) -> f64 {
        let shapes = self.map.shapes();
        let mut total = 0.0;
        let mut add = |(d, g): (f64, Vec3)| {
            let (value, slope) = self.smoothing.eval(self.clearance - d);
            if slope != 0.0 || value != 0.0 {
                total += value;
                *grad_p -= g * (weight * slope);
            }
        };
        for &i in &self.near {
            if !beyond_clearance(&shapes[i], p, self.clearance) {
                add(shapes[i].distance_and_gradient(p));
            }
        }
        if self.use_esdf
            && let Some(esdf) = self.map.esdf()
            && esdf.lower_bound(p) < self.clearance
        {
            add(esdf.distance_and_gradient(p));
        }
        if self.near_bounds {
            let b = self.map.bounds();
            for k in 0..3 {
                let mut unit = Vec3::zeros();
                unit[k] = 1.0;
                if p[k] - b.min[k] < self.clearance {
                    add((p[k] - b.min[k], unit));
                }
                if b.max[k] - p[k] < self.clearance {
                    add((b.max[k] - p[k], -unit));
                }
            }
        }
        total
    }

    /// Sets `flags[k]` for every node `k` (position `(x[k], y[k], z[k])`) that is not provably
    /// farther than the clearance plus
    /// [`FILTER_MARGIN_M`](crate::costs::integrand::FILTER_MARGIN_M) from a shape kept by the
    /// piece's broad phase (the rejection of [`beyond_clearance`], column by column) or whose
    /// ESDF lower bound ([`trust_geometry::Esdf::lower_bound`]) is below that distance.
    #[expect(
        clippy::neg_cmp_op_on_partial_ord,
        reason = "a NaN must count as possibly active"
    )]
    pub(crate) fn flag_nodes(&self, x: &[f64], y: &[f64], z: &[f64], flags: &mut [bool]) {
        let m = flags.len();
        let (x, y, z) = (&x[..m], &y[..m], &z[..m]);
        let grow = self.clearance + crate::costs::integrand::FILTER_MARGIN_M;
        if self.near_bounds {
            let b = self.map.bounds();
            let (lo, hi) = (b.min.add_scalar(grow), b.max.add_scalar(-grow));
            for (k, flag) in flags.iter_mut().enumerate() {
                let inside = x[k] >= lo.x
                    && x[k] <= hi.x
                    && y[k] >= lo.y
                    && y[k] <= hi.y
                    && z[k] >= lo.z
                    && z[k] <= hi.z;
                *flag |= !inside;
            }
        }
        if self.use_esdf
            && let Some(esdf) = self.map.esdf()
        {
            // The coarse lower bound of the ESDF rejects most nodes with one memory access.
            for (k, flag) in flags.iter_mut().enumerate() {
                *flag |= !(esdf.lower_bound(&Vec3::new(x[k], y[k], z[k])) >= grow);
            }
        }
        let shapes = self.map.shapes();
        for &i in &self.near {
            match &shapes[i] {
                Shape::Sphere(s) => {
                    let (c, r) = (s.center, s.radius + grow);
                    for (k, flag) in flags.iter_mut().enumerate() {
                        let (qx, qy, qz) = (x[k] - c.x, y[k] - c.y, z[k] - c.z);
                        *flag |= !(qx * qx + qy * qy + qz * qz >= r * r);
                    }
                }
                Shape::Cylinder(cyl) => {
                    let (c, r, h) = (cyl.center, cyl.radius + grow, cyl.half_height + grow);
                    for (k, flag) in flags.iter_mut().enumerate() {
                        let (qx, qy, qz) = (x[k] - c.x, y[k] - c.y, z[k] - c.z);
                        *flag |= !(qx * qx + qy * qy >= r * r || qz.abs() >= h);
                    }
                }
                Shape::AaBox(b) => {
                    let (lo, hi) = (b.min.add_scalar(-grow), b.max.add_scalar(grow));
                    for (k, flag) in flags.iter_mut().enumerate() {
                        let outside = x[k] <= lo.x
                            || x[k] >= hi.x
                            || y[k] <= lo.y
                            || y[k] >= hi.y
                            || z[k] <= lo.z
                            || z[k] >= hi.z;
                        *flag |= !outside;
                    }
                }
            }
        }
    }
}

/// Cheap exact rejection before the signed distance: `true` only if `p` is at least `clearance`
/// away from `shape` (no penalty there). Squared distances for spheres and cylinder walls, the
/// inflated box for boxes and cylinder caps (a superset of the points within `clearance`).
#[inline]
fn beyond_clearance(shape: &Shape, p: &Vec3, clearance: f64) -> bool {
    match shape {
        Shape::Sphere(s) => {
            let r = s.radius + clearance;
            (p - s.center).norm_squared() >= r * r
        }
        Shape::Cylinder(c) => {
            let q = p - c.center;
            let r = c.radius + clearance;
            q.x * q.x + q.y * q.y >= r * r || q.z.abs() >= c.half_height + clearance
        }
        Shape::AaBox(b) => {
            (0..3).any(|k| p[k] <= b.min[k] - clearance || p[k] >= b.max[k] + clearance)
        }
    }
}

impl Integrand for StaticObstacleTerm<'_> {
    fn begin_piece(
        &mut self,
        _piece: usize,
        _t_begin: f64,
        _t_end: f64,
        samples_box: &Aabb,
    ) -> bool {
        self.begin_piece_impl(samples_box)
    }

    #[inline]
    fn sample(&mut self, s: &SampleState, grad: &mut SampleGrad) -> f64 {
        self.at(&s.p, 1.0, &mut grad.p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use trust_core::Aabb;

    fn state(p: Vec3) -> SampleState {
        SampleState {
            piece: 0,
            index: 0,
            t: 0.0,
            weight: 1.0,
            p,
            v: Vec3::zeros(),
            a: Vec3::zeros(),
            j: Vec3::zeros(),
        }
    }

    /// The ESDF path (point clouds): positive penalty near the wall, analytic gradient equal to
    /// the finite difference inside one voxel (the trilinear interpolant is smooth there).
    #[test]
    fn esdf_penalty_and_gradient() {
        let bounds = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(4.0, 4.0, 4.0),
        };
        let wall: Vec<Vec3> = (0..40)
            .flat_map(|i| {
                (0..40).map(move |k| Vec3::new(2.05, 0.05 + 0.1 * i as f64, 0.05 + 0.1 * k as f64))
            })
            .collect();
        let map = StaticMap::new(bounds)
            .and_then(|m| m.with_point_cloud(&wall, 0.1))
            .expect("valid cloud");
        let mut term = StaticObstacleTerm::new(&map, 0.3, 1e-2);
        let p = Vec3::new(1.873, 1.234, 2.017);
        let samples = Aabb { min: p, max: p };
        assert!(term.begin_piece(0, 0.0, 1.0, &samples));
        let mut g = SampleGrad::ZERO;
        let value = term.sample(&state(p), &mut g);
        assert!(value > 0.0, "within 0.3 m of the wall");
        let h = 1e-6;
        for d in 0..3 {
            let fd = trust_numdiff::central_difference(
                |s| term.sample(&state(p + Vec3::ith(d, s)), &mut { SampleGrad::ZERO }),
                0.0,
                h,
            );
            assert_relative_eq!(g.p[d], fd, epsilon = 1e-6, max_relative = 1e-6);
        }
    }

    /// The cheap rejection never skips a point closer than the clearance.
    #[test]
    fn rejection_is_exact() {
        use trust_geometry::{AaBox, Cylinder, Sphere};
        let shapes = [
            Shape::Sphere(Sphere {
                center: Vec3::new(1.0, 1.0, 1.0),
                radius: 0.7,
            }),
            Shape::Cylinder(Cylinder {
                center: Vec3::new(1.0, 1.0, 1.0),
                radius: 0.6,
                half_height: 0.9,
            }),
            Shape::AaBox(AaBox {
                min: Vec3::new(0.5, 0.4, 0.3),
                max: Vec3::new(1.5, 1.2, 1.9),
            }),
        ];
        for shape in &shapes {
            for i in 0..=40 {
                for j in 0..=40 {
                    let p = Vec3::new(0.05 * i as f64, 1.0 + 0.013 * j as f64, 0.05 * j as f64);
                    for clearance in [0.0, 0.1, 0.3] {
                        if beyond_clearance(shape, &p, clearance) {
                            assert!(
                                shape.distance_and_gradient(&p).0 >= clearance - 1e-12,
                                "{shape:?} {p:?} {clearance}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn empty_map_is_skipped_away_from_its_faces() {
        let map = StaticMap::empty(Aabb {
            min: Vec3::zeros(),
            max: Vec3::repeat(10.0),
        })
        .expect("bounds");
        let mut term = StaticObstacleTerm::new(&map, 0.3, 1e-2);
        let inside = Aabb {
            min: Vec3::repeat(1.0),
            max: Vec3::repeat(9.0),
        };
        assert!(!term.begin_piece(0, 0.0, 1.0, &inside));
        let touching = Aabb {
            min: Vec3::new(1.0, 1.0, 0.1),
            max: Vec3::repeat(9.0),
        };
        assert!(term.begin_piece(0, 0.0, 1.0, &touching));
    }

    /// Within the clearance of a face of the bounds the penalty pushes inward, with the analytic
    /// gradient of the face distance; a point away from every face costs nothing.
    #[test]
    fn bounds_faces_are_penalized() {
        let map = StaticMap::empty(Aabb {
            min: Vec3::zeros(),
            max: Vec3::repeat(10.0),
        })
        .expect("bounds");
        let mut term = StaticObstacleTerm::new(&map, 0.5, 1e-2);
        let all = Aabb {
            min: Vec3::zeros(),
            max: Vec3::repeat(10.0),
        };
        assert!(term.begin_piece(0, 0.0, 1.0, &all));
        let p = Vec3::new(5.0, 9.8, 0.2);
        let mut g = SampleGrad::ZERO;
        let value = term.sample(&state(p), &mut g);
        assert!(value > 0.0);
        assert!(g.p.y > 0.0 && g.p.z < 0.0 && g.p.x == 0.0, "{:?}", g.p);
        for k in 0..3 {
            let h = 1e-6;
            let fd = trust_numdiff::central_difference(
                |s| term.sample(&state(p + Vec3::ith(k, s)), &mut { SampleGrad::ZERO }),
                0.0,
                h,
            );
            assert_relative_eq!(fd, g.p[k], epsilon = 1e-5, max_relative = 1e-5);
        }
        let mut g = SampleGrad::ZERO;
        assert_eq!(term.sample(&state(Vec3::repeat(5.0)), &mut g), 0.0);
        assert_eq!(g.p, Vec3::zeros());
    }
}
