//! The operator's motion requests (PLCopen MC_MoveAbsolute / MC_MoveRelative, MC_MoveVelocity,
//! MC_TorqueControl, MC_Home, MC_Halt, MC_Stop, MC_Reset, MC_SetOverride, programs): each
//! checked against the cell and handed to the motion engine or the RT thread.

use super::*;
use cellrt_fieldbus::mr_je_c::cell::AxisCommand;

impl OperatorServer {
    /// MC_MoveAbsolute / MC_MoveRelative: a time-synchronised move, or with `line` a straight
    /// line whose asked velocity is the path velocity.
    pub(super) fn move_axes(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        targets: &BTreeMap<String, f64>,
        relative: bool,
        line: bool,
        asked: Asked,
    ) -> (Reply, Followup) {
        // MR-JE-C axes: checked first, sent once the RT loop's part is accepted.
        let (je_c, targets) = match backend::split(ctx.cell, targets) {
            Ok(s) => (s.on_link, s.on_loop),
            Err(e) => return rejected(format!("move: {e}")),
        };
        if let (true, Some((_, name, _))) = (line, je_c.first()) {
            let e = TargetError::NotStreamed {
                axis: name.clone(),
                backend: cellrt_config::Backend::Link,
                what: "a line",
            };
            return rejected(format!("move: {e}"));
        }
        let je_c_commands = match link::move_commands(ctx.je_c, &je_c, relative, asked) {
            Ok(c) => c,
            Err(e) => return rejected(format!("move: {e}")),
        };
        if je_c_commands.is_empty() {
            return self.move_streamed(ctx, state, &targets, relative, line, asked);
        }
        let reply = if targets.is_empty() {
            (self.accept("move", true), Followup::None)
        } else {
            self.move_streamed(ctx, state, &targets, relative, line, asked)
        };
        let Reply::Accepted { id } = reply.0 else {
            return reply; // nothing sent to the MR-JE-C axes either
        };
        if self.active.as_ref().is_none_or(|a| a.id != id) {
            // The streamed part was not tracked (pp axes only): track the move now.
            self.track(id, "move");
        }
        self.je_c_moves.expect(id, "move", ctx.je_c, &je_c_commands);
        match link::send(ctx.je_c, &je_c_commands) {
            Ok(()) => reply,
            Err(e) => {
                self.finish_active(Some(e.to_string()));
                rejected(format!("move: {e}"))
            }
        }
    }

    /// The streamed and profile axes of a move.
    fn move_streamed(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        targets: &BTreeMap<String, f64>,
        relative: bool,
        line: bool,
        asked: Asked,
    ) -> (Reply, Followup) {
        let axis_velocity = if line { None } else { asked.velocity };
        let list = match resolve_targets(ctx, state, targets, relative, |a| {
            move_limits(
                a,
                Asked {
                    velocity: axis_velocity,
                    ..asked
                },
            )
        }) {
            Ok(l) => l,
            Err(e) => return rejected(format!("move: {e}")),
        };
        for &(i, target, limits, here) in &list {
            let a = &ctx.cell.axes.on_loop()[i];
            if let Err(e) = check_travel(
                || format!("axis '{}' ({})", a.name, a.unit),
                target - here,
                &limits,
            ) {
                return rejected(format!("move: {e}"));
            }
        }
        if !line {
            let list: Vec<_> = list.into_iter().map(|(i, t, l, _)| (i, t, l)).collect();
            return self.move_with_profile_axes(ctx, state, list);
        }
        let start: Vec<f64> = list.iter().map(|t| t.3).collect();
        let end: Vec<f64> = list.iter().map(|t| t.1).collect();
        let limits: Vec<KinematicLimits> = list.iter().map(|t| t.2).collect();
        let max = cellrt_trajectory::line::max_path_velocity(&start, &end, &limits);
        let path_velocity = match asked.velocity {
            Some(v) if !(v.is_finite() && v > 0.0) => {
                return rejected(format!(
                    "move: path velocity {v} must be a finite number > 0"
                ))
            }
            Some(v) if v < max * MIN_LIMIT_FRACTION => {
                return rejected(format!(
                    "move: path velocity {v:?} is too small to plan with (at least {:.3e}, a millionth of the most every axis allows along this line)",
                    max * MIN_LIMIT_FRACTION
                ))
            }
            Some(v) if v > max && !asked.clamp => {
                return rejected(format!(
                    "move: path velocity {v} exceeds {max:.3}, the most every axis allows along this line (add --clamp to use it)"
                ))
            }
            Some(v) => Some(v.min(max)),
            None => None,
        };
        if let Some(v) = path_velocity {
            // The path at `v`: its time is the length over `v` whatever the axes' ramps.
            let path = KinematicLimits {
                velocity: v,
                acceleration: f64::MAX,
                jerk: f64::MAX,
            };
            let length = start
                .iter()
                .zip(&end)
                .map(|(s, e)| (e - s) * (e - s))
                .sum::<f64>()
                .sqrt();
            let unit = &ctx.cell.axes.on_loop()[list[0].0].unit;
            if let Err(e) = check_travel(|| format!("the line ({unit})"), length, &path) {
                return rejected(format!("move: {e}"));
            }
        }
        let req = MotionRequest::Line {
            targets: list.iter().map(|t| (t.0, t.1, t.2)).collect(),
            path_velocity,
        };
        self.motion("move", req, ctx)
    }

    /// A move whose pp axes the drive moves by itself (`profile::split_move`): the streamed
    /// axes go to the motion engine first, then each pp axis gets its set-point.
    pub(super) fn move_with_profile_axes(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        list: Vec<(usize, f64, KinematicLimits)>,
    ) -> (Reply, Followup) {
        let modes = profile::AxisModes::now(ctx.cell, state);
        let (commands, streamed) = match profile::split_move(ctx.cell, &modes, list) {
            Ok(split) => split,
            Err(e) => return rejected(format!("move: {e}")),
        };
        let reply = if streamed.is_empty() {
            (self.accept("move", !commands.is_empty()), Followup::None)
        } else {
            let r = self.motion("move", MotionRequest::Move(streamed), ctx);
            if matches!(r.0, Reply::Rejected { .. }) {
                return r; // nothing sent to the pp axes either
            }
            r
        };
        // The move ends when the pp axes' drives report their set-points done, too.
        if let (Reply::Accepted { id }, Ok(before)) = (&reply.0, ctx.link.status()) {
            self.profile_moves.expect(*id, &commands, &before);
        }
        // The pp axes start in the streamed motion's first cycle.
        let start = ctx.engine.start_cycle().unwrap_or(0);
        match profile::send(ctx.link, commands, start) {
            Ok(()) => reply,
            Err(e) => {
                self.finish_active(Some(e.to_string()));
                rejected(format!("move: {e}"))
            }
        }
    }

    /// A waypoint move from rest: through each waypoint but the last, to the last at rest.
    pub(super) fn path(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        waypoints: &[BTreeMap<String, f64>],
        asked: Asked,
    ) -> (Reply, Followup) {
        let Some(last) = waypoints.last() else {
            return rejected("path: no waypoints".into());
        };
        let resolved = match resolve_targets(ctx, state, last, false, |a| move_limits(a, asked)) {
            Ok(l) => l,
            Err(e) => return rejected(format!("path: {e}")),
        };
        let mut via: Vec<Vec<f64>> = Vec::with_capacity(waypoints.len() - 1);
        for (w, point) in waypoints[..waypoints.len() - 1].iter().enumerate() {
            if point.len() != last.len() || point.keys().any(|k| !last.contains_key(k)) {
                return rejected(format!(
                    "path: waypoint {w} names other axes than the target ({})",
                    last.keys().cloned().collect::<Vec<_>>().join(", ")
                ));
            }
            via.push(last.keys().map(|k| point[k]).collect());
        }
        // Each axis travels at least from here through every waypoint to its target.
        for (k, &(i, target, limits, here)) in resolved.iter().enumerate() {
            let mut at = here;
            let mut travel = 0.0;
            for p in via.iter().map(|v| v[k]).chain([target]) {
                travel += (p - at).abs();
                at = p;
            }
            let a = &ctx.cell.axes.on_loop()[i];
            if let Err(e) = check_travel(
                || format!("axis '{}' ({})", a.name, a.unit),
                travel,
                &limits,
            ) {
                return rejected(format!("path: {e}"));
            }
        }
        let targets = resolved.into_iter().map(|(i, t, l, _)| (i, t, l)).collect();
        self.motion("path", MotionRequest::Path { targets, via }, ctx)
    }

    /// MC_MoveVelocity: jogs one axis at a signed velocity until halted.
    pub(super) fn velocity(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        axis: &str,
        velocity: f64,
        acceleration: Option<f64>,
        clamp: bool,
    ) -> (Reply, Followup) {
        let i = match axis_ref(ctx.cell, axis) {
            Ok(AxisRef::Loop(i)) => i,
            Ok(AxisRef::Link(k)) => {
                return match link::velocity_command(ctx.je_c, k, velocity, acceleration, clamp)
                    .and_then(|c| link::send(ctx.je_c, &[(k, c)]))
                {
                    Ok(()) => (self.accept("velocity", false), Followup::None),
                    Err(e) => rejected(format!("velocity: {e}")),
                }
            }
            Err(e) => return rejected(format!("velocity: {e}")),
        };
        let a = &ctx.cell.axes.on_loop()[i];
        let asked = Asked {
            velocity: None,
            acceleration,
            jerk: None,
            clamp,
        };
        let limits = match move_limits(a, asked) {
            Ok(l) => l,
            Err(e) => return rejected(format!("velocity: {e}")),
        };
        let v = match jog_velocity(&a.name, &a.unit, velocity, a.limits.velocity, clamp) {
            Ok(v) => v,
            Err(e) => return rejected(format!("velocity: {e}")),
        };
        let mode = profile::AxisModes::now(ctx.cell, state).of(i);
        if mode.is_some() {
            return match profile::jog(i, a, mode, v, &limits)
                .and_then(|c| profile::send(ctx.link, vec![c], 0))
            {
                Ok(()) => (self.accept("velocity", false), Followup::None),
                Err(e) => rejected(format!("velocity: {e}")),
            };
        }
        self.motion(
            "velocity",
            MotionRequest::Jog {
                axis: i,
                velocity: v,
                limits,
            },
            ctx,
        )
    }

    /// MC_TorqueControl: torque on cst axes, held for `seconds`.
    pub(super) fn torque(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        targets: &BTreeMap<String, f64>,
        seconds: f64,
    ) -> (Reply, Followup) {
        if seconds > MAX_MOTION_S {
            return rejected(format!(
                "torque: {seconds:?} s is longer than a motion may take ({MAX_MOTION_S} s, one day)"
            ));
        }
        let (je_c, targets) = match backend::split(ctx.cell, targets) {
            Ok(s) => (s.on_link, s.on_loop),
            Err(e) => return rejected(format!("torque: {e}")),
        };
        if !je_c.is_empty() {
            return self.torque_je_c(ctx, &je_c, !targets.is_empty());
        }
        let targets = &targets;
        let modes = profile::AxisModes::now(ctx.cell, state);
        let (drive_side, list) = match profile::split_torque(ctx.cell, &modes, targets) {
            Ok(split) => split,
            Err(e) => return rejected(format!("torque: {e}")),
        };
        if !drive_side.is_empty() {
            // tq axes hold their torque until a halt or stop (`seconds` is for cst axes).
            return match profile::send(ctx.link, drive_side, 0) {
                Ok(()) => (self.accept("torque", false), Followup::None),
                Err(e) => rejected(format!("torque: {e}")),
            };
        }
        if !(seconds.is_finite() && seconds >= 0.0) {
            return rejected(format!(
                "torque: seconds {seconds} must be a finite number ≥ 0"
            ));
        }
        self.motion(
            "torque",
            MotionRequest::Torque {
                targets: list,
                hold_s: seconds,
            },
            ctx,
        )
    }

    /// MC_TorqueControl of MR-JE-C axes: each drive ramps to its torque in tq and holds it
    /// until a halt or stop (as a tq axis); not mixed with the RT thread's axes (`others`).
    fn torque_je_c(
        &mut self,
        ctx: &mut Context<'_>,
        je_c: &[backend::LinkTarget],
        others: bool,
    ) -> (Reply, Followup) {
        if others {
            return rejected(
                "torque: MR-JE-C axes and the cell's other axes in one command (their drives hold \
                 the torque, cst axes only for `seconds`): send them apart"
                    .into(),
            );
        }
        match link::torque_commands(ctx.je_c, je_c).and_then(|c| link::send(ctx.je_c, &c)) {
            Ok(()) => (self.accept("torque", false), Followup::None),
            Err(e) => rejected(format!("torque: {e}")),
        }
    }

    /// MC_Home: one axis, from idle, in its drive's homing mode; tracked until the RT thread
    /// reports the homing sequence ended.
    pub(super) fn home(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        axis: &str,
        method: Option<i8>,
        setting: Option<HomeSettingEdge>,
    ) -> (Reply, Followup) {
        let i = match axis_ref(ctx.cell, axis) {
            Ok(AxisRef::Loop(i)) => i,
            Ok(AxisRef::Link(k)) => return self.home_je_c(ctx, k, method, setting.is_some()),
            Err(e) => return rejected(format!("home: {e}")),
        };
        let a = &ctx.cell.axes.on_loop()[i];
        // `[axes.homing] method` where the request names neither a method nor an edge.
        let method = method.or(a.homing.method.filter(|_| setting.is_none()));
        let procedure = match choose_procedure(&*a.profile, method, setting) {
            Ok(p) => p,
            Err(e) => return rejected(format!("home: axis '{axis}': {e}")),
        };
        if ctx.engine.is_busy() || state.state != CellState::Idle {
            return rejected(format!(
                "home: the cell is {}; homing starts from idle (power on, halt or wait first)",
                state.state.as_str()
            ));
        }
        self.home_seq = state.homing.seq;
        self.home_on_je_c = false;
        match ctx.link.home(HomeRequest {
            axis: i as u16,
            procedure,
        }) {
            Ok(()) => (self.accept("home", true), Followup::None),
            Err(e) => rejected(format!("home: {e}")),
        }
    }

    /// Switches a csp axis to pp or back at standstill (the drive's mode-switch rules, on the
    /// RT thread); tracked until 6061h shows the new mode or the switch is withdrawn.
    pub(super) fn switch_mode(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        axis: &str,
        mode: &str,
    ) -> (Reply, Followup) {
        let i = match axis_index(ctx.cell, axis) {
            Ok(i) => i,
            Err(e) => return rejected(format!("mode: {e}")),
        };
        let Some(to) = SwitchableMode::parse(mode) else {
            return rejected(format!(
                "mode: '{mode}' is not a mode an axis switches to at run time (csp or pp)"
            ));
        };
        if let Err(e) = cellrt_config::profile_axis::pp_switch(&ctx.cell.axes.on_loop()[i]) {
            return rejected(format!("mode: {e}"));
        }
        let now = state.mode_now(ctx.cell, i);
        if now == to.mode() {
            return rejected(format!(
                "mode: axis '{axis}' already runs in {}",
                now.as_str()
            ));
        }
        if ctx.engine.is_busy() || state.state != CellState::Idle {
            return rejected(format!(
                "mode: the cell is {}; a mode switch starts from idle (power on, halt or wait first)",
                state.state.as_str()
            ));
        }
        if state.live[i].powered == 0
            || Statusword(state.live[i].statusword).state()
                != Some(cellrt_cia402::fsa::FsaState::OperationEnabled)
        {
            return rejected(format!(
                "mode: axis '{axis}' is not powered and enabled (power it on first)"
            ));
        }
        let reply = self.accept("mode", true);
        let command = ProfileCommand {
            axis: i as u16,
            motion: ProfileMotion::SwitchMode(to),
            start_cycle: 0,
        };
        if let Reply::Accepted { id } = reply {
            self.profile_moves.expect(id, &[command], state);
        }
        match profile::send(ctx.link, vec![command], 0) {
            Ok(()) => (reply, Followup::None),
            Err(e) => {
                self.finish_active(Some(e.to_string()));
                rejected(format!("mode: {e}"))
            }
        }
    }

    /// MC_Home of MR-JE-C axis `k`: hm on its drive with method 37, tracked until its job ends.
    fn home_je_c(
        &mut self,
        ctx: &mut Context<'_>,
        k: usize,
        method: Option<i8>,
        setting: bool,
    ) -> (Reply, Followup) {
        let command = match link::home_command(ctx.je_c, k, method, setting) {
            Ok(c) => c,
            Err(e) => return rejected(format!("home: {e}")),
        };
        let reply = self.accept("home", true);
        let Reply::Accepted { id } = reply else {
            return (reply, Followup::None);
        };
        self.home_on_je_c = true;
        self.je_c_moves
            .expect(id, "homing", ctx.je_c, &[(k, command)]);
        match link::send(ctx.je_c, &[(k, command)]) {
            Ok(()) => (reply, Followup::None),
            Err(e) => {
                self.finish_active(Some(e.to_string()));
                rejected(format!("home: {e}"))
            }
        }
    }

    /// MC_Halt: the named axes (every axis when none) ramp down, MR-JE-C axes by their
    /// drives' Halt; a running program is aborted.
    pub(super) fn halt(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        axes: &[String],
    ) -> (Reply, Followup) {
        let named = match backend::name_axes(ctx.cell, axes) {
            Ok(n) => n,
            Err(e) => return rejected(format!("halt: {e}")),
        };
        let halted = if axes.is_empty() {
            ctx.je_c.command_all(AxisCommand::Halt)
        } else {
            named
                .on_link
                .iter()
                .try_for_each(|&k| ctx.je_c.command(k, AxisCommand::Halt))
        };
        if let Err(e) = halted {
            return rejected(format!("halt: {e}"));
        }
        if named.on_loop.is_empty() && !named.on_link.is_empty() {
            return (
                self.accept("halt", false),
                program_abort(ctx.program_running),
            );
        }
        let list = (!named.on_loop.is_empty()).then_some(named.on_loop);
        let abort = ctx.program_running;
        let modes = profile::AxisModes::now(ctx.cell, state);
        let halts = profile::halts(ctx.cell, &modes, list.as_deref());
        if let Err(e) = profile::send(ctx.link, halts, 0) {
            return rejected(format!("halt: {e}"));
        }
        if !ctx.engine.is_busy() {
            return (self.accept("halt", false), program_abort(abort));
        }
        match ctx.engine.submit(MotionRequest::Halt(list), ctx.link) {
            Ok(()) => (self.accept("halt", true), program_abort(abort)),
            Err(e) => rejected(format!("halt: {e}")),
        }
    }

    /// MC_Stop: the RT thread stops the cell, the MR-JE-C axes halt on their drives' ramps (an
    /// indexer axis quick-stops); a running program is aborted.
    pub(super) fn stop(&mut self, ctx: &mut Context<'_>) -> (Reply, Followup) {
        if let Err(e) = ctx.je_c.stop_all() {
            return rejected(format!("stop: {e}"));
        }
        match ctx.link.command(CellCommand::Stop) {
            Ok(()) => {
                let reply = self.accept("stop", false);
                (reply, program_abort(ctx.program_running))
            }
            Err(e) => rejected(format!("stop: {e}")),
        }
    }

    /// MC_Reset: clears the MR-JE-C axes their watchdog or an alarm stopped, and leaves a
    /// stopped or faulted cell (nothing to do otherwise).
    pub(super) fn reset(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
    ) -> (Reply, Followup) {
        if let Err(e) = link::reset_stopped(ctx.je_c) {
            return rejected(format!("reset: {e}"));
        }
        if !matches!(state.state, CellState::Stopped | CellState::Faulted) {
            return (self.accept("reset", false), Followup::None);
        }
        ctx.engine.abandon();
        match ctx.link.command(CellCommand::Reset) {
            Ok(()) => (self.accept("reset", false), Followup::None),
            Err(e) => rejected(format!("reset: {e}")),
        }
    }

    /// The feed override, 0–100 %.
    pub(super) fn set_override(
        &mut self,
        ctx: &mut Context<'_>,
        percent: f64,
    ) -> (Reply, Followup) {
        if !(percent.is_finite() && (0.0..=100.0).contains(&percent)) {
            return rejected(format!("override: {percent} % is outside 0–100 %"));
        }
        if let Err(e) = ctx.engine.set_override(percent / 100.0, ctx.link) {
            return rejected(format!("override: {e}"));
        }
        match ctx.je_c.set_override(percent / 100.0) {
            Ok(()) => (self.accept("override", false), Followup::None),
            Err(e) => rejected(format!("override: {e}")),
        }
    }

    /// Loads and validates a program for the planner thread to run.
    pub(super) fn program(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        path: &Path,
    ) -> (Reply, Followup) {
        if ctx.engine.is_busy() {
            return rejected("program: a motion is active; halt it first".into());
        }
        // A program plans with the configured modes.
        let switched = (0..ctx.cell.axes.on_loop().len())
            .find(|&i| state.mode_now(ctx.cell, i) != ctx.cell.axes.on_loop()[i].mode);
        if let Some(i) = switched {
            let a = &ctx.cell.axes.on_loop()[i];
            return rejected(format!(
                "program: axis '{}' was switched to {} at run time and a program plans with the \
                 configured modes: switch it back first (`cellrt mode {} {}`)",
                a.name,
                state.mode_now(ctx.cell, i).as_str(),
                a.name,
                a.mode.as_str()
            ));
        }
        match Program::load(path, ctx.cell) {
            Ok(p) => (self.accept("program", true), Followup::RunProgram(p)),
            Err(e) => rejected(format!("program: {e}")),
        }
    }

    pub(super) fn motion(
        &mut self,
        name: &str,
        req: MotionRequest,
        ctx: &mut Context<'_>,
    ) -> (Reply, Followup) {
        match ctx.engine.submit(req, ctx.link) {
            Ok(()) => (self.accept(name, true), Followup::None),
            Err(e) => (
                Reply::Rejected {
                    reason: format!("{name}: {e}"),
                },
                Followup::None,
            ),
        }
    }
}
