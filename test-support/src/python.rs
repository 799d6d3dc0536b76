//! The Python with pymodbus the independent-implementation tests run, and their scripts (`CELLRT_PYTHON`, as CI
//! sets up; `python3` otherwise).

use std::process::Command;

/// The Python to run, if it has pymodbus; without one a test skips, saying so, except under
/// CI, where it fails.
pub fn pymodbus(test: &str) -> Option<String> {
    let python = std::env::var("CELLRT_PYTHON").unwrap_or_else(|_| "python3".into());
    let ok = Command::new(&python)
        .args(["-c", "import pymodbus"])
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        return Some(python);
    }
    if std::env::var_os("CI").is_some() {
        panic!("CI must run {test} (CELLRT_PYTHON with pymodbus)");
    }
    eprintln!(
        "SKIPPED {test}: no Python with pymodbus (pip install pymodbus, or set CELLRT_PYTHON)"
    );
    None
}

/// The path of one of the Python scripts in `test-support/python/`.
pub fn script(name: &str) -> String {
    format!("{}/python/{name}", env!("CARGO_MANIFEST_DIR"))
}
