//! The node's DDS layer in-process, talking over loopback to a test publisher/subscriber on a
//! ROS domain of its own (derived from the process id): odometry and a goal in, a trajectory
//! out, within a timeout.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use ros2_client::{Context, ContextOptions, NodeName, NodeOptions};
use trust_core::Vec3;
use trust_ros2::dds::{self, plan_qos, system_time, topics};
use trust_ros2::msg::geometry_msgs::PoseStamped;
use trust_ros2::msg::nav_msgs::Odometry;
use trust_ros2::msg::tf2_msgs::TFMessage;
use trust_ros2::msg::trajectory_msgs::MultiDOFJointTrajectory;
use trust_ros2::test_support::{goal, odometry, quickstart_dds_node};

/// A domain id in 0..=232 of this process (tests running in parallel processes do not meet).
fn domain_id() -> u16 {
    (std::process::id() % 200) as u16 + 20
}

fn context(domain: u16) -> Context {
    Context::with_options(ContextOptions::new().domain_id(domain)).expect("DDS participant")
}

#[test]
fn odometry_and_goal_over_dds_give_a_trajectory() {
    let domain = domain_id();
    let stop = Arc::new(AtomicBool::new(false));
    let node_stop = Arc::clone(&stop);
    let node = std::thread::spawn(move || {
        let (mut core, mut node) = quickstart_dds_node(domain).expect("quickstart node");
        node.run(&mut core, &node_stop, &mut |what, e| {
            eprintln!("node warning ({what}): {e}");
        });
        core.counters()
    });

    let ctx = context(domain);
    let mut test_node = ctx
        .new_node(
            NodeName::new("/", "trust_loopback_test").expect("name"),
            NodeOptions::new().enable_rosout(false),
        )
        .expect("test node");
    let odom_pub =
        dds::publisher::<Odometry>(&mut test_node, topics::ODOM, plan_qos()).expect("odom");
    let goal_pub =
        dds::publisher::<PoseStamped>(&mut test_node, topics::GOAL, plan_qos()).expect("goal");
    let traj_sub = dds::subscription::<MultiDOFJointTrajectory>(
        &mut test_node,
        topics::TRAJECTORY,
        plan_qos(),
    )
    .expect("trajectory");
    let tf_sub =
        dds::subscription::<TFMessage>(&mut test_node, topics::TF, dds::tf_qos()).expect("tf");

    let deadline = Instant::now() + Duration::from_secs(30);
    let mut received = None;
    let mut tf = None;
    let mut next_publish = Instant::now();
    let start = Vec3::new(2.0, 10.0, 3.0);
    while Instant::now() < deadline && (received.is_none() || tf.is_none()) {
        if Instant::now() >= next_publish {
            // Before discovery matches the writers a publish may fail; it is retried.
            let odom = odometry(system_time(), "base_link", start, Vec3::zeros());
            let _ = odom_pub.publish(odom);
            let _ = goal_pub.publish(goal(system_time(), Vec3::new(38.0, 10.0, 3.0)));
            next_publish += Duration::from_millis(100);
        }
        if let Ok(Some((msg, _))) = traj_sub.take() {
            received = Some(msg);
        }
        if let Ok(Some((msg, _))) = tf_sub.take() {
            tf = Some(msg);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    stop.store(true, Ordering::Relaxed);
    let counters = node.join().expect("node thread");
    let traj = received.unwrap_or_else(|| {
        panic!("no trajectory within 30 s on domain {domain}; node counters {counters:?}")
    });
    assert_eq!(traj.header.frame_id, "map");
    assert_eq!(traj.joint_names, vec!["base_link".to_string()]);
    assert!(!traj.points.is_empty());
    let p = traj.points[0].transforms[0].translation;
    assert!(
        (p.x - 2.0).abs() < 1.0 && (p.y - 10.0).abs() < 1.0 && (p.z - 3.0).abs() < 1.0,
        "the plan starts at the vehicle: {p:?}"
    );
    assert!(counters.cycle_count >= 1);
    // The odometry came back on /tf as map -> base_link.
    let tf = tf.expect("a /tf message");
    assert_eq!(tf.transforms.len(), 1);
    let t = &tf.transforms[0];
    assert_eq!(
        (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
        ("map", "base_link")
    );
    assert_eq!(Vec3::from(t.transform.translation), start);
}
