//! The README's exit-code table, walked: every example command of the "Exit codes" section is
//! run (against a running demo cell where it names `CELL`) and must exit with its row's code.

mod common;

use std::path::Path;
use std::process::Command;

use common::cell::Cell;

/// (code, the example commands) of each row of the README's table.
fn table() -> Vec<(i32, Vec<String>)> {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md"))
        .expect("README.md");
    let section = readme
        .split("### Exit codes")
        .nth(1)
        .expect("an \"Exit codes\" section");
    section
        .lines()
        .skip_while(|l| !l.starts_with("| Code"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|row| {
            let cols: Vec<&str> = row.split('|').map(str::trim).collect();
            let code = cols[1].parse().expect("a numeric code");
            let commands = cols[3]
                .split('`')
                .skip(1)
                .step_by(2)
                .map(str::to_string)
                .collect();
            (code, commands)
        })
        .collect()
}

/// The demo configuration as `name`, without CPU pinning or the overrun watchdog, with `extra`
/// appended.
fn demo_config(dir: &Path, file: &str, name: &str, extra: &str) -> std::path::PathBuf {
    let cfg = common::demo_cell(dir, "");
    let text = std::fs::read_to_string(&cfg).unwrap();
    let old = common::cell_name_of(&text);
    let text = text.replace(&format!("name = \"{old}\""), &format!("name = \"{name}\""));
    let path = dir.join(file);
    std::fs::write(&path, format!("{text}\n{extra}")).unwrap();
    std::fs::copy(
        concat!(env!("CARGO_MANIFEST_DIR"), "/../configs/demo-program.toml"),
        dir.join("program.toml"),
    )
    .unwrap();
    path
}

#[test]
fn every_example_of_the_readme_exit_code_table_exits_with_its_code() {
    let rows = table();
    assert_eq!(
        rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        [0, 1, 2, 3, 4],
        "one row per code"
    );
    let dir = tempfile::tempdir().unwrap();
    let name = common::unique_cell_name();
    let cell_cfg = demo_config(dir.path(), "cell.toml", &name, "");
    let faulting = demo_config(
        dir.path(),
        "faulting.toml",
        &common::unique_cell_name(),
        "[[inject]]\nat_ms = 500\nfault = \"drive_alarm\"\naxis = \"x\"\ncode = 0x2220\n",
    );
    let cell = Cell::start(&cell_cfg, &dir.path().join("cell.mcap"));
    let busy = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let busy_port = busy.local_addr().unwrap().port().to_string();
    let repo = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    for (code, commands) in rows {
        assert!(!commands.is_empty(), "row {code} gives an example");
        for command in commands {
            let line = command
                .replace("FAULTING.toml", faulting.to_str().unwrap())
                .replace("CELL.toml", cell_cfg.to_str().unwrap())
                .replace("CELL", &cell.name)
                .replace("BUSY", &busy_port);
            let args: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(args[0], "cellrt", "{command}");
            let out = Command::new(env!("CARGO_BIN_EXE_cellrt"))
                .args(&args[1..])
                .current_dir(repo)
                .output()
                .unwrap();
            let (err, stdout) = (
                String::from_utf8_lossy(&out.stderr),
                String::from_utf8_lossy(&out.stdout),
            );
            assert_eq!(out.status.code(), Some(code), "`{command}`: {stdout}{err}");
            // Bad input and no cell say why in an `error:` line, the cell's refusal in a
            // `rejected:` (an operator command) or `error:` one, a failed run in its summary.
            let said = match code {
                0 => true,
                1 => stdout.contains("FAILED") || err.contains("error:"),
                3 => err
                    .lines()
                    .any(|l| l.starts_with("rejected:") || l.starts_with("error:")),
                _ => err.lines().any(|l| l.starts_with("error:")),
            };
            assert!(said, "`{command}` says why: {stdout}{err}");
        }
    }
    cell.end();
}
