//! `cellrt param list|get|set|save|diff AXIS …` and `cellrt alarms AXIS [--clear]`: an axis'
//! servo parameters by their manual names and its alarm history, on a running cell; the cell
//! checks each request against the model's parameter table before anything is sent.

use cellrt_runtime::host::operator::wire::{
    AlarmsReply, ParamOp, ParamReply, ParamValue, Reply, Request,
};
use clap::{Args, Subcommand};

use super::operate::Target;
use super::sdo::{ask, unexpected};
use crate::exit::Exit;

/// `cellrt param`.
#[derive(Debug, Args)]
pub struct ParamArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: ParamCommand,
    /// Print the cell's reply as JSON.
    #[arg(long, global = true)]
    pub json: bool,
}

/// `cellrt param` subcommands.
#[derive(Debug, Subcommand)]
pub enum ParamCommand {
    /// Every parameter of the model's table with its value, initial value and range.
    List {
        /// Axis name.
        axis: String,
    },
    /// One parameter, by its manual name (e.g. PA14).
    Get {
        /// Axis name.
        axis: String,
        /// Parameter name.
        name: String,
    },
    /// Write one parameter (value in decimal, or hex as 0x000E / 000Eh), range-checked first.
    Set {
        /// Axis name.
        axis: String,
        /// Parameter name.
        name: String,
        /// The value.
        #[arg(allow_hyphen_values = true, value_parser = crate::numbers::integer)]
        value: i64,
    },
    /// Store every parameter in the drive's non-volatile memory (1010h).
    Save {
        /// Axis name.
        axis: String,
    },
    /// The parameters whose value differs from the model's initial value.
    Diff {
        /// Axis name.
        axis: String,
    },
}

/// `cellrt alarms`.
#[derive(Debug, Args)]
pub struct AlarmsArgs {
    /// Axis name.
    pub axis: String,
    /// Clear the history instead of reading it.
    #[arg(long)]
    pub clear: bool,
    /// Print the cell's reply as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `cellrt param`.
pub fn run(args: ParamArgs, target: Target) -> Exit {
    let (axis, op) = match args.command {
        ParamCommand::List { axis } => (axis, ParamOp::List),
        ParamCommand::Get { axis, name } => (axis, ParamOp::Get { name }),
        ParamCommand::Set { axis, name, value } => (axis, ParamOp::Set { name, value }),
        ParamCommand::Save { axis } => (axis, ParamOp::Save),
        ParamCommand::Diff { axis } => (axis, ParamOp::Diff),
    };
    let diff = op == ParamOp::Diff;
    let set = matches!(op, ParamOp::Set { .. });
    match ask(&target, &Request::Param { axis, op }, args.json) {
        Ok(Reply::Param(r)) => {
            if !args.json {
                print!("{}", render(&r, diff, set));
            }
            Exit::Ok
        }
        Ok(other) => unexpected("param", &other),
        Err(exit) => exit,
    }
}

/// Runs `cellrt alarms`.
pub fn run_alarms(args: AlarmsArgs, target: Target) -> Exit {
    let request = Request::Alarms {
        axis: args.axis,
        clear: args.clear,
    };
    match ask(&target, &request, args.json) {
        Ok(Reply::Alarms(r)) => {
            if !args.json {
                print!("{}", render_alarms(&r));
            }
            Exit::Ok
        }
        Ok(other) => unexpected("alarms", &other),
        Err(exit) => exit,
    }
}

/// The reply as printed: a table for list/diff, one line for get/set, the note after.
fn render(r: &ParamReply, diff: bool, set: bool) -> String {
    let mut out = String::new();
    match (r.parameters.as_slice(), diff, set) {
        ([p], false, true) => out += &format!("{} {} written: {}\n", r.axis, p.name, p.shown),
        ([p], false, false) => out += &format!("{} {}\n", r.axis, line(p)),
        ([], true, _) => out += &format!("{}: every parameter at its initial value\n", r.axis),
        (ps, _, _) => {
            for p in ps {
                out += &format!("{}\n", line(p));
            }
        }
    }
    if let Some(n) = &r.note {
        out += &format!("{}: {n}\n", r.axis);
    }
    out
}

/// One parameter: "PA14 *POL = 1 (initial 0; 0..1; after power cycle) 2300h:0E Rotation …".
fn line(p: &ParamValue) -> String {
    let units = if p.units.is_empty() {
        String::new()
    } else {
        format!(" {}", p.units)
    };
    format!(
        "{:<5} {:<6} = {:<10} (initial {}; {}{units}; {}) {} {}",
        p.name, p.symbol, p.shown, p.default, p.setting, p.effect, p.object, p.title
    )
}

fn render_alarms(r: &AlarmsReply) -> String {
    if r.cleared {
        return format!("{}: alarm history cleared\n", r.axis);
    }
    if r.entries.is_empty() {
        return format!("{}: alarm history empty\n", r.axis);
    }
    let mut out = format!("{} alarm history ({}, newest first):\n", r.axis, r.model);
    for e in &r.entries {
        out += &format!(
            "{}  {} ({:04X}h) at {} h, detail {}\n",
            e.entry, e.name, e.number, e.hours, e.detail
        );
        if let Some(c) = &e.cause {
            out += &format!("   cause: {c}\n");
        }
        if let Some(r) = &e.remedy {
            out += &format!("   remedy: {r}\n");
        }
    }
    out
}
