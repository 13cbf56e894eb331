//! The static map: bounds, analytic shapes in a BVH, and an optional voxel ESDF.

use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhNode};
use parry3d_f64::query::Ray;

use crate::Vec3;
use crate::aabb::Aabb;
use crate::error::{GeometryError, check_positive};
use crate::esdf::Esdf;
use crate::parry_conv::{ray_input, ray_shape_hit, segment_blocked, to_p, to_p_aabb};
use crate::shapes::Shape;

/// Step length reported by [`StaticMap::resolution`] for maps without a voxel grid, in metres:
/// 0.1 m, the voxel size of Fast-Planner's SDF map (`sdf_map/resolution` in its launch files).
pub const DEFAULT_RESOLUTION: f64 = 0.1;

/// Upper bound on how fast the trilinear ESDF can decrease along a line, in metres per metre.
///
/// Adjacent voxel values differ by at most one voxel (two across a free/occupied interface), so
/// each partial derivative of the interpolant is at most 2 and its gradient norm at most `2√3`.
/// Outside the box of voxel centres the extension's gradient combines the unclamped part of the
/// interpolant's gradient (norm at most `2√2`) with an orthogonal unit part, so its norm is at
/// most 3.
const ESDF_LIPSCHITZ: f64 = 2.0 * 1.732_050_807_568_877_3;

/// Most sphere-tracing steps one ESDF line-of-sight test takes before it gives up (answers "not
/// clear"): a count that does not depend on any float being finite.
pub const MAX_TRACE_STEPS: usize = 1 << 16;

/// The static world: bounds, analytic [`Shape`]s and an optional voxel [`Esdf`] from a point cloud.
///
/// * Bounds are where the planner may go ([`StaticMap::contains`]); distance queries are defined
///   everywhere, also outside the bounds.
/// * Obstacles are the union of the shapes and the occupied voxels. The map's signed distance is
///   the minimum of the shapes' exact signed distances and the ESDF's interpolated value (see
///   [`Esdf`] for its voxel-centre convention and accuracy). Where shapes overlap, the minimum is
///   exact outside and conservative (reports less depth than the union's) inside.
/// * A map with no obstacles reports `f64::INFINITY` with a zero gradient; callers must handle it.
/// * A query point with a non-finite coordinate is reported as in collision: distance
///   `f64::NEG_INFINITY`, zero gradient.
///
/// Shapes are indexed by a parry BVH, so nearest-obstacle, freedom and broad-phase queries are
/// sub-linear in the number of shapes.
#[derive(Debug, Clone)]
pub struct StaticMap {
    bounds: Aabb,
    shapes: Vec<Shape>,
    bvh: Bvh,
    esdf: Option<Esdf>,
    default_resolution: f64,
    /// Largest coordinate magnitude of the shapes' boxes: the distance functions round at a few
    /// ulps of it, and line of sight widens its broad phase by as much.
    shape_coord_max: f64,
}

/// Elementary operations done by the counted map queries ([`StaticMap::segment_clear_counted`],
/// [`StaticMap::is_free_counted`], [`StaticMap::distance_and_gradient_counted`]): what a search
/// with a deterministic work budget charges for a query, since their cost differs by orders of
/// magnitude between an empty map, a few shapes and a dense point-cloud ESDF.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MapWork {
    /// Queries answered (one broad phase each).
    pub queries: u64,
    /// ESDF samples (one trilinear interpolation each; a line-of-sight trace takes many).
    pub esdf_samples: u64,
    /// Exact shape tests: a segment against one shape (narrow phase) or one shape's distance at a
    /// point.
    pub shape_tests: u64,
}

impl MapWork {
    /// The sum of two counts.
    pub fn plus(self, other: MapWork) -> MapWork {
        MapWork {
            queries: self.queries.saturating_add(other.queries),
            esdf_samples: self.esdf_samples.saturating_add(other.esdf_samples),
            shape_tests: self.shape_tests.saturating_add(other.shape_tests),
        }
    }
}

/// Prefixes the field name of an error with `prefix` (e.g. `shapes[3].`).
fn prefixed(e: GeometryError, prefix: &str) -> GeometryError {
    match e {
        GeometryError::NonFinite { field, value } => GeometryError::NonFinite {
            field: prefix.to_owned() + &field,
            value,
        },
        GeometryError::Negative { field, value } => GeometryError::Negative {
            field: prefix.to_owned() + &field,
            value,
        },
        GeometryError::NonPositive { field, value } => GeometryError::NonPositive {
            field: prefix.to_owned() + &field,
            value,
        },
        GeometryError::InvertedBox {
            field,
            axis,
            min,
            max,
        } => GeometryError::InvertedBox {
            field: prefix.to_owned() + &field,
            axis,
            min,
            max,
        },
        other => other,
    }
}

/// Signed distance from `p` to a BVH node's box: a lower bound on the signed distance to anything
/// inside the box.
fn node_sdf(node: &BvhNode, p: &Vec3) -> f64 {
    let (lo, hi) = (node.mins(), node.maxs());
    // Per axis: positive outside the slab, minus the depth inside it.
    let q = [
        (lo.x - p.x).max(p.x - hi.x),
        (lo.y - p.y).max(p.y - hi.y),
        (lo.z - p.z).max(p.z - hi.z),
    ];
    let outside = q.iter().map(|&d| d.max(0.0) * d.max(0.0)).sum::<f64>();
    if outside > 0.0 {
        outside.sqrt()
    } else {
        q[0].max(q[1]).max(q[2])
    }
}

impl StaticMap {
    /// An obstacle-free map with the given bounds; errors if the bounds have zero volume.
    pub fn new(bounds: Aabb) -> Result<Self, GeometryError> {
        crate::aabb::check_box("bounds", &bounds.min, &bounds.max)?;
        bounds.check_volume("bounds")?;
        Ok(Self {
            bounds,
            shapes: Vec::new(),
            bvh: Bvh::new(),
            esdf: None,
            default_resolution: DEFAULT_RESOLUTION,
            shape_coord_max: 0.0,
        })
    }

    /// Same as [`StaticMap::new`]; reads better where the emptiness is the point.
    pub fn empty(bounds: Aabb) -> Result<Self, GeometryError> {
        Self::new(bounds)
    }

    /// A map with the given bounds and shapes. Errors on zero-volume bounds or an invalid shape
    /// (the field is prefixed with `shapes[i].`). Shapes may extend beyond the bounds.
    pub fn from_shapes(bounds: Aabb, shapes: Vec<Shape>) -> Result<Self, GeometryError> {
        Self::new(bounds)?.with_shapes(shapes)
    }

    /// Adds shapes (validated; see [`StaticMap::from_shapes`]) and rebuilds the BVH.
    pub fn with_shapes(
        mut self,
        shapes: impl IntoIterator<Item = Shape>,
    ) -> Result<Self, GeometryError> {
        let start = self.shapes.len();
        for (i, s) in shapes.into_iter().enumerate() {
            s.validate()
                .map_err(|e| prefixed(e, &format!("shapes[{}].", start + i)))?;
            self.shapes.push(s);
        }
        let leaves: Vec<_> = self.shapes.iter().map(|s| to_p_aabb(&s.aabb())).collect();
        self.shape_coord_max = self
            .shapes
            .iter()
            .map(|s| {
                let b = s.aabb();
                b.min.amax().max(b.max.amax())
            })
            .fold(0.0, f64::max);
        self.bvh = Bvh::from_leaves(BvhBuildStrategy::default(), &leaves);
        Ok(self)
    }

    /// Adds the occupied points of a point cloud as a voxel ESDF of the given `resolution` over
    /// the map bounds (see [`Esdf::from_points`]; points outside the bounds are ignored). Replaces
    /// any previous ESDF. Errors on a non-positive resolution, a grid above
    /// [`crate::MAX_VOXELS`] voxels, or a non-finite point.
    pub fn with_point_cloud(self, points: &[Vec3], resolution: f64) -> Result<Self, GeometryError> {
        let esdf = Esdf::from_points(&self.bounds, points, resolution)?;
        Ok(self.with_esdf(esdf))
    }

    /// Uses a prebuilt ESDF (replacing any previous one).
    pub fn with_esdf(mut self, esdf: Esdf) -> Self {
        self.esdf = Some(esdf);
        self
    }

    /// Sets the step length reported by [`StaticMap::resolution`] when the map has no ESDF
    /// (default [`DEFAULT_RESOLUTION`]). Errors unless `resolution` is finite and positive.
    pub fn with_resolution(mut self, resolution: f64) -> Result<Self, GeometryError> {
        self.default_resolution = check_positive("resolution", resolution)?;
        Ok(self)
    }

    /// The map bounds.
    pub fn bounds(&self) -> &Aabb {
        &self.bounds
    }

    /// The analytic shapes, in insertion order (indices match [`StaticMap::shapes_near`]).
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    /// The voxel ESDF, if the map has one.
    pub fn esdf(&self) -> Option<&Esdf> {
        self.esdf.as_ref()
    }

    /// A natural step length for planners: the ESDF voxel size, or the value set by
    /// [`StaticMap::with_resolution`] ([`DEFAULT_RESOLUTION`] unless changed).
    pub fn resolution(&self) -> f64 {
        self.esdf
            .as_ref()
            .map_or(self.default_resolution, Esdf::resolution)
    }

    /// True if the map has neither shapes nor occupied voxels.
    pub fn has_no_obstacles(&self) -> bool {
        self.shapes.is_empty() && self.esdf.as_ref().is_none_or(|e| e.occupied_count() == 0)
    }

    /// True if `p` lies inside the (closed) map bounds.
    pub fn contains(&self, p: &Vec3) -> bool {
        self.bounds.contains(p)
    }

    /// Signed distance from `p` to the nearest obstacle (negative inside one).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// Signed distance from `p` to the nearest obstacle and its gradient: the gradient of the
    /// nearest shape's SDF or of the ESDF interpolant, whichever is smaller (shapes win ties).
    /// A non-finite `p` gives `(-inf, 0)` ("not free"); so does a point beyond
    /// [`crate::scale::QUERY_LIMIT`] near a shape (the shapes' distance functions answer so).
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        self.distance_and_gradient_counted(p, &mut MapWork::default())
    }

    /// [`StaticMap::distance_and_gradient`], adding the operations it does to `work`.
    pub fn distance_and_gradient_counted(&self, p: &Vec3, work: &mut MapWork) -> (f64, Vec3) {
        work.queries = work.queries.saturating_add(1);
        if !p.iter().all(|c| c.is_finite()) {
            return (f64::NEG_INFINITY, Vec3::zeros());
        }
        let mut best = self
            .esdf
            .as_ref()
            .map_or((f64::INFINITY, Vec3::zeros()), |e| {
                work.esdf_samples = work.esdf_samples.saturating_add(1);
                e.distance_and_gradient(p)
            });
        if let Some((_, d, g)) = self.nearest_shape_within(p, best.0, work)
            && d <= best.0
        {
            best = (d, g);
        }
        best
    }

    /// Like [`StaticMap::distance_and_gradient`], but over the ESDF and only the shapes listed in
    /// `shape_indices` (e.g. gathered once with [`StaticMap::shapes_near`] for a whole trajectory
    /// piece, so that inner loops avoid the BVH). Indices out of range are ignored. Same
    /// conventions: `+inf` with a zero gradient if nothing is listed and there is no ESDF.
    pub fn distance_and_gradient_among(&self, p: &Vec3, shape_indices: &[usize]) -> (f64, Vec3) {
        if !p.iter().all(|c| c.is_finite()) {
            return (f64::NEG_INFINITY, Vec3::zeros());
        }
        let mut best = (f64::INFINITY, Vec3::zeros());
        for shape in shape_indices.iter().filter_map(|&i| self.shapes.get(i)) {
            let (d, g) = shape.distance_and_gradient(p);
            if d < best.0 {
                best = (d, g);
            }
        }
        match &self.esdf {
            Some(e) => {
                let from_esdf = e.distance_and_gradient(p);
                if from_esdf.0 < best.0 {
                    from_esdf
                } else {
                    best
                }
            }
            None => best,
        }
    }

    /// The shape with the smallest signed distance to `p`: `(index, distance, gradient)`, or
    /// `None` if the map has no shapes or `p` is not finite. Ignores the ESDF.
    pub fn nearest_shape(&self, p: &Vec3) -> Option<(usize, f64, Vec3)> {
        if !p.iter().all(|c| c.is_finite()) {
            return None;
        }
        self.nearest_shape_within(p, f64::INFINITY, &mut MapWork::default())
    }

    /// Best-first BVH search for the shape of least signed distance below `max` (ties and values
    /// equal to `max` included via the final comparison by the caller).
    fn nearest_shape_within(
        &self,
        p: &Vec3,
        max: f64,
        work: &mut MapWork,
    ) -> Option<(usize, f64, Vec3)> {
        if self.shapes.is_empty() {
            return None;
        }
        // Allow equality with `max` to be found: search strictly below the next float up.
        let limit = if max.is_finite() {
            max + max.abs().max(1.0) * 1e-12
        } else {
            max
        };
        let tests = std::cell::Cell::new(0u64);
        let found = self.bvh.find_best(
            limit,
            |node: &BvhNode, _| node_sdf(node, p),
            |leaf, _| {
                tests.set(tests.get() + 1);
                Some(self.shapes[leaf as usize].signed_distance(p))
            },
        );
        work.shape_tests = work.shape_tests.saturating_add(tests.get() + 1);
        let (i, _) = found?;
        let (d, g) = self.shapes[i as usize].distance_and_gradient(p);
        Some((i as usize, d, g))
    }

    /// True if `p` is at signed distance `>= clearance` from every obstacle. A NaN clearance or a
    /// non-finite `p` gives `false`.
    pub fn is_free(&self, p: &Vec3, clearance: f64) -> bool {
        self.is_free_counted(p, clearance, &mut MapWork::default())
    }

    /// [`StaticMap::is_free`], adding the operations it does to `work`.
    pub fn is_free_counted(&self, p: &Vec3, clearance: f64, work: &mut MapWork) -> bool {
        work.queries = work.queries.saturating_add(1);
        if clearance.is_nan() || !p.iter().all(|c| c.is_finite()) {
            return false;
        }
        if let Some(e) = &self.esdf {
            work.esdf_samples = work.esdf_samples.saturating_add(1);
            if e.signed_distance(p) < clearance {
                return false;
            }
        }
        if self.shapes.is_empty() {
            return true;
        }
        let mut leaves = self
            .bvh
            .leaves(|node: &BvhNode| node_sdf(node, p) < clearance);
        let mut tests = 0u64;
        let blocked = leaves.any(|i| {
            tests += 1;
            self.shapes[i as usize].signed_distance(p) < clearance
        });
        work.shape_tests = work.shape_tests.saturating_add(tests);
        !blocked
    }

    /// Line of sight: true if every point of the segment `[a, b]` is at distance `>= clearance`
    /// from every obstacle.
    ///
    /// * Shapes: exact, from parry's segment–shape distance (GJK, to its tolerance) for the shapes
    ///   whose boxes overlap the segment's box inflated by `clearance`. A segment touching a shape
    ///   with `clearance == 0` counts as blocked.
    /// * ESDF: conservative sphere tracing on the interpolated field — from each sample the
    ///   tracer advances by `(d - clearance) / L` with `L = 2√3` bounding the slope of the
    ///   interpolant, so no point in between can fall below the clearance. Every sample, the end
    ///   point included, must be more than `resolution / 1000` above the clearance level (so a
    ///   segment touching the zero level at clearance 0 is blocked); the tracer gives up (returns
    ///   `false`) after `min(64 + 64 * length / resolution, MAX_TRACE_STEPS)` steps.
    /// * Every length follows these rules, zero included: a zero-length segment is the point
    ///   `a` tested as a segment, so touching at clearance 0 is blocked for a segment of 0 m,
    ///   1 µm or 1 km alike (whereas [`StaticMap::is_free`], a point query, accepts a distance
    ///   exactly equal to the clearance). Negative clearances are treated as 0; a NaN clearance,
    ///   a non-finite end point or one outside the scale policy ([`crate::scale`]: a coordinate
    ///   beyond [`crate::scale::MAX_COORD_M`]) gives `false`.
    pub fn segment_clear(&self, a: &Vec3, b: &Vec3, clearance: f64) -> bool {
        self.segment_clear_counted(a, b, clearance, &mut MapWork::default())
    }

    /// [`StaticMap::segment_clear`], adding the operations it does to `work` (the ESDF samples of
    /// the trace and the exact tests of the shapes the broad phase keeps).
    pub fn segment_clear_counted(
        &self,
        a: &Vec3,
        b: &Vec3,
        clearance: f64,
        work: &mut MapWork,
    ) -> bool {
        work.queries = work.queries.saturating_add(1);
        if clearance.is_nan()
            || !crate::scale::position_in_scale(a)
            || !crate::scale::position_in_scale(b)
        {
            return false;
        }
        let clearance = clearance.max(0.0);
        if let Some(e) = &self.esdf
            && !esdf_segment_clear(e, a, b, clearance, &mut work.esdf_samples)
        {
            return false;
        }
        if self.shapes.is_empty() {
            return true;
        }
        // Inflated by a few ulps of the segment's and the shapes' coordinates too, so that a shape
        // the segment touches within the rounding of the distance functions is a candidate (the
        // exact tests below are conservative at that scale).
        let ulps = 8.0 * f64::EPSILON * (a.amax() + b.amax() + self.shape_coord_max);
        let query = to_p_aabb(&Aabb::from_segment(a, b).inflated(clearance + ulps));
        let mut candidates = self.bvh.intersect_aabb(&query);
        // Each shape sees only the part of the segment inside its box inflated by the clearance
        // (a closest pair closer than the clearance lies there): a long segment past a small
        // shape then costs GJK no precision.
        let pad = clearance + 1e-9 * (1.0 + clearance);
        let mut tests = 0u64;
        let blocked = candidates.any(|i| {
            let shape = &self.shapes[i as usize];
            let Some((p, q)) = shape.aabb().inflated(pad).clip_segment(a, b) else {
                return false;
            };
            tests += 1;
            segment_blocked(shape, &p, &q, clearance)
        });
        work.shape_tests = work.shape_tests.saturating_add(tests);
        !blocked
    }

    /// Ray cast against every obstacle: the distance in metres from `origin` along `dir` (any
    /// non-zero length; it is normalized) to the first obstacle point within `max_range`,
    /// `Some(0.0)` if `origin` is inside or on an obstacle, `None` if the ray stays clear.
    ///
    /// * Shapes: parry's ray casts ([`Shape::cast_ray`]) on the leaves of the map's BVH, visited
    ///   nearest box first, so the cost grows with the shapes the ray passes, not their number.
    /// * ESDF: sphere tracing on the interpolated field — from each sample the ray advances by
    ///   `d / L` (`L = 2√3` bounds the interpolant's slope, as in [`StaticMap::segment_clear`]),
    ///   so it never steps over the zero level; a sample within `resolution / 1000` of the zero
    ///   level is the hit. After [`MAX_TRACE_STEPS`] samples the trace answers a hit where it
    ///   stands (conservative).
    ///
    /// Invalid input answers conservatively ([`crate::scale`]): a non-finite or out-of-scale
    /// `origin`, a zero or non-finite `dir` or a NaN `max_range` gives `Some(0.0)`; a negative
    /// `max_range` counts as 0 (then only an origin inside an obstacle hits).
    pub fn cast_ray(&self, origin: &Vec3, dir: &Vec3, max_range: f64) -> Option<f64> {
        let Ok((unit, max_t)) = ray_input(origin, dir, max_range) else {
            return Some(0.0);
        };
        let mut best = self
            .esdf
            .as_ref()
            .and_then(|e| esdf_ray_hit(e, origin, &unit, max_t));
        if !self.shapes.is_empty() {
            let limit = best.unwrap_or(max_t);
            let ray = Ray::new(to_p(origin), to_p(&unit));
            if let Some((_, t)) = self.bvh.cast_ray(&ray, limit, |i, so_far| {
                ray_shape_hit(&self.shapes[i as usize], origin, &unit, so_far)
            }) && best.is_none_or(|b| t < b)
            {
                best = Some(t);
            }
        }
        best
    }

    /// Indices of the shapes whose bounding boxes intersect `region` (broad phase), ascending.
    /// `out` is cleared first. Sub-linear in the number of shapes (BVH).
    pub fn shapes_near(&self, region: &Aabb, out: &mut Vec<usize>) {
        out.clear();
        if self.shapes.is_empty() {
            return;
        }
        let query = to_p_aabb(region);
        out.extend(self.bvh.intersect_aabb(&query).map(|i| i as usize));
        out.sort_unstable();
    }
}

/// Sphere tracing of the ray `origin + t * unit`, `t` in `[0, max_t]`, on the ESDF (see
/// [`StaticMap::cast_ray`]).
fn esdf_ray_hit(esdf: &Esdf, origin: &Vec3, unit: &Vec3, max_t: f64) -> Option<f64> {
    let tol = esdf.resolution() * 1e-3;
    let mut t = 0.0;
    for _ in 0..MAX_TRACE_STEPS {
        let d = esdf.signed_distance(&(origin + unit * t));
        if d.is_nan() || d <= tol {
            return Some(t);
        }
        if d == f64::INFINITY {
            return None;
        }
        t += d / ESDF_LIPSCHITZ;
        if t > max_t {
            return None;
        }
    }
    Some(t.min(max_t))
}

/// Conservative line-of-sight test of `[a, b]` against the ESDF (see
/// [`StaticMap::segment_clear`]).
fn esdf_segment_clear(esdf: &Esdf, a: &Vec3, b: &Vec3, clearance: f64, samples: &mut u64) -> bool {
    let len = (b - a).norm();
    if !len.is_finite() {
        return false;
    }
    let res = esdf.resolution();
    let margin = res * 1e-3;
    // Saturating float-to-int conversion; NaN (impossible here) would give 0 steps.
    let max_steps = ((64.0 + 64.0 * len / res) as usize).min(MAX_TRACE_STEPS);
    // A zero-length segment is its one sample `b = a` (the loop ends at once: `t >= len`).
    let dir = if len > 0.0 {
        (b - a) / len
    } else {
        Vec3::zeros()
    };
    let mut t = 0.0;
    for _ in 0..=max_steps {
        let p = if t >= len { *b } else { a + dir * t };
        // The same test at every sample, the end point included, so that the verdict does not
        // depend on the segment's length as it shrinks to a point.
        *samples = samples.saturating_add(1);
        let slack = esdf.signed_distance(&p) - clearance;
        if slack.is_nan() || slack < margin {
            return false;
        }
        if t >= len {
            return true;
        }
        t += slack / ESDF_LIPSCHITZ;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{AaBox, Cylinder, Sphere};
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    fn bounds() -> Aabb {
        Aabb::new(v(0.0, 0.0, 0.0), v(20.0, 20.0, 10.0)).unwrap()
    }

    fn random_point(rng: &mut ChaCha8Rng, b: &Aabb) -> Vec3 {
        v(
            rng.random_range(b.min.x..b.max.x),
            rng.random_range(b.min.y..b.max.y),
            rng.random_range(b.min.z..b.max.z),
        )
    }

    fn random_shapes(n: usize, seed: u64) -> Vec<Shape> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let b = bounds();
        (0..n)
            .map(|i| {
                let c = random_point(&mut rng, &b);
                let r = rng.random_range(0.1..1.2);
                match i % 3 {
                    0 => Sphere::new(c, r).unwrap().into(),
                    1 => Cylinder::new(c, r, rng.random_range(0.1..2.0))
                        .unwrap()
                        .into(),
                    _ => AaBox::from_center_half_extents(
                        c,
                        v(
                            rng.random_range(0.0..1.0),
                            rng.random_range(0.0..1.0),
                            rng.random_range(0.0..1.0),
                        ),
                    )
                    .unwrap()
                    .into(),
                }
            })
            .collect()
    }

    fn random_cloud(n: usize, seed: u64) -> Vec<Vec3> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // A few clumps, so the cloud has solid interiors as well as thin parts.
        let b = bounds();
        let mut pts = Vec::new();
        for _ in 0..n {
            let c = random_point(&mut rng, &b);
            for _ in 0..40 {
                pts.push(
                    c + v(
                        rng.random_range(-0.6..0.6),
                        rng.random_range(-0.6..0.6),
                        rng.random_range(-0.6..0.6),
                    ),
                );
            }
        }
        pts
    }

    fn brute_distance(shapes: &[Shape], p: &Vec3) -> f64 {
        shapes
            .iter()
            .map(|s| s.signed_distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    fn point_strategy() -> impl Strategy<Value = Vec3> {
        (-2.0f64..22.0, -2.0f64..22.0, -2.0f64..12.0).prop_map(|(x, y, z)| v(x, y, z))
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        #[test]
        fn distance_matches_brute_force(seed in 0u64..4, n in 1usize..300, p in point_strategy()) {
            let shapes = random_shapes(n, seed);
            let map = StaticMap::from_shapes(bounds(), shapes.clone()).unwrap();
            let (d, g) = map.distance_and_gradient(&p);
            let brute = brute_distance(&shapes, &p);
            prop_assert_eq!(d, brute);
            prop_assert!((g.norm() - 1.0).abs() < 1e-12);
            let (i, di, _) = map.nearest_shape(&p).unwrap();
            prop_assert_eq!(shapes[i].signed_distance(&p), di);
            prop_assert_eq!(di, brute);
            for clearance in [0.0, 0.3, 1.0] {
                prop_assert_eq!(map.is_free(&p, clearance), brute >= clearance);
            }
        }

        #[test]
        fn shapes_near_matches_brute_force(
            seed in 0u64..4, lo in point_strategy(), size in (0.0f64..8.0, 0.0f64..8.0, 0.0f64..8.0),
        ) {
            let shapes = random_shapes(500, seed);
            let map = StaticMap::from_shapes(bounds(), shapes.clone()).unwrap();
            let region = Aabb::new(lo, lo + v(size.0, size.1, size.2)).unwrap();
            let mut out = vec![12345];
            map.shapes_near(&region, &mut out);
            let brute: Vec<usize> = (0..shapes.len()).filter(|&i| shapes[i].aabb().intersects(&region)).collect();
            prop_assert_eq!(out, brute);
        }

        /// Map gradient against central differences wherever the map is smooth: the analytic
        /// gradients at `p ± h e_i` agree with the one at `p` (no kink in between).
        #[test]
        fn map_gradient_matches_fd(seed in 0u64..4, p in point_strategy()) {
            let map = StaticMap::from_shapes(bounds(), random_shapes(60, seed))
                .unwrap()
                .with_point_cloud(&random_cloud(6, seed + 10), 0.25)
                .unwrap();
            let h = 1e-6;
            let (_, g) = map.distance_and_gradient(&p);
            for i in 0..3 {
                let mut a = p;
                let mut b = p;
                a[i] += h;
                b[i] -= h;
                let (_, ga) = map.distance_and_gradient(&a);
                let (_, gb) = map.distance_and_gradient(&b);
                if (ga - g).norm() > 1e-4 || (gb - g).norm() > 1e-4 {
                    continue; // a kink lies between the samples
                }
                let fd = trust_numdiff::central_difference(
                    |s| map.distance_and_gradient(&(p + Vec3::ith(i, s))).0,
                    0.0,
                    h,
                );
                prop_assert!((fd - g[i]).abs() < 1e-5, "axis {i}: {} vs {fd}", g[i]);
            }
        }

        /// Line of sight against dense sampling of the segment (25 segments per map).
        #[test]
        fn segment_clear_matches_dense_sampling(seed in 0u64..4, segment_seed in any::<u64>(), with_cloud in any::<bool>()) {
            let mut map = StaticMap::from_shapes(bounds(), random_shapes(150, seed)).unwrap();
            if with_cloud {
                map = map.with_point_cloud(&random_cloud(8, seed + 20), 0.2).unwrap();
            }
            let mut rng = ChaCha8Rng::seed_from_u64(segment_seed);
            let wide = Aabb::new(v(-2.0, -2.0, -2.0), v(22.0, 22.0, 12.0)).unwrap();
            for _ in 0..25 {
                let a = random_point(&mut rng, &wide);
                let b = a + v(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0), rng.random_range(-3.0..3.0));
                let clearance = if rng.random_bool(0.2) { 0.0 } else { rng.random_range(0.0..1.0) };
                let len = (b - a).norm();
                let samples = 2000;
                let spacing = len / samples as f64;
                let min_sampled = (0..=samples)
                    .map(|k| map.signed_distance(&(a + (b - a) * (k as f64 / samples as f64))))
                    .fold(f64::INFINITY, f64::min);
                let clear = map.segment_clear(&a, &b, clearance);
                if clear {
                    prop_assert!(min_sampled >= clearance - 1e-9, "said clear, but a sample is at {min_sampled}");
                }
                // The true minimum is at least the sampled one minus the slope bound times
                // spacing / 2; the ESDF tracer may also give up within resolution / 1000 of the
                // clearance level.
                let slope = if with_cloud { ESDF_LIPSCHITZ } else { 1.0 };
                if min_sampled - slope * spacing / 2.0 > clearance + 1e-3 {
                    prop_assert!(clear, "said blocked, but all samples are at >= {min_sampled}");
                }
            }
        }
    }

    #[test]
    fn ray_casts_have_known_answers() {
        let ball = Sphere::new(v(10.0, 10.0, 5.0), 2.0).unwrap();
        let cyl = Cylinder::new(v(4.0, 4.0, 5.0), 1.0, 2.0).unwrap();
        let bx = AaBox::new(v(15.0, 2.0, 1.0), v(17.0, 4.0, 3.0)).unwrap();
        let map =
            StaticMap::from_shapes(bounds(), vec![ball.into(), cyl.into(), bx.into()]).unwrap();
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-9);
        // Ball: from (1, 10, 5) along +x the surface is at x = 8; the direction's length is free.
        assert!(close(
            map.cast_ray(&v(1.0, 10.0, 5.0), &v(3.0, 0.0, 0.0), 20.0),
            7.0
        ));
        assert_eq!(
            map.cast_ray(&v(1.0, 10.0, 5.0), &v(1.0, 0.0, 0.0), 6.9),
            None
        );
        // Cylinder (axis z): side at x = 3 from the left, top cap at z = 7 from above.
        assert!(close(
            map.cast_ray(&v(0.0, 4.0, 5.0), &v(1.0, 0.0, 0.0), 20.0),
            3.0
        ));
        assert!(close(
            map.cast_ray(&v(4.0, 4.0, 9.5), &v(0.0, 0.0, -1.0), 20.0),
            2.5
        ));
        // Past the cap: z = 7.5 passes over it.
        assert_eq!(
            map.cast_ray(&v(0.0, 4.0, 7.5), &v(1.0, 0.0, 0.0), 8.0),
            None
        );
        // Box: diagonal ray into its corner region.
        assert!(close(
            map.cast_ray(&v(16.0, 3.0, 9.0), &v(0.0, 0.0, -1.0), 20.0),
            6.0
        ));
        let d = v(1.0, 1.0, 0.0);
        let hit = map.cast_ray(&v(12.0, -1.0, 2.0), &d, 20.0).unwrap();
        assert!((hit - 3.0 * 2f64.sqrt()).abs() < 1e-9, "{hit}");
        // Inside an obstacle: 0. Nearest of several along the ray wins.
        assert_eq!(
            map.cast_ray(&v(10.0, 10.0, 5.0), &v(1.0, 0.0, 0.0), 5.0),
            Some(0.0)
        );
        assert!(close(
            map.cast_ray(&v(0.0, 4.0, 5.0), &v(1.0, 0.0, 0.0), 100.0),
            3.0
        ));
        // Invalid input is "blocked at once"; a zero range hits only from inside.
        assert_eq!(map.cast_ray(&v(f64::NAN, 0.0, 0.0), &d, 1.0), Some(0.0));
        assert_eq!(
            map.cast_ray(&v(1.0, 1.0, 1.0), &Vec3::zeros(), 1.0),
            Some(0.0)
        );
        assert_eq!(map.cast_ray(&v(1.0, 1.0, 1.0), &d, f64::NAN), Some(0.0));
        assert_eq!(map.cast_ray(&v(1.0, 1.0, 1.0), &d, 0.0), None);
        assert_eq!(map.cast_ray(&v(1.0, 1.0, 1.0), &d, -3.0), None);
        // An empty map never hits.
        let empty = StaticMap::new(bounds()).unwrap();
        assert_eq!(empty.cast_ray(&v(1.0, 1.0, 1.0), &d, 1e3), None);
        // The shape method agrees with the map.
        assert!(close(
            Shape::from(ball).cast_ray(&v(1.0, 10.0, 5.0), &v(1.0, 0.0, 0.0), 20.0),
            7.0
        ));
    }

    #[test]
    fn ray_cast_on_the_esdf_stops_at_the_zero_level() {
        // A wall of points at x in [10, 10.5): voxels of 0.25 m from x = 10.
        let mut pts = Vec::new();
        for j in 0..80 {
            for k in 0..40 {
                pts.push(v(10.1, 0.125 + 0.25 * j as f64, 0.125 + 0.25 * k as f64));
            }
        }
        let map = StaticMap::new(bounds())
            .unwrap()
            .with_point_cloud(&pts, 0.25)
            .unwrap();
        let hit = map
            .cast_ray(&v(2.0, 10.1, 5.1), &v(1.0, 0.0, 0.0), 20.0)
            .unwrap();
        // The zero level lies on the voxel face at x = 10 (within the tracer's tolerance).
        assert!((hit - 8.0).abs() < 1e-3, "{hit}");
        assert!(map.signed_distance(&v(2.0 + hit, 10.1, 5.1)).abs() < 1e-3);
        assert_eq!(
            map.cast_ray(&v(2.0, 10.1, 5.1), &v(-1.0, 0.0, 0.0), 20.0),
            None
        );
        assert_eq!(
            map.cast_ray(&v(2.0, 10.1, 5.1), &v(1.0, 0.0, 0.0), 7.9),
            None
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

        /// The closed-form cylinder cast agrees with parry's GJK cast.
        #[test]
        fn closed_form_ray_cylinder_agrees_with_parry(
            o in point_strategy(), az in 0.0f64..6.0, el in -1.5f64..1.5, r in 0.1f64..2.0, h in 0.1f64..3.0,
        ) {
            let c = Cylinder::new(v(10.0, 10.0, 5.0), r, h).unwrap();
            let d = v(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            let ours = crate::parry_conv::ray_cylinder_hit(&c, &o, &d, 30.0);
            let gjk = crate::parry_conv::parry_ray_cylinder_hit(&c, &o, &d, 30.0);
            match (ours, gjk) {
                (Some(a), Some(b)) => prop_assert!((a - b).abs() < 1e-6, "{a} vs {b}"),
                (None, None) => {}
                // Grazing rays: both answers are within rounding of the surface.
                (a, b) => {
                    let t = a.or(b).unwrap();
                    prop_assert!(Shape::from(c).signed_distance(&(o + d * t)).abs() < 1e-6, "{a:?} vs {b:?}");
                }
            }
        }

        /// The BVH cast equals the nearest hit over all shapes, and the point it reports lies on
        /// the surface.
        #[test]
        fn cast_ray_matches_brute_force(seed in 0u64..4, o in point_strategy(), az in 0.0f64..6.0, el in -1.5f64..1.5) {
            let shapes = random_shapes(120, seed);
            let map = StaticMap::from_shapes(bounds(), shapes.clone()).unwrap();
            let d = v(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            let got = map.cast_ray(&o, &d, 30.0);
            let brute = shapes.iter().filter_map(|s| s.cast_ray(&o, &d, 30.0)).fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t))));
            prop_assert_eq!(got.is_some(), brute.is_some());
            if let (Some(g), Some(b)) = (got, brute) {
                prop_assert!((g - b).abs() < 1e-9, "{g} vs {b}");
                if g > 0.0 {
                    prop_assert!(map.signed_distance(&(o + d * g)).abs() < 1e-6);
                }
            }
        }
    }

    #[test]
    fn empty_map_is_infinitely_far() {
        let map = StaticMap::new(bounds()).unwrap();
        let p = v(1.0, 2.0, 3.0);
        assert_eq!(
            map.distance_and_gradient(&p),
            (f64::INFINITY, Vec3::zeros())
        );
        assert!(map.is_free(&p, 100.0));
        assert!(map.segment_clear(&p, &v(5.0, 5.0, 5.0), 10.0));
        assert!(map.has_no_obstacles());
        assert_eq!(map.nearest_shape(&p), None);
        let mut out = vec![1];
        map.shapes_near(&bounds(), &mut out);
        assert!(out.is_empty());
        assert_eq!(map.resolution(), DEFAULT_RESOLUTION);
        // An empty point cloud keeps it empty.
        let map = map.with_point_cloud(&[], 0.5).unwrap();
        assert_eq!(
            map.distance_and_gradient(&p),
            (f64::INFINITY, Vec3::zeros())
        );
        assert!(map.has_no_obstacles());
        assert_eq!(map.resolution(), 0.5);
    }

    #[test]
    fn degenerate_queries() {
        let s = Sphere::new(v(5.0, 5.0, 5.0), 1.0).unwrap();
        let map = StaticMap::from_shapes(bounds(), vec![s.into()]).unwrap();
        // Point exactly at the centre.
        assert_eq!(
            map.distance_and_gradient(&s.center),
            (-1.0, v(0.0, 0.0, 1.0))
        );
        // Zero-length segments.
        assert!(map.segment_clear(&v(1.0, 1.0, 1.0), &v(1.0, 1.0, 1.0), 0.5));
        assert!(!map.segment_clear(&s.center, &s.center, 0.0));
        // Non-finite input.
        let nan = v(f64::NAN, 0.0, 0.0);
        assert_eq!(
            map.distance_and_gradient(&nan),
            (f64::NEG_INFINITY, Vec3::zeros())
        );
        assert!(!map.is_free(&nan, 0.0));
        assert!(!map.is_free(&v(0.0, 0.0, 0.0), f64::NAN));
        assert!(!map.segment_clear(&nan, &v(0.0, 0.0, 0.0), 0.0));
        assert!(!map.segment_clear(&v(0.0, 0.0, 0.0), &v(1.0, 0.0, 0.0), f64::NAN));
        // Grazing segments: tangent at clearance 0 counts as blocked, passing at 0.5 is clear
        // with clearance 0.5 - eps and blocked with 0.5 + eps.
        assert!(!map.segment_clear(&v(0.0, 4.0, 5.0), &v(10.0, 4.0, 5.0), 0.0));
        assert!(map.segment_clear(&v(0.0, 3.5, 5.0), &v(10.0, 3.5, 5.0), 0.5 - 1e-6));
        assert!(!map.segment_clear(&v(0.0, 3.5, 5.0), &v(10.0, 3.5, 5.0), 0.5 + 1e-6));
        // Negative clearance acts as zero.
        assert!(!map.segment_clear(&v(0.0, 5.0, 5.0), &v(10.0, 5.0, 5.0), -5.0));
        // Points outside the bounds are fine for distance queries.
        assert!(!map.contains(&v(-5.0, 5.0, 5.0)));
        assert!((map.signed_distance(&v(-5.0, 5.0, 5.0)) - 9.0).abs() < 1e-12);
    }

    #[test]
    fn box_edge_and_cylinder_segments() {
        let b = AaBox::new(v(2.0, 2.0, 2.0), v(4.0, 4.0, 4.0)).unwrap();
        let c = Cylinder::new(v(10.0, 10.0, 5.0), 1.0, 2.0).unwrap();
        let map = StaticMap::from_shapes(bounds(), vec![b.into(), c.into()]).unwrap();
        let (d, g) = map.distance_and_gradient(&v(4.0, 4.0, 3.0));
        assert_eq!(d, 0.0);
        assert!((g.norm() - 1.0).abs() < 1e-12);
        // Segment over the box's top edge at height 0.3 above it.
        assert!(map.segment_clear(&v(0.0, 3.0, 4.3), &v(6.0, 3.0, 4.3), 0.29));
        assert!(!map.segment_clear(&v(0.0, 3.0, 4.3), &v(6.0, 3.0, 4.3), 0.31));
        // A vertical segment beside the cylinder (its axis is z, not parry's y).
        assert!(map.segment_clear(&v(11.5, 10.0, 0.0), &v(11.5, 10.0, 9.0), 0.49));
        assert!(!map.segment_clear(&v(11.5, 10.0, 0.0), &v(11.5, 10.0, 9.0), 0.51));
        // A horizontal segment above the cap.
        assert!(map.segment_clear(&v(5.0, 10.0, 7.5), &v(15.0, 10.0, 7.5), 0.49));
        assert!(!map.segment_clear(&v(5.0, 10.0, 7.5), &v(15.0, 10.0, 7.5), 0.51));
    }

    #[test]
    fn constructors_validate() {
        let flat = Aabb::new(v(0.0, 0.0, 0.0), v(1.0, 1.0, 0.0)).unwrap();
        let e = StaticMap::new(flat).unwrap_err();
        assert_eq!(
            e.to_string(),
            "bounds: zero extent along z (min = max = 0); expected a positive volume"
        );
        let bad = Shape::Sphere(Sphere {
            center: Vec3::zeros(),
            radius: -1.0,
        });
        let ok = Shape::Sphere(Sphere {
            center: Vec3::zeros(),
            radius: 1.0,
        });
        let e = StaticMap::from_shapes(bounds(), vec![ok, bad]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "shapes[1].sphere.radius must be >= 0, got -1"
        );
        let map = StaticMap::new(bounds()).unwrap();
        assert!(matches!(
            map.clone().with_resolution(0.0),
            Err(GeometryError::NonPositive { .. })
        ));
        assert!(matches!(
            map.clone().with_point_cloud(&[], -1.0),
            Err(GeometryError::NonPositive { .. })
        ));
        assert!(matches!(
            map.with_point_cloud(&[], 1e-4),
            Err(GeometryError::GridTooLarge { .. })
        ));
    }

    #[test]
    fn map_is_send_sync_debug_clone() {
        fn check<T: Send + Sync + std::fmt::Debug + Clone>() {}
        check::<StaticMap>();
        check::<Esdf>();
        check::<Shape>();
    }
}
