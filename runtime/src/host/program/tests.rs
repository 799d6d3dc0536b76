//! Program parsing and validation against a cell.

use super::*;
use cellrt_config::AxisRef;
use cellrt_trajectory::planner::MAX_MOVE_AXES;

fn cell(axes: usize) -> CellConfig {
    let mut text = String::from("[cell]\nname = \"p\"\ncycle_time_us = 1000\n");
    for i in 0..axes {
        text.push_str(&format!(
            "[[axes]]\nname = \"a{i}\"\ndrive = \"mr-j5-g-n1\"\nmotor = {{ counts_per_rev = 10000 }}\ncounts_per_unit = 1000\nlimits = {{ position = [0.0, 100.0], velocity = 10.0, acceleration = 100.0, jerk = 1000.0 }}\n"
        ));
    }
    CellConfig::parse(Path::new("c.toml"), &text).unwrap()
}

fn program(targets: usize) -> String {
    let t: Vec<String> = (0..targets).map(|i| format!("a{i} = 1.0")).collect();
    format!("[[step]]\ndo = \"move\"\ntarget = {{ {} }}\n", t.join(", "))
}

#[test]
fn a_move_of_more_axes_than_the_planner_takes_is_refused_up_front() {
    let c = cell(20);
    Program::parse(Path::new("p.toml"), &program(MAX_MOVE_AXES), &c).unwrap();
    let e = Program::parse(Path::new("p.toml"), &program(MAX_MOVE_AXES + 1), &c).unwrap_err();
    assert_eq!(e.key, "step[0].target");
    assert!(e.message.contains("at most"), "{e}");
}

fn parse(text: &str) -> Result<Program, ConfigError> {
    Program::parse(Path::new("p.toml"), text, &cell(3))
}

#[test]
fn power_steps_name_axes_or_the_whole_cell() {
    let p = parse(
        "[[step]]\ndo = \"power_on\"\naxes = [\"a2\", \"a0\"]\n[[step]]\ndo = \"power_off\"\naxes = [\"a0\"]\n[[step]]\ndo = \"power_on\"\n",
    )
    .unwrap();
    assert_eq!(
        p.steps,
        vec![
            Step::PowerOn(vec![AxisRef::Loop(2), AxisRef::Loop(0)]),
            Step::PowerOff(vec![AxisRef::Loop(0)]),
            Step::PowerOn(vec![])
        ]
    );
    let e = parse("[[step]]\ndo = \"power_on\"\naxes = [\"q\"]\n").unwrap_err();
    assert_eq!(e.key, "step[0].axes");
    assert!(e.message.contains("axis 'q' is not in cell"), "{e}");
    let e = parse("[[step]]\ndo = \"power_off\"\naxes = [\"a1\", \"a1\"]\n").unwrap_err();
    assert!(e.message.contains("named twice"), "{e}");
    let e = parse("[[step]]\ndo = \"power_on\"\naxis = \"a1\"\n").unwrap_err();
    assert!(e.message.contains("unknown field"), "{e}");
}

#[test]
fn repeat_expands_its_steps_count_times() {
    let p = parse(
        "[[step]]\ndo = \"repeat\"\ncount = 3\n[[step.steps]]\ndo = \"move\"\ntarget = { a0 = 1.0 }\n[[step.steps]]\ndo = \"override\"\npercent = 50\n[[step]]\ndo = \"power_off\"\n",
    )
    .unwrap();
    assert_eq!(p.steps.len(), 7);
    assert_eq!(p.steps[1], Step::Override(0.5));
    assert!(matches!(p.steps[4], Step::Move(..)));
    assert_eq!(p.steps[6], Step::PowerOff(vec![]));
    let e = parse("[[step]]\ndo = \"repeat\"\ncount = 0\n[[step.steps]]\ndo = \"power_on\"\n")
        .unwrap_err();
    assert_eq!(e.key, "step[0].count");
    let e = parse("[[step]]\ndo = \"repeat\"\ncount = 2\nsteps = []\n").unwrap_err();
    assert_eq!(e.key, "step[0].steps");
    let e = parse(
        "[[step]]\ndo = \"repeat\"\ncount = 2\n[[step.steps]]\ndo = \"move\"\ntarget = { q = 1.0 }\n",
    )
    .unwrap_err();
    assert_eq!(e.key, "step[0].steps[0].target.q");
    let e = parse(
        "[[step]]\ndo = \"repeat\"\ncount = 10000\n[[step.steps]]\ndo = \"repeat\"\ncount = 10000\n[[step.steps.steps]]\ndo = \"power_on\"\n",
    )
    .unwrap_err();
    assert!(e.message.contains("more than"), "{e}");
}

#[test]
fn line_path_jog_and_override_steps_are_checked() {
    let p = parse(
        "[[step]]\ndo = \"line\"\ntarget = { a0 = 5.0, a1 = 6.0 }\nvelocity = 4.0\n\
         [[step]]\ndo = \"path\"\nwaypoints = [{ a0 = 1.0, a1 = 2.0 }, { a0 = 3.0, a1 = 4.0 }]\n\
         [[step]]\ndo = \"jog\"\naxis = \"a2\"\nvelocity = -5.0\nseconds = 1.0\n",
    )
    .unwrap();
    assert!(
        matches!(&p.steps[0], Step::Line { targets, path_velocity: Some(v) } if targets.len() == 2 && *v == 4.0)
    );
    assert!(
        matches!(&p.steps[1], Step::Path { targets, via } if via == &vec![vec![1.0, 2.0]] && targets[1].target == 4.0)
    );
    assert_eq!(
        p.steps[2],
        Step::Jog {
            axis: AxisRef::Loop(2),
            velocity: -5.0,
            seconds: 1.0
        }
    );
    for (text, key) in [
        (
            "[[step]]\ndo = \"line\"\ntarget = { a0 = 5.0 }\n",
            "step[0].target",
        ),
        (
            "[[step]]\ndo = \"line\"\ntarget = { a0 = 5.0, a1 = 1.0 }\nvelocity = -1.0\n",
            "step[0].velocity",
        ),
        (
            "[[step]]\ndo = \"path\"\nwaypoints = [{ a0 = 1.0 }, { a0 = 3.0, a1 = 4.0 }]\n",
            "step[0].waypoints[0]",
        ),
        (
            "[[step]]\ndo = \"path\"\nwaypoints = [{ a0 = 101.0 }, { a0 = 3.0 }]\n",
            "step[0].waypoints[0].a0",
        ),
        (
            "[[step]]\ndo = \"path\"\nwaypoints = []\n",
            "step[0].waypoints",
        ),
        (
            "[[step]]\ndo = \"jog\"\naxis = \"a0\"\nvelocity = 11.0\nseconds = 1.0\n",
            "step[0].velocity",
        ),
        (
            "[[step]]\ndo = \"jog\"\naxis = \"zz\"\nvelocity = 1.0\nseconds = 1.0\n",
            "step[0].axis",
        ),
        (
            "[[step]]\ndo = \"override\"\npercent = 101\n",
            "step[0].percent",
        ),
    ] {
        let e = parse(text).unwrap_err();
        assert_eq!(e.key, key, "{text}: {e}");
    }
}

#[test]
fn per_move_limits_may_lower_but_never_raise_the_axis_limit() {
    let c = cell(2);
    let ok = "[[step]]\ndo = \"move\"\ntarget = { a0 = 5.0 }\nvelocity = 5.0\n";
    let p = Program::parse(Path::new("p.toml"), ok, &c).unwrap();
    let Step::Move(t) = &p.steps[0] else { panic!() };
    let AxisMove::Planned(t) = &t[0] else {
        panic!("{t:?}")
    };
    assert_eq!(t.limits.velocity, 5.0);
    let bad = "[[step]]\ndo = \"move\"\ntarget = { a0 = 5.0 }\nvelocity = { a0 = 50.0 }\n";
    let e = Program::parse(Path::new("p.toml"), bad, &c).unwrap_err();
    assert_eq!(e.key, "step[0].velocity");
    let stray = "[[step]]\ndo = \"move\"\ntarget = { a0 = 5.0 }\njerk = { a1 = 5.0 }\n";
    let e = Program::parse(Path::new("p.toml"), stray, &c).unwrap_err();
    assert_eq!(e.key, "step[0].jerk.a1");
}

#[test]
fn per_move_limits_too_small_to_plan_with_are_refused_at_load() {
    let c = cell(2);
    for (step, key) in [
        (
            "do = \"move\"\ntarget = { a0 = 5.0 }\nvelocity = 1e-300",
            "step[0].velocity",
        ),
        (
            "do = \"move\"\ntarget = { a0 = 5.0 }\njerk = 1e-300",
            "step[0].jerk",
        ),
        (
            "do = \"line\"\ntarget = { a0 = 5.0, a1 = 5.0 }\nvelocity = 1e-300",
            "step[0].velocity",
        ),
    ] {
        let e = Program::parse(Path::new("p.toml"), &format!("[[step]]\n{step}\n"), &c)
            .expect_err(step);
        assert_eq!(e.key, key, "{e}");
        assert!(e.message.contains("too small to plan with"), "{e}");
        assert_eq!(e.to_string().lines().count(), 1, "{e}");
        assert!(
            e.message.starts_with("1e-300 ") || e.message.contains(" 1e-300 "),
            "{e}"
        );
    }
    // A millionth of the axis limit (10 mm/s) is still taken.
    let ok = "[[step]]\ndo = \"move\"\ntarget = { a0 = 5.0 }\nvelocity = 1e-5\n";
    Program::parse(Path::new("p.toml"), ok, &c).unwrap();
}

/// A move or a jog the axis' drive profile does not take at that point of the program is
/// refused at load, naming the step, before anything moves: a jog of a pp axis, a move of a pv
/// axis, and a jog of a csp axis after a `mode` step switched it to pp (allowed again once it
/// is switched back).
#[test]
fn moves_and_jogs_a_profile_mode_does_not_take_are_refused_at_load() {
    let axis = |name: &str, mode: &str| {
        format!(
            "[[axes]]\nname = \"{name}\"\ndrive = \"mr-j5-g-n1\"\nmode = \"{mode}\"\nmotor = {{ counts_per_rev = 10000, rated_speed = 3000 }}\ncounts_per_unit = 1000\nlimits = {{ position = [0.0, 100.0], velocity = 10.0, acceleration = 100.0, jerk = 1000.0 }}\n"
        )
    };
    let text = format!(
        "[cell]\nname = \"p\"\ncycle_time_us = 1000\n{}{}{}",
        axis("pos", "pp"),
        axis("vel", "pv"),
        axis("c", "csp")
    );
    let c = CellConfig::parse(Path::new("c.toml"), &text).unwrap_or_else(|e| panic!("{e}"));
    let parse = |program: &str| Program::parse(Path::new("p.toml"), program, &c);
    let jog = |axis: &str| {
        format!("[[step]]\ndo = \"jog\"\naxis = \"{axis}\"\nvelocity = 1.0\nseconds = 0.1\n")
    };
    let e = parse(&jog("pos")).unwrap_err();
    assert_eq!(e.key, "step[0].axis");
    assert_eq!(
        e.message,
        "axis 'pos' runs in pp (the drive's profile): velocity needs a csp, csv, cst or pv axis"
    );
    let e = parse("[[step]]\ndo = \"move\"\ntarget = { vel = 5.0 }\n").unwrap_err();
    assert_eq!(e.key, "step[0].target.vel");
    assert_eq!(
        e.message,
        "axis 'vel' runs in pv (the drive's profile): move needs a csp, csv, cst or pp axis"
    );
    parse(&(jog("vel") + &jog("c") + "[[step]]\ndo = \"move\"\ntarget = { pos = 5.0, c = 5.0 }\n"))
        .unwrap_or_else(|e| panic!("{e}"));
    let to = |mode: &str| format!("[[step]]\ndo = \"mode\"\naxis = \"c\"\nmode = \"{mode}\"\n");
    let e = parse(&format!("{}{}", to("pp"), jog("c"))).unwrap_err();
    assert_eq!(e.key, "step[1].axis");
    parse(&format!("{}{}{}", to("pp"), to("csp"), jog("c"))).unwrap_or_else(|e| panic!("{e}"));
}
