//! Tracking error of the simulator's vehicles on the gentle and the aggressive figure-eight.
//!
//! `cargo run --release -p trust-vehicle --example figure_eight`
//!
//! Flies three laps of each [`FigureEight`] at 500 Hz with the default [`ControlledQuadrotor`]
//! and with [`PerfectTracking`], both starting on the reference, and prints one line per flight:
//! errors (position in m, velocity in m/s), the vehicle's peak speed, acceleration, body-rate norm
//! and thrust, the number of saturated steps, and the fastest wall time of five identical flights
//! (the least disturbed by other processes). The numbers are the ones quoted in the
//! `trust_vehicle` module docs.

use std::time::Instant;

use trust_vehicle::{
    ControlledQuadrotor, FigureEight, PerfectTracking, QuadrotorParams, Se3Gains, TrackingReport,
    Vehicle, VehicleError, tracking_error,
};

const DT_S: f64 = 0.002;
const LAP_COUNT: f64 = 3.0;
const REPEAT_COUNT: usize = 5;

/// Flies fresh copies of `vehicle`; returns the report and the fastest wall time (ms).
fn fly<V: Vehicle + Clone>(
    vehicle: &V,
    fig: &FigureEight,
) -> Result<(TrackingReport, f64), VehicleError> {
    let reference = |t: f64| fig.reference(t);
    let mut best_ms = f64::INFINITY;
    let mut report = tracking_error(&mut vehicle.clone(), &reference, 0.0, DT_S)?;
    for _ in 0..REPEAT_COUNT {
        let mut v = vehicle.clone();
        let start = Instant::now();
        report = tracking_error(&mut v, &reference, LAP_COUNT * fig.period_s, DT_S)?;
        best_ms = best_ms.min(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok((report, best_ms))
}

fn print_row(label: &str, name: &str, r: &TrackingReport, wall_ms: f64) {
    println!(
        "{:<11} {:<17} {:>8.4} {:>8.4} {:>8.4} {:>8.4} | {:>6.2} {:>6.2} {:>6.2} {:>7} {:>4} {:>6} {:>8.2}",
        label,
        name,
        r.rms_position_m,
        r.max_position_m,
        r.rms_velocity_m_s,
        r.max_velocity_m_s,
        r.max_speed_m_s,
        r.max_acceleration_m_s2,
        r.max_body_rate_rad_s,
        r.max_thrust_n.map_or("-".to_owned(), |f| format!("{f:.2}")),
        r.saturated_step_count,
        r.step_count,
        wall_ms
    );
}

fn main() -> Result<(), VehicleError> {
    let params = QuadrotorParams::default();
    println!(
        "vehicle: {:.2} kg, thrust-to-weight {:.2}; dt = {DT_S} s; {LAP_COUNT} laps from the reference",
        params.mass_kg,
        params.thrust_to_weight()
    );
    println!(
        "{:<11} {:<17} {:>8} {:>8} {:>8} {:>8} | {:>6} {:>6} {:>6} {:>7} {:>4} {:>6} {:>8}",
        "figure",
        "vehicle",
        "rms_p",
        "max_p",
        "rms_v",
        "max_v",
        "v_max",
        "a_max",
        "w_max",
        "f_max_N",
        "sat",
        "steps",
        "wall_ms"
    );
    for (label, fig) in [
        ("gentle", FigureEight::gentle()),
        ("aggressive", FigureEight::aggressive()),
    ] {
        let start = fig.reference(0.0);
        let quad = ControlledQuadrotor::starting_on(params, Se3Gains::default(), 0.0, &start)?;
        let (r, wall_ms) = fly(&quad, &fig)?;
        print_row(label, quad.name(), &r, wall_ms);
        let perfect = PerfectTracking::new(0.0, &start)?;
        let (r, wall_ms) = fly(&perfect, &fig)?;
        print_row(label, perfect.name(), &r, wall_ms);
        println!(
            "{:<11} reference peaks: speed {:.2} m/s, acceleration {:.2} m/s²",
            "",
            fig.peak_speed(),
            fig.peak_acceleration()
        );
    }
    Ok(())
}
