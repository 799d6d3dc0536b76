use rsruckig::prelude::*;
fn main() {
    let n = 2;
    let mut input = InputParameter::<0>::new(Some(n));
    input.synchronization = Synchronization::Time;
    let s = [
        (
            -0.8304404172300521,
            -1.2629348247216845,
            4.4318178823658245,
            -0.9648417308949346,
            3.5246569108835275,
            21.462700554763405,
            27.79606347643826,
        ),
        (
            4.949841443847839,
            -2.846021645180635,
            0.0,
            -2.419766765089452,
            2.964605880396495,
            6.722803599879222,
            508.16633601743416,
        ),
    ];
    for (i, x) in s.iter().enumerate() {
        input.current_position[i] = x.0;
        input.current_velocity[i] = x.1;
        input.current_acceleration[i] = x.2;
        input.target_position[i] = x.3;
        input.max_velocity[i] = x.4;
        input.max_acceleration[i] = x.5;
        input.max_jerk[i] = x.6;
    }
    let mut otg = Ruckig::<0, ThrowErrorHandler>::new(Some(n), 1e-3);
    let mut tr = Trajectory::<0>::new(Some(n));
    let r = otg.calculate(&input, &mut tr).unwrap();
    println!(
        "{r:?} duration {} indep {:?}",
        tr.get_duration(),
        tr.get_independent_min_durations()
    );
    for (d, p) in tr.get_profiles()[0].iter().enumerate() {
        println!(
            "dof {d}: limits {:?} dir {:?} cs {:?}",
            p.limits, p.direction, p.control_signs
        );
        println!(
            "  t {:?}\n  t_sum {:?}\n  j {:?}\n  a {:?}\n  v {:?}\n  p {:?}",
            p.t, p.t_sum, p.j, p.a, p.v, p.p
        );
        println!("  brake {:?}\n  accel {:?}", p.brake, p.accel);
    }
}
