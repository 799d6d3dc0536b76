//! Where the log goes: the journal with its fields (priority, cell, axis, event, cycle) when
//! systemd connected stderr to it, else plain lines on stderr, coloured only on a terminal.

use std::io::IsTerminal;
use std::os::unix::fs::MetadataExt;

use tracing_subscriber::layer::SubscriberExt;
use tracing_subscriber::util::SubscriberInitExt;
use tracing_subscriber::EnvFilter;

/// The fields cellrt's own events carry for the journal, which their message also says.
const JOURNAL_FIELDS: [&str; 4] = ["cell", "axis", "event", "cycle"];

/// The level filter: `$CELLRT_LOG` (tracing's `EnvFilter` syntax), `info` by default.
fn filter() -> EnvFilter {
    EnvFilter::try_from_env("CELLRT_LOG").unwrap_or_else(|_| EnvFilter::new("info"))
}

/// Installs the process' subscriber.
pub fn init() {
    if stderr_is_the_journal() {
        if let Ok(journal) = tracing_journald::layer() {
            tracing_subscriber::registry()
                .with(filter())
                .with(
                    journal
                        .with_field_prefix(None)
                        .with_syslog_identifier("cellrt".into()),
                )
                .init();
            return;
        }
    }
    // On stderr the journal fields cellrt adds stay out of the line (its message already says
    // them in words); any other field (a dependency's) is shown as `name=value`.
    let fields = tracing_subscriber::fmt::format::debug_fn(|w, field, value| match field.name() {
        "message" => write!(w, "{value:?}"),
        name if JOURNAL_FIELDS.contains(&name) => Ok(()),
        name => write!(w, " {name}={value:?}"),
    });
    tracing_subscriber::fmt()
        .with_writer(std::io::stderr)
        .with_target(false)
        .with_ansi(std::io::stderr().is_terminal())
        .fmt_fields(fields)
        .with_env_filter(filter())
        .init();
}

/// Whether stderr is the journal's stream: `$JOURNAL_STREAM` names its device and inode
/// (`systemd.exec(5)`), so a redirected stderr of a service is not mistaken for it.
fn stderr_is_the_journal() -> bool {
    let Some(stream) = std::env::var_os("JOURNAL_STREAM") else {
        return false;
    };
    let Ok(meta) = std::fs::metadata("/proc/self/fd/2") else {
        return false;
    };
    stream.to_str() == Some(format!("{}:{}", meta.dev(), meta.ino()).as_str())
}
