//! `cellrt planner`: runs a program (or serves the operator) in a process of its own against a
//! running controller.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use cellrt_config::CellConfig;
use cellrt_runtime::host::planner;
use cellrt_runtime::host::program::Program;

use crate::cli::PlannerArgs;
use crate::exit::Exit;

/// Runs `cellrt planner`.
pub fn run(args: PlannerArgs) -> Exit {
    let bad = |e: &dyn std::fmt::Display| {
        eprintln!("error: {e}");
        Exit::BadInput
    };
    let cell = match CellConfig::load(&args.config) {
        Ok(c) => c,
        Err(e) => return bad(&e),
    };
    let program = if args.no_program {
        None
    } else {
        let Some(path) = args.program.clone().or_else(|| cell.program.clone()) else {
            return bad(&format!(
                "{}: cell.program: no program named; pass --program FILE (or --no-program)",
                args.config.display()
            ));
        };
        match Program::load(&path, &cell) {
            Ok(p) => Some(p),
            Err(e) => return bad(&e),
        }
    };
    if !(args.connect_timeout.is_finite() && args.connect_timeout > 0.0) {
        return bad(&format!(
            "--connect-timeout: must be a positive number of seconds (got {})",
            args.connect_timeout
        ));
    }
    let abort = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if let Err(e) = signal_hook::flag::register(sig, abort.clone()) {
            eprintln!("error: cannot install the signal handler: {e}");
            return Exit::Failed;
        }
    }
    match &program {
        Some(p) => eprintln!(
            "cellrt planner: cell '{}', program {}",
            cell.name,
            p.source.display()
        ),
        None => eprintln!(
            "cellrt planner: cell '{}', no program: serving the operator until SIGINT/SIGTERM",
            cell.name
        ),
    }
    match planner::run_external(
        &cell,
        program.as_ref(),
        &abort,
        Duration::from_secs_f64(args.connect_timeout),
    ) {
        Ok(()) if program.is_none() => {
            eprintln!("cellrt planner: stopped");
            Exit::Ok
        }
        Ok(()) => {
            eprintln!("cellrt planner: program ended");
            Exit::Ok
        }
        Err(e) if program.is_none() => {
            eprintln!("error: {}", e.reason);
            Exit::Failed
        }
        Err(e) => {
            eprintln!("error: {e}");
            Exit::Failed
        }
    }
}
