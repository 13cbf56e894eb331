//! `trust-node`: TRUST-Planner as a ROS 2 node over DDS, without a ROS install.
//!
//! ```text
//! trust-node SCENARIO.toml [--params NODE.toml] [--domain-id N] [--namespace NS] [--px4]
//!     [--use-sim-time]
//! ```
//!
//! The scenario file gives the planner (`[planner]`), the vehicle and the map (bounds, static
//! shapes); `--params` the node's parameters (`trust_ros2::NodeParams`). Topics, frames and
//! QoS: `docs/ros2.md`. Runs until killed, or until stdin closes with `--until-stdin-closes`.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context as _, Result};
use clap::Parser;
use ros2_client::{Context, ContextOptions};
use trust_ros2::dds::{DdsNode, DdsOptions};
use trust_ros2::msg::builtin_interfaces::Time;
use trust_ros2::{NodeCore, NodeParams, NodeSetup, Ros2Error};

/// TRUST-Planner as a ROS 2 node (docs/ros2.md).
#[derive(Debug, Parser)]
#[command(name = "trust-node", version)]
struct Args {
    /// Scenario file: its `[planner]` section, vehicle and map (bounds, static shapes).
    scenario: PathBuf,
    /// Node parameters (TOML: world_frame, body_frame, cycle_period_s, ...).
    #[arg(long)]
    params: Option<PathBuf>,
    /// ROS domain id (default: $ROS_DOMAIN_ID, else 0).
    #[arg(long)]
    domain_id: Option<u16>,
    /// The node's namespace.
    #[arg(long, default_value = "/")]
    namespace: String,
    /// Publish PX4's TrajectorySetpoint (NED) on /fmu/in/trajectory_setpoint instead of setpoint.
    #[arg(long)]
    px4: bool,
    /// Take ROS time from /clock (a simulator's, e.g. `trust-sim dds-world`) instead of the
    /// system clock: ROS's `use_sim_time` (also the parameter file's `use_sim_time = true`).
    #[arg(long)]
    use_sim_time: bool,
    /// Stop when standard input closes (for scripts and tests); otherwise run until killed.
    #[arg(long)]
    until_stdin_closes: bool,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut params = match &args.params {
        Some(p) => NodeParams::load(p)?,
        None => NodeParams::default(),
    };
    params.use_sim_time |= args.use_sim_time;
    let setup = NodeSetup::from_scenario(&args.scenario)
        .with_context(|| format!("reading {}", args.scenario.display()))?;
    let domain_id = match args.domain_id {
        Some(d) => d,
        None => match std::env::var("ROS_DOMAIN_ID") {
            Ok(v) => v
                .parse()
                .with_context(|| format!("ROS_DOMAIN_ID = {v:?}: expected 0..=232"))?,
            Err(_) => 0,
        },
    };
    let context = Context::with_options(ContextOptions::new().domain_id(domain_id))
        .map_err(|e| Ros2Error::dds("create DDS participant", e))?;
    let options = DdsOptions {
        namespace: args.namespace.clone(),
        px4: args.px4,
        ..DdsOptions::for_params(&params)
    };
    let mut node = DdsNode::new(&context, &options)?;
    let stop = Arc::new(AtomicBool::new(false));
    if args.until_stdin_closes {
        let stop = Arc::clone(&stop);
        std::thread::spawn(move || {
            let _ = std::io::copy(&mut std::io::stdin(), &mut std::io::sink());
            stop.store(true, Ordering::Relaxed);
        });
    }
    if params.use_sim_time {
        eprintln!("trust-node: use_sim_time: waiting for /clock on domain {domain_id}...");
    }
    // Node time 0 is the whole second of ROS time at the start (the first /clock in sim time).
    let Some(start) = node.wait_for_time(&stop) else {
        eprintln!("trust-node: stopped before the first /clock");
        return Ok(());
    };
    let origin = Time {
        sec: start.sec,
        nanosec: 0,
    };
    let clock = if params.use_sim_time {
        "/clock"
    } else {
        "system clock"
    };
    let mut core = NodeCore::new(setup, params, origin)?;
    eprintln!(
        "trust-node: domain {domain_id}, namespace {}, ROS time from the {clock}, node time 0 = \
         ROS time {} s",
        args.namespace, origin.sec
    );
    let mut warnings = 0u64;
    node.run(&mut core, &stop, &mut |what, e| {
        warnings += 1;
        // The first 20 warnings, then every 100th: a bad publisher at 100 Hz must not flood.
        if warnings <= 20 || warnings.is_multiple_of(100) {
            eprintln!("trust-node: warning #{warnings} ({what}): {e}");
        }
    });
    let c = core.counters();
    eprintln!(
        "trust-node: {} cycles, {} odometry, {} goals, {} obstacle messages, {} clouds ({} \
         points, {} skipped; {} dropped behind newer), {} rejected",
        c.cycle_count,
        c.odom_count,
        c.goal_count,
        c.obstacles_count,
        c.cloud_count,
        c.cloud_point_count,
        c.cloud_skipped_point_count,
        c.cloud_dropped_count,
        c.rejected_count
    );
    Ok(())
}
