//! The predictive directional cone (PDC, paper Sec. III-B, eq. PDC): the one implementation every
//! user of the cone shares (DEV-PRM's roadmap, the UVD and TVD checkers, safety checks, plots).
//!
//! # Geometry
//!
//! Over a window `[t_s, t_e]` the obstacle is the base shape at `c(t)` inflated to `r(t)` (cylinders:
//! radius and half-height both grow, see [`ObstacleShape`]). With `λ = (t − t_s)/(t_e − t_s)` the
//! centre, radius and half-height are affine in `λ`, and the shapes are homothetic, so the shape at
//! `λ` is the Minkowski combination `(1 − λ)·K(0) + λ·K(1)`: **the PDC is the convex hull of its two
//! end shapes** — a round cone (tapered capsule) for a sphere, the hull of two vertical cylinders for
//! a cylinder. (A window that starts before the forecast's `t0`, where the inflation is clamped, is
//! the hull of its end shapes too; it contains the union of the slices and equals it when `mu = 0`.)
//!
//! Consequences used below: `(x, λ) ↦ sd(x, K(λ))` is jointly convex (the signed distance to a
//! convex set is `sup_n (n·x − σ_K(n))` and the support function `σ_{K(λ)}(n)` is affine in `λ`), so
//! the PDC's signed distance `min_λ sd(x, K(λ))` is convex in `x` and along any segment.
//!
//! # How the queries are answered
//!
//! * **Sphere**: the signed distance of the round cone in closed form ([`round_cone_sdf`]: cap,
//!   lateral surface, cap), which equals `min_λ (‖x − c(λ)‖ − r(λ))` everywhere. Segment tests
//!   reject by bounding box, then accept or reject by the distance between the segment and the
//!   cone's axis, and otherwise minimize the convex distance along the segment by cutting planes
//!   ([`convex_segment_clear`]).
//! * **Cylinder, at heights every slice covers** (the *core*: between the higher of the two bottoms
//!   and the lower of the two tops — every height of interest for an obstacle taller than the
//!   region, like the full-height pillars of experiment E1): the PDC's cross-section there is the
//!   2-D round cone of the end discs, so the sphere machinery applies to the horizontal projection.
//! * **Cylinder, elsewhere**: the *square-rim* distance `min_λ max(ρ(λ), ζ(λ))` (`ρ` the horizontal
//!   and `ζ` the vertical signed distance to `K(λ)`; a convex function of `x`) is minimized over
//!   `λ` in closed form — the minimum of the maximum of a norm-minus-affine function and two affine
//!   ones lies at an end of the window, at the norm's own minimizer, or where two of them cross —
//!   and a segment test minimizes the horizontal distance over the convex polygon of `(s, λ)` where
//!   the vertical extents overlap ([`min_over_convex_polygon`]).
//!
//! # Exactness
//!
//! | query | sphere | cylinder |
//! |---|---|---|
//! | [`Pdc::signed_distance`], [`Pdc::distance_and_gradient`] | exact outside; inside negative, magnitude ≤ true depth | the square-rim distance: exact in the core and wherever the nearest point is not on a rim; near a rim at least `1/√2` of the Euclidean distance; inside negative, magnitude ≤ true depth |
//! | [`Pdc::point_clear`], [`Pdc::contains`] | exact | exact for `clearance ≤ 0`; conservative for `clearance > 0` |
//! | [`Pdc::segment_clear`] | exact | exact for `clearance ≤ 0`; conservative for `clearance > 0` |
//!
//! "Conservative" for cylinders: a positive clearance inflates the cylinder's radius and half-height
//! by `clearance` (a square rim instead of the rounded offset surface), so a point or segment may be
//! reported blocked although its distance is up to `√2·clearance` — never the other way round; in
//! the core the two agree. "Exact" means up to floating-point rounding; all clearance tests
//! additionally use [`CLEAR_TOLERANCE`] so that rounding can only make them stricter.

use trust_geometry::{Aabb, Vec3};

use crate::convex::{
    NormMinusAffine2d, Vec2, clip_half_plane, convex_segment_clear, min_norm_minus_affine,
    min_over_convex_polygon, segment_segment_distance,
};
use crate::error::{check_finite, check_non_negative};
use crate::{Forecast, ObstacleShape, PredictError};
use trust_geometry::scale::Quantity;

mod samples;

/// A point or segment counts as clear of a PDC only if its distance exceeds the requested clearance
/// by more than this (m); absorbs floating-point rounding in the exact tests.
pub const CLEAR_TOLERANCE: f64 = 1e-9;

/// The predictive directional cone of one [`Forecast`] over a time window (paper eq. PDC), with the
/// data its queries need precomputed (end shapes, bounding box, the core of a cylinder).
///
/// Build with [`Pdc::new`] (the paper's `[t0, t0 + T_h]`), [`Pdc::over_window`] or [`Pdc::at_time`]
/// (the obstacle at one instant, for temporal checks such as TVD). See the module documentation for
/// the geometry and the exactness of every query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pdc {
    forecast: Forecast,
    t_start: f64,
    /// Window length `T` (s).
    duration: f64,
    cylinder: bool,
    /// Centre at the start and at the end of the window.
    a: Vec3,
    b: Vec3,
    /// Radius at the start and at the end.
    ra: f64,
    rb: f64,
    /// Vertical half-extent at the start and at the end (the radius for a sphere).
    ha: f64,
    hb: f64,
    /// Heights every slice of a cylinder covers: `(higher bottom, lower top)`; empty if `lo > hi`.
    core: (f64, f64),
    aabb: Aabb,
}

impl Pdc {
    /// The PDC over `[t0, t0 + horizon]` (paper eq. PDC with `T_h = horizon`).
    ///
    /// # Errors
    /// [`PredictError`] if the forecast is invalid or `horizon` is non-finite or negative.
    pub fn new(forecast: &Forecast, horizon: f64) -> Result<Self, PredictError> {
        check_non_negative("horizon", horizon, Quantity::Duration)?;
        forecast.validate()?;
        let t_end = forecast.t0 + horizon;
        if !Quantity::Time.accepts(t_end) {
            // Name the input, not the window end it drove out of the policy.
            return Err(PredictError::Derived {
                what: "forecast.t0 + horizon".into(),
                value: t_end,
                limit: trust_geometry::scale::MAX_TIME_S,
                cause: format!(
                    "horizon = {} s from forecast.t0 = {} s ends beyond the scale policy's \
                     times; shorten the horizon",
                    trust_geometry::scale::Sci(horizon),
                    trust_geometry::scale::Sci(forecast.t0)
                ),
            });
        }
        Self::over_window(forecast, forecast.t0, t_end)
    }

    /// The PDC over an arbitrary window `[t_start, t_end]` (e.g. from the planning time, later than
    /// the observation, to the end of the horizon). A window starting before `forecast.t0` gives
    /// the hull of its end shapes (see the module documentation).
    ///
    /// # Errors
    /// [`PredictError`] if the forecast is invalid, a time is non-finite or `t_end < t_start`.
    pub fn over_window(
        forecast: &Forecast,
        t_start: f64,
        t_end: f64,
    ) -> Result<Self, PredictError> {
        forecast.validate()?;
        check_finite("t_start", t_start, Quantity::Time)?;
        check_finite("t_end", t_end, Quantity::Time)?;
        if t_end < t_start {
            return Err(PredictError::InvalidWindow {
                t_start,
                t_end,
                hint: String::new(),
            });
        }
        Ok(Self::between(forecast, t_start, t_end))
    }

    /// The obstacle as forecast at time `t` (a window of length zero): the chord test of temporal
    /// visibility deformation and dense safety checks against forecasts.
    ///
    /// # Errors
    /// [`PredictError`] if the forecast is invalid or `t` is non-finite.
    pub fn at_time(forecast: &Forecast, t: f64) -> Result<Self, PredictError> {
        Self::over_window(forecast, t, t)
    }

    /// Builds the cone of a valid forecast over `[t_a, t_b]`, `t_a <= t_b` finite.
    #[inline]
    pub(crate) fn between(forecast: &Forecast, t_a: f64, t_b: f64) -> Self {
        let (a, b) = (forecast.center(t_a), forecast.center(t_b));
        let (mut ra, rb) = (forecast.radius(t_a), forecast.radius(t_b));
        let (mut ha, hb) = (
            forecast.vertical_half_extent(t_a),
            forecast.vertical_half_extent(t_b),
        );
        // Growth that stops inside the window: the slices after the stop are as large as the
        // end, so a cone growing linearly from the start would cut them; the window's largest
        // shape all along contains them (conservative).
        let stop = forecast.t0 + forecast.growth_s;
        if t_a < stop && stop < t_b {
            (ra, ha) = (rb, hb);
        }
        let (ext_a, ext_b) = (Vec3::new(ra, ra, ha), Vec3::new(rb, rb, hb));
        Pdc {
            forecast: *forecast,
            t_start: t_a,
            duration: t_b - t_a,
            cylinder: matches!(forecast.shape, ObstacleShape::Cylinder { .. }),
            a,
            b,
            ra,
            rb,
            ha,
            hb,
            core: ((a.z - ha).max(b.z - hb), (a.z + ha).min(b.z + hb)),
            aabb: Aabb {
                min: (a - ext_a).inf(&(b - ext_b)),
                max: (a + ext_a).sup(&(b + ext_b)),
            },
        }
    }

    /// The forecast this cone was built from.
    pub fn forecast(&self) -> &Forecast {
        &self.forecast
    }

    /// Start of the window (s).
    pub fn t_start(&self) -> f64 {
        self.t_start
    }

    /// End of the window (s).
    pub fn t_end(&self) -> f64 {
        self.t_start + self.duration
    }

    /// Window length (s).
    pub fn horizon(&self) -> f64 {
        self.duration
    }

    /// The two end shapes whose convex hull the PDC is, at the start and at the end of the window:
    /// `(centre, radius, vertical half-extent)` each (the half-extent equals the radius for a
    /// sphere).
    pub fn ends(&self) -> [(Vec3, f64, f64); 2] {
        [(self.a, self.ra, self.ha), (self.b, self.rb, self.hb)]
    }

    /// Axis-aligned bounding box of the PDC (exact: the box of the two end shapes).
    #[inline]
    pub fn aabb(&self) -> Aabb {
        self.aabb
    }

    /// The signed distance from `p` to the PDC (negative inside); see [`Pdc::distance_and_gradient`].
    #[inline]
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// The signed distance from `p` to the PDC and its gradient in `p` (a unit vector except at
    /// kinks, where it is a subgradient of norm at most 1; never NaN for finite `p`).
    ///
    /// Spheres: exact outside; inside negative with magnitude at most the true depth. Cylinders:
    /// the square-rim distance of the module documentation (exact in the core and away from the
    /// rims). A non-finite `p`, or one beyond `trust_geometry::scale::QUERY_LIMIT`, gives
    /// `(-inf, 0)`: "not free".
    #[inline]
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        if !trust_geometry::scale::queryable(&[p.x, p.y, p.z]) {
            return (f64::NEG_INFINITY, Vec3::zeros());
        }
        if !self.cylinder {
            return round_cone_sdf(&self.a, &self.b, self.ra, self.rb, p);
        }
        let (d, g) = self.horizontal_distance(p);
        if d >= 0.0 && self.in_core(p.z) {
            return (d, g);
        }
        self.square_rim_distance(p)
    }

    /// Whether `p` lies in the PDC (within [`CLEAR_TOLERANCE`]). Exact for both shapes.
    /// Non-finite `p` counts as contained.
    #[inline]
    pub fn contains(&self, p: &Vec3) -> bool {
        !self.point_clear(p, 0.0)
    }

    /// Whether `p` is farther than `clearance` (m, may be negative) from the PDC: exact for spheres
    /// and for `clearance ≤ 0`; conservative (may say "not clear" up to `√2·clearance`) for
    /// cylinders with `clearance > 0`. Non-finite input counts as not clear.
    #[inline]
    pub fn point_clear(&self, p: &Vec3, clearance: f64) -> bool {
        if !p.iter().all(|x| x.is_finite()) || !clearance.is_finite() {
            return false;
        }
        let c = clearance + CLEAR_TOLERANCE;
        if (0..3).any(|i| p[i] < self.aabb.min[i] - c || p[i] > self.aabb.max[i] + c) {
            return true; // outside the box grown by the clearance
        }
        if self.cylinder && c >= 0.0 && self.in_core(p.z) {
            // Inside the 2-D round cone means inside the PDC; outside, the distance is horizontal.
            return self.horizontal_distance(p).0 > c;
        }
        self.distance_and_gradient(p).0 > c
    }

    /// Whether the segment `a → b` stays farther than `clearance` (m, may be negative) from the
    /// obstacle at **every** time of the window — the roadmap visibility test of DEV-PRM. Exact for
    /// spheres; for cylinders exact for `clearance ≤ 0` and conservative for `clearance > 0`.
    /// Non-finite input counts as not clear.
    #[inline]
    pub fn segment_clear(&self, a: &Vec3, b: &Vec3, clearance: f64) -> bool {
        if !a.iter().chain(b.iter()).all(|x| x.is_finite()) || !clearance.is_finite() {
            return false;
        }
        self.segment_clear_in_box(a, b, clearance, &Aabb::from_segment(a, b))
    }

    /// [`Pdc::segment_clear`] without the input checks, for a caller that tests one segment against
    /// many cones: `a`, `b` and `clearance` must be finite and `seg_box` must be
    /// `Aabb::from_segment(a, b)` (computed once by the caller).
    #[inline]
    pub fn segment_clear_in_box(&self, a: &Vec3, b: &Vec3, clearance: f64, seg_box: &Aabb) -> bool {
        let c = clearance + CLEAR_TOLERANCE;
        for i in 0..3 {
            if seg_box.min[i] > self.aabb.max[i] + c || seg_box.max[i] < self.aabb.min[i] - c {
                return true;
            }
        }
        let (r_min, r_max) = (self.ra.min(self.rb), self.ra.max(self.rb));
        if !self.cylinder {
            // The cone lies within `r_max` of its axis and contains the balls of radius `r_min`
            // around it.
            let d = segment_segment_distance(a, b, &self.a, &self.b);
            if d >= r_max + c {
                return true;
            }
            if d < r_min + c {
                return false;
            }
            return convex_segment_clear(a, b, c, |x| {
                round_cone_sdf(&self.a, &self.b, self.ra, self.rb, x)
            });
        }
        let (fa, fb, ca, cb) = (flat(a), flat(b), flat(&self.a), flat(&self.b));
        let d = segment_segment_distance(&fa, &fb, &ca, &cb);
        if d >= r_max + c {
            return true;
        }
        if c >= 0.0 && self.in_core(seg_box.min.z) && self.in_core(seg_box.max.z) {
            // Within the core the question is 2-D: the projected segment against the round cone
            // of the end discs.
            if d < r_min + c {
                return false;
            }
            return convex_segment_clear(&fa, &fb, c, |x| {
                round_cone_sdf(&ca, &cb, self.ra, self.rb, x)
            });
        }
        self.cylinder_segment_clear(a, b, c)
    }

    /// A point of the PDC that maximizes `x·d` (its support mapping, for GJK-type separation
    /// tests); the start centre for `d = 0` or a non-finite `d`.
    #[inline]
    pub fn support(&self, d: &Vec3) -> Vec3 {
        // Only the direction matters: rescale so that huge components cannot overflow the norm.
        let m = d.amax();
        if !(m.is_finite() && m > 0.0) {
            return self.a;
        }
        let d = &(d / m);
        if !self.cylinder {
            let n = d.norm();
            if n.is_nan() || n <= 0.0 {
                return self.a;
            }
            let u = d / n;
            let (pa, pb) = (self.a + u * self.ra, self.b + u * self.rb);
            return if pa.dot(d) >= pb.dot(d) { pa } else { pb };
        }
        let n = (d.x * d.x + d.y * d.y).sqrt();
        let end = |c: &Vec3, r: f64, h: f64| {
            let (x, y) = if n > 0.0 {
                (c.x + d.x / n * r, c.y + d.y / n * r)
            } else {
                (c.x, c.y)
            };
            Vec3::new(x, y, if d.z >= 0.0 { c.z + h } else { c.z - h })
        };
        let (pa, pb) = (
            end(&self.a, self.ra, self.ha),
            end(&self.b, self.rb, self.hb),
        );
        if pa.dot(d) >= pb.dot(d) { pa } else { pb }
    }

    #[inline]
    fn in_core(&self, z: f64) -> bool {
        z >= self.core.0 && z <= self.core.1
    }

    /// Signed distance of the horizontal projection of `p` to the 2-D round cone of the end discs
    /// of a cylinder PDC, with its (horizontal) gradient.
    #[inline]
    fn horizontal_distance(&self, p: &Vec3) -> (f64, Vec3) {
        let (d, g) = round_cone_sdf(&flat(&self.a), &flat(&self.b), self.ra, self.rb, &flat(p));
        (d, flat(&g))
    }

    /// Cylinder segment test outside the core: the horizontal distance minimized over the convex
    /// polygon of `(s, λ) ∈ [0, 1]²` where the vertical extents (inflated by `c`) overlap.
    fn cylinder_segment_clear(&self, a: &Vec3, b: &Vec3, c: f64) -> bool {
        let m = a - self.a;
        let d = b - a;
        let sweep = self.b - self.a;
        let (dr, dh) = (self.rb - self.ra, self.hb - self.ha);
        let square = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        // e(s, λ) = m_z + d_z s − sweep_z λ must satisfy |e| ≤ ha + c + dh λ.
        let h = self.ha + c;
        let poly = clip_half_plane(&square, &Vec2::new(d.z, -sweep.z - dh), h - m.z);
        let poly = clip_half_plane(&poly, &Vec2::new(-d.z, sweep.z - dh), h + m.z);
        let f = NormMinusAffine2d {
            m: flat(&m),
            mx: flat(&d),
            my: -flat(&sweep),
            k0: self.ra + c,
            k: Vec2::new(0.0, dr),
        };
        min_over_convex_polygon(&f, &poly) > 0.0
    }

    /// The square-rim distance `min_λ max(ρ(λ), top(λ), bottom(λ))` of a cylinder PDC and a
    /// subgradient. `ρ(λ) = ‖w − λ·sweep‖_xy − r(λ)` is a norm minus an affine function, the two
    /// vertical terms are affine, so the minimum lies at `λ ∈ {0, 1}`, at `ρ`'s minimizer, where
    /// top and bottom cross, or where `ρ` crosses one of them; every candidate is evaluated.
    fn square_rim_distance(&self, p: &Vec3) -> (f64, Vec3) {
        let w = p - self.a;
        let sweep = self.b - self.a;
        let (wh, sh) = (flat(&w), flat(&sweep));
        let (dr, dh) = (self.rb - self.ra, self.hb - self.ha);
        // top(λ) = (w_z − λ sweep_z) − h(λ), bottom(λ) = −(w_z − λ sweep_z) − h(λ): `α + β λ`.
        let caps = [
            (w.z - self.ha, -sweep.z - dh),
            (-w.z - self.ha, sweep.z - dh),
        ];
        let radial = |l: f64| (wh - sh * l).norm() - (self.ra + dr * l);
        let value = |l: f64| {
            radial(l)
                .max(caps[0].0 + caps[0].1 * l)
                .max(caps[1].0 + caps[1].1 * l)
        };
        let mut best = (value(0.0), 0.0);
        let mut consider = |l: f64| {
            if l.is_finite() {
                let l = l.clamp(0.0, 1.0);
                let v = value(l);
                if v < best.0 {
                    best = (v, l);
                }
            }
        };
        consider(1.0);
        consider(min_norm_minus_affine(&wh, &(-sh), self.ra, dr, 0.0, 1.0).arg);
        if sweep.z != 0.0 {
            consider(w.z / sweep.z);
        }
        for (alpha, beta) in caps {
            for root in norm_affine_crossings(&wh, &sh, self.ra + alpha, dr + beta) {
                consider(root);
            }
        }
        let (q, l) = best;
        // The gradient: an active term whose λ-derivative satisfies the optimality condition at
        // `l`, or the combination of two active terms whose λ-derivatives cancel (Danskin).
        let rv = wh - sh * l;
        let rn = rv.norm();
        let radial_dir = if rn > 0.0 { rv / rn } else { Vec3::x() };
        let terms = [
            (radial(l), radial_dir, -radial_dir.dot(&sh) - dr),
            (caps[0].0 + caps[0].1 * l, Vec3::z(), caps[0].1),
            (caps[1].0 + caps[1].1 * l, -Vec3::z(), caps[1].1),
        ];
        let scale = 1.0 + w.norm() + sweep.norm() + self.rb + self.hb;
        let tol_value = 1e-12 * scale;
        let tol_slope = 1e-9 * (1.0 + sweep.norm() + dr.abs() + dh.abs());
        let optimal = |eta: f64| (l >= 1.0 || eta >= -tol_slope) && (l <= 0.0 || eta <= tol_slope);
        let active = |i: usize| terms[i].0 >= q - tol_value;
        if let Some(t) = (0..3).find(|&i| active(i) && optimal(terms[i].2)) {
            return (q, terms[t].1);
        }
        for i in 0..3 {
            for j in 0..3 {
                let (ei, ej) = (terms[i].2, terms[j].2);
                if active(i) && active(j) && ei < 0.0 && ej > 0.0 {
                    let weight = ej / (ej - ei);
                    return (q, terms[i].1 * weight + terms[j].1 * (1.0 - weight));
                }
            }
        }
        let first = (0..3).find(|&i| active(i)).unwrap_or(0);
        (q, terms[first].1)
    }
}

/// The horizontal part of a vector.
#[inline]
fn flat(v: &Vec3) -> Vec3 {
    Vec3::new(v.x, v.y, 0.0)
}

/// The `λ` where `‖w − λ·u‖ = α + β·λ` (roots of the squared equation, refined by two Newton steps
/// on the unsquared one; spurious roots of the squaring may be included — the caller evaluates every
/// candidate).
fn norm_affine_crossings(w: &Vec3, u: &Vec3, alpha: f64, beta: f64) -> impl Iterator<Item = f64> {
    // (u·u − β²) λ² − 2 (w·u + αβ) λ + (w·w − α²) = 0
    let qa = u.dot(u) - beta * beta;
    let qb = -2.0 * (w.dot(u) + alpha * beta);
    let qc = w.dot(w) - alpha * alpha;
    let mut roots = [f64::NAN; 2];
    if qa.abs() <= 1e-14 * (u.dot(u) + beta * beta) {
        if qb != 0.0 {
            roots[0] = -qc / qb;
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            roots[0] = -qb / (2.0 * qa); // tangency up to rounding
        } else {
            let q = -0.5 * (qb + disc.sqrt().copysign(qb));
            roots[0] = q / qa;
            if q != 0.0 {
                roots[1] = qc / q;
            }
        }
    }
    roots.into_iter().map(move |mut l| {
        for _ in 0..2 {
            let r = w - u * l;
            let n = r.norm();
            let slope = -r.dot(u) / n - beta;
            let step = (n - alpha - beta * l) / slope;
            if !(n > 0.0 && step.is_finite()) {
                break;
            }
            l -= step;
        }
        l
    })
}

/// Signed distance from `p` to the convex hull of the balls `B(a, ra)` and `B(b, rb)` (a round cone,
/// the PDC of a sphere), with its gradient (a unit vector). It equals
/// `min_λ (‖p − c(λ)‖ − r(λ))` over the linear interpolation of centre and radius: exact outside and
/// on the surface; inside, the (negative) distance to the face of the nearest region (cap `a`,
/// lateral surface, cap `b`).
#[inline]
pub fn round_cone_sdf(a: &Vec3, b: &Vec3, ra: f64, rb: f64, p: &Vec3) -> (f64, Vec3) {
    if !trust_geometry::scale::queryable(&[a.x, a.y, a.z, b.x, b.y, b.z, ra, rb, p.x, p.y, p.z]) {
        return (f64::NEG_INFINITY, Vec3::zeros());
    }
    let ab = b - a;
    let len = ab.norm();
    // One ball contains the other (or the sweep is a point): a single sphere.
    if len <= (ra - rb).abs() || len <= 1e-12 {
        return if ra >= rb {
            trust_geometry::sphere_sdf(a, ra, p)
        } else {
            trust_geometry::sphere_sdf(b, rb, p)
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
        trust_geometry::sphere_sdf(a, ra, p)
    } else if along > len * cos_a {
        trust_geometry::sphere_sdf(b, rb, p)
    } else {
        let d = x * sin_a + y * cos_a - ra;
        (d, (u * sin_a + radial_dir * cos_a).normalize())
    }
}

/// A unit vector perpendicular to `u` (unit).
#[inline]
fn any_perpendicular(u: &Vec3) -> Vec3 {
    let pick = if u.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    (pick - u * u.dot(&pick)).normalize()
}

/// An orthonormal right-handed frame `[x, y, z]` whose first axis points along `axis` (any length)
/// and whose second axis is horizontal. A vertical `axis` gets world `x` as second axis; a zero or
/// non-finite `axis` gets the world axes.
pub fn frame_along(axis: &Vec3) -> [Vec3; 3] {
    let n = axis.norm();
    if !n.is_finite() || n <= 0.0 {
        return [Vec3::x(), Vec3::y(), Vec3::z()];
    }
    let x = axis / n;
    let horizontal_sq = x.x * x.x + x.y * x.y;
    let y = if horizontal_sq.is_nan() || horizontal_sq <= 0.0 {
        // Vertical: any horizontal axis is perpendicular to x.
        Vec3::x()
    } else {
        // z × x is horizontal and perpendicular to x.
        Vec3::new(-x.y, x.x, 0.0) / horizontal_sq.sqrt()
    };
    let z = x.cross(&y);
    [x, y, z]
}

// Here, not in `forecast`: the cone is made from a forecast, and `forecast` knows nothing of it
// (no module cycle, tests/tests/tidy.rs).
impl Forecast {
    /// The predictive directional cone of this forecast over `[t0, t0 + horizon]` (paper eq. PDC).
    ///
    /// # Errors
    /// As [`Pdc::new`].
    pub fn pdc(&self, horizon: f64) -> Result<Pdc, PredictError> {
        Pdc::new(self, horizon)
    }

    /// Whether the segment `a → b` keeps more than `clearance` (m) from the obstacle as forecast at
    /// time `t`: [`Pdc::segment_clear`] of [`Pdc::at_time`], without validating the forecast again
    /// — for temporal checks that test many instants (the chords of temporal visibility
    /// deformation, dense safety checks of a trajectory). Assumes a valid forecast, like the other
    /// query methods; a non-finite `t`, end point or clearance counts as not clear.
    #[inline]
    pub fn segment_clear(&self, a: &Vec3, b: &Vec3, t: f64, clearance: f64) -> bool {
        t.is_finite() && Pdc::between(self, t, t).segment_clear(a, b, clearance)
    }
}

#[cfg(test)]
mod tests;
