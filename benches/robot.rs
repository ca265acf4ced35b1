//! Figures of the robot layer (issue 3): IK of one pose, a 1 m CP line checked every
//! 0.1 mm, and PTP sampling throughput. `cargo bench --bench robot`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use xsel_pendant::robot::{
    Arm, CoordSystem, CpMove, CpParams, Joints, Pose, PtpMove, PtpParams, RobotModel, Scara,
};

fn ik(c: &mut Criterion) {
    let k = Scara::new(&RobotModel::default_model());
    let near = Joints::new(10.0, 80.0, 50.0, 30.0);
    let p = Pose::new(312.5, 147.25, 55.0, 123.0);
    c.bench_function("ik/one_pose", |b| {
        b.iter(|| k.inverse(black_box(&p), Arm::Right, black_box(&near)))
    });
}

fn cp_params() -> CpParams {
    CpParams {
        speed_mm_s: 500.0,
        accel_mm_s2: 9806.65,
        decel_mm_s2: 9806.65,
    }
}

fn cp(c: &mut Criterion) {
    let mut g = c.benchmark_group("cp");
    g.throughput(Throughput::Elements(10_001));
    // No shipped model has room for a 1 m straight line (the 500 mm arm's longest legal
    // chord is shorter), so the 1 m figure uses a 1.2 m reach variant of it.
    let mut big = RobotModel::default_model();
    big.arm1_mm = 600.0;
    big.arm2_mm = 600.0;
    big.j1.min = -170.0;
    big.j1.max = 170.0;
    let kb = Scara::new(&big);
    let start = kb
        .inverse(
            &Pose::new(-500.0, 400.0, 20.0, 0.0),
            Arm::Right,
            &Joints::default(),
        )
        .unwrap();
    let target = Pose::new(500.0, 400.0, 20.0, 45.0);
    let p = cp_params();
    assert!(CpMove::plan(&kb, start, &target, &CoordSystem::ZERO, &p, 0.1).is_ok());
    g.bench_function("plan_and_check_1m_line_every_0.1mm", |b| {
        b.iter(|| {
            CpMove::plan(
                &kb,
                black_box(start),
                black_box(&target),
                &CoordSystem::ZERO,
                &p,
                0.1,
            )
        })
    });
    // The shipped 500 mm model with a tool that turns with R: 500 mm line every 0.05 mm.
    let k = Scara::new(&RobotModel::default_model());
    let tool = CoordSystem::from_wire([30_000, 10_000, 25_000, 5_000]);
    let s2 = k
        .inverse(
            &Pose::new(300.0, -250.0, 20.0, 0.0),
            Arm::Right,
            &Joints::default(),
        )
        .unwrap();
    let start_tip = tool.flange_to_tip(&k.forward(&s2));
    let t2 = Pose::new(start_tip.x, start_tip.y + 500.0, 60.0, start_tip.r + 30.0);
    assert!(CpMove::plan(&k, s2, &t2, &tool, &p, 0.05).is_ok());
    g.bench_function("plan_and_check_500mm_line_with_tool_every_0.05mm", |b| {
        b.iter(|| CpMove::plan(&k, black_box(s2), black_box(&t2), &tool, &p, 0.05))
    });
    g.finish();
}

fn ptp(c: &mut Criterion) {
    let k = Scara::new(&RobotModel::default_model());
    let m = PtpMove::joints(
        &k,
        Joints::new(-30.0, 60.0, 10.0, 0.0),
        Joints::new(90.0, -45.0, 150.0, 200.0),
        &PtpParams {
            speed_pct: 80.0,
            accel_pct: 50.0,
            decel_pct: 50.0,
        },
    )
    .unwrap();
    const N: u64 = 1000;
    let dt = m.profile().duration() / N as f64;
    let mut g = c.benchmark_group("ptp");
    g.throughput(Throughput::Elements(N));
    g.bench_function("sample_1000_instants", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for i in 0..N {
                let j = m.joints_at(black_box(i as f64 * dt));
                acc += j.j1 + j.j2 + j.z + j.j4;
            }
            acc
        })
    });
    g.finish();
}

criterion_group!(benches, ik, cp, ptp);
criterion_main!(benches);
