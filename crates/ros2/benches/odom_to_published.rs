//! Odometry received → trajectory published, over DDS on loopback, less the planning cycle
//! itself: the latency the node adds to the planner (docs/ros2.md, "Latency").
//!
//! A world thread flies the quickstart with perfect tracking: it publishes the vehicle's
//! `odom` (the latest `trajectory` sampled at the current time) and waits for the next
//! `trajectory`. The node (the `DdsNode` of `trust-node`, driven by odometry instead of its
//! 10 Hz timer, polling every 0.1 ms) runs a cycle as soon as an odometry arrives. Per cycle:
//!
//! * `node`: from the poll that takes the odometry from DDS to the trajectory written, less
//!   the manager's step (`events.cycle_time_ms`): decoding and validation, forecasts, sampling
//!   the plan into messages, CDR encoding and the writes of `trajectory`, `path`, `markers`,
//!   `events`;
//! * `wire`: from the world's `odom` write to its `trajectory` read, less the same step: the
//!   above plus both DDS transfers and both polls.
//!
//! Prints median, p99 and max of each (ms). `--test` or `--quick` (CI's smoke run): 10 cycles;
//! otherwise 300.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use ros2_client::{Context, ContextOptions, NodeName, NodeOptions};
use trust_core::Vec3;
use trust_ros2::dds::{self, plan_qos, system_time, topics};
use trust_ros2::dds_world::reference_at;
use trust_ros2::msg::geometry_msgs::PoseStamped;
use trust_ros2::msg::nav_msgs::Odometry;
use trust_ros2::msg::trajectory_msgs::MultiDOFJointTrajectory;
use trust_ros2::test_support::{goal, odometry, quickstart_dds_node};

const POLL: Duration = Duration::from_micros(100);
const START: Vec3 = Vec3::new(2.0, 10.0, 3.0);
const GOAL: Vec3 = Vec3::new(38.0, 10.0, 3.0);

fn context(domain: u16) -> Context {
    Context::with_options(ContextOptions::new().domain_id(domain)).expect("DDS participant")
}

/// One cycle as the node saw it: the planning step (ms) and the time beyond it (ms).
struct NodeSample {
    planning_ms: f64,
    beyond_ms: f64,
}

fn node_thread(domain: u16, stop: Arc<AtomicBool>, out: mpsc::Sender<NodeSample>) {
    let (mut core, mut node) = quickstart_dds_node(domain).expect("quickstart node");
    let mut warn = |what: &str, e: &trust_ros2::Ros2Error| eprintln!("node ({what}): {e}");
    let mut odom_count = 0;
    while !stop.load(Ordering::Relaxed) {
        // The poll that finds the odometry counts: taking it from DDS, decoding, validating.
        let received = Instant::now();
        node.receive(&mut core, &mut warn);
        if core.counters().odom_count > odom_count {
            odom_count = core.counters().odom_count;
            match node.cycle(&mut core, system_time()) {
                Ok(Some(planning_ms)) => {
                    let total_ms = received.elapsed().as_secs_f64() * 1e3;
                    let _ = out.send(NodeSample {
                        planning_ms,
                        beyond_ms: total_ms - planning_ms,
                    });
                }
                Ok(None) => {}
                Err(e) => warn("cycle", &e),
            }
        }
        std::thread::sleep(POLL);
    }
}

/// The vehicle's odometry now, its twist in the world frame.
fn odom_at(p: Vec3, v: Vec3) -> Odometry {
    odometry(system_time(), "map", p, v)
}

/// Median, p99 and max of `x` (sorted in place).
fn stats(x: &mut [f64]) -> (f64, f64, f64) {
    x.sort_by(f64::total_cmp);
    let at = |q: f64| x[((x.len() - 1) as f64 * q).round() as usize];
    (at(0.5), at(0.99), x[x.len() - 1])
}

fn main() {
    let quick = std::env::args().any(|a| a == "--test" || a == "--quick");
    let cycles = if quick { 10 } else { 300 };
    let domain = (std::process::id() % 50) as u16 + 180;
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let node = {
        let stop = Arc::clone(&stop);
        std::thread::spawn(move || node_thread(domain, stop, tx))
    };

    let ctx = context(domain);
    let mut world = ctx
        .new_node(
            NodeName::new("/", "trust_latency_world").expect("name"),
            NodeOptions::new().enable_rosout(false),
        )
        .expect("world node");
    let odom_pub = dds::publisher::<Odometry>(&mut world, topics::ODOM, dds::input_qos())
        .expect("odom writer");
    let goal_pub =
        dds::publisher::<PoseStamped>(&mut world, topics::GOAL, plan_qos()).expect("goal writer");
    let traj_sub =
        dds::subscription::<MultiDOFJointTrajectory>(&mut world, topics::TRAJECTORY, plan_qos())
            .expect("trajectory reader");
    let goal = goal(system_time(), GOAL);

    // Discovery: until the first trajectory comes back.
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut plan = None;
    while plan.is_none() {
        assert!(
            Instant::now() < deadline,
            "no trajectory on domain {domain}"
        );
        let _ = goal_pub.publish(goal.clone());
        let _ = odom_pub.publish(odom_at(START, Vec3::zeros()));
        std::thread::sleep(Duration::from_millis(100));
        while let Ok(Some((m, _))) = traj_sub.take() {
            plan = Some(m);
        }
    }
    while rx.try_recv().is_ok() {}

    let mut wire = Vec::with_capacity(cycles);
    let mut beyond = Vec::with_capacity(cycles);
    let mut planning = Vec::with_capacity(cycles);
    while wire.len() < cycles {
        // The vehicle where the latest plan says (perfect tracking); from the start again at
        // the goal.
        let r = plan
            .as_ref()
            .and_then(|p| reference_at(p, system_time().as_seconds()));
        let (p, v) = match r {
            Some(r) if (r.p - GOAL).norm() > 1.0 => (r.p, r.v),
            _ => (START, Vec3::zeros()),
        };
        let sent = Instant::now();
        if odom_pub.publish(odom_at(p, v)).is_err() {
            continue;
        }
        let deadline = sent + Duration::from_secs(5);
        let traj = loop {
            if let Ok(Some((m, _))) = traj_sub.take() {
                break Some(m);
            }
            if Instant::now() > deadline {
                break None;
            }
            std::thread::sleep(POLL);
        };
        let wire_ms = sent.elapsed().as_secs_f64() * 1e3;
        let Some(traj) = traj else {
            eprintln!("no trajectory within 5 s of an odometry; sending another");
            continue;
        };
        plan = Some(traj);
        let s = rx
            .recv_timeout(Duration::from_secs(5))
            .expect("the node's sample");
        wire.push(wire_ms - s.planning_ms);
        beyond.push(s.beyond_ms);
        planning.push(s.planning_ms);
        // Goal re-sent now and then (the node keeps the latest).
        if wire.len().is_multiple_of(50) {
            let _ = goal_pub.publish(goal.clone());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    stop.store(true, Ordering::Relaxed);
    node.join().expect("node thread");

    println!("odom_to_published: {cycles} cycles, quickstart, DDS loopback, poll 0.1 ms");
    for (name, x) in [
        ("planning cycle (manager step)", &mut planning),
        (
            "node: odom received -> trajectory published, beyond the cycle",
            &mut beyond,
        ),
        (
            "wire: odom written -> trajectory read, beyond the cycle",
            &mut wire,
        ),
    ] {
        let (median, p99, max) = stats(x);
        println!("  {name}: median {median:.3} ms, p99 {p99:.3} ms, max {max:.3} ms");
    }
}
