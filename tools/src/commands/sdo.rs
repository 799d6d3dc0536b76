//! `cellrt sdo read|write AXIS INDEX[:SUB] [VALUE]`: one object of an axis' drive on a running
//! cell, through the cell's operator service, which checks it against the drive's object
//! dictionary before the RT thread's acyclic channel carries it. `cellrt sdo list AXIS`: that
//! dictionary, read from the drive by SDO Information where it offers it.

use std::time::Duration;

use cellrt_fieldbus::mr_je_c::ObjectId;
use cellrt_runtime::host::operator::client::OperatorClient;
use cellrt_runtime::host::operator::sdo::object_text;
use cellrt_runtime::host::operator::sdo_list::SdoListReply;
use cellrt_runtime::host::operator::wire::{Reply, Request, SdoAnswer, SdoReply};
use clap::{Args, Subcommand};

use super::operate::Target;
use crate::exit::Exit;

/// `cellrt sdo`.
#[derive(Debug, Args)]
pub struct SdoArgs {
    /// Read or write.
    #[command(subcommand)]
    pub command: SdoCommand,
    /// Print the cell's reply as JSON.
    #[arg(long, global = true)]
    pub json: bool,
}

/// `cellrt sdo` subcommands.
#[derive(Debug, Subcommand)]
pub enum SdoCommand {
    /// Read one object: its value, typed by the drive's dictionary, in decimal and hex.
    Read {
        /// Axis name.
        axis: String,
        /// The object: index in hex with an optional decimal sub-index, e.g. 6041 or 1C32:2.
        object: ObjectId,
    },
    /// Write one object (value in decimal, or hex as 0x1EA5 / 1EA5h).
    Write {
        /// Axis name.
        axis: String,
        /// The object: index in hex with an optional decimal sub-index, e.g. 6085 or 1C32:2.
        object: ObjectId,
        /// The value.
        #[arg(allow_hyphen_values = true, value_parser = crate::numbers::integer)]
        value: i64,
    },
    /// List the drive's object dictionary: from the drive by SDO Information where it offers
    /// it, else the drive profile's own table (the first line says which).
    List {
        /// Axis name.
        axis: String,
    },
}

/// Runs `cellrt sdo`.
pub fn run(args: SdoArgs, target: Target) -> Exit {
    let (axis, object, value) = match args.command {
        SdoCommand::List { axis } => return list(axis, &target, args.json),
        SdoCommand::Read { axis, object } => (axis, object, None),
        SdoCommand::Write {
            axis,
            object,
            value,
        } => (axis, object, Some(value)),
    };
    let request = Request::Sdo {
        axis,
        index: object.index,
        sub: object.sub,
        value,
    };
    match ask(&target, &request, args.json) {
        Ok(Reply::Sdo(r)) => answered(&r, args.json),
        Ok(other) => unexpected("sdo", &other),
        Err(exit) => exit,
    }
}

/// Asks for `axis`' dictionary and prints it as a table (unless `json`).
fn list(axis: String, target: &Target, json: bool) -> Exit {
    match ask(target, &Request::SdoList { axis }, json) {
        Ok(Reply::SdoList(r)) => {
            if !json {
                print!("{}", list_table(&r));
            }
            Exit::Ok
        }
        Ok(other) => unexpected("sdo list", &other),
        Err(exit) => exit,
    }
}

/// The listing: a line saying where it came from, then one row per entry.
fn list_table(r: &SdoListReply) -> String {
    use std::fmt::Write;
    let mut out = match &r.fallback {
        None => format!(
            "{}: {} entries from the drive's SDO Information\n",
            r.axis,
            r.entries.len()
        ),
        Some(why) => format!(
            "{}: {} entries from the profile's dictionary ({}), not the drive: {why}\n",
            r.axis,
            r.entries.len(),
            r.dictionary
        ),
    };
    let name_width = r
        .entries
        .iter()
        .map(|e| e.name.len())
        .max()
        .unwrap_or(0)
        .max(4);
    let _ = writeln!(
        out,
        "{:<9}  {:<name_width$}  {:<14}  {:>4}  {:<16}  PDO",
        "OBJECT", "NAME", "TYPE", "BITS", "ACCESS"
    );
    for e in &r.entries {
        let bits = e.bits.map_or_else(|| "-".to_string(), |b| b.to_string());
        let access = match &e.write_restriction {
            Some(states) => format!("{} ({states})", e.access),
            None => e.access.to_string(),
        };
        let _ = writeln!(
            out,
            "{:<9}  {:<name_width$}  {:<14}  {:>4}  {:<16}  {}",
            object_text(e.index, e.sub),
            e.name,
            e.data_type,
            bits,
            access,
            e.pdo.as_str()
        );
    }
    out
}

/// The least a client waits for the reply to a request of many SDO transfers (`param list`,
/// `alarms`: one transfer after the other through the mailbox, each bounded by the cell's
/// own 3 s answer timeout); `--reply-timeout` counts where it is longer.
const MANY_TRANSFERS_REPLY_TIMEOUT: Duration = Duration::from_secs(30);

/// Sends `request` to the target cell and returns the reply (printed as JSON first when
/// `json`); a rejection is printed (unless `json`) and becomes its exit, as does no answer.
pub(crate) fn ask(target: &Target, request: &Request, json: bool) -> Result<Reply, Exit> {
    let client = OperatorClient::connect(target.cell.as_deref()).map_err(|e| {
        eprintln!("error: {e}");
        Exit::Unreachable
    })?;
    let timeout = match request {
        Request::Sdo { .. } => Duration::from_secs_f64(target.reply_timeout),
        _ => Duration::from_secs_f64(target.reply_timeout).max(MANY_TRANSFERS_REPLY_TIMEOUT),
    };
    let reply = client.request(request, timeout).map_err(|e| {
        eprintln!("error: {e}");
        Exit::Unreachable
    })?;
    if json {
        println!("{}", serde_json::to_string(&reply).unwrap_or_default());
    }
    match reply {
        Reply::Rejected { reason } => {
            if !json {
                eprintln!("rejected: {reason}");
            }
            Err(Exit::Rejected)
        }
        r => Ok(r),
    }
}

/// A reply of another kind than `what` asked for.
pub(crate) fn unexpected(what: &str, reply: &Reply) -> Exit {
    eprintln!("error: unexpected reply to {what}: {reply:?}");
    Exit::Unreachable
}

/// Prints the drive's answer (unless `json`); an abort is a rejection.
fn answered(r: &SdoReply, json: bool) -> Exit {
    let what = format!(
        "{} {} {} ({})",
        r.axis,
        object_text(r.index, r.sub),
        r.name,
        r.data_type
    );
    let (line, exit) = match &r.outcome {
        SdoAnswer::Read { value } => (
            format!("{what} = {value} ({})", hex(*value, r.bits)),
            Exit::Ok,
        ),
        SdoAnswer::Written { value } => (
            format!("{what} written: {value} ({})", hex(*value, r.bits)),
            Exit::Ok,
        ),
        SdoAnswer::Aborted { code, meaning } => (
            format!("refused by the drive: {what}: abort code 0x{code:08X} ({meaning})"),
            Exit::Rejected,
        ),
    };
    if !json {
        match exit {
            Exit::Ok => println!("{line}"),
            _ => eprintln!("{line}"),
        }
    }
    exit
}

/// `value` in hex as the object's `bits` hold it (two's complement for a negative value).
fn hex(value: i64, bits: u16) -> String {
    match bits {
        1..=63 => {
            let digits = usize::from(bits.div_ceil(4));
            format!("0x{:0digits$X}", value as u64 & ((1u64 << bits) - 1))
        }
        _ => format!("0x{:X}", value as u64),
    }
}

#[cfg(test)]
mod tests {
    use super::hex;

    #[test]
    fn hex_shows_the_object_width_in_twos_complement() {
        assert_eq!(hex(0x1237, 16), "0x1237");
        assert_eq!(hex(-1, 8), "0xFF");
        assert_eq!(hex(-100, 32), "0xFFFFFF9C");
        assert_eq!(hex(250, 32), "0x000000FA");
        assert_eq!(hex(1, 1), "0x1");
    }
}
