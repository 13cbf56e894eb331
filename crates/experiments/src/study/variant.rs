//! One-component ablations of a study (`--variant`).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use trust_minco::MincoParams;
use trust_topo_prm::{UvdParams, VprmParams};

use crate::ExperimentError;
use trust_flight::scenario::Scenario;
use trust_planner::{BackendSpec, CheckerSpec, FrontendSpec};
use trust_world::map_sensing::{DepthSpec, StaticSensing};
use trust_world::scenario::{Latency, MAX_CPU_SCALE, VehicleModel};

/// An ablation: one component changed for every planner it concerns (the others fly as they
/// are). Written and parsed as in the list below.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Variant {
    /// `none`: the planners as the paper defines them.
    #[default]
    None,
    /// `vprm`: DEV-PRM replaced by Fast-Planner's V-PRM (same clearance and budget).
    VPrm,
    /// `minco`: UTF-MINCO replaced by fixed-terminal MINCO (same weights and penalties).
    Minco,
    /// `uvd`: TVD replaced by UVD (same clearance).
    Uvd,
    /// `no-pdc`: DEV-PRM and sparse A* ignore the predictive directional cones (V-PRM has
    /// none).
    NoPdc,
    /// `no-ggs`: the frontends end their paths at the goal instead of the goal guidance surface.
    NoGgs,
    /// `no-history`: the manager forgets its branches every cycle.
    NoHistory,
    /// `no-hysteresis`: the main branch switches to any better challenger (factor 1).
    NoHysteresis,
    /// `no-worker`: every solve in the cycle (`manager.background = false`): the sub-branches'
    /// re-solves and FwdExplore are not taken off the cycle's critical path.
    NoWorker,
    /// `perfect`: perfect tracking instead of the scenario's vehicle model.
    Perfect,
    /// `quadrotor`: the rigid-body quadrotor with its SE(3) controller.
    Quadrotor,
    /// `mu=X`: the tracker's forecast growth scaled by `X` (`sensing.ekf.sigma_scale`).
    Mu(f64),
    /// `fault=X`: obstacles maneuver with `1 + X` times their stated bounds
    /// (`traffic.fault_level`), beyond what the forecasts expect.
    Fault(f64),
    /// `explore=K`: the multi-branch managers with history run FwdExplore (the frontend and the
    /// cold solves) every `K`-th cycle and whenever fewer than two branches are kept
    /// (`manager.explore_period_cycles`); `K = 1` explores every cycle as the paper's Algorithm 1
    /// does (the warm re-solve budgets stay).
    Explore(usize),
    /// `route`: every planner follows a global route on the known static map
    /// (`[planner.route]`, beyond the paper). Without it a study flies the paper's setting: every
    /// query aims at the final goal.
    Route,
    /// `real-time` or `real-time=X`: the loop charges each cycle's measured wall time (times
    /// `X`, default 1: an onboard computer `X` times slower) and a busy planner skips replanning
    /// ticks (`sim.latency = { kind = "measured", cpu_scale = X }`). Machine-dependent: fly it
    /// with `--jobs 1` on a quiet machine.
    RealTime(f64),
    /// `unknown`: the static map is not given; the vehicle's depth camera senses it into an
    /// online map (`[sensing.static] = { depth = {} }`, the camera's defaults; issue 34). A
    /// scenario that already senses it keeps its sensor.
    Unknown,
}

impl Variant {
    /// Every variant name, for help texts.
    pub const NAMES: &'static str = "none, vprm, minco, uvd, no-pdc, no-ggs, no-history, \
                                     no-hysteresis, no-worker, perfect, quadrotor, mu=X, fault=X, \
                                     explore=K, route, real-time, real-time=X, unknown";

    /// Applies the variant to `scenario` (whose planner preset is already chosen): replaces the
    /// preset's part it concerns, or the scenario section it sweeps.
    ///
    /// # Errors
    /// [`ExperimentError::Input`] if the planner section cannot be resolved.
    pub fn apply(&self, scenario: &mut Scenario) -> Result<(), ExperimentError> {
        let planner = &mut scenario.planner;
        let resolved = planner.resolve();
        match *self {
            Variant::None => {}
            Variant::VPrm => {
                if let FrontendSpec::DevPrm(d) = &resolved.frontend {
                    planner.frontend = Some(FrontendSpec::VPrm(VprmParams {
                        clearance: d.clearance,
                        budget_ms: d.budget_ms,
                        ..VprmParams::default()
                    }));
                }
            }
            Variant::Minco => {
                if let BackendSpec::UtfMinco(u) = &resolved.backend {
                    planner.backend = Some(BackendSpec::Minco(MincoParams {
                        weights: u.weights.clone(),
                        penalty: u.penalty.clone(),
                        pieces: u.pieces.clone(),
                        solver: u.solver.clone(),
                    }));
                }
            }
            Variant::Uvd => {
                if let CheckerSpec::Tvd(t) = &resolved.checker {
                    planner.checker = Some(CheckerSpec::Uvd(UvdParams {
                        clearance: t.clearance,
                        ..UvdParams::default()
                    }));
                }
            }
            Variant::NoPdc => match resolved.frontend {
                FrontendSpec::DevPrm(mut d) => {
                    d.pdc = false;
                    planner.frontend = Some(FrontendSpec::DevPrm(d));
                }
                FrontendSpec::SparseAStar(mut a) => {
                    a.pdc = false;
                    planner.frontend = Some(FrontendSpec::SparseAStar(a));
                }
                FrontendSpec::VPrm(_) | FrontendSpec::StraightLine(_) => {}
            },
            Variant::NoGgs => match resolved.frontend {
                FrontendSpec::DevPrm(mut d) => {
                    d.goal_guidance_surface = false;
                    planner.frontend = Some(FrontendSpec::DevPrm(d));
                }
                FrontendSpec::SparseAStar(mut a) => {
                    a.goal_guidance_surface = false;
                    planner.frontend = Some(FrontendSpec::SparseAStar(a));
                }
                FrontendSpec::VPrm(_) | FrontendSpec::StraightLine(_) => {}
            },
            Variant::NoHistory => manager_overrides(planner).history = Some(false),
            Variant::NoHysteresis => manager_overrides(planner).hysteresis = Some(1.0),
            Variant::NoWorker => manager_overrides(planner).background = Some(false),
            Variant::Perfect => scenario.vehicle.model = VehicleModel::Perfect,
            Variant::Quadrotor => scenario.vehicle.model = VehicleModel::Quadrotor,
            Variant::Mu(x) => scenario.sensing.ekf.sigma_scale *= x,
            Variant::Fault(x) => scenario.traffic.fault_level = x,
            Variant::Explore(k) => manager_overrides(planner).explore_period_cycles = Some(k),
            Variant::Route => planner.route.enabled = true,
            Variant::RealTime(x) => scenario.sim.latency = Latency::real_time(x),
            Variant::Unknown => {
                if scenario.sensing.static_map == StaticSensing::Known {
                    scenario.sensing.static_map = StaticSensing::Depth(DepthSpec::default());
                }
            }
        }
        Ok(())
    }
}

/// The scenario's `[planner.manager]` overrides, created empty if absent.
fn manager_overrides(
    planner: &mut trust_planner::PlannerSpec,
) -> &mut trust_planner::ManagerOverrides {
    planner.manager.get_or_insert_default()
}

impl fmt::Display for Variant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Variant::None => f.write_str("none"),
            Variant::VPrm => f.write_str("vprm"),
            Variant::Minco => f.write_str("minco"),
            Variant::Uvd => f.write_str("uvd"),
            Variant::NoPdc => f.write_str("no-pdc"),
            Variant::NoGgs => f.write_str("no-ggs"),
            Variant::NoHistory => f.write_str("no-history"),
            Variant::NoHysteresis => f.write_str("no-hysteresis"),
            Variant::NoWorker => f.write_str("no-worker"),
            Variant::Perfect => f.write_str("perfect"),
            Variant::Quadrotor => f.write_str("quadrotor"),
            Variant::Mu(x) => write!(f, "mu={x}"),
            Variant::Fault(x) => write!(f, "fault={x}"),
            Variant::Explore(k) => write!(f, "explore={k}"),
            Variant::Route => f.write_str("route"),
            Variant::RealTime(x) if *x == 1.0 => f.write_str("real-time"),
            Variant::RealTime(x) => write!(f, "real-time={x}"),
            Variant::Unknown => f.write_str("unknown"),
        }
    }
}

impl FromStr for Variant {
    type Err = ExperimentError;

    fn from_str(text: &str) -> Result<Variant, ExperimentError> {
        let number = |v: &str, what: &str| -> Result<f64, ExperimentError> {
            match v.parse::<f64>() {
                Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
                _ => Err(ExperimentError::input(
                    "--variant",
                    text,
                    format!("{what}=X with X a finite number >= 0"),
                )),
            }
        };
        Ok(match text.trim() {
            "none" | "" => Variant::None,
            "vprm" | "v-prm" => Variant::VPrm,
            "minco" => Variant::Minco,
            "uvd" => Variant::Uvd,
            "no-pdc" => Variant::NoPdc,
            "route" => Variant::Route,
            "no-ggs" => Variant::NoGgs,
            "no-history" => Variant::NoHistory,
            "no-hysteresis" => Variant::NoHysteresis,
            "no-worker" => Variant::NoWorker,
            "perfect" => Variant::Perfect,
            "quadrotor" => Variant::Quadrotor,
            "real-time" => Variant::RealTime(1.0),
            "unknown" => Variant::Unknown,
            t => match t.split_once('=') {
                Some(("mu", v)) => Variant::Mu(number(v, "mu")?),
                Some(("fault", v)) => Variant::Fault(number(v, "fault")?),
                Some(("real-time", v)) => match number(v, "real-time")? {
                    x if x > 0.0 && x <= MAX_CPU_SCALE => Variant::RealTime(x),
                    _ => {
                        return Err(ExperimentError::input(
                            "--variant",
                            text,
                            format!("real-time=X with X in (0, {MAX_CPU_SCALE}]"),
                        ));
                    }
                },
                Some(("explore", v)) => match v.parse::<usize>() {
                    Ok(k) if k >= 1 => Variant::Explore(k),
                    _ => {
                        return Err(ExperimentError::input(
                            "--variant",
                            text,
                            "explore=K with K an integer >= 1",
                        ));
                    }
                },
                _ => {
                    return Err(ExperimentError::input(
                        "--variant",
                        text,
                        format!("one of {}", Variant::NAMES),
                    ));
                }
            },
        })
    }
}

impl Serialize for Variant {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

impl<'de> Deserialize<'de> for Variant {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Variant, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_planner::PlannerPreset;

    fn scenario() -> Scenario {
        trust_flight::scenario::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenarios/quickstart.toml"
        )))
        .expect("quickstart loads")
    }

    #[test]
    fn names_round_trip_and_bad_names_are_explained() {
        for name in [
            "none",
            "vprm",
            "minco",
            "uvd",
            "no-pdc",
            "no-ggs",
            "no-history",
            "no-hysteresis",
            "no-worker",
            "perfect",
            "quadrotor",
            "mu=2",
            "fault=0.5",
            "explore=3",
            "route",
            "real-time",
            "real-time=3",
            "unknown",
        ] {
            let v: Variant = name.parse().unwrap();
            assert_eq!(v.to_string(), name);
        }
        for bad in [
            "vrpm",
            "mu=-1",
            "fault=x",
            "mu=inf",
            "explore=0",
            "explore=1.5",
            "real-time=0",
            "real-time=1000",
        ] {
            let e = bad.parse::<Variant>().unwrap_err().to_string();
            assert!(e.contains("--variant") && e.contains(bad), "{e}");
        }
    }

    #[test]
    fn each_variant_changes_exactly_its_component() {
        let base = {
            let mut s = scenario();
            s.planner.name = PlannerPreset::Trust;
            s
        };
        let resolved = |v: Variant| {
            let mut s = base.clone();
            v.apply(&mut s).unwrap();
            (s.planner.resolve(), s)
        };
        let (r, _) = resolved(Variant::VPrm);
        assert!(matches!(r.frontend, FrontendSpec::VPrm(_)));
        let (r, _) = resolved(Variant::Minco);
        assert!(matches!(r.backend, BackendSpec::Minco(_)));
        let (r, _) = resolved(Variant::Uvd);
        assert!(matches!(r.checker, CheckerSpec::Uvd(_)));
        let (r, _) = resolved(Variant::NoPdc);
        assert!(matches!(r.frontend, FrontendSpec::DevPrm(ref d) if !d.pdc));
        let (r, _) = resolved(Variant::NoGgs);
        assert!(matches!(r.frontend, FrontendSpec::DevPrm(ref d) if !d.goal_guidance_surface));
        let (r, _) = resolved(Variant::NoHistory);
        assert!(!r.manager.history);
        let (r, _) = resolved(Variant::NoHysteresis);
        assert_eq!(r.manager.hysteresis, 1.0);
        let (r, _) = resolved(Variant::Explore(3));
        assert_eq!(r.manager.explore_period_cycles, 3);
        let (_, s) = resolved(Variant::Fault(0.5));
        assert_eq!(s.traffic.fault_level, 0.5);
        let (_, s) = resolved(Variant::Mu(2.0));
        assert_eq!(
            s.sensing.ekf.sigma_scale,
            2.0 * base.sensing.ekf.sigma_scale
        );
        let (_, s) = resolved(Variant::Unknown);
        assert!(matches!(s.sensing.static_map, StaticSensing::Depth(_)));
        let (r, s) = resolved(Variant::None);
        assert_eq!(r, base.planner.resolve());
        assert_eq!(s, base);
        // Baseline 1 has no frontend to ablate: the V-PRM variant leaves it alone.
        let mut b1 = base.clone();
        b1.planner.name = PlannerPreset::Baseline1;
        Variant::VPrm.apply(&mut b1).unwrap();
        assert!(matches!(
            b1.planner.resolve().frontend,
            FrontendSpec::StraightLine(_)
        ));
    }
}
