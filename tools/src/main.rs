//! `cellrt`: the cell controller and its tools.

mod cli;
mod commands;
mod exit;
mod logging;
mod numbers;
mod summary;

use clap::Parser;

fn main() {
    logging::init();
    let cli = cli::Cli::parse();
    let code = match cli.command {
        cli::Command::Run(args) => commands::run::run(args),
        cli::Command::Planner(args) => commands::planner::run(args),
        cli::Command::Inspect(args) => commands::inspect::run(args),
        cli::Command::Recover(args) => commands::recover::run(args),
        cli::Command::Report(args) => commands::report::run(args),
        cli::Command::Replay(args) => commands::replay::run(args),
        cli::Command::DriveSim(args) => commands::drive_sim::run(args, cli.target.cell.clone()),
        cli::Command::Bus(args) => commands::bus::run(args, cli.target),
        cli::Command::JeC(args) => commands::je_c::run(args),
        cli::Command::Esi(args) => commands::esi::run(args),
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
