//! The operator commands (`cellrt status`, `power`, `move`, `jog`, `torque`, `halt`, `stop`,
//! `reset`, `override`, `program`): clients of the running cell's operator service.

use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::homing::HomeSettingEdge;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use cellrt_config::echo::Echo;
use cellrt_runtime::host::operator::client::{ClientError, OperatorClient};
use cellrt_runtime::host::operator::wire::{Reply, Request, StatusReport};
use cellrt_trajectory::KinematicLimits;
use clap::{Args, Subcommand};

use crate::exit::Exit;

/// How long `--wait` follows a command by default.
const WAIT_TIMEOUT: Duration = Duration::from_secs(120);

/// Options every operator command takes.
#[derive(Debug, Args)]
pub struct Target {
    /// The cell (its `cell.name`); default: the only running cell.
    #[arg(long, global = true, value_name = "NAME")]
    pub cell: Option<String>,
    /// Seconds to wait for the cell's reply.
    #[arg(long, global = true, value_name = "SECONDS", default_value_t = 5.0,
          value_parser = crate::numbers::reply_timeout)]
    pub reply_timeout: f64,
}

/// Per-move limits of `move` and `path`.
#[derive(Debug, Args)]
pub struct LimitArgs {
    /// Velocity limit, unit/s (for `--line`: the path speed).
    #[arg(long = "vel", value_name = "V", value_parser = crate::numbers::positive)]
    velocity: Option<f64>,
    /// Acceleration limit, unit/s².
    #[arg(long = "acc", value_name = "A", value_parser = crate::numbers::positive)]
    acceleration: Option<f64>,
    /// Jerk limit, unit/s³.
    #[arg(long, value_name = "J", value_parser = crate::numbers::positive)]
    jerk: Option<f64>,
    /// Use the axis limit where a requested limit exceeds it (default: refuse).
    #[arg(long)]
    clamp: bool,
}

/// An operator command.
#[derive(Debug, Subcommand)]
pub enum OperatorCommand {
    /// Cell and axis status (MC_ReadStatus / MC_ReadActualPosition).
    Status {
        /// Redraw every 200 ms until Ctrl-C.
        #[arg(long)]
        watch: bool,
        /// Print the status as JSON.
        #[arg(long, conflicts_with = "watch")]
        json: bool,
    },
    /// MC_Power: enable (on) or cleanly disable (off) the named axes, or every axis.
    Power {
        /// on or off.
        #[arg(value_parser = ["on", "off"])]
        state: String,
        /// Axis names (the whole cell when none).
        axes: Vec<String>,
        /// Return once accepted instead of waiting for the cell to get there.
        #[arg(long)]
        no_wait: bool,
    },
    /// MC_MoveAbsolute / MC_MoveRelative: `cellrt move x=100 y=20`, time-synchronised.
    Move {
        /// AXIS=POSITION pairs, in the axis units.
        #[arg(required = true, value_name = "AXIS=POSITION")]
        targets: Vec<String>,
        #[command(flatten)]
        limits: LimitArgs,
        /// Positions are distances from the current position.
        #[arg(long = "rel")]
        relative: bool,
        /// A straight line in the axes' space (gantry; one unit); --vel is the path speed.
        #[arg(long)]
        line: bool,
        /// Return once accepted instead of waiting for the end of the move.
        #[arg(long)]
        no_wait: bool,
    },
    /// A waypoint move: `cellrt path x=100,y=20 x=300,y=50 x=400,y=0` passes the first
    /// waypoints and ends at rest at the last.
    Path {
        /// Waypoints, each AXIS=POS[,AXIS=POS…]; the last is the target.
        #[arg(required = true, value_name = "AXIS=POS,…")]
        waypoints: Vec<String>,
        #[command(flatten)]
        limits: LimitArgs,
        /// Return once accepted.
        #[arg(long)]
        no_wait: bool,
    },
    /// MC_MoveVelocity: jog AXIS at VELOCITY (unit/s, signed) until `cellrt halt`.
    Jog {
        /// Axis name.
        axis: String,
        /// Velocity, unit/s.
        #[arg(allow_negative_numbers = true, value_parser = crate::numbers::finite)]
        velocity: f64,
        /// Acceleration of the ramp, unit/s².
        #[arg(long = "acc", value_name = "A", value_parser = crate::numbers::positive)]
        acceleration: Option<f64>,
        /// Use the axis limit if VELOCITY exceeds it (default: refuse).
        #[arg(long)]
        clamp: bool,
    },
    /// MC_TorqueControl: `cellrt torque c=20 --seconds 1` on cst axes (ramped, held, released).
    Torque {
        /// AXIS=PERCENT pairs (% of rated torque).
        #[arg(
            required = true,
            value_name = "AXIS=PERCENT",
            allow_negative_numbers = true
        )]
        targets: Vec<String>,
        /// Seconds at the torque.
        #[arg(long, default_value_t = 1.0, value_parser = crate::numbers::motion_seconds)]
        seconds: f64,
        /// Return once accepted.
        #[arg(long)]
        no_wait: bool,
    },
    /// MC_Home: home AXIS in its drive's homing mode (hm); waits for the result.
    Home {
        /// Axis name.
        axis: String,
        /// 6098h homing method (default: the drive model's data-set method).
        #[arg(long, allow_negative_numbers = true)]
        method: Option<i8>,
        /// Home by a Controlword2 edge in the cyclic mode instead of hm (MR-J3-T04): clear =
        /// C_CR, home where the axis stands; clear-z = C_CR2, home at the last Z phase.
        #[arg(long, value_enum, conflicts_with = "method")]
        setting: Option<SettingArg>,
        /// Return once accepted.
        #[arg(long)]
        no_wait: bool,
    },
    /// Switch a csp AXIS to pp (its drive positions it by its own profile: `move` sends it
    /// set-points) or back to csp, at standstill; waits until the drive shows the new mode.
    Mode {
        /// Axis name.
        axis: String,
        /// The mode to switch to.
        #[arg(value_enum)]
        mode: ModeArg,
        /// Return once accepted.
        #[arg(long)]
        no_wait: bool,
    },
    /// MC_Halt: brake to rest (all axes, or the named ones); the cell stays ready.
    Halt {
        /// Axes (all when none).
        axes: Vec<String>,
    },
    /// MC_Stop: the RT thread's controlled stop.
    Stop,
    /// MC_Reset: clear a stopped or faulted cell.
    Reset {
        /// Return once accepted.
        #[arg(long)]
        no_wait: bool,
    },
    /// MC_SetOverride: feed override in percent (0–100), applied smoothly.
    Override {
        /// Percent.
        #[arg(value_parser = crate::numbers::finite)]
        percent: f64,
    },
    /// Run a program file on the cell.
    Program {
        /// The program (TOML).
        file: PathBuf,
        /// Return once accepted.
        #[arg(long)]
        no_wait: bool,
    },
    /// Write the triggered recording's ring now: one MCAP file with the last `pre_s` seconds
    /// and the next `post_s` (`recording.mode = "triggered"`).
    Capture,
}

/// Runs one operator command.
pub fn run(command: OperatorCommand, target: Target) -> Exit {
    let timeout = Duration::from_secs_f64(target.reply_timeout);
    let (request, wait) = match build(&command) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let client = match OperatorClient::connect(target.cell.as_deref()) {
        Ok(c) => c,
        Err(e) => return unreachable(e),
    };
    if let OperatorCommand::Status { watch, json } = command {
        return status(&client, timeout, watch, json);
    }
    if let Err(e) = check_travel(&client, &request, timeout) {
        eprintln!("error: {e}");
        return Exit::BadInput;
    }
    let id = match client.request(&request, timeout) {
        Ok(Reply::Accepted { id }) => id,
        Ok(Reply::Rejected { reason }) => {
            eprintln!("rejected: {reason}");
            return Exit::Rejected;
        }
        Ok(
            Reply::Status(_)
            | Reply::Sdo(_)
            | Reply::Param(_)
            | Reply::Alarms(_)
            | Reply::BusDiag(_)
            | Reply::SdoList(_),
        ) => {
            eprintln!("error: the cell answered with a report instead of accepting");
            return Exit::Unreachable;
        }
        Err(e) => return unreachable(e),
    };
    println!("accepted: {} (command {id})", request.name());
    match wait {
        Wait::No => Exit::Ok,
        Wait::Finished => wait_finished(&client, id, timeout),
        Wait::State(states) => wait_state(&client, states, timeout),
        Wait::Power { axes, on } => wait_power(&client, &axes, on, timeout),
        Wait::CellPower { on } => wait_cell_power(&client, on, timeout),
    }
}

/// `cellrt home --setting`: the Controlword2 edge.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum SettingArg {
    /// C_CR: home where the axis stands.
    Clear,
    /// C_CR2: home at the last Z phase.
    ClearZ,
}

/// `cellrt mode`: the mode a csp axis switches to at run time.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum ModeArg {
    /// Cyclic synchronous position: the controller streams the axis' setpoints.
    Csp,
    /// Profile position: the drive positions the axis by its own profile.
    Pp,
}

impl ModeArg {
    /// The mode's name on the wire.
    fn as_str(self) -> &'static str {
        cellrt_runtime::handoff::SwitchableMode::from(self).as_str()
    }
}

impl From<ModeArg> for cellrt_runtime::handoff::SwitchableMode {
    fn from(m: ModeArg) -> Self {
        match m {
            ModeArg::Csp => cellrt_runtime::handoff::SwitchableMode::Csp,
            ModeArg::Pp => cellrt_runtime::handoff::SwitchableMode::Pp,
        }
    }
}

/// What to follow after acceptance.
enum Wait {
    No,
    Finished,
    State(&'static [&'static str]),
    /// The named axes in Operation enabled (`on`) or out of it, and the cell settled.
    Power {
        axes: Vec<String>,
        on: bool,
    },
    /// The cell idle (`on`) or disabled, and every MR-JE-C axis in Operation enabled or out.
    CellPower {
        on: bool,
    },
}

/// Why an operator command's arguments make no request.
#[derive(Debug, thiserror::Error)]
pub enum RequestArgsError {
    /// An argument is not `AXIS=VALUE`.
    #[error("{what}: '{}' is not AXIS=VALUE", Echo(.arg))]
    NotAPair {
        /// The command.
        what: &'static str,
        /// The argument.
        arg: String,
    },
    /// The value of an `AXIS=VALUE` argument is not a number.
    #[error("{what}: '{}': '{}' is not a number", Echo(.arg), Echo(.value))]
    NotANumber {
        /// The command.
        what: &'static str,
        /// The argument.
        arg: String,
        /// Its value.
        value: String,
    },
    /// The value of an `AXIS=VALUE` argument is infinite or NaN.
    #[error("{what}: '{}': '{}' is not a finite number", Echo(.arg), Echo(.value))]
    NotFinite {
        /// The command.
        what: &'static str,
        /// The argument.
        arg: String,
        /// Its value.
        value: String,
    },
    /// Two arguments name one axis.
    #[error("{what}: axis '{}' is given twice", Echo(.axis))]
    AxisTwice {
        /// The command.
        what: &'static str,
        /// The axis.
        axis: String,
    },
    /// The program file cannot be found.
    #[error("program: {}: {source}", .file.display())]
    Program {
        /// The file given.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

fn build(command: &OperatorCommand) -> Result<(Request, Wait), RequestArgsError> {
    let wait = |no_wait: bool, w: Wait| if no_wait { Wait::No } else { w };
    Ok(match command {
        OperatorCommand::Status { .. } => (Request::Status, Wait::No),
        OperatorCommand::Power {
            state,
            axes,
            no_wait,
        } => {
            let (request, w) = power(state == "on", axes);
            (request, wait(*no_wait, w))
        }
        OperatorCommand::Move {
            targets,
            limits,
            relative,
            line,
            no_wait,
        } => (
            Request::Move {
                targets: pairs("move", targets)?,
                relative: *relative,
                velocity: limits.velocity,
                acceleration: limits.acceleration,
                jerk: limits.jerk,
                clamp: limits.clamp,
                line: *line,
            },
            wait(*no_wait, Wait::Finished),
        ),
        OperatorCommand::Path {
            waypoints,
            limits,
            no_wait,
        } => (path(waypoints, limits)?, wait(*no_wait, Wait::Finished)),
        OperatorCommand::Jog {
            axis,
            velocity,
            acceleration,
            clamp,
        } => (
            Request::Velocity {
                axis: axis.clone(),
                velocity: *velocity,
                acceleration: *acceleration,
                clamp: *clamp,
            },
            Wait::No,
        ),
        OperatorCommand::Torque {
            targets,
            seconds,
            no_wait,
        } => (
            Request::Torque {
                targets: pairs("torque", targets)?,
                seconds: *seconds,
            },
            wait(*no_wait, Wait::Finished),
        ),
        OperatorCommand::Home {
            axis,
            method,
            setting,
            no_wait,
        } => (
            Request::Home {
                axis: axis.clone(),
                method: *method,
                setting: setting.map(|s| match s {
                    SettingArg::Clear => HomeSettingEdge::Clear,
                    SettingArg::ClearZ => HomeSettingEdge::ClearZ,
                }),
            },
            wait(*no_wait, Wait::Finished),
        ),
        OperatorCommand::Mode {
            axis,
            mode,
            no_wait,
        } => (
            Request::Mode {
                axis: axis.clone(),
                mode: mode.as_str().to_string(),
            },
            wait(*no_wait, Wait::Finished),
        ),
        OperatorCommand::Halt { axes } => (Request::Halt { axes: axes.clone() }, Wait::No),
        OperatorCommand::Stop => (Request::Stop, Wait::No),
        OperatorCommand::Capture => (Request::Capture, Wait::No),
        OperatorCommand::Reset { no_wait } => (
            Request::Reset,
            wait(*no_wait, Wait::State(&["idle", "disabled"])),
        ),
        OperatorCommand::Override { percent } => {
            (Request::Override { percent: *percent }, Wait::No)
        }
        OperatorCommand::Program { file, no_wait } => {
            // The cell resolves paths from its own working directory: send an absolute one.
            let path = std::fs::canonicalize(file).map_err(|source| RequestArgsError::Program {
                file: file.clone(),
                source,
            })?;
            (Request::Program { path }, wait(*no_wait, Wait::Finished))
        }
    })
}

/// MC_Power for the cell (no axes named) or the named axes, and what settles it.
fn power(on: bool, axes: &[String]) -> (Request, Wait) {
    let w = if axes.is_empty() {
        Wait::CellPower { on }
    } else {
        Wait::Power {
            axes: axes.to_vec(),
            on,
        }
    };
    (
        Request::Power {
            on,
            axes: axes.to_vec(),
        },
        w,
    )
}

/// A waypoint path: each waypoint is `AXIS=VALUE,AXIS=VALUE,…`.
fn path(waypoints: &[String], limits: &LimitArgs) -> Result<Request, RequestArgsError> {
    Ok(Request::Path {
        waypoints: waypoints
            .iter()
            .map(|w| {
                pairs(
                    "path",
                    &w.split(',').map(str::to_string).collect::<Vec<_>>(),
                )
            })
            .collect::<Result<_, _>>()?,
        velocity: limits.velocity,
        acceleration: limits.acceleration,
        jerk: limits.jerk,
        clamp: limits.clamp,
    })
}

/// Refuses a move or path whose own limits (`--vel`, `--acc`, `--jerk`) would make it take
/// longer than a motion may ([`KinematicLimits::check_travel`]), before it is sent: per axis
/// (its travel through every waypoint), and for `--line` along the path. Absolute targets are
/// measured from the positions the cell reports; where it reports none the cell judges alone
/// (it checks every move again with the axis limits).
fn check_travel(client: &OperatorClient, req: &Request, timeout: Duration) -> Result<(), String> {
    let (what, points, relative, line, [velocity, acceleration, jerk]) = match req {
        Request::Move {
            targets,
            relative,
            velocity,
            acceleration,
            jerk,
            line,
            ..
        } => (
            "move",
            std::slice::from_ref(targets),
            *relative,
            *line,
            [*velocity, *acceleration, *jerk],
        ),
        Request::Path {
            waypoints,
            velocity,
            acceleration,
            jerk,
            ..
        } => (
            "path",
            waypoints.as_slice(),
            false,
            false,
            [*velocity, *acceleration, *jerk],
        ),
        _ => return Ok(()),
    };
    let Some(last) = points.last() else {
        return Ok(());
    };
    if velocity.is_none() && acceleration.is_none() && jerk.is_none() {
        return Ok(());
    }
    // Only the asked limits bind here; the axis limits are the cell's to apply.
    let asked = |v: Option<f64>| v.unwrap_or(f64::MAX);
    let per_axis = KinematicLimits {
        velocity: if line { f64::MAX } else { asked(velocity) },
        acceleration: asked(acceleration),
        jerk: asked(jerk),
    };
    let here = if relative {
        None
    } else {
        match client.request(&Request::Status, timeout) {
            Ok(Reply::Status(s)) => Some(s),
            _ => return Ok(()),
        }
    };
    let mut distances = Vec::with_capacity(last.len());
    for axis in last.keys() {
        let (from, unit) = match &here {
            None => (0.0, String::new()),
            Some(s) => match s.axes.iter().find(|a| &a.name == axis) {
                Some(a) => (a.position, format!(" ({})", a.unit)),
                None => return Ok(()), // the cell names the unknown axis
            },
        };
        let (mut at, mut travel) = (from, 0.0);
        for p in points.iter().filter_map(|p| p.get(axis)) {
            travel += (p - at).abs();
            at = *p;
        }
        per_axis
            .check_travel(travel)
            .map_err(|e| format!("{what}: axis '{}'{unit}: {e}", Echo(axis)))?;
        distances.push(last[axis] - from);
    }
    if let (true, Some(v)) = (line, velocity) {
        let length = distances.iter().map(|d| d * d).sum::<f64>().sqrt();
        let path = KinematicLimits {
            velocity: v,
            acceleration: f64::MAX,
            jerk: f64::MAX,
        };
        path.check_travel(length)
            .map_err(|e| format!("{what}: the line: {e}"))?;
    }
    Ok(())
}

/// Parses `AXIS=VALUE` arguments.
fn pairs(what: &'static str, args: &[String]) -> Result<BTreeMap<String, f64>, RequestArgsError> {
    let mut out = BTreeMap::new();
    for a in args {
        let (axis, value) = a
            .split_once('=')
            .ok_or_else(|| RequestArgsError::NotAPair {
                what,
                arg: a.clone(),
            })?;
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| RequestArgsError::NotANumber {
                what,
                arg: a.clone(),
                value: value.to_string(),
            })?;
        if !v.is_finite() {
            return Err(RequestArgsError::NotFinite {
                what,
                arg: a.clone(),
                value: value.to_string(),
            });
        }
        if out.insert(axis.trim().to_string(), v).is_some() {
            return Err(RequestArgsError::AxisTwice {
                what,
                axis: axis.to_string(),
            });
        }
    }
    Ok(out)
}

fn unreachable(e: ClientError) -> Exit {
    eprintln!("error: {e}");
    Exit::Unreachable
}

fn fetch(client: &OperatorClient, timeout: Duration) -> Result<StatusReport, Exit> {
    match client.request(&Request::Status, timeout) {
        Ok(Reply::Status(s)) => Ok(*s),
        Ok(other) => {
            eprintln!("error: unexpected reply to status: {other:?}");
            Err(Exit::Unreachable)
        }
        Err(e) => Err(unreachable(e)),
    }
}

/// Follows command `id` until it ends; fails if it ended with an error.
fn wait_finished(client: &OperatorClient, id: u64, timeout: Duration) -> Exit {
    let end = Instant::now() + WAIT_TIMEOUT;
    loop {
        let s = match fetch(client, timeout) {
            Ok(s) => s,
            Err(e) => return e,
        };
        if let Some(f) = s.last_finished.as_ref().filter(|f| f.id >= id) {
            if f.id == id {
                return match &f.error {
                    None => {
                        println!("done: command {id}");
                        Exit::Ok
                    }
                    Some(e) => {
                        eprintln!("failed: command {id}: {e}");
                        Exit::Failed
                    }
                };
            }
        }
        if s.active_command.as_ref().is_none_or(|a| a.id != id)
            && s.last_finished.as_ref().is_none_or(|f| f.id < id)
        {
            // Ended without a trace (a command that completes at once).
            println!("done: command {id}");
            return Exit::Ok;
        }
        if Instant::now() >= end {
            eprintln!("error: command {id} did not end within {WAIT_TIMEOUT:?}");
            return Exit::Failed;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Waits until the cell state is one of `states`; fails on a fault.
fn wait_state(client: &OperatorClient, states: &[&str], timeout: Duration) -> Exit {
    poll_status(client, timeout, states.contains(&"faulted"), |s| {
        if states.contains(&s.state.as_str()) {
            Verdict::Done(format!("cell {}", s.state))
        } else {
            Verdict::Pending(format!(
                "the cell is {}, not {}",
                s.state,
                states.join(" or ")
            ))
        }
    })
}

/// Waits until the named axes are (`on`) or are not in Operation enabled and the cell has
/// settled.
fn wait_power(client: &OperatorClient, axes: &[String], on: bool, timeout: Duration) -> Exit {
    poll_status(client, timeout, false, |s| {
        let enabled = FsaState::OperationEnabled.as_str();
        let pending: Vec<&str> = s
            .axes
            .iter()
            .filter(|a| axes.contains(&a.name) && (a.fsa == enabled) != on)
            .map(|a| a.name.as_str())
            .collect();
        let settled = !matches!(s.state.as_str(), "enabling" | "disabling");
        let (done, not_done) = if on {
            ("powered", "not enabled")
        } else {
            ("unpowered", "enabled")
        };
        if pending.is_empty() && settled {
            Verdict::Done(format!("{} {done}, cell {}", axes.join(", "), s.state))
        } else {
            Verdict::Pending(format!(
                "{} still {not_done} (cell {})",
                pending.join(", "),
                s.state
            ))
        }
    })
}

/// Waits until the cell is idle (`on`) or disabled and every axis its link drives (the RT
/// loop's are judged by the cell's state) is (or is not) in Operation enabled.
fn wait_cell_power(client: &OperatorClient, on: bool, timeout: Duration) -> Exit {
    let want = if on { "idle" } else { "disabled" };
    poll_status(client, timeout, false, |s| {
        let enabled = FsaState::OperationEnabled.as_str();
        let pending: Vec<&str> = s
            .axes
            .iter()
            .filter(|a| a.link.is_some() && (a.fsa == enabled) != on)
            .map(|a| a.name.as_str())
            .collect();
        if s.state == want && pending.is_empty() {
            Verdict::Done(format!("cell {}", s.state))
        } else if s.state != want {
            Verdict::Pending(format!("the cell is {}, not {want}", s.state))
        } else {
            Verdict::Pending(format!(
                "axes {} still {}",
                pending.join(", "),
                if on { "not enabled" } else { "enabled" }
            ))
        }
    })
}

/// What a status says of the state a command waits for.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Verdict {
    /// Reached: what it is.
    Done(String),
    /// Not yet: what is still pending.
    Pending(String),
}

/// Polls the status until `judge` says done, the cell faults (unless `faulted_ok`), or 15 s
/// pass (what is still pending is printed).
fn poll_status(
    client: &OperatorClient,
    timeout: Duration,
    faulted_ok: bool,
    judge: impl Fn(&StatusReport) -> Verdict,
) -> Exit {
    let end = Instant::now() + Duration::from_secs(15);
    // Let the RT thread take the command before judging the state.
    std::thread::sleep(Duration::from_millis(50));
    loop {
        let s = match fetch(client, timeout) {
            Ok(s) => s,
            Err(e) => return e,
        };
        let verdict = judge(&s);
        if let Verdict::Done(what) = &verdict {
            println!("done: {what}");
            return Exit::Ok;
        }
        if s.state == "faulted" && !faulted_ok {
            eprintln!(
                "failed: the cell faulted ({})",
                s.stop_reason.as_deref().unwrap_or("see cellrt status")
            );
            return Exit::Failed;
        }
        if Instant::now() >= end {
            if let Verdict::Pending(what) = verdict {
                eprintln!("failed: {what}");
            }
            return Exit::Failed;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn status(client: &OperatorClient, timeout: Duration, watch: bool, json: bool) -> Exit {
    loop {
        let s = match fetch(client, timeout) {
            Ok(s) => s,
            Err(e) => return e,
        };
        if json {
            println!(
                "{}",
                serde_json::to_string_pretty(&s).expect("status serialises")
            );
            return Exit::Ok;
        }
        let text = render(&s);
        if watch {
            // Clear the screen and home the cursor, then redraw.
            print!("\x1b[2J\x1b[H{text}");
            let _ = std::io::stdout().flush();
            std::thread::sleep(Duration::from_millis(200));
        } else {
            print!("{text}");
            return Exit::Ok;
        }
    }
}

/// The compact status table.
pub fn render(s: &StatusReport) -> String {
    let mut out = format!(
        "cell {}  state {}{}  cycle {} at {} µs  override {:.0} %\n",
        s.cell,
        s.state,
        s.stop_reason
            .as_ref()
            .map(|r| format!(" ({r})"))
            .unwrap_or_default(),
        s.cycle,
        s.cycle_time_us,
        s.override_percent
    );
    if let Some(a) = &s.active_command {
        out += &format!("active  {} (command {})\n", a.command, a.id);
    }
    if let Some(f) = &s.last_finished {
        out += &format!(
            "last    {} (command {}): {}\n",
            f.command,
            f.id,
            f.error.as_deref().unwrap_or("done")
        );
    }
    out += &format!(
        "{:<8} {:<5} {:<22} {:>12} {:>12} {:>11} {:>10} {:>6}  {}\n",
        "axis",
        "mode",
        "fsa",
        "position",
        "setpoint",
        "velocity",
        "follow err",
        "alarm",
        "status DO / link"
    );
    for a in &s.axes {
        let dash = || "-".to_string();
        let (setpoint, following_error) = match &a.link {
            None => (
                format!("{:.3}", a.setpoint),
                format!("{:.4}", a.following_error),
            ),
            Some(l) => (if l.busy { "moving".into() } else { dash() }, dash()),
        };
        let detail = match &a.link {
            None if a.status_do.is_empty() => dash(),
            None => a.status_do.join(" "),
            Some(l) => format!(
                "{} over {}, {} exchanges, {} missed ({} in a row), round trip {:.0} µs{}",
                a.backend,
                l.transport,
                l.exchanges,
                l.missed,
                l.missed_in_row,
                l.round_trip_us,
                l.stopped
                    .as_ref()
                    .map(|r| format!(", stopped: {r}"))
                    .unwrap_or_default()
            ),
        };
        out += &format!(
            "{:<8} {:<5} {:<22} {:>9.3} {:<2} {:>12} {:>11.3} {:>10} {:>6}  {}\n",
            a.name,
            a.mode,
            a.fsa,
            a.position,
            a.unit,
            setpoint,
            a.velocity,
            following_error,
            if a.error_code == 0 {
                dash()
            } else {
                format!("{:04X}h", a.error_code)
            },
            detail
        );
    }
    for a in s.axes.iter() {
        if let Some(alarm) = &a.alarm {
            out += &format!("alarm   {}: {alarm}\n", a.name);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_value_pairs() {
        let p = pairs("move", &["x=100".into(), "y = -2.5".into()]).unwrap();
        assert_eq!(p["x"], 100.0);
        assert_eq!(p["y"], -2.5);
        let e = pairs("move", &["x100".into()]).unwrap_err();
        assert!(matches!(e, RequestArgsError::NotAPair { .. }), "{e:?}");
        assert_eq!(e.to_string(), "move: 'x100' is not AXIS=VALUE");
        let e = pairs("move", &["x=abc".into()]).unwrap_err();
        assert!(matches!(e, RequestArgsError::NotANumber { .. }), "{e:?}");
        assert!(e.to_string().contains("'abc' is not a number"));
        let e = pairs("move", &["x=inf".into()]).unwrap_err();
        assert!(matches!(e, RequestArgsError::NotFinite { .. }), "{e:?}");
        assert!(e.to_string().contains("not a finite number"));
        let e = pairs("move", &["x=1".into(), "x=2".into()]).unwrap_err();
        assert!(matches!(e, RequestArgsError::AxisTwice { .. }), "{e:?}");
        assert!(e.to_string().contains("given twice"));
    }
}
