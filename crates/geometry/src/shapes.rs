//! Analytic shapes (sphere, vertical cylinder, axis-aligned box) and their exact signed distance
//! functions with gradients.
//!
//! # Conventions
//!
//! * Signed distance is negative inside, zero on the surface, positive outside, and exact
//!   (Euclidean) everywhere.
//! * The gradient is the unit outward direction of steepest increase of the distance. Where the
//!   distance is not differentiable it is a documented unit vector from the subdifferential, never
//!   NaN:
//!   - sphere centre: `+z`;
//!   - inside a box or cylinder where two faces are equally near (medial surface, including edges
//!     and the centre): the face listed first wins — box: `x` before `y` before `z`; cylinder: the
//!     side wall before the caps; on a symmetry plane (`p_i` equal to the centre's `p_i`) the `+`
//!     side is chosen;
//!   - cylinder axis (inside, side wall nearest): `+x`.
//!
//! The free functions ([`sphere_sdf`], [`cylinder_sdf`], [`box_sdf`], and the size-gradient
//! variants) take raw parameters so that callers with time-varying centres and radii (moving
//! obstacles in `trust-predict`, the DDF cost in `trust-minco`) can reuse them. They do not
//! validate; the shape structs do.

use serde::{Deserialize, Serialize};

use crate::Vec3;
use crate::aabb::{Aabb, check_box};
use crate::error::{GeometryError, check_coord, check_non_negative, check_vec};

/// The direction used where the distance to a sphere's centre (or a cylinder's axis) has no
/// direction.
const SPHERE_CENTRE_GRADIENT: Vec3 = Vec3::new(0.0, 0.0, 1.0);

/// `+1` for `x >= 0`, `-1` otherwise (so a point on a symmetry plane picks the `+` side).
fn side(x: f64) -> f64 {
    if x >= 0.0 { 1.0 } else { -1.0 }
}

/// Exact signed distance from `p` to the sphere `(center, radius)` and its gradient with respect
/// to `p`.
///
/// The gradient is `(p - center) / |p - center|`, or `+z` at the centre. Derivatives with respect
/// to the other arguments follow directly: `∂d/∂center = -gradient`, `∂d/∂radius = -1`.
#[inline]
pub fn sphere_sdf(center: &Vec3, radius: f64, p: &Vec3) -> (f64, Vec3) {
    if !crate::scale::queryable(&[p.x, p.y, p.z, center.x, center.y, center.z, radius]) {
        return (f64::NEG_INFINITY, Vec3::zeros());
    }
    let d = p - center;
    let n = d.norm();
    if n > 0.0 {
        (n - radius, d / n)
    } else {
        (-radius, SPHERE_CENTRE_GRADIENT)
    }
}

/// Exact signed distance from `p` to the vertical (z-axis) cylinder with the given `center` (the
/// middle of its axis), `radius` and `half_height`, and its gradient with respect to `p`.
///
/// `∂d/∂center = -gradient`. For derivatives with respect to the radius and half-height use
/// [`cylinder_sdf_with_size_gradient`].
pub fn cylinder_sdf(center: &Vec3, radius: f64, half_height: f64, p: &Vec3) -> (f64, Vec3) {
    let s = cylinder_sdf_with_size_gradient(center, radius, half_height, p);
    (s.distance, s.gradient)
}

/// Signed distance to a cylinder with all its first derivatives; see
/// [`cylinder_sdf_with_size_gradient`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderSdf {
    /// Signed distance.
    pub distance: f64,
    /// `∂d/∂p` (a unit vector); `∂d/∂center` is its negative.
    pub gradient: Vec3,
    /// `∂d/∂radius` (in `[-1, 0]`).
    pub d_radius: f64,
    /// `∂d/∂half_height` (in `[-1, 0]`).
    pub d_half_height: f64,
}

/// [`cylinder_sdf`] plus the derivatives of the distance with respect to the radius and the
/// half-height (for obstacles whose size changes with time).
///
/// Writing `ρ = |(p - c)_xy|`, `a = |p_z - c_z|`, `dr = ρ - radius`, `dz = a - half_height`:
/// outside (`dr > 0` or `dz > 0`) the distance is `|(max(dr,0), max(dz,0))|`; inside it is
/// `max(dr, dz)` (ties go to the side wall).
#[inline]
pub fn cylinder_sdf_with_size_gradient(
    center: &Vec3,
    radius: f64,
    half_height: f64,
    p: &Vec3,
) -> CylinderSdf {
    if !crate::scale::queryable(&[
        p.x,
        p.y,
        p.z,
        center.x,
        center.y,
        center.z,
        radius,
        half_height,
    ]) {
        return CylinderSdf {
            distance: f64::NEG_INFINITY,
            gradient: Vec3::zeros(),
            d_radius: 0.0,
            d_half_height: 0.0,
        };
    }
    let q = p - center;
    let rho = q.x.hypot(q.y);
    let radial = if rho > 0.0 {
        Vec3::new(q.x / rho, q.y / rho, 0.0)
    } else {
        Vec3::x()
    };
    let axial = Vec3::new(0.0, 0.0, side(q.z));
    let dr = rho - radius;
    let dz = q.z.abs() - half_height;
    if dr > 0.0 || dz > 0.0 {
        let er = dr.max(0.0);
        let ez = dz.max(0.0);
        let d = er.hypot(ez);
        CylinderSdf {
            distance: d,
            gradient: (radial * er + axial * ez) / d,
            d_radius: -er / d,
            d_half_height: -ez / d,
        }
    } else if dr >= dz {
        CylinderSdf {
            distance: dr,
            gradient: radial,
            d_radius: -1.0,
            d_half_height: 0.0,
        }
    } else {
        CylinderSdf {
            distance: dz,
            gradient: axial,
            d_radius: 0.0,
            d_half_height: -1.0,
        }
    }
}

/// Exact signed distance from `p` to the axis-aligned box `[min, max]` and its gradient with
/// respect to `p`.
///
/// Outside, the gradient points from the nearest surface point to `p`; inside, it is the outward
/// normal of the nearest face (ties: `x` before `y` before `z`, `+` side on the mid-plane).
/// `min <= max` is assumed (not checked).
pub fn box_sdf(min: &Vec3, max: &Vec3, p: &Vec3) -> (f64, Vec3) {
    if !crate::scale::queryable(&[p.x, p.y, p.z, min.x, min.y, min.z, max.x, max.y, max.z]) {
        return (f64::NEG_INFINITY, Vec3::zeros());
    }
    let c = 0.5 * (min + max);
    let h = 0.5 * (max - min);
    let rel = p - c;
    let s = Vec3::new(side(rel.x), side(rel.y), side(rel.z));
    let q = rel.abs() - h;
    let outside = q.sup(&Vec3::zeros());
    let n = outside.norm();
    if n > 0.0 {
        return (n, s.component_mul(&outside) / n);
    }
    let mut k = 0;
    for i in 1..3 {
        if q[i] > q[k] {
            k = i;
        }
    }
    let mut g = Vec3::zeros();
    g[k] = s[k];
    (q[k], g)
}

/// A solid ball.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawSphere", into = "RawSphere")]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (`>= 0`).
    pub radius: f64,
}

/// A solid cylinder with a vertical (z) axis and flat caps.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawCylinder", into = "RawCylinder")]
pub struct Cylinder {
    /// Middle of the axis segment.
    pub center: Vec3,
    /// Radius (`>= 0`).
    pub radius: f64,
    /// Half of the height (`>= 0`); the caps are at `center.z ± half_height`.
    pub half_height: f64,
}

/// A solid axis-aligned box `[min, max]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawAaBox", into = "RawAaBox")]
pub struct AaBox {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner (`>= min` per axis).
    pub max: Vec3,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSphere {
    center: Vec3,
    radius: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCylinder {
    center: Vec3,
    radius: f64,
    half_height: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAaBox {
    min: Vec3,
    max: Vec3,
}

impl TryFrom<RawSphere> for Sphere {
    type Error = GeometryError;
    fn try_from(r: RawSphere) -> Result<Self, GeometryError> {
        Sphere::new(r.center, r.radius)
    }
}
impl From<Sphere> for RawSphere {
    fn from(s: Sphere) -> Self {
        RawSphere {
            center: s.center,
            radius: s.radius,
        }
    }
}
impl TryFrom<RawCylinder> for Cylinder {
    type Error = GeometryError;
    fn try_from(r: RawCylinder) -> Result<Self, GeometryError> {
        Cylinder::new(r.center, r.radius, r.half_height)
    }
}
impl From<Cylinder> for RawCylinder {
    fn from(c: Cylinder) -> Self {
        RawCylinder {
            center: c.center,
            radius: c.radius,
            half_height: c.half_height,
        }
    }
}
impl TryFrom<RawAaBox> for AaBox {
    type Error = GeometryError;
    fn try_from(r: RawAaBox) -> Result<Self, GeometryError> {
        AaBox::new(r.min, r.max)
    }
}
impl From<AaBox> for RawAaBox {
    fn from(b: AaBox) -> Self {
        RawAaBox {
            min: b.min,
            max: b.max,
        }
    }
}

/// Replaces a non-finite inflation by 0.
fn finite_or_zero(r: f64) -> f64 {
    if r.is_finite() { r } else { 0.0 }
}

impl Sphere {
    /// Creates a sphere; errors on a non-finite centre or a negative/non-finite radius.
    pub fn new(center: Vec3, radius: f64) -> Result<Self, GeometryError> {
        check_vec("sphere.center", &center)?;
        check_non_negative("sphere.radius", radius)?;
        // `abs` turns an accepted `-0.0` into `+0.0` (parry asserts positive signs).
        Ok(Self {
            center,
            radius: radius.abs(),
        })
    }

    /// Exact signed distance from `p` (negative inside).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// Signed distance and its gradient (see [`sphere_sdf`]).
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        sphere_sdf(&self.center, self.radius, p)
    }

    /// Bounding box.
    pub fn aabb(&self) -> Aabb {
        let r = Vec3::repeat(self.radius);
        Aabb {
            min: self.center - r,
            max: self.center + r,
        }
    }

    /// The sphere with radius `radius + r` (clamped at 0; a non-finite `r` is treated as 0). This
    /// is exactly the Minkowski sum with a ball of radius `r` for `r >= 0`.
    pub fn inflated(&self, r: f64) -> Sphere {
        Sphere {
            center: self.center,
            radius: (self.radius + finite_or_zero(r)).max(0.0),
        }
    }
}

impl Cylinder {
    /// Creates a vertical cylinder; errors on a non-finite centre or a negative/non-finite radius or
    /// half-height.
    pub fn new(center: Vec3, radius: f64, half_height: f64) -> Result<Self, GeometryError> {
        check_vec("cylinder.center", &center)?;
        check_non_negative("cylinder.radius", radius)?;
        check_non_negative("cylinder.half_height", half_height)?;
        // `abs` turns an accepted `-0.0` into `+0.0` (parry asserts positive signs).
        Ok(Self {
            center,
            radius: radius.abs(),
            half_height: half_height.abs(),
        })
    }

    /// Creates a vertical cylinder standing on `z = z_min` and reaching `z = z_max` at the
    /// horizontal position `(x, y)`.
    pub fn from_extent(
        x: f64,
        y: f64,
        z_min: f64,
        z_max: f64,
        radius: f64,
    ) -> Result<Self, GeometryError> {
        check_coord("cylinder.z_min", z_min)?;
        check_coord("cylinder.z_max", z_max)?;
        if z_min > z_max {
            return Err(GeometryError::InvertedBox {
                field: "cylinder".into(),
                axis: 'z',
                min: z_min,
                max: z_max,
            });
        }
        Self::new(
            Vec3::new(x, y, 0.5 * (z_min + z_max)),
            radius,
            0.5 * (z_max - z_min),
        )
    }

    /// Exact signed distance from `p` (negative inside).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// Signed distance and its gradient (see [`cylinder_sdf`]).
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        cylinder_sdf(&self.center, self.radius, self.half_height, p)
    }

    /// Bounding box.
    pub fn aabb(&self) -> Aabb {
        let e = Vec3::new(self.radius, self.radius, self.half_height);
        Aabb {
            min: self.center - e,
            max: self.center + e,
        }
    }

    /// The cylinder with radius `radius + r` and half-height `half_height + r` (each clamped at 0;
    /// a non-finite `r` is treated as 0). For `r >= 0` it contains the Minkowski sum with a ball of
    /// radius `r` (which has rounded rims), so it is a conservative inflation.
    pub fn inflated(&self, r: f64) -> Cylinder {
        let r = finite_or_zero(r);
        Cylinder {
            center: self.center,
            radius: (self.radius + r).max(0.0),
            half_height: (self.half_height + r).max(0.0),
        }
    }
}

impl AaBox {
    /// Creates a box; errors on non-finite corners or `min > max` along an axis (zero extent is
    /// allowed: a flat plate).
    pub fn new(min: Vec3, max: Vec3) -> Result<Self, GeometryError> {
        check_box("box", &min, &max)?;
        Ok(Self { min, max })
    }

    /// Creates a box from its centre and half extents (each `>= 0`).
    pub fn from_center_half_extents(
        center: Vec3,
        half_extents: Vec3,
    ) -> Result<Self, GeometryError> {
        check_vec("box.center", &center)?;
        check_vec("box.half_extents", &half_extents)?;
        for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
            check_non_negative(&format!("box.half_extents.{axis}"), half_extents[i])?;
        }
        Self::new(center - half_extents, center + half_extents)
    }

    /// Exact signed distance from `p` (negative inside).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// Signed distance and its gradient (see [`box_sdf`]).
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        box_sdf(&self.min, &self.max, p)
    }

    /// Bounding box (the box itself).
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    /// The box grown by `r` on every side (each axis clamped at zero extent; a non-finite `r` is
    /// treated as 0). For `r >= 0` it contains the Minkowski sum with a ball of radius `r`.
    pub fn inflated(&self, r: f64) -> AaBox {
        let a = self.aabb().inflated(finite_or_zero(r));
        AaBox {
            min: a.min,
            max: a.max,
        }
    }
}

/// One of the analytic obstacle shapes.
///
/// Serialized with a `kind` tag: `{ kind = "sphere", center = [..], radius = .. }`,
/// `kind = "cylinder"` or `kind = "box"`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Shape {
    /// A ball.
    Sphere(Sphere),
    /// A vertical cylinder.
    Cylinder(Cylinder),
    /// An axis-aligned box.
    #[serde(rename = "box")]
    AaBox(AaBox),
}

impl From<Sphere> for Shape {
    fn from(s: Sphere) -> Self {
        Shape::Sphere(s)
    }
}
impl From<Cylinder> for Shape {
    fn from(c: Cylinder) -> Self {
        Shape::Cylinder(c)
    }
}
impl From<AaBox> for Shape {
    fn from(b: AaBox) -> Self {
        Shape::AaBox(b)
    }
}

impl Shape {
    /// Re-checks the invariants of the wrapped shape (useful after mutating public fields).
    pub fn validate(&self) -> Result<(), GeometryError> {
        match self {
            Shape::Sphere(s) => Sphere::new(s.center, s.radius).map(|_| ()),
            Shape::Cylinder(c) => Cylinder::new(c.center, c.radius, c.half_height).map(|_| ()),
            Shape::AaBox(b) => AaBox::new(b.min, b.max).map(|_| ()),
        }
    }

    /// Bounding box.
    pub fn aabb(&self) -> Aabb {
        match self {
            Shape::Sphere(s) => s.aabb(),
            Shape::Cylinder(c) => c.aabb(),
            Shape::AaBox(b) => b.aabb(),
        }
    }

    /// The same kind of shape grown by `r` (see [`Sphere::inflated`], [`Cylinder::inflated`],
    /// [`AaBox::inflated`]); always contains the Minkowski sum with a ball of radius `r >= 0`.
    pub fn inflated(&self, r: f64) -> Shape {
        match self {
            Shape::Sphere(s) => Shape::Sphere(s.inflated(r)),
            Shape::Cylinder(c) => Shape::Cylinder(c.inflated(r)),
            Shape::AaBox(b) => Shape::AaBox(b.inflated(r)),
        }
    }

    /// Exact signed distance from `p` (negative inside).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// Signed distance and its gradient (see the module docs for non-differentiable points).
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        match self {
            Shape::Sphere(s) => s.distance_and_gradient(p),
            Shape::Cylinder(c) => c.distance_and_gradient(p),
            Shape::AaBox(b) => b.distance_and_gradient(p),
        }
    }

    /// True if `p` is at distance `>= clearance` from the shape.
    pub fn is_free(&self, p: &Vec3, clearance: f64) -> bool {
        self.signed_distance(p) >= clearance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const H: f64 = 1e-6;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    /// Central finite-difference gradient of `f` at `p`.
    fn fd_gradient(f: impl Fn(&Vec3) -> f64, p: &Vec3) -> Vec3 {
        Vec3::from(trust_numdiff::gradient_array(
            |q| f(&Vec3::from(q)),
            (*p).into(),
            H,
        ))
    }

    fn assert_close(a: &Vec3, b: &Vec3, tol: f64) -> Result<(), TestCaseError> {
        prop_assert!(
            (a - b).norm() <= tol,
            "analytic {a:?} vs finite difference {b:?}"
        );
        Ok(())
    }

    fn coord() -> impl Strategy<Value = f64> {
        -3.0f64..3.0
    }

    fn point() -> impl Strategy<Value = Vec3> {
        (coord(), coord(), coord()).prop_map(|(x, y, z)| v(x, y, z))
    }

    /// The two largest entries of `q` differ by more than `gap`.
    fn top_two_separated(q: &[f64], gap: f64) -> bool {
        let mut s = q.to_vec();
        s.sort_by(|a, b| b.total_cmp(a));
        s[0] - s[1] > gap
    }

    proptest! {
        #[test]
        fn sphere_gradient_matches_fd(c in point(), r in 0.0f64..2.0, p in point()) {
            prop_assume!((p - c).norm() > 1e-3);
            let (d, g) = sphere_sdf(&c, r, &p);
            prop_assert!((d - ((p - c).norm() - r)).abs() < 1e-12);
            prop_assert!((g.norm() - 1.0).abs() < 1e-12);
            assert_close(&g, &fd_gradient(|x| sphere_sdf(&c, r, x).0, &p), 1e-6)?;
        }

        #[test]
        fn box_gradient_matches_fd(c in point(), h in (0.0f64..2.0, 0.0f64..2.0, 0.0f64..2.0), p in point()) {
            let h = v(h.0, h.1, h.2);
            let (min, max) = (c - h, c + h);
            let rel = p - c;
            let q = rel.abs() - h;
            let inside = q.max() <= 1e-4;
            if inside {
                // Medial surfaces inside: the two nearest faces are equally near.
                prop_assume!(top_two_separated(q.as_slice(), 1e-4));
                let k = q.imax();
                prop_assume!(rel[k].abs() > 1e-4);
            }
            let (d, g) = box_sdf(&min, &max, &p);
            prop_assert!((g.norm() - 1.0).abs() < 1e-12);
            prop_assert!(d.is_finite());
            assert_close(&g, &fd_gradient(|x| box_sdf(&min, &max, x).0, &p), 1e-5)?;
        }

        #[test]
        fn cylinder_gradient_matches_fd(
            c in point(), r in 0.0f64..2.0, hh in 0.0f64..2.0, p in point(),
        ) {
            let q = p - c;
            let rho = q.x.hypot(q.y);
            let dr = rho - r;
            let dz = q.z.abs() - hh;
            prop_assume!(rho > 1e-4);
            if dr <= 1e-4 && dz <= 1e-4 {
                prop_assume!((dr - dz).abs() > 1e-4);
                prop_assume!(dr > dz || q.z.abs() > 1e-4);
            }
            let s = cylinder_sdf_with_size_gradient(&c, r, hh, &p);
            prop_assert!((s.gradient.norm() - 1.0).abs() < 1e-12);
            assert_close(&s.gradient, &fd_gradient(|x| cylinder_sdf(&c, r, hh, x).0, &p), 1e-5)?;
            // Size derivatives.
            let fd_r = (cylinder_sdf(&c, r + H, hh, &p).0 - cylinder_sdf(&c, (r - H).max(0.0), hh, &p).0)
                / (r + H - (r - H).max(0.0));
            let fd_h = (cylinder_sdf(&c, r, hh + H, &p).0 - cylinder_sdf(&c, r, (hh - H).max(0.0), &p).0)
                / (hh + H - (hh - H).max(0.0));
            if r > 1e-4 && hh > 1e-4 {
                prop_assert!((s.d_radius - fd_r).abs() < 1e-5, "{} vs {}", s.d_radius, fd_r);
                prop_assert!((s.d_half_height - fd_h).abs() < 1e-5, "{} vs {}", s.d_half_height, fd_h);
            }
        }

        /// Points sampled near the cylinder's caps and rim, where the branches meet.
        #[test]
        fn cylinder_gradient_near_caps_and_rim(
            r in 0.2f64..2.0, hh in 0.2f64..2.0, ang in 0.0f64..std::f64::consts::TAU,
            drho in -0.15f64..0.15, dzz in -0.15f64..0.15, top in any::<bool>(),
        ) {
            let c = v(0.3, -0.2, 1.0);
            let rho = (r + drho).max(0.0);
            let zc = if top { hh + dzz } else { -(hh + dzz) };
            let p = c + v(rho * ang.cos(), rho * ang.sin(), zc);
            let (dr, dz) = (rho - r, zc.abs() - hh);
            if dr <= 1e-4 && dz <= 1e-4 {
                prop_assume!((dr - dz).abs() > 1e-4);
            }
            prop_assume!(rho > 1e-4);
            let (_, g) = cylinder_sdf(&c, r, hh, &p);
            assert_close(&g, &fd_gradient(|x| cylinder_sdf(&c, r, hh, x).0, &p), 1e-5)?;
        }

        /// The exact distance agrees with the distance to dense surface samples (outside points).
        #[test]
        fn cylinder_distance_is_euclidean(r in 0.1f64..2.0, hh in 0.1f64..2.0, p in point()) {
            let c = Vec3::zeros();
            let d = cylinder_sdf(&c, r, hh, &p).0;
            prop_assume!(d > 0.0);
            // Nearest point on the solid: clamp radially and axially.
            let rho = p.x.hypot(p.y);
            let scale = if rho > r { r / rho } else { 1.0 };
            let near = v(p.x * scale, p.y * scale, p.z.clamp(-hh, hh));
            prop_assert!((d - (p - near).norm()).abs() < 1e-12);
        }
    }

    #[test]
    fn degenerate_points_have_unit_gradients() {
        let (d, g) = sphere_sdf(&v(1.0, 2.0, 3.0), 0.5, &v(1.0, 2.0, 3.0));
        assert_eq!((d, g), (-0.5, v(0.0, 0.0, 1.0)));
        // Box centre and edge.
        let (min, max) = (v(-1.0, -1.0, -1.0), v(1.0, 1.0, 1.0));
        assert_eq!(
            box_sdf(&min, &max, &Vec3::zeros()),
            (-1.0, v(1.0, 0.0, 0.0))
        );
        let (d, g) = box_sdf(&min, &max, &v(1.0, 1.0, 0.0));
        assert_eq!(d, 0.0);
        assert_eq!(g, v(1.0, 0.0, 0.0));
        let (d, g) = box_sdf(&min, &max, &v(2.0, 2.0, 0.0));
        assert!((d - 2f64.sqrt()).abs() < 1e-15);
        assert!((g - v(1.0, 1.0, 0.0).normalize()).norm() < 1e-15);
        // Corner.
        let (d, g) = box_sdf(&min, &max, &v(-1.0, -1.0, -1.0));
        assert_eq!((d, g), (0.0, v(-1.0, 0.0, 0.0)));
        // Zero-size box is a point.
        let (d, g) = box_sdf(&Vec3::zeros(), &Vec3::zeros(), &Vec3::zeros());
        assert_eq!(d, 0.0);
        assert!((g.norm() - 1.0).abs() < 1e-15);
        // Cylinder axis, centre, rim, and a zero-radius cylinder.
        let c = Vec3::zeros();
        assert_eq!(cylinder_sdf(&c, 1.0, 2.0, &c), (-1.0, v(1.0, 0.0, 0.0)));
        assert_eq!(cylinder_sdf(&c, 1.0, 0.5, &c), (-0.5, v(0.0, 0.0, 1.0)));
        assert_eq!(
            cylinder_sdf(&c, 1.0, 0.5, &v(0.0, 0.0, -0.2)),
            (-0.3, v(0.0, 0.0, -1.0))
        );
        let (d, g) = cylinder_sdf(&c, 1.0, 1.0, &v(1.0, 0.0, 1.0));
        assert_eq!(d, 0.0);
        assert!((g.norm() - 1.0).abs() < 1e-15);
        let (d, g) = cylinder_sdf(&c, 0.0, 0.0, &c);
        assert_eq!(d, 0.0);
        assert!((g.norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn constructors_validate_and_name_fields() {
        let e = Sphere::new(v(0.0, f64::NAN, 0.0), 1.0).unwrap_err();
        assert_eq!(e.to_string(), "sphere.center.y must be finite, got NaN");
        let e = Sphere::new(Vec3::zeros(), -1.0).unwrap_err();
        assert_eq!(e.to_string(), "sphere.radius must be >= 0, got -1");
        let e = Cylinder::new(Vec3::zeros(), 1.0, f64::INFINITY).unwrap_err();
        assert!(e.to_string().contains("cylinder.half_height"), "{e}");
        let e = Cylinder::new(Vec3::zeros(), -0.5, 1.0).unwrap_err();
        assert!(matches!(e, GeometryError::Negative { .. }), "{e}");
        let e = Cylinder::from_extent(0.0, 0.0, 2.0, 1.0, 1.0).unwrap_err();
        assert!(
            matches!(e, GeometryError::InvertedBox { axis: 'z', .. }),
            "{e}"
        );
        let e = AaBox::new(v(0.0, 0.0, 1.0), v(1.0, 1.0, 0.0)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "box: min.z = 1 exceeds max.z = 0; expected min <= max"
        );
        let e = AaBox::from_center_half_extents(Vec3::zeros(), v(1.0, -1.0, 1.0)).unwrap_err();
        assert!(e.to_string().contains("box.half_extents.y"), "{e}");
        assert!(AaBox::new(Vec3::zeros(), v(1.0, 0.0, 1.0)).is_ok());
        let c = Cylinder::from_extent(1.0, 2.0, 0.0, 4.0, 0.5).unwrap();
        assert_eq!(c.center, v(1.0, 2.0, 2.0));
        assert_eq!(c.half_height, 2.0);
    }

    #[test]
    fn shape_enum_dispatches_and_inflates() {
        let s: Shape = Sphere::new(Vec3::zeros(), 1.0).unwrap().into();
        let c: Shape = Cylinder::new(Vec3::zeros(), 1.0, 2.0).unwrap().into();
        let b: Shape = AaBox::new(v(-1.0, -1.0, -1.0), v(1.0, 1.0, 1.0))
            .unwrap()
            .into();
        let p = v(3.0, 0.0, 0.0);
        for shape in [s, c, b] {
            assert!((shape.signed_distance(&p) - 2.0).abs() < 1e-12);
            let inflated = shape.inflated(0.5);
            assert!((inflated.signed_distance(&p) - 1.5).abs() < 1e-12);
            assert!(inflated.aabb().contains(&v(1.5, 0.0, 0.0)));
            // Shrinking below zero size clamps, never inverts.
            assert!(shape.inflated(-10.0).validate().is_ok());
            assert_eq!(shape.inflated(f64::NAN), shape);
            assert!(shape.is_free(&p, 2.0) && !shape.is_free(&p, 2.1));
        }
        assert_eq!(c.aabb().max, v(1.0, 1.0, 2.0));
        // The inflated cylinder contains the Minkowski sum: rim points at distance r are inside.
        let rim = v(1.0 + 0.3, 0.0, 2.0 + 0.3);
        assert!(c.inflated(0.5).signed_distance(&rim) <= 0.0);
    }
}
