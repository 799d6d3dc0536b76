//! Planning time (issue target: median ≤ 10 µs for a 6-axis synchronised move): a move from
//! rest with `plan_move`, and a re-target of a 6-axis online motion mid-move (one
//! `OnlineMotion::step` that recalculates). Run: `cargo bench -p cellrt-trajectory --bench plan`.

use std::hint::black_box;

use cellrt_trajectory::{
    plan_move, AxisState, KinematicLimits, MoveAxis, OnlineAxis, OnlineMotion, PositionRange,
};
use criterion::{criterion_group, criterion_main, Criterion};

const LIMITS: KinematicLimits = KinematicLimits {
    velocity: 400.0,
    acceleration: 2000.0,
    jerk: 20000.0,
};

fn targets(k: usize) -> [f64; 6] {
    // Deterministic, different per iteration family.
    let mut t = [0.0; 6];
    for (i, v) in t.iter_mut().enumerate() {
        *v = 50.0 + ((k * 37 + i * 113) % 700) as f64;
    }
    t
}

fn bench(c: &mut Criterion) {
    let mut k = 0usize;
    c.bench_function("plan_move 6 axes from rest", |b| {
        b.iter(|| {
            k += 1;
            let t = targets(k);
            let axes: Vec<MoveAxis> = (0..6)
                .map(|i| MoveAxis {
                    start: AxisState {
                        position: 400.0,
                        ..AxisState::default()
                    },
                    target: t[i],
                    limits: LIMITS,
                })
                .collect();
            black_box(plan_move(black_box(&axes)).unwrap().duration())
        })
    });

    let axes = vec![
        OnlineAxis {
            limits: LIMITS,
            range: PositionRange {
                min: 0.0,
                max: 800.0,
            },
        };
        6
    ];
    let mut m = OnlineMotion::new(axes, 1e-3, &[400.0; 6]);
    let mut out = vec![AxisState::default(); 6];
    m.move_to(&(0..6).map(|i| (i, 700.0, LIMITS)).collect::<Vec<_>>())
        .unwrap();
    for _ in 0..200 {
        m.step(&mut out).unwrap();
    }
    let mut k = 0usize;
    c.bench_function(
        "online re-target 6 axes mid-move (step with recalculation)",
        |b| {
            b.iter(|| {
                k += 1;
                let t = targets(k);
                m.move_to(&(0..6).map(|i| (i, t[i], LIMITS)).collect::<Vec<_>>())
                    .unwrap();
                m.step(&mut out).unwrap();
                black_box(out[0].position)
            })
        },
    );
    c.bench_function("online step 6 axes (no recalculation)", |b| {
        b.iter(|| {
            m.step(&mut out).unwrap();
            black_box(out[0].position)
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
