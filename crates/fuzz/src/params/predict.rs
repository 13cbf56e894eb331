//! `EkfParams`, `Forecast` and PDC arguments at their edges.

use trust_core::Vec3;
use trust_predict::{CvEkf, EkfParams, Forecast, ObstacleShape};

use super::{COUNT_EDGES, FLOAT_EDGES, Field, Fields, judge, judge_error, judge_use};
use crate::apis::{Api, Fixtures, Outcome};
use crate::inputs::Gen;

const EKF: Fields<EkfParams> = Fields(&[
    Field::Float("ekf.meas_std", |p, x| p.meas_std = x),
    Field::Float("ekf.accel_psd", |p, x| p.accel_psd = x),
    Field::Float("ekf.init_vel_std", |p, x| p.init_vel_std = x),
    Field::Float("ekf.sigma_scale", |p, x| p.sigma_scale = x),
    Field::Float("ekf.mu_min", |p, x| p.mu_min = x),
]);

fn ekf_params(g: &mut Gen, _: &Fixtures) -> Outcome {
    let (params, edited) = EKF.edit(g, EkfParams::default());
    if let Some(o) = judge(&params.validate(), &edited) {
        return o;
    }
    let mut ekf = match CvEkf::new(0.0, Vec3::new(1.0, 2.0, 3.0), params) {
        Ok(e) => e,
        Err(e) => return judge_use(&e, &edited),
    };
    // A track with dropouts and, sometimes, long gaps: the estimate may leave the scale policy,
    // and the error must then name the EKF parameters that drove it.
    let gap = if g.chance(0.3) { 1e5 } else { 0.05 };
    // With long gaps the measurement times are a culprit too.
    let mut culprits = edited.clone();
    if gap > 1.0 {
        culprits.push("time since the last measurement");
    }
    for k in 1..=20 {
        let t = f64::from(k) * gap;
        let z = (k % 4 != 0).then(|| Vec3::new(1.0 + 0.1 * f64::from(k), 2.0, 3.0));
        if let Err(e) = ekf.step(t, z) {
            return judge_use(&e, &culprits);
        }
    }
    if !(ekf.state().iter().all(|x| x.is_finite())
        && ekf.covariance().iter().all(|x| x.is_finite()))
    {
        return Outcome::NonFinite(format!("ekf {ekf:?}"));
    }
    match ekf.forecast(ObstacleShape::Sphere, 0.5, 0.1) {
        Ok(f) => {
            if f.validate().is_err() {
                return Outcome::Wrong(format!("invalid forecast {f:?}"));
            }
            Outcome::Ok
        }
        Err(e) => judge_use(&e, &culprits),
    }
}

/// One `Forecast::new` argument at an edge: the error names it; an accepted forecast gives finite
/// PDCs and surface samples for edge counts and margins.
fn forecast_args(g: &mut Gen, _: &Fixtures) -> Outcome {
    let x = FLOAT_EDGES[g.index(FLOAT_EDGES.len())];
    let mut args = (
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(1.0, 0.0, 0.0),
        0.0,
        0.5,
        0.1,
        0.2,
        1.0,
    );
    let i = g.index(7);
    let name = [
        "forecast.p0",
        "forecast.v0",
        "forecast.t0",
        "forecast.r_o",
        "forecast.r_safe",
        "forecast.mu",
        "forecast.shape.half_height",
    ][i];
    match i {
        0 => args.0[g.index(3)] = x,
        1 => args.1[g.index(3)] = x,
        2 => args.2 = x,
        3 => args.3 = x,
        4 => args.4 = x,
        5 => args.5 = x,
        _ => args.6 = x,
    }
    let shape = if i == 6 || g.chance(0.5) {
        ObstacleShape::Cylinder {
            half_height: args.6,
        }
    } else {
        ObstacleShape::Sphere
    };
    let f = match Forecast::new(shape, args.0, args.1, args.2, args.3, args.4, args.5) {
        Ok(f) => f,
        Err(e) => return judge_error(&e.to_string(), &[name]).unwrap_or(Outcome::Err),
    };
    let horizon = FLOAT_EDGES[g.index(FLOAT_EDGES.len())];
    let pdc = match f.pdc(horizon) {
        Ok(p) => p,
        Err(e) => return judge_error(&e.to_string(), &["horizon"]).unwrap_or(Outcome::Err),
    };
    let (slices, per_slice) = (COUNT_EDGES[g.index(COUNT_EDGES.len())], g.count(8));
    let margin = if g.chance(0.5) {
        FLOAT_EDGES[g.index(FLOAT_EDGES.len())]
    } else {
        0.3
    };
    let region = trust_core::Aabb {
        min: Vec3::repeat(-30.0),
        max: Vec3::repeat(30.0),
    };
    if (slices as u128) * (per_slice as u128) > 5_000
        && (slices as u128) * (per_slice as u128) <= 100_000
    {
        // Requested work (each sample is an iterative solve); the cap is checked below it.
        return Outcome::Err;
    }
    match pdc.surface_samples(slices, per_slice, margin, &region) {
        Ok(s) => {
            if s.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
                return Outcome::NonFinite(format!("surface sample of {pdc:?}"));
            }
            Outcome::Ok
        }
        Err(e) => {
            judge_error(&e.to_string(), &["margin", "slices * per_slice"]).unwrap_or(Outcome::Err)
        }
    }
}

/// The APIs of this module.
pub fn apis() -> Vec<Api> {
    vec![
        Api {
            name: "params::predict::EkfParams",
            weight: 20,
            run: ekf_params,
        },
        Api {
            name: "params::predict::Forecast+Pdc",
            weight: 20,
            run: forecast_args,
        },
    ]
}
