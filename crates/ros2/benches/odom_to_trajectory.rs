//! Odometry received → trajectory message built and serialized, without the planning cycle:
//! decode a CDR `nav_msgs/Odometry` payload, hand it to the node core (validation, frame
//! rotation), sample the committed plan (quickstart, one cycle) into a
//! `MultiDOFJointTrajectory` every 0.05 s, and encode it to CDR.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use trust_core::Vec3;
use trust_ros2::cdr;
use trust_ros2::convert::trajectory_message;
use trust_ros2::heading::Heading;
use trust_ros2::msg::builtin_interfaces::Time;
use trust_ros2::msg::nav_msgs::Odometry;
use trust_ros2::test_support::{goal, odometry, quickstart_core};

fn bench(c: &mut Criterion) {
    let origin = Time {
        sec: 1_700_000_000,
        nanosec: 0,
    };
    let mut core = quickstart_core(origin).expect("core");
    let odom = odometry(
        origin,
        "base_link",
        Vec3::new(2.0, 10.0, 3.0),
        Vec3::zeros(),
    );
    core.on_odometry(&odom).expect("odometry");
    core.on_goal(&goal(origin, Vec3::new(38.0, 10.0, 3.0)))
        .expect("goal");
    core.cycle(origin).expect("cycle").expect("ran");
    let payload = cdr::encode(&odom).expect("encode");
    let samples = core
        .manager()
        .plan()
        .map(|p| (p.duration() / 0.05).ceil() as usize + 1)
        .unwrap_or(0);
    c.bench_function(
        &format!("odom_to_trajectory (quickstart plan, {samples} samples)"),
        |b| {
            b.iter(|| {
                let msg: Odometry = cdr::decode(black_box(&payload)).expect("decode");
                core.on_odometry(&msg).expect("odometry");
                let params = core.params();
                let plan = core.manager().plan().expect("plan");
                let mut heading = Heading::new(params.yaw).expect("yaw policy");
                let traj = trajectory_message(
                    plan,
                    0.0,
                    params.trajectory_dt_s,
                    core.clock(),
                    (&params.world_frame, &params.body_frame),
                    &mut heading,
                )
                .expect("trajectory");
                black_box(cdr::encode(&traj).expect("encode"))
            })
        },
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
