//! Bad input to `cellrt run`: every case must fail before the cell starts, with exit code 2 and
//! exactly one `error: ` line on stderr that names the file, the key and what is wrong.
//!
//! Each case writes a copy of `configs/demo.toml` (and its program) into a fresh temp dir,
//! breaks one thing, and runs the binary there with `--no-record`.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::host::program::Program;

const DEMO_CONFIG_FILE: &str = include_str!("../../configs/demo.toml");
const DEMO_PROGRAM: &str = include_str!("../../configs/demo-program.toml");
const DEMO_PROGRAM_LINE: &str = "program = \"demo-program.toml\"";

/// The demo config without `rt.cpu` (validation rejects a CPU the machine lacks, so pinning
/// would make these tests depend on the host).
fn demo_config() -> String {
    replace_once(DEMO_CONFIG_FILE, "\ncpu = 1 ", "\n# cpu = 1 ")
}

/// Longest a rejected run may take; a run that got past validation would start the cell and,
/// with `--no-program`, never end on its own.
const TIMEOUT: Duration = Duration::from_secs(30);

/// A temp dir holding the config and program of one case; the binary runs with it as cwd.
struct Case {
    dir: tempfile::TempDir,
    /// Where stdout/stderr are captured (outside `dir`, so `dir` only holds what we wrote).
    out: tempfile::TempDir,
    written: Vec<PathBuf>,
}

/// What one run produced.
struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

impl Case {
    fn new() -> Case {
        Case {
            dir: tempfile::tempdir().expect("temp dir"),
            out: tempfile::tempdir().expect("temp dir"),
            written: Vec::new(),
        }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn write(&mut self, name: &str, text: &str) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, text).expect("write case file");
        self.written.push(p.clone());
        p
    }

    /// Writes `cell.toml` (the demo config with `program` pointing at `program.toml` in the
    /// temp dir) and `program.toml`.
    fn with(config: &str, program: &str) -> (Case, PathBuf, PathBuf) {
        let mut c = Case::new();
        let program_path = c.write("program.toml", program);
        let config = replace_once(
            config,
            DEMO_PROGRAM_LINE,
            &format!("program = {:?}", program_path.display().to_string()),
        );
        let config_path = c.write("cell.toml", &config);
        (c, config_path, program_path)
    }

    /// Runs `cellrt run <args> --no-record` in the temp dir.
    fn run(&self, args: &[&str]) -> Run {
        let stdout_path = self.out.path().join("stdout");
        let stderr_path = self.out.path().join("stderr");
        let mut child = Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .arg("run")
            .args(args)
            .arg("--no-record")
            .current_dir(self.dir.path())
            .env_remove("CELLRT_LOG")
            .env("NO_COLOR", "1")
            .stdin(Stdio::null())
            .stdout(File::create(&stdout_path).expect("stdout file"))
            .stderr(File::create(&stderr_path).expect("stderr file"))
            .spawn()
            .expect("spawn cellrt");
        let start = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().expect("wait for cellrt") {
                break s;
            }
            if start.elapsed() > TIMEOUT {
                let _ = child.kill();
                let _ = child.wait();
                panic!(
                    "cellrt {args:?} still running after {TIMEOUT:?}: the cell started\nstderr:\n{}",
                    std::fs::read_to_string(&stderr_path).unwrap_or_default()
                );
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        let run = Run {
            code: status.code(),
            stdout: std::fs::read_to_string(&stdout_path).expect("read stdout"),
            stderr: std::fs::read_to_string(&stderr_path).expect("read stderr"),
        };
        self.assert_nothing_written(&run);
        run
    }

    /// The temp dir holds exactly the files the case wrote: no recording, no summary.
    fn assert_nothing_written(&self, run: &Run) {
        let mut found: Vec<PathBuf> = std::fs::read_dir(self.dir.path())
            .expect("read temp dir")
            .map(|e| e.expect("dir entry").path())
            .collect();
        found.sort();
        let mut expected = self.written.clone();
        expected.sort();
        assert_eq!(
            found, expected,
            "cellrt wrote into its working dir\nstderr:\n{}",
            run.stderr
        );
    }
}

/// `text` with the one occurrence of `from` replaced by `to`.
fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(
        text.matches(from).count(),
        1,
        "fixture: expected exactly one {from:?} in the demo config/program"
    );
    text.replacen(from, to, 1)
}

/// Removes ANSI escape sequences (`ESC [ ... letter`).
fn strip_ansi(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c == '\u{1b}' {
            if chars.next() == Some('[') {
                for c in chars.by_ref() {
                    if c.is_ascii_alphabetic() {
                        break;
                    }
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// A line written by the tracing subscriber: `<RFC 3339 timestamp> <LEVEL> ...`.
fn is_log_line(line: &str) -> bool {
    let mut words = line.split_whitespace();
    let (Some(ts), Some(level)) = (words.next(), words.next()) else {
        return false;
    };
    ts.len() >= 20
        && ts.as_bytes()[..4].iter().all(u8::is_ascii_digit)
        && ts.contains('T')
        && matches!(level, "TRACE" | "DEBUG" | "INFO" | "WARN" | "ERROR")
}

impl Run {
    /// Checks exit code 2, that the cell never started, and that stderr has exactly one
    /// non-log line, starting `error: `; returns that line.
    fn error_line(&self) -> String {
        let stderr = strip_ansi(&self.stderr);
        assert_eq!(
            self.code,
            Some(2),
            "expected exit code 2\nstderr:\n{stderr}"
        );
        assert!(
            !stderr.contains("panicked"),
            "cellrt panicked\nstderr:\n{stderr}"
        );
        assert!(
            !stderr.contains("cellrt: cell '"),
            "the cell started\nstderr:\n{stderr}"
        );
        assert!(
            self.stdout.is_empty(),
            "expected nothing on stdout (no summary)\nstdout:\n{}",
            self.stdout
        );
        let lines: Vec<&str> = stderr
            .lines()
            .filter(|l| !l.trim().is_empty() && !is_log_line(l))
            .collect();
        assert_eq!(
            lines.len(),
            1,
            "expected exactly one non-log line on stderr\nstderr:\n{stderr}"
        );
        let line = lines[0];
        assert!(
            line.starts_with("error: "),
            "the line must start with `error: `: {line}"
        );
        line.to_string()
    }

    /// [`Run::error_line`], then checks the line names `file`, `key` and each of `words`.
    fn expect_error(&self, file: &Path, key: &str, words: &[&str]) -> String {
        let line = self.error_line();
        let file = file.display().to_string();
        assert!(line.contains(&file), "line does not name {file}: {line}");
        assert!(line.contains(key), "line does not name key {key}: {line}");
        for w in words {
            assert!(line.contains(w), "line does not say {w:?}: {line}");
        }
        line
    }
}

/// Runs the demo config with `edit` applied to the config text, and the demo program.
fn run_config_edit(edit: impl FnOnce(&str) -> String) -> (Run, PathBuf) {
    let (case, config, _) = Case::with(&edit(&demo_config()), DEMO_PROGRAM);
    (case.run(&[config.to_str().unwrap()]), config)
}

/// Runs the demo config with `program` as its program.
fn run_program(program: &str) -> (Run, PathBuf) {
    let (case, config, program) = Case::with(&demo_config(), program);
    (case.run(&[config.to_str().unwrap()]), program)
}

/// `limits = { ... }` line of axis `y` (index 1) in the demo config.
const Y_LIMITS: &str =
    "limits = { position = [0.0, 600.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }";

/// Runs the demo config with `field = value` in the limits of axis `y` (index 1).
fn run_y_limit(field: &str, value: &str) -> (Run, PathBuf) {
    let default = match field {
        "velocity" => "400.0",
        "acceleration" => "2000.0",
        "jerk" => "20000.0",
        _ => unreachable!(),
    };
    run_config_edit(|t| {
        let bad = Y_LIMITS.replace(
            &format!("{field} = {default}"),
            &format!("{field} = {value}"),
        );
        assert_ne!(bad, Y_LIMITS);
        replace_once(t, Y_LIMITS, &bad)
    })
}

/// Line number (1-based) of the first line of the file at `path` equal to `line` (trimmed).
fn line_of(path: &Path, line: &str) -> usize {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .position(|l| l.trim() == line)
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("{line:?} not in {}", path.display()))
}

// --- The fixture itself is valid: each case fails only because of its one edit. ---

#[test]
fn fixture_is_valid() {
    let (case, config, program) = Case::with(&demo_config(), DEMO_PROGRAM);
    let cell = CellConfig::load(&config).expect("fixture config is valid");
    assert_eq!(cell.program.as_deref(), Some(program.as_path()));
    Program::load(&program, &cell).expect("fixture program is valid");
    drop(case);
}

// --- 1. Unknown keys. ---

#[test]
fn unknown_key_in_cell() {
    let (case, config, _) = Case::with(
        &replace_once(
            &demo_config(),
            "name = \"demo\"",
            "name = \"demo\"\ncolour = \"red\"",
        ),
        DEMO_PROGRAM,
    );
    let run = case.run(&[config.to_str().unwrap()]);
    let line = run.expect_error(&config, "cell.colour", &["unknown field"]);
    let n = line_of(&config, "colour = \"red\"");
    assert!(
        line.contains(&format!(":{n}: ")),
        "line {n} not shown: {line}"
    );
}

#[test]
fn unknown_key_in_axis() {
    let (case, config, _) = Case::with(
        &replace_once(&demo_config(), "name = \"y\"", "name = \"y\"\nbrake = true"),
        DEMO_PROGRAM,
    );
    let run = case.run(&[config.to_str().unwrap()]);
    let line = run.expect_error(&config, "axes[1].brake", &["unknown field"]);
    let n = line_of(&config, "brake = true");
    assert!(
        line.contains(&format!(":{n}: ")),
        "line {n} not shown: {line}"
    );
}

// --- 2. Wrong types. ---

#[test]
fn wrong_type_cycle_time() {
    let (run, config) =
        run_config_edit(|t| replace_once(t, "cycle_time_us = 1000", "cycle_time_us = \"fast\""));
    run.expect_error(&config, "cell.cycle_time_us", &["invalid type", "\"fast\""]);
}

#[test]
fn wrong_type_velocity_limit() {
    let (run, config) = run_y_limit("velocity", "\"x\"");
    run.expect_error(
        &config,
        "axes[1].limits.velocity",
        &["invalid type", "\"x\""],
    );
}

// --- 3. Disallowed cycle time. ---

#[test]
fn disallowed_cycle_time_lists_allowed_ones() {
    let (run, config) =
        run_config_edit(|t| replace_once(t, "cycle_time_us = 1000", "cycle_time_us = 300"));
    run.expect_error(
        &config,
        "cell.cycle_time_us",
        &[
            "300",
            "not supported",
            "125, 250, 500, 1000, 2000, 4000, 8000",
        ],
    );
}

// --- 4. Kinematic limits <= 0 and NaN. ---

#[test]
fn velocity_limit_zero() {
    let (run, config) = run_y_limit("velocity", "0.0");
    run.expect_error(&config, "axes[1].limits.velocity", &["> 0", "got 0"]);
}

#[test]
fn velocity_limit_nan() {
    let (run, config) = run_y_limit("velocity", "nan");
    run.expect_error(&config, "axes[1].limits.velocity", &["finite", "NaN"]);
}

#[test]
fn acceleration_limit_negative() {
    let (run, config) = run_y_limit("acceleration", "-2000.0");
    run.expect_error(
        &config,
        "axes[1].limits.acceleration",
        &["> 0", "got -2000"],
    );
}

#[test]
fn acceleration_limit_nan() {
    let (run, config) = run_y_limit("acceleration", "nan");
    run.expect_error(&config, "axes[1].limits.acceleration", &["finite", "NaN"]);
}

#[test]
fn jerk_limit_zero() {
    let (run, config) = run_y_limit("jerk", "0.0");
    run.expect_error(&config, "axes[1].limits.jerk", &["> 0", "got 0"]);
}

#[test]
fn jerk_limit_nan() {
    let (run, config) = run_y_limit("jerk", "-nan");
    run.expect_error(&config, "axes[1].limits.jerk", &["finite", "NaN"]);
}

#[test]
fn acceleration_and_jerk_beyond_one_cycle_are_refused() {
    let (run, config) = run_y_limit("acceleration", "1e18");
    run.expect_error(
        &config,
        "axes[1].limits.acceleration",
        &[
            "1000000000000000000 mm/s²",
            "less than one 1000 µs cycle",
            "at most 400000 mm/s²",
        ],
    );
    let (run, config) = run_y_limit("jerk", "1e18");
    run.expect_error(&config, "axes[1].limits.jerk", &["at most 2000000 mm/s³"]);
}

// --- 5. Duplicate axis names. ---

#[test]
fn duplicate_axis_name() {
    let (run, config) = run_config_edit(|t| replace_once(t, "name = \"z\"", "name = \"x\""));
    run.expect_error(&config, "axes[2].name", &["duplicate", "'x'"]);
}

// --- 6. Program names an axis the cell lacks. ---

#[test]
fn program_axis_not_in_cell() {
    let (run, program) = run_program(&replace_once(
        DEMO_PROGRAM,
        "target = { x = 400.0, y = 300.0, c = 90.0 }",
        "target = { x = 400.0, w = 300.0 }",
    ));
    run.expect_error(&program, "step[1].target.w", &["axis 'w'", "not in cell"]);
}

// --- 7. Target outside the position range. ---

#[test]
fn program_target_out_of_range() {
    let (run, program) = run_program(&replace_once(
        DEMO_PROGRAM,
        "target = { z = -150.0 }\nacceleration = 1000.0",
        "target = { z = -250.0 }\nacceleration = 1000.0",
    ));
    run.expect_error(
        &program,
        "step[6].target.z",
        &["-250", "outside the position range", "[-200, 0]"],
    );
}

// --- 8. Missing program file. ---

#[test]
fn missing_program_on_command_line() {
    let (case, config, _) = Case::with(&demo_config(), DEMO_PROGRAM);
    let run = case.run(&[config.to_str().unwrap(), "--program", "nope.toml"]);
    run.expect_error(Path::new("nope.toml"), "", &["not found"]);
}

#[test]
fn missing_program_named_by_config() {
    let mut case = Case::new();
    let config = case.write(
        "cell.toml",
        &replace_once(&demo_config(), DEMO_PROGRAM_LINE, "program = \"gone.toml\""),
    );
    let run = case.run(&[config.to_str().unwrap()]);
    // Resolved relative to the config file.
    run.expect_error(&case.path("gone.toml"), "", &["not found"]);
}

// --- Command line and whole-file problems. ---

#[test]
fn missing_config_file() {
    let case = Case::new();
    let missing = case.path("missing.toml");
    let run = case.run(&[missing.to_str().unwrap()]);
    run.expect_error(&missing, "", &["not found"]);
}

#[test]
fn invalid_toml_syntax_shows_line() {
    let (case, config, _) = Case::with(
        &replace_once(
            &demo_config(),
            "cycle_time_us = 1000",
            "cycle_time_us = = 1000",
        ),
        DEMO_PROGRAM,
    );
    let run = case.run(&[config.to_str().unwrap()]);
    let line = run.expect_error(&config, "", &["TOML syntax error"]);
    let n = line_of(&config, "cycle_time_us = = 1000");
    assert!(
        line.contains(&format!("{}:{n}: ", config.display())),
        "line {n} not shown: {line}"
    );
}

#[test]
fn negative_duration() {
    let (case, config, _) = Case::with(&demo_config(), DEMO_PROGRAM);
    let run = case.run(&[config.to_str().unwrap(), "--no-program", "--duration=-1"]);
    run.expect_error(Path::new(""), "--duration", &["got -1"]);
}

/// `--duration -1` (separate word): clap takes `-1` for a flag. Still bad input (exit 2) and the
/// cell must not start; clap's own message is several lines (usage, tip), so only its first
/// line is checked.
#[test]
fn negative_duration_separate_word() {
    let (case, config, _) = Case::with(&demo_config(), DEMO_PROGRAM);
    let run = case.run(&[config.to_str().unwrap(), "--no-program", "--duration", "-1"]);
    let stderr = strip_ansi(&run.stderr);
    assert_eq!(run.code, Some(2), "stderr:\n{stderr}");
    assert!(
        !stderr.contains("cellrt: cell '"),
        "the cell started\n{stderr}"
    );
    assert!(run.stdout.is_empty(), "stdout:\n{}", run.stdout);
    let first = stderr.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("error: ") && first.contains("-1"),
        "stderr:\n{stderr}"
    );
}

// --- Cyclic modes and torque (issue 3). ---

const C_LIMITS: &str =
    "limits = { position = [-360.0, 360.0], velocity = 180.0, acceleration = 720.0, jerk = 3600.0 }";

/// The demo config with axis `c`'s `unit = "deg"` line followed by `extra`, and its limits
/// line replaced by `limits`.
fn c_axis_edit(extra: &str, limits: &str) -> impl FnOnce(&str) -> String {
    let extra = extra.to_owned();
    let limits = limits.to_owned();
    move |t: &str| {
        let t = replace_once(t, "unit = \"deg\"", &format!("unit = \"deg\"\n{extra}"));
        replace_once(&t, C_LIMITS, &limits)
    }
}

#[test]
fn cst_without_a_torque_limit() {
    let (run, config) = run_config_edit(c_axis_edit("mode = \"cst\"", C_LIMITS));
    run.expect_error(
        &config,
        "axes[3].limits.torque",
        &["'c'", "cst", "limits.torque"],
    );
}

#[test]
fn torque_limit_out_of_range() {
    let bad = C_LIMITS.replace(" }", ", torque = 1500.0 }");
    let (run, config) = run_config_edit(c_axis_edit("mode = \"cst\"", &bad));
    run.expect_error(&config, "axes[3].limits.torque", &["1500", "0 < t ≤ 1000"]);
}

/// Homing is a procedure of an axis, not a mode it runs in: refused naming the modes there are.
#[test]
fn homing_as_an_axis_mode_is_refused() {
    let (run, config) = run_config_edit(c_axis_edit("mode = \"hm\"", C_LIMITS));
    run.expect_error(
        &config,
        "axes[3].mode",
        &[
            "'c'",
            "hm",
            "not an axis mode",
            "csp, csv, cst",
            "pp, pv, tq",
        ],
    );
}

#[test]
fn mode_the_model_lacks_is_refused() {
    let (run, config) = run_config_edit(|t| {
        let t = replace_once(
            t,
            "name = \"c\"\ndrive = \"mr-j5-g-n1\"",
            "name = \"c\"\ndrive = \"mr-j3-t04\"\nmode = \"cst\"",
        );
        replace_once(&t, C_LIMITS, &C_LIMITS.replace(" }", ", torque = 100.0 }"))
    });
    run.expect_error(
        &config,
        "axes[3].mode",
        &["'c'", "mr-j3-t04", "cst", "hm, csp, csv"],
    );
}

#[test]
fn torque_step_on_a_csp_axis() {
    let (run, program) = run_program(&format!(
        "{DEMO_PROGRAM}\n[[step]]\ndo = \"torque\"\ntarget = {{ c = 10.0 }}\nseconds = 0.1\n"
    ));
    let steps = DEMO_PROGRAM.matches("[[step]]").count();
    run.expect_error(
        &program,
        &format!("step[{steps}].target.c"),
        &["'c'", "runs in csp", "cst"],
    );
}

#[test]
fn csv_position_gain_negative() {
    let (run, config) = run_config_edit(c_axis_edit("csv_position_gain = -1.0", C_LIMITS));
    run.expect_error(&config, "axes[3].csv_position_gain", &["-1", "gain"]);
}

#[test]
fn a_wire_fault_on_sim_drives_is_refused() {
    let (run, config) = run_config_edit(|t| {
        format!("{t}\n[[inject]]\nat_ms = 100\nfault = \"link_loss\"\nduration_ms = 10\n")
    });
    run.expect_error(
        &config,
        "inject[0].fault",
        &["link_loss", "no EtherCAT axes"],
    );
}

/// Operator numbers are checked before anything is sent: NaN, infinities and out-of-range
/// values give exit 2 naming the argument (no cell needs to run).
#[test]
fn operator_numbers_are_refused_at_the_command_line() {
    for (args, named) in [
        (&["move", "x=100", "--vel", "nan"][..], "--vel"),
        (&["move", "x=100", "--acc", "inf"], "--acc"),
        (&["move", "x=100", "--jerk=-inf"], "--jerk"),
        (&["move", "x=100", "--vel", "0"], "--vel"),
        (&["move", "x=100", "--line", "--vel", "nan"], "--vel"),
        (&["path", "x=1", "x=2", "--acc", "nan"], "--acc"),
        (&["jog", "x", "nan"], "<VELOCITY>"),
        (&["jog", "x", "10", "--acc", "nan"], "--acc"),
        (&["override", "nan"], "<PERCENT>"),
        (&["torque", "c=20", "--seconds", "nan"], "--seconds"),
        (&["status", "--reply-timeout", "1e300"], "--reply-timeout"),
        (&["status", "--reply-timeout", "1e20"], "--reply-timeout"),
        (&["status", "--reply-timeout", "nan"], "--reply-timeout"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "cellrt {args:?}: {err}");
        assert!(
            err.contains(named)
                && (err.contains("finite") || err.contains("> 0") || err.contains("longer")),
            "cellrt {args:?}: {err}"
        );
    }
}

#[test]
fn live_page_port_without_a_live_view_or_out_of_range() {
    let (run, config) = run_config_edit(|t| format!("{t}\n[live]\npage_port = 8766\n"));
    run.expect_error(&config, "live.page_port", &["set live.listen too"]);
    let (run, config) = run_config_edit(|t| {
        format!("{t}\n[live]\nlisten = \"127.0.0.1:8765\"\npage_port = 8765\n")
    });
    run.expect_error(&config, "live.page_port", &["live view's port 8765"]);
    let (run, config) =
        run_config_edit(|t| format!("{t}\n[live]\nlisten = \"127.0.0.1:8765\"\npage_port = -1\n"));
    run.expect_error(&config, "live.page_port", &["-1 is not a port"]);
}

#[test]
fn live_on_the_last_port_leaves_no_port_for_the_page() {
    let (case, config, _) = Case::with(&demo_config(), DEMO_PROGRAM);
    let run = case.run(&[config.to_str().unwrap(), "--live", "127.0.0.1:65535"]);
    let line = run.error_line();
    assert!(line.contains("--live 127.0.0.1:65535"), "{line}");
    assert!(line.contains("set live.page_port"), "{line}");
}
