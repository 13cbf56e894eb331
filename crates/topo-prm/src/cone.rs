//! Swept obstacle volumes for the roadmap: predictive directional cones (paper eq. PDC) and single
//! time slices of a forecast (for TVD chords).
//!
//! A forecast sphere whose centre moves linearly while its radius grows linearly sweeps the convex
//! hull of its first and last balls (a *round cone*): the Minkowski combination
//! `(1−λ)·B(c₀, r₀) + λ·B(c₁, r₁)` is the ball `B(c_λ, r_λ)`, so the union over the horizon equals the
//! hull. A vertical cylinder moving horizontally sweeps a 2-D round cone in `xy` times a vertical
//! slab; [`Cone`] uses the slab spanning both end cylinders (whose half-heights grow with the
//! forecast's inflation, see `trust_predict::ObstacleShape`), which is exact when the half-height does
//! not change and the motion is horizontal, and a conservative superset otherwise.
//!
//! Everything here is closed form except the exact segment test, which minimizes the (convex) signed
//! distance along the segment with tangent-line lower bounds (1-D cutting planes) after cheap box and
//! capsule accept/reject tests.
//!
//! `trust_predict::Pdc` describes the same set for other users; this module is the roadmap's own
//! tuned copy (precomputed boxes, a shared segment box, early exits), because the visibility test is
//! the hot path of both PRMs.

use trust_core::{Aabb, Forecast, ObstacleShape, Vec3};

/// Iteration cap of [`convex_segment_clear`] (each step shrinks the bracket by at least 5 %; in
/// practice a handful of steps decide).
const CUTTING_PLANE_ITERATIONS: usize = 200;

/// The cross-section of a swept obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConeKind {
    /// A ball.
    Sphere,
    /// A vertical cylinder.
    Cylinder,
}

/// A convex swept volume: the hull of the obstacle at the start of the horizon (centre `a`, radius
/// `ra`) and at its end (centre `b`, radius `rb`); for cylinders, times a vertical slab.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    kind: ConeKind,
    a: Vec3,
    b: Vec3,
    ra: f64,
    rb: f64,
    /// Vertical slab of a cylinder cone (lower, upper); unused for spheres.
    slab: (f64, f64),
    aabb: Aabb,
}

/// Negative or non-finite sizes become 0.
fn clean(r: f64) -> f64 {
    if r.is_finite() { r.max(0.0) } else { 0.0 }
}

impl Cone {
    /// The round cone swept by a ball moving from `B(a, ra)` to `B(b, rb)` (radius changing linearly).
    /// Negative or non-finite radii are treated as 0.
    pub fn sphere(a: Vec3, b: Vec3, ra: f64, rb: f64) -> Self {
        let (ra, rb) = (clean(ra), clean(rb));
        let lo = (a - Vec3::repeat(ra)).inf(&(b - Vec3::repeat(rb)));
        let hi = (a + Vec3::repeat(ra)).sup(&(b + Vec3::repeat(rb)));
        Cone {
            kind: ConeKind::Sphere,
            a,
            b,
            ra,
            rb,
            slab: (0.0, 0.0),
            aabb: Aabb { min: lo, max: hi },
        }
    }

    /// The volume swept by a vertical cylinder moving from centre `a` (radius `ra`, half-height `ha`)
    /// to centre `b` (radius `rb`, half-height `hb`): the 2-D round cone of the discs in `xy` times the
    /// vertical slab spanning both cylinders. Exact for horizontal motion at constant height, a
    /// conservative superset otherwise. Negative or non-finite sizes are treated as 0.
    pub fn cylinder(a: Vec3, b: Vec3, ra: f64, rb: f64, ha: f64, hb: f64) -> Self {
        let (ra, rb, ha, hb) = (clean(ra), clean(rb), clean(ha), clean(hb));
        let slab = ((a.z - ha).min(b.z - hb), (a.z + ha).max(b.z + hb));
        let lo = Vec3::new((a.x - ra).min(b.x - rb), (a.y - ra).min(b.y - rb), slab.0);
        let hi = Vec3::new((a.x + ra).max(b.x + rb), (a.y + ra).max(b.y + rb), slab.1);
        Cone {
            kind: ConeKind::Cylinder,
            a,
            b,
            ra,
            rb,
            slab,
            aabb: Aabb { min: lo, max: hi },
        }
    }

    /// The obstacle of `forecast` swept between times `t_a` and `t_b`.
    pub fn between(forecast: &Forecast, t_a: f64, t_b: f64) -> Self {
        let (a, b) = (forecast.center(t_a), forecast.center(t_b));
        let (ra, rb) = (forecast.radius(t_a), forecast.radius(t_b));
        match forecast.shape {
            ObstacleShape::Cylinder { .. } => Cone::cylinder(
                a,
                b,
                ra,
                rb,
                forecast.vertical_half_extent(t_a),
                forecast.vertical_half_extent(t_b),
            ),
            _ => Cone::sphere(a, b, ra, rb),
        }
    }

    /// The predictive directional cone of `forecast` over `[t_start, t_start + horizon_s]` (paper eq.
    /// PDC): the obstacle inflated to `radius(t)` at `center(t)` for every `t` in the window.
    pub fn from_forecast(forecast: &Forecast, t_start: f64, horizon_s: f64) -> Self {
        Cone::between(forecast, t_start, t_start + horizon_s.max(0.0))
    }

    /// The obstacle as forecast at time `t` (a zero-length sweep).
    pub fn at_time(forecast: &Forecast, t: f64) -> Self {
        Cone::between(forecast, t, t)
    }

    /// The cross-section kind.
    pub fn kind(&self) -> ConeKind {
        self.kind
    }

    /// Centres and radii of the first and last slice: `(a, ra, b, rb)`.
    pub fn ends(&self) -> (Vec3, f64, Vec3, f64) {
        (self.a, self.ra, self.b, self.rb)
    }

    /// Axis-aligned bounding box.
    pub fn aabb(&self) -> Aabb {
        self.aabb
    }

    /// Signed distance from `p` (negative inside). Exact outside; inside, the depth below the
    /// nearest face of the partition used for the gradient (sign always exact).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// Signed distance from `p` and its gradient (a unit vector, never NaN).
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        match self.kind {
            ConeKind::Sphere => round_cone_sdf(&self.a, &self.b, self.ra, self.rb, p),
            ConeKind::Cylinder => {
                let flat = |v: &Vec3| Vec3::new(v.x, v.y, 0.0);
                let (dxy, gxy) =
                    round_cone_sdf(&flat(&self.a), &flat(&self.b), self.ra, self.rb, &flat(p));
                let mid = 0.5 * (self.slab.0 + self.slab.1);
                let half = 0.5 * (self.slab.1 - self.slab.0);
                let dz = (p.z - mid).abs() - half;
                let gz = Vec3::new(0.0, 0.0, if p.z >= mid { 1.0 } else { -1.0 });
                let gxy = Vec3::new(gxy.x, gxy.y, 0.0);
                if dxy > 0.0 || dz > 0.0 {
                    let (ex, ez) = (dxy.max(0.0), dz.max(0.0));
                    let d = (ex * ex + ez * ez).sqrt();
                    (d, (gxy * ex + gz * ez) / d)
                } else if dxy >= dz {
                    (dxy, gxy)
                } else {
                    (dz, gz)
                }
            }
        }
    }

    /// True if `p` is closer than `clearance` to the cone (or inside it).
    pub fn contains(&self, p: &Vec3, clearance: f64) -> bool {
        // Outside the box grown by the clearance: farther than that from the cone.
        let far = clearance >= 0.0
            && (0..3).any(|i| {
                p[i] < self.aabb.min[i] - clearance || p[i] > self.aabb.max[i] + clearance
            });
        !far && self.signed_distance(p) < clearance
    }

    /// True if every point of the segment `[p, q]` keeps at least `clearance` from the cone. Cheap
    /// box and capsule tests decide most cases; the rest minimize the convex signed distance along the
    /// segment with tangent-line lower bounds ([`convex_segment_clear`]). A NaN clearance or non-finite
    /// end point gives `false`.
    pub fn segment_clear(&self, p: &Vec3, q: &Vec3, clearance: f64) -> bool {
        if clearance.is_nan() || !p.iter().chain(q.iter()).all(|c| c.is_finite()) {
            return false;
        }
        let c = clearance.max(0.0);
        self.segment_clear_in_box(p, q, c, &Aabb::from_segment(p, q))
    }

    /// [`Cone::segment_clear`] for a finite segment, a clearance `c >= 0` and the segment's box
    /// `seg_box` computed once by the caller (no validation).
    pub(crate) fn segment_clear_in_box(&self, p: &Vec3, q: &Vec3, c: f64, seg_box: &Aabb) -> bool {
        for i in 0..3 {
            if seg_box.min[i] > self.aabb.max[i] + c || seg_box.max[i] < self.aabb.min[i] - c {
                return true;
            }
        }
        let rmax = self.ra.max(self.rb);
        match self.kind {
            ConeKind::Sphere => {
                let d = segment_segment_distance(p, q, &self.a, &self.b);
                if d >= rmax + c {
                    return true;
                }
                if d < self.ra.min(self.rb) + c {
                    return false;
                }
            }
            ConeKind::Cylinder => {
                let flat = |v: &Vec3| Vec3::new(v.x, v.y, 0.0);
                let d =
                    segment_segment_distance(&flat(p), &flat(q), &flat(&self.a), &flat(&self.b));
                if d >= rmax + c {
                    return true;
                }
            }
        }
        convex_segment_clear(p, q, c, |x| self.distance_and_gradient(x))
    }

    /// Obstacle-aware samples (paper Sec. III-B): `slices` cross-sections evenly spaced along the
    /// sweep (perpendicular to the predicted velocity), `per_slice` points on each at signed distance
    /// `offset` outside the cone and inside `region`, appended to `out`.
    ///
    /// * Sphere cones: points on the ring around the slice centre.
    /// * Cylinder cones: points on the two vertical sides of the slice at heights spread over the part
    ///   of the slab inside `region`, and above and below the cylinder.
    /// * A cone that does not move has one slice: a horizontal ring (at the region's mid-height for a
    ///   cylinder).
    /// * A moving cone also gets one point beyond each cap, on the axis of the sweep (at the region's
    ///   mid-height for a cylinder): the ways around its front and back.
    ///
    /// Candidates are spread evenly over each slice's boundary and those outside `region` are dropped,
    /// so that the samples land where the planner samples. At most `slices · per_slice + 2` points.
    pub fn surface_samples(
        &self,
        slices: usize,
        per_slice: usize,
        offset: f64,
        region: &Aabb,
        out: &mut Vec<Vec3>,
    ) {
        if slices == 0 || per_slice == 0 || !offset.is_finite() {
            return;
        }
        let sweep = self.b - self.a;
        let moving = sweep.norm() > 1e-9;
        let slice_count = if moving { slices } else { 1 };
        let reach =
            self.ra.max(self.rb) + sweep.norm() + (self.slab.1 - self.slab.0) + offset.abs() + 1.0;
        // Slack for the cheap region pre-test of a candidate direction: the exact point is within this
        // distance of its guess (the hull's cross-section radius exceeds the slice radius by at most
        // the radius change over the sweep, scaled by the cone's slope).
        let slack = 2.0 * (self.ra - self.rb).abs() + offset.abs() + 0.5;
        // Cosine of the lateral surface's slope: a ray perpendicular to the axis from the slice
        // centre (radius r) meets the offset surface at (r + offset) / cos α when it leaves through
        // the lateral surface — the Newton start, exact in that case.
        let axis_len = match self.kind {
            ConeKind::Sphere => sweep.norm(),
            ConeKind::Cylinder => sweep.x.hypot(sweep.y),
        };
        let sin_a = if axis_len > (self.ra - self.rb).abs() {
            (self.ra - self.rb) / axis_len
        } else {
            0.0
        };
        let cos_a = (1.0 - sin_a * sin_a).sqrt().max(0.05);
        let mut candidates: Vec<(Vec3, Vec3, f64)> = Vec::new();
        let mut kept = Vec::new();
        for k in 0..slice_count {
            let s = if slice_count == 1 {
                0.5 * f64::from(u8::from(moving))
            } else {
                k as f64 / (slice_count - 1) as f64
            };
            let center = self.a + sweep * s;
            let r_k = self.ra + (self.rb - self.ra) * s;
            let stagger = 0.5 * (k % 2) as f64;
            let lateral = (r_k + offset) / cos_a;
            candidates.clear();
            let ring = |axis: &Vec3, origin: Vec3, n: usize, out: &mut Vec<(Vec3, Vec3, f64)>| {
                let [_, w1, w2] = crate::sampling::frame(&Vec3::zeros(), axis);
                for j in 0..n {
                    let theta = std::f64::consts::TAU * (j as f64 + stagger) / n as f64;
                    out.push((origin, w1 * theta.cos() + w2 * theta.sin(), lateral));
                }
            };
            match (self.kind, moving) {
                (ConeKind::Sphere, true) => {
                    ring(&sweep.normalize(), center, 4 * per_slice, &mut candidates);
                }
                (ConeKind::Sphere, false) => {
                    ring(&Vec3::z(), center, 4 * per_slice, &mut candidates)
                }
                (ConeKind::Cylinder, _) => {
                    let z_mid =
                        (0.5 * (region.min.z + region.max.z)).clamp(self.slab.0, self.slab.1);
                    let flat_sweep = Vec3::new(sweep.x, sweep.y, 0.0);
                    if flat_sweep.norm() > 1e-9 {
                        let side = Vec3::new(-flat_sweep.y, flat_sweep.x, 0.0).normalize();
                        let z_lo = region.min.z.max(self.slab.0);
                        let z_hi = region.max.z.min(self.slab.1);
                        let heights = 2 * per_slice;
                        if z_lo <= z_hi {
                            for j in 0..heights {
                                let z = z_lo + (j as f64 + 0.5) / heights as f64 * (z_hi - z_lo);
                                let origin = Vec3::new(center.x, center.y, z);
                                candidates.push((origin, side, lateral));
                                candidates.push((origin, -side, lateral));
                            }
                        }
                    } else {
                        ring(
                            &Vec3::z(),
                            Vec3::new(center.x, center.y, z_mid),
                            4 * per_slice,
                            &mut candidates,
                        );
                    }
                    let top = Vec3::new(center.x, center.y, z_mid);
                    candidates.push((top, Vec3::z(), self.slab.1 - z_mid + offset));
                    candidates.push((top, -Vec3::z(), z_mid - self.slab.0 + offset));
                }
            }
            kept.clear();
            for (origin, dir, y0) in &candidates {
                let guess = origin + dir * (r_k + offset);
                if region.distance_to_point(&guess) > slack {
                    continue;
                }
                let p = self.point_at_distance(origin, dir, offset, *y0, reach);
                if region.contains(&p) {
                    kept.push(p);
                }
            }
            if kept.len() <= per_slice {
                out.extend_from_slice(&kept);
            } else {
                out.extend((0..per_slice).map(|i| kept[i * kept.len() / per_slice]));
            }
            // The end slices also get the point on the axis beyond the cap: the way around the front
            // or the back of the swept volume.
            if moving && (k == 0 || k + 1 == slice_count) {
                let axial = match self.kind {
                    ConeKind::Sphere => Some(sweep / sweep.norm()),
                    ConeKind::Cylinder => {
                        let flat = Vec3::new(sweep.x, sweep.y, 0.0);
                        let n = flat.norm();
                        (n > 1e-9).then(|| flat / n)
                    }
                };
                if let Some(axial) = axial {
                    let dir = if k == 0 { -axial } else { axial };
                    let origin = match self.kind {
                        ConeKind::Sphere => center,
                        ConeKind::Cylinder => Vec3::new(
                            center.x,
                            center.y,
                            (0.5 * (region.min.z + region.max.z)).clamp(self.slab.0, self.slab.1),
                        ),
                    };
                    let r_end = if k == 0 { self.ra } else { self.rb };
                    let p = self.point_at_distance(&origin, &dir, offset, r_end + offset, reach);
                    if region.contains(&p) {
                        out.push(p);
                    }
                }
            }
        }
    }

    /// The point on the ray `origin + y·dir` (from a point inside the cone) whose signed distance is
    /// `offset`: Newton steps on `d(y) − offset` with the analytic gradient from `y = y0`, falling
    /// back to bisection on `y ∈ [0, reach]` (the distance grows along the ray) if they do not
    /// converge.
    fn point_at_distance(
        &self,
        origin: &Vec3,
        dir: &Vec3,
        offset: f64,
        y0: f64,
        reach: f64,
    ) -> Vec3 {
        let mut y = if y0.is_finite() { y0 } else { offset }.clamp(0.0, reach);
        for _ in 0..8 {
            let (d, g) = self.distance_and_gradient(&(origin + dir * y));
            let err = offset - d;
            if err.abs() < 1e-9 {
                return origin + dir * y;
            }
            let slope = g.dot(dir);
            if slope.is_nan() || slope <= 0.05 {
                break;
            }
            y = (y + err / slope).clamp(0.0, reach);
        }
        let (mut lo, mut hi) = (0.0, reach);
        for _ in 0..48 {
            let mid = 0.5 * (lo + hi);
            if self.signed_distance(&(origin + dir * mid)) < offset {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        origin + dir * hi
    }
}

impl crate::gjk::SupportMap for Cone {
    fn support(&self, d: &Vec3) -> Vec3 {
        match self.kind {
            ConeKind::Sphere => {
                let n = d.norm();
                if n.is_nan() || n <= 0.0 {
                    return self.a;
                }
                let u = d / n;
                let (pa, pb) = (self.a + u * self.ra, self.b + u * self.rb);
                if pa.dot(d) >= pb.dot(d) { pa } else { pb }
            }
            ConeKind::Cylinder => {
                let n = (d.x * d.x + d.y * d.y).sqrt();
                let (x, y) = if n > 0.0 {
                    let (ux, uy) = (d.x / n, d.y / n);
                    let (ax, ay) = (self.a.x + ux * self.ra, self.a.y + uy * self.ra);
                    let (bx, by) = (self.b.x + ux * self.rb, self.b.y + uy * self.rb);
                    if ax * d.x + ay * d.y >= bx * d.x + by * d.y {
                        (ax, ay)
                    } else {
                        (bx, by)
                    }
                } else {
                    (self.a.x, self.a.y)
                };
                let z = if d.z >= 0.0 { self.slab.1 } else { self.slab.0 };
                Vec3::new(x, y, z)
            }
        }
    }
}

/// Signed distance from `p` to the convex hull of the balls `B(a, ra)` and `B(b, rb)` (a round cone),
/// with its gradient. Exact outside and on the surface; inside it is the (negative) distance to the
/// face of the nearest region (cap a, lateral surface, cap b). The gradient is a unit vector.
pub fn round_cone_sdf(a: &Vec3, b: &Vec3, ra: f64, rb: f64, p: &Vec3) -> (f64, Vec3) {
    let ab = b - a;
    let len = ab.norm();
    // One ball contains the other (or the sweep is a point): a single sphere.
    if len <= (ra - rb).abs() || len <= 1e-12 {
        return if ra >= rb {
            sphere(a, ra, p)
        } else {
            sphere(b, rb, p)
        };
    }
    let u = ab / len;
    let ap = p - a;
    // 2-D coordinates in the half-plane through the axis: x along the axis, y >= 0 radial.
    let x = ap.dot(&u);
    let radial = ap - u * x;
    let y = radial.norm();
    let radial_dir = if y > 1e-12 {
        radial / y
    } else {
        any_perpendicular(&u)
    };
    // The lateral line is tangent to both circles; its outward normal is (sin α, cos α).
    let sin_a = (ra - rb) / len;
    let cos_a = (1.0 - sin_a * sin_a).max(0.0).sqrt();
    // Tangent direction from a toward b along the lateral line: (cos α, −sin α).
    let along = x * cos_a - y * sin_a;
    if along < 0.0 {
        sphere(a, ra, p)
    } else if along > len * cos_a {
        sphere(b, rb, p)
    } else {
        let d = x * sin_a + y * cos_a - ra;
        (d, (u * sin_a + radial_dir * cos_a).normalize())
    }
}

fn sphere(c: &Vec3, r: f64, p: &Vec3) -> (f64, Vec3) {
    trust_geometry::sphere_sdf(c, r, p)
}

/// A unit vector perpendicular to `u` (unit).
fn any_perpendicular(u: &Vec3) -> Vec3 {
    let pick = if u.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    (pick - u * u.dot(&pick)).normalize()
}

/// Parameters `(s, t) ∈ [0, 1]²` of the closest points `p0 + s·(p1 − p0)` and `q0 + t·(q1 − q0)` of
/// the segments `[p0, p1]` and `[q0, q1]` (clamped projection; degenerate segments allowed).
pub fn segment_segment_params(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> (f64, f64) {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.dot(&d1);
    let e = d2.dot(&d2);
    let f = d2.dot(&r);
    let tiny = 1e-18;
    if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > tiny * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    }
}

/// Distance between the segments `[p0, p1]` and `[q0, q1]` (closest points by clamped projection;
/// degenerate segments allowed).
pub fn segment_segment_distance(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> f64 {
    let (s, t) = segment_segment_params(p0, p1, q0, q1);
    ((p0 + (p1 - p0) * s) - (q0 + (q1 - q0) * t)).norm()
}

/// Whether a convex function `f` (value and gradient) stays at or above `c` along the segment
/// `[p, q]`.
///
/// Kelley's cutting-plane method in one dimension: the tangent lines at the ends of the bracket bound
/// the function from below, so the search stops as soon as that bound reaches `c` (clear) or a value
/// below `c` is seen (blocked); otherwise it evaluates at the tangents' intersection and shrinks the
/// bracket by the sign of the derivative there. Subgradients at kinks are valid.
pub fn convex_segment_clear(p: &Vec3, q: &Vec3, c: f64, f: impl Fn(&Vec3) -> (f64, Vec3)) -> bool {
    let d = q - p;
    let eval = |s: f64| {
        let (v, g) = f(&(p + d * s));
        (v, g.dot(&d))
    };
    let (mut lo, (mut f_lo, mut d_lo)) = (0.0, eval(0.0));
    if f_lo.is_nan() || f_lo < c {
        return false;
    }
    let (mut hi, (mut f_hi, mut d_hi)) = (1.0, eval(1.0));
    if f_hi.is_nan() || f_hi < c {
        return false;
    }
    for _ in 0..CUTTING_PLANE_ITERATIONS {
        if d_lo >= 0.0 || d_hi <= 0.0 {
            // Monotone on the bracket: the minimum is at an end, already checked.
            return true;
        }
        let width = hi - lo;
        let mut m = (f_hi - f_lo + d_lo * lo - d_hi * hi) / (d_lo - d_hi);
        let bound = f_lo + d_lo * (m - lo);
        if bound >= c {
            return true;
        }
        if width < 1e-12 {
            return true;
        }
        // Keep the new point away from the ends so that the bracket always shrinks.
        m = m.clamp(lo + 0.05 * width, hi - 0.05 * width);
        let (f_m, d_m) = eval(m);
        if f_m.is_nan() || f_m < c {
            return false;
        }
        if d_m > 0.0 {
            (hi, f_hi, d_hi) = (m, f_m, d_m);
        } else {
            (lo, f_lo, d_lo) = (m, f_m, d_m);
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// Brute-force distance to the union of slices (the definition, eq. PDC).
    fn brute_sphere_cone(a: &Vec3, b: &Vec3, ra: f64, rb: f64, p: &Vec3) -> f64 {
        (0..=4000)
            .map(|k| {
                let s = k as f64 / 4000.0;
                (p - (a + (b - a) * s)).norm() - (ra + (rb - ra) * s)
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn v3() -> impl Strategy<Value = Vec3> {
        prop::array::uniform3(-4.0..4.0f64).prop_map(|a| Vec3::new(a[0], a[1], a[2]))
    }

    proptest! {
        #[test]
        fn round_cone_matches_the_union_of_slices_outside(
            a in v3(), b in v3(), ra in 0.1..2.0f64, rb in 0.1..2.0f64, p in v3()
        ) {
            let brute = brute_sphere_cone(&a, &b, ra, rb, &p);
            let (d, g) = round_cone_sdf(&a, &b, ra, rb, &p);
            prop_assert!((d > 0.0) == (brute > 0.0) || brute.abs() < 1e-3);
            if brute > 0.0 {
                prop_assert!((d - brute).abs() < 1e-3, "{d} vs {brute}");
            }
            prop_assert!((g.norm() - 1.0).abs() < 1e-9);
        }

        #[test]
        fn round_cone_gradient_matches_finite_differences(
            a in v3(), b in v3(), ra in 0.1..2.0f64, rb in 0.1..2.0f64, p in v3()
        ) {
            let (d, g) = round_cone_sdf(&a, &b, ra, rb, &p);
            prop_assume!(d > 0.05);
            let h = 1e-6;
            let mut fd = Vec3::zeros();
            for i in 0..3 {
                let mut e = Vec3::zeros();
                e[i] = h;
                fd[i] = (round_cone_sdf(&a, &b, ra, rb, &(p + e)).0
                    - round_cone_sdf(&a, &b, ra, rb, &(p - e)).0) / (2.0 * h);
            }
            prop_assert!((fd - g).norm() < 1e-4, "{fd:?} vs {g:?}");
        }

        #[test]
        fn segment_test_agrees_with_dense_sampling(
            a in v3(), b in v3(), ra in 0.1..1.5f64, rb in 0.1..1.5f64,
            p in v3(), q in v3(), cyl in any::<bool>(), c in 0.0..0.5f64
        ) {
            let cone = if cyl {
                Cone::cylinder(a, b, ra, rb, 1.0, 1.3)
            } else {
                Cone::sphere(a, b, ra, rb)
            };
            let dense = (0..=4000)
                .map(|k| cone.signed_distance(&(p + (q - p) * (k as f64 / 4000.0))))
                .fold(f64::INFINITY, f64::min);
            let clear = cone.segment_clear(&p, &q, c);
            if dense < c - 3e-3 {
                prop_assert!(!clear, "dense min {dense} < {c} but reported clear");
            }
            if dense > c + 3e-3 {
                prop_assert!(clear, "dense min {dense} > {c} but reported blocked");
            }
        }

        #[test]
        fn support_points_are_extreme_points_of_the_cone(
            a in v3(), b in v3(), ra in 0.1..1.5f64, rb in 0.1..1.5f64, d in v3(), cyl in any::<bool>(),
            probes in prop::collection::vec(v3(), 20)
        ) {
            use crate::gjk::SupportMap;
            let cone = if cyl {
                Cone::cylinder(a, b, ra, rb, 1.0, 1.3)
            } else {
                Cone::sphere(a, b, ra, rb)
            };
            let s = cone.support(&d);
            // On the surface (the cylinder's support is a rim point: distance 0 up to rounding).
            prop_assert!(cone.signed_distance(&s).abs() < 1e-6, "{}", cone.signed_distance(&s));
            // No point of the cone goes farther along d: project probes onto the cone's closed set
            // by moving them inward along the gradient until inside.
            for p in &probes {
                let (dist, g) = cone.distance_and_gradient(p);
                let q = if dist > 0.0 { p - g * dist } else { *p };
                prop_assert!(q.dot(&d) <= s.dot(&d) + 1e-6 * (1.0 + d.norm()));
            }
        }

        #[test]
        fn segment_distance_matches_sampling(p0 in v3(), p1 in v3(), q0 in v3(), q1 in v3()) {
            let d = segment_segment_distance(&p0, &p1, &q0, &q1);
            let mut brute = f64::INFINITY;
            for i in 0..=200 {
                for j in 0..=200 {
                    let x = p0 + (p1 - p0) * (i as f64 / 200.0);
                    let y = q0 + (q1 - q0) * (j as f64 / 200.0);
                    brute = brute.min((x - y).norm());
                }
            }
            prop_assert!(d <= brute + 1e-9);
            prop_assert!(brute - d < 0.1);
        }
    }

    #[test]
    fn degenerate_cones_are_spheres_and_cylinders() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let s = Cone::sphere(c, c, 1.0, 1.0);
        assert_relative_eq!(s.signed_distance(&Vec3::new(3.0, 2.0, 3.0)), 1.0);
        let cyl = Cone::cylinder(c, c, 1.0, 1.0, 2.0, 2.0);
        assert_relative_eq!(cyl.signed_distance(&Vec3::new(1.0, 2.0, 6.0)), 1.0);
        assert_relative_eq!(cyl.signed_distance(&Vec3::new(3.0, 2.0, 3.0)), 1.0);
        assert!(cyl.contains(&c, 0.0));
        // Containing ball: the larger one wins.
        let big = Cone::sphere(c, c + Vec3::x() * 0.5, 0.1, 2.0);
        assert_relative_eq!(
            big.signed_distance(&(c + Vec3::new(0.5, 3.0, 0.0))),
            1.0,
            epsilon = 1e-12
        );
    }

    #[test]
    fn surface_samples_lie_at_the_offset() {
        for cyl in [false, true] {
            for b in [Vec3::new(4.0, 1.0, 0.0), Vec3::zeros()] {
                let cone = if cyl {
                    Cone::cylinder(Vec3::zeros(), b, 0.8, 1.4, 1.5, 1.9)
                } else {
                    Cone::sphere(Vec3::zeros(), b, 0.8, 1.4)
                };
                let kind = cone.kind();
                let region = Aabb::new(Vec3::repeat(-10.0), Vec3::repeat(10.0)).unwrap();
                let mut out = Vec::new();
                cone.surface_samples(3, 8, 0.4, &region, &mut out);
                assert!(!out.is_empty());
                assert!(out.len() <= 26);
                assert!(out.iter().all(|p| region.contains(p)));
                for p in &out {
                    assert!(
                        (cone.signed_distance(p) - 0.4).abs() < 1e-6,
                        "{kind:?} {p:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn non_finite_segments_are_blocked() {
        let cone = Cone::sphere(Vec3::zeros(), Vec3::x(), 1.0, 1.0);
        let far = Vec3::new(10.0, 10.0, 10.0);
        assert!(cone.segment_clear(&far, &(far + Vec3::x()), 0.0));
        assert!(!cone.segment_clear(&far, &Vec3::new(f64::NAN, 0.0, 0.0), 0.0));
        assert!(!cone.segment_clear(&far, &far, f64::NAN));
    }
}
