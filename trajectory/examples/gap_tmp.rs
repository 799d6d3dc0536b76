use rsruckig::prelude::*;
struct R(u64);
impl R {
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn u(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.f()
    }
}
#[derive(Clone, Copy)]
struct Ax {
    p: f64,
    v: f64,
    a: f64,
    t: f64,
    vm: f64,
    am: f64,
    jm: f64,
}
fn start_state(vm: f64, am: f64, jm: f64, fa: f64, fv: f64) -> (f64, f64) {
    let a0 = fa * am.min((jm * vm).sqrt());
    let s = a0 * a0.abs() / (2.0 * jm);
    let lo = (-vm).max(-vm + s);
    let hi = vm.min(vm + s);
    (lo + fv * (hi - lo) - s, a0)
}
fn plan(ax: &[Ax], sync: Synchronization, md: Option<f64>) -> Trajectory<0> {
    let n = ax.len();
    let mut input = InputParameter::<0>::new(Some(n));
    input.synchronization = sync;
    input.minimum_duration = md;
    for (i, x) in ax.iter().enumerate() {
        input.current_position[i] = x.p;
        input.current_velocity[i] = x.v;
        input.current_acceleration[i] = x.a;
        input.target_position[i] = x.t;
        input.max_velocity[i] = x.vm;
        input.max_acceleration[i] = x.am;
        input.max_jerk[i] = x.jm;
    }
    let mut otg = Ruckig::<0, ThrowErrorHandler>::new(Some(n), 1e-3);
    let mut tr = Trajectory::<0>::new(Some(n));
    otg.calculate(&input, &mut tr).unwrap();
    tr
}
fn gaps(tr: &Trajectory<0>, ax: &[Ax]) -> f64 {
    let mut m: f64 = 0.0;
    for (p, x) in tr.get_profiles()[0].iter().zip(ax) {
        let g = (p.p[7] - x.t).abs() / (f64::EPSILON * x.t.abs().max(1.0));
        m = m.max(g);
    }
    m
}
fn main() {
    let mut r = R(0x9E3779B97F4A7C15);
    let mut hist = [0usize; 8];
    let n_cases = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1024);
    let mut bad = 0;
    let mut fixed = [0usize; 6];
    for _ in 0..n_cases {
        let k = 1 + (r.f() * 6.0) as usize;
        let ax: Vec<Ax> = (0..k)
            .map(|_| {
                let vm = r.u(0.2, 5.0);
                let am = r.u(0.5, 50.0);
                let jm = r.u(5.0, 1000.0);
                let p = r.u(-5.0, 5.0);
                let t = r.u(-5.0, 5.0);
                let fa = r.u(-0.9, 0.9);
                let fv = r.u(0.02, 0.98);
                let (v, a) = start_state(vm, am, jm, fa, fv);
                Ax {
                    p,
                    v,
                    a,
                    t,
                    vm,
                    am,
                    jm,
                }
            })
            .collect();
        let tr = plan(&ax, Synchronization::Time, None);
        let g = gaps(&tr, &ax);
        let b = if g <= 1.0 {
            0
        } else if g <= 4.0 {
            1
        } else if g <= 16.0 {
            2
        } else if g <= 1e3 {
            3
        } else if g <= 1e6 {
            4
        } else {
            5
        };
        hist[b] += 1;
        if g > 8.0 {
            bad += 1;
            let d = tr.get_duration();
            let tries = [
                plan(&ax, Synchronization::Time, Some(d * (1.0 + 1e-9))),
                plan(&ax, Synchronization::Time, Some(d * (1.0 + 1e-6))),
                plan(&ax, Synchronization::Time, Some(d * (1.0 + 1e-4))),
                plan(&ax, Synchronization::Phase, None),
                plan(&ax, Synchronization::Time, Some(d * (1.0 + 1e-3))),
            ];
            let gs: Vec<f64> = tries.iter().map(|t| gaps(t, &ax)).collect();
            for (i, x) in gs.iter().enumerate() {
                if *x <= 8.0 {
                    fixed[i] += 1;
                }
            }
            println!(
                "gap {g:.3e} ulps, k={k}, retries {:?}",
                gs.iter().map(|x| format!("{x:.1e}")).collect::<Vec<_>>()
            );
        }
    }
    println!(
        "hist(ulps <=1,<=4,<=16,<=1e3,<=1e6,>1e6) {hist:?} bad {bad} fixed by retry {fixed:?}"
    );
}
