//! `cellrt completions` and `cellrt man`: the shell completions and man pages, generated from
//! the same command-line definition the binary parses (`clap_complete`, `clap_mangen`).

use std::io::{ErrorKind, Write};
use std::path::Path;

use clap::CommandFactory;

use crate::cli::Cli;
use crate::exit::Exit;

/// Writes `shell`'s completion script for every command and option to stdout.
pub fn completions(shell: clap_complete::Shell) -> Exit {
    // Into memory first: the generator panics on a failed write (a closed pipe).
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "cellrt", &mut script);
    to_stdout(&script, "the completion script")
}

/// Writes the man page to stdout, or every command's page into `out`.
pub fn man(out: Option<&Path>) -> Exit {
    let Some(dir) = out else {
        let mut page = Vec::new();
        if let Err(e) = clap_mangen::Man::new(Cli::command()).render(&mut page) {
            eprintln!("error: cannot render the man page: {e}");
            return Exit::Failed;
        }
        return to_stdout(&page, "the man page");
    };
    match std::fs::create_dir_all(dir).and_then(|()| clap_mangen::generate_to(Cli::command(), dir))
    {
        Ok(()) => Exit::Ok,
        Err(e) => {
            eprintln!(
                "error: cannot write the man pages to {}: {e}",
                dir.display()
            );
            Exit::Failed
        }
    }
}

/// Writes `bytes` to stdout; a reader that closed the pipe early (`| head`) is not an error.
fn to_stdout(bytes: &[u8], what: &str) -> Exit {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Ok(()) => Exit::Ok,
        Err(e) if e.kind() == ErrorKind::BrokenPipe => Exit::Ok,
        Err(e) => {
            eprintln!("error: cannot write {what}: {e}");
            Exit::Failed
        }
    }
}
