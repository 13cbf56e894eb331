//! Geometry constructors with each scalar argument at its edges, and `segment_clear` at contact.

use trust_core::Vec3;
use trust_geometry::{AaBox, Aabb, Cylinder, Shape, Sphere, StaticMap};

use super::{COUNT_EDGES, FLOAT_EDGES, judge_error};
use crate::apis::{Api, Fixtures, Outcome};
use crate::inputs::Gen;

fn edge(g: &mut Gen) -> f64 {
    FLOAT_EDGES[g.index(FLOAT_EDGES.len())]
}

/// One constructor argument at an edge (the others ordinary): an error must name it.
fn geo_constructors(g: &mut Gen, _: &Fixtures) -> Outcome {
    let x = edge(g);
    let axis = g.index(3);
    let mut v = Vec3::new(1.0, 2.0, 3.0);
    v[axis] = x;
    let (r, culprit): (Result<(), String>, &str) = match g.index(9) {
        0 => (
            Sphere::new(v, 1.0).map(|_| ()).map_err(|e| e.to_string()),
            "sphere.center",
        ),
        1 => (
            Sphere::new(Vec3::zeros(), x)
                .map(|_| ())
                .map_err(|e| e.to_string()),
            "sphere.radius",
        ),
        2 => (
            Cylinder::new(v, 1.0, 1.0)
                .map(|_| ())
                .map_err(|e| e.to_string()),
            "cylinder.center",
        ),
        3 => (
            Cylinder::new(Vec3::zeros(), x, 1.0)
                .map(|_| ())
                .map_err(|e| e.to_string()),
            "cylinder.radius",
        ),
        4 => (
            Cylinder::new(Vec3::zeros(), 1.0, x)
                .map(|_| ())
                .map_err(|e| e.to_string()),
            "cylinder.half_height",
        ),
        5 => (
            AaBox::new(Vec3::zeros(), v)
                .map(|_| ())
                .map_err(|e| e.to_string()),
            "box",
        ),
        6 => {
            let b = Aabb::new(Vec3::zeros(), Vec3::repeat(10.0)).expect("valid box");
            (
                b.try_inflated(x).map(|_| ()).map_err(|e| e.to_string()),
                "inflation",
            )
        }
        7 => {
            let b = Aabb::new(Vec3::zeros(), Vec3::repeat(10.0)).expect("valid box");
            let map = StaticMap::new(b).expect("valid bounds");
            (
                map.with_resolution(x)
                    .map(|_| ())
                    .map_err(|e| e.to_string()),
                "resolution",
            )
        }
        _ => {
            // ESDF resolution: grids above ~4e6 voxels are requested work, not accidents (as in
            // `geometry::StaticMap::build`); the cap itself is a regression test.
            let b = Aabb::new(Vec3::zeros(), Vec3::repeat(10.0)).expect("valid box");
            if x.is_finite() && x > 0.0 && (10.0 / x).powi(3) > 4.2e6 && (10.0 / x).powi(3) <= 2e8 {
                return Outcome::Err;
            }
            let map = StaticMap::new(b).expect("valid bounds");
            let r = map.with_point_cloud(&[Vec3::repeat(5.0)], x);
            (r.map(|_| ()).map_err(|e| e.to_string()), "resolution")
        }
    };
    match r {
        Ok(()) => Outcome::Ok,
        Err(msg) => judge_error(&msg, &[culprit]).unwrap_or(Outcome::Err),
    }
}

/// ESDF dimensions at the count edges: an error, never an allocation failure, readable.
fn geo_voxel_counts(g: &mut Gen, _: &Fixtures) -> Outcome {
    let dims = [
        COUNT_EDGES[g.index(COUNT_EDGES.len())],
        COUNT_EDGES[g.index(COUNT_EDGES.len())],
        g.count(4),
    ];
    match trust_geometry::checked_voxel_count(dims) {
        Ok(n) if n > 4_000_000 => Outcome::Ok,
        Ok(n) => {
            let occ = vec![false; n];
            match trust_geometry::Esdf::from_occupancy(Vec3::zeros(), 0.5, dims, &occ) {
                Ok(_) => Outcome::Ok,
                Err(e) => judge_error(&e.to_string(), &[]).unwrap_or(Outcome::Err),
            }
        }
        Err(e) => judge_error(&e.to_string(), &["voxel"]).unwrap_or(Outcome::Err),
    }
}

/// `segment_clear` at and near contact: a point at signed distance ≤ 0 is blocked as a segment
/// of every length (0, 1e-12, 1e-9, 1 µm) and direction; a point more than 1 mm away is clear
/// for all of those; and a segment is never clearer than its own end point.
fn geo_segment_clear_at_contact(g: &mut Gen, fx: &Fixtures) -> Outcome {
    let one;
    let map: &StaticMap = match g.index(3) {
        0 => &fx.shapes_map,
        1 => &fx.cloud_map,
        _ => {
            let b = fx.shapes_map.bounds();
            let s: Shape = match g.index(3) {
                0 => match Sphere::new(g.in_box(b), g.num(0.01, 3.0).abs().min(5.0)) {
                    Ok(s) => s.into(),
                    Err(_) => return Outcome::Err,
                },
                1 => match Cylinder::new(
                    g.in_box(b),
                    g.num(0.01, 3.0).abs().min(5.0),
                    g.num(0.01, 3.0).abs().min(5.0),
                ) {
                    Ok(s) => s.into(),
                    Err(_) => return Outcome::Err,
                },
                _ => {
                    let (a, c) = (g.in_box(b), g.in_box(b));
                    match AaBox::new(a.inf(&c), a.sup(&c)) {
                        Ok(s) => s.into(),
                        Err(_) => return Outcome::Err,
                    }
                }
            };
            one = match StaticMap::from_shapes(*b, vec![s]) {
                Ok(m) => m,
                Err(_) => return Outcome::Err,
            };
            &one
        }
    };
    let b = *map.bounds();
    let mut p = g.in_box(&b);
    if !p.iter().all(|c| c.is_finite() && c.abs() < 1e3) {
        return Outcome::Err;
    }
    // Most of the time, project onto the zero level (a touching point).
    if g.chance(0.7) {
        for _ in 0..3 {
            let (d, grad) = map.distance_and_gradient(&p);
            if !d.is_finite() {
                break;
            }
            p -= grad * d;
        }
    }
    let clearance = if g.chance(0.7) {
        0.0
    } else {
        g.num(0.0, 1.0).abs().min(2.0)
    };
    let d = map.signed_distance(&p) - clearance;
    let mut dir = Vec3::new(g.num(-1.0, 1.0), g.num(-1.0, 1.0), g.num(-1.0, 1.0));
    if !(dir.iter().all(|c| c.is_finite()) && dir.norm() > 1e-3) {
        dir = Vec3::x();
    }
    let dir = dir.normalize();
    let point = map.segment_clear(&p, &p, clearance);
    for len in [0.0, 1e-12, 1e-9, 1e-6] {
        let q = p + dir * len;
        for (a, c) in [(p, q), (q, p)] {
            let clear = map.segment_clear(&a, &c, clearance);
            if clear && !point {
                return Outcome::Wrong(format!(
                    "segment {a:?}..{c:?} clear at clearance {clearance} but its end {p:?} is not"
                ));
            }
            if clear && d <= 0.0 {
                return Outcome::Wrong(format!(
                    "segment of {len} m from {p:?} (distance − clearance = {d}) reported clear; \
                     nearest {:?}",
                    map.nearest_shape(&p).map(|(i, _, _)| map.shapes()[i])
                ));
            }
            if !clear && d > 1e-3 {
                return Outcome::Wrong(format!(
                    "segment of {len} m from {p:?} (distance − clearance = {d}) reported blocked"
                ));
            }
        }
    }
    Outcome::Ok
}

/// The APIs of this module.
pub fn apis() -> Vec<Api> {
    vec![
        Api {
            name: "params::geometry::constructors",
            weight: 50,
            run: geo_constructors,
        },
        Api {
            name: "params::geometry::voxel_counts",
            weight: 10,
            run: geo_voxel_counts,
        },
        Api {
            name: "params::geometry::segment_clear_at_contact",
            weight: 50,
            run: geo_segment_clear_at_contact,
        },
    ]
}
