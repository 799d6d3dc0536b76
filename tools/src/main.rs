//! `cellrt`: the cell controller and its tools.

mod cli;
mod commands;
mod exit;
mod logging;
mod numbers;
mod summary;

use cellrt_config::echo::{Echo, MAX_ECHO_CHARS};
use clap::Parser;

fn main() {
    logging::init();
    let cli = cli::Cli::try_parse().unwrap_or_else(|e| refuse_arguments(&e));
    if cli.command.only_prints() {
        quiet_on_closed_stdout();
    }
    let code = match cli.command {
        cli::Command::Run(args) => commands::run::run(args),
        cli::Command::Planner(args) => commands::planner::run(args),
        cli::Command::Inspect(args) => commands::inspect::run(args),
        cli::Command::Recover(args) => commands::recover::run(args),
        cli::Command::Report(args) => commands::report::run(args),
        cli::Command::Replay(args) => commands::replay::run(args),
        cli::Command::DriveSim(args) => commands::drive_sim::run(args),
        cli::Command::Bus(args) => commands::bus::run(args, cli.target),
        cli::Command::JeC(args) => commands::je_c::run(args),
        cli::Command::Esi(args) => commands::esi::run(args, cli.target),
        cli::Command::Bench(args) => commands::bench::run(args, cli.target.cell.clone()),
        cli::Command::Sdo(args) => commands::sdo::run(args, cli.target),
        cli::Command::Param(args) => commands::param::run(args, cli.target),
        cli::Command::Alarms(args) => commands::param::run_alarms(args, cli.target),
        cli::Command::Completions { shell } => commands::docs::completions(shell),
        cli::Command::Man { out } => commands::docs::man(out.as_deref()),
        cli::Command::Operate(c) => commands::operate::run(c, cli.target),
    };
    std::process::exit(code.code());
}

/// A command whose output goes to a pipe closed early (`cellrt inspect FILE | head`) ends
/// quietly, as Unix tools do, instead of panicking on the failed write: SIGPIPE's default
/// action. Only for commands that print and exit; a controller must outlive a closed socket.
fn quiet_on_closed_stdout() {
    use nix::sys::signal::{signal, SigHandler, Signal};
    // SAFETY: restoring a signal's default disposition; no handler runs.
    let _ = unsafe { signal(Signal::SIGPIPE, SigHandler::SigDfl) };
}

/// Ends the process on clap's refusal of the command line (or its help): as clap would, except
/// that an argument it repeats is shown as [`Echo`] does when long.
fn refuse_arguments(e: &clap::Error) -> ! {
    // Each long argument as typed, and the value of a long `--name=value`.
    let long: Vec<String> = std::env::args()
        .flat_map(|a| {
            let value = a.split_once('=').map(|(_, v)| v.to_string());
            std::iter::once(a).chain(value)
        })
        .filter(|a| a.chars().count() > MAX_ECHO_CHARS)
        .collect();
    if long.is_empty() {
        e.exit();
    }
    let mut text = e.render().to_string();
    for a in &long {
        text = text.replace(a.as_str(), &Echo(a).to_string());
    }
    eprint!("{text}");
    std::process::exit(e.exit_code());
}
