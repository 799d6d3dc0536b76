//! Straight-line moves: every sample on the line, no axis beyond its own limits, the end exact,
//! a halt brakes along the line.

use cellrt_trajectory::{AxisState, KinematicLimits, LineError, LineMove};

const PERIOD: f64 = 1e-3;

fn limits() -> Vec<KinematicLimits> {
    vec![
        KinematicLimits {
            velocity: 400.0,
            acceleration: 2000.0,
            jerk: 20000.0,
        },
        KinematicLimits {
            velocity: 300.0,
            acceleration: 1500.0,
            jerk: 20000.0,
        },
        KinematicLimits {
            velocity: 250.0,
            acceleration: 1500.0,
            jerk: 15000.0,
        },
    ]
}

/// Distance of `p` from the line through `a` and `b`.
fn off_line(p: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(a, b)| b - a).collect();
    let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    let w: Vec<f64> = p.iter().zip(a).map(|(p, a)| p - a).collect();
    let t = w.iter().zip(&d).map(|(w, d)| w * d).sum::<f64>() / len;
    w.iter()
        .zip(&d)
        .map(|(w, d)| (w - t * d / len).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn run(line: &mut LineMove, max: usize) -> Vec<Vec<AxisState>> {
    let mut out = vec![AxisState::default(); 3];
    let mut samples = Vec::new();
    for _ in 0..max {
        line.step(&mut out).unwrap();
        samples.push(out.clone());
        if line.is_done() {
            break;
        }
    }
    samples
}

#[test]
fn a_line_stays_on_the_line_within_every_axis_limit() {
    let (a, b) = ([50.0, 50.0, 0.0], [700.0, 300.0, -100.0]);
    let l = limits();
    let mut line = LineMove::new(&a, &b, &l, None, PERIOD).unwrap();
    let s = run(&mut line, 20_000);
    assert!(line.is_done());
    let end: Vec<f64> = s.last().unwrap().iter().map(|x| x.position).collect();
    for (e, t) in end.iter().zip(&b) {
        assert!((e - t).abs() < 1e-9, "{end:?}");
    }
    let mut vmax = [0.0f64; 3];
    for row in &s {
        let p: Vec<f64> = row.iter().map(|x| x.position).collect();
        assert!(off_line(&p, &a, &b) < 1e-9, "{p:?} off the line");
        for (i, x) in row.iter().enumerate() {
            assert!(
                x.velocity.abs() <= l[i].velocity * (1.0 + 1e-9),
                "{i}: {x:?}"
            );
            assert!(
                x.acceleration.abs() <= l[i].acceleration * (1.0 + 1e-9),
                "{i}: {x:?}"
            );
            vmax[i] = vmax[i].max(x.velocity.abs());
        }
    }
    // The path speed is set by the tightest axis: x (650 of 400 mm/s) here; it reaches its limit.
    assert!((vmax[0] - 400.0).abs() < 1e-6, "{vmax:?}");
}

#[test]
fn a_halted_line_stops_on_the_line() {
    let (a, b) = ([0.0, 0.0, 0.0], [600.0, 400.0, -150.0]);
    let mut line = LineMove::new(&a, &b, &limits(), None, PERIOD).unwrap();
    run(&mut line, 300);
    line.halt();
    let s = run(&mut line, 5000);
    assert!(line.is_done());
    let last = s.last().unwrap();
    let p: Vec<f64> = last.iter().map(|x| x.position).collect();
    assert!(last.iter().all(|x| x.velocity == 0.0));
    assert!(off_line(&p, &a, &b) < 1e-9);
    assert!(p[0] > 10.0 && p[0] < 600.0, "{p:?}");
}

#[test]
fn degenerate_and_bad_lines() {
    let l = limits();
    let mut line = LineMove::new(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0], &l, None, PERIOD).unwrap();
    assert!(line.is_done());
    assert_eq!(run(&mut line, 10)[0][1].position, 2.0);
    assert_eq!(
        LineMove::new(&[1.0], &[2.0], &l[..1], None, PERIOD).err(),
        Some(LineError::Shape(1))
    );
    assert!(matches!(
        LineMove::new(&[0.0, f64::NAN, 0.0], &[1.0, 1.0, 1.0], &l, None, PERIOD),
        Err(LineError::NotFinite { axis: 1, .. })
    ));
}

#[test]
fn a_path_velocity_above_what_the_axes_allow_is_refused() {
    let l = limits();
    // Along x only: x allows 400.
    let (a, b) = ([0.0, 0.0, 0.0], [500.0, 0.0, 0.0]);
    assert_eq!(
        cellrt_trajectory::line::max_path_velocity(&a, &b, &l),
        400.0
    );
    assert!(matches!(
        LineMove::new(&a, &b, &l, Some(450.0), PERIOD),
        Err(LineError::PathVelocity { .. })
    ));
    let mut line = LineMove::new(&a, &b, &l, Some(100.0), PERIOD).unwrap();
    let s = run(&mut line, 20_000);
    let v = s.iter().map(|r| r[0].velocity).fold(0.0, f64::max);
    assert!((v - 100.0).abs() < 1e-9, "{v}");
}
