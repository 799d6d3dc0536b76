//! `cellrt completions` and `cellrt man` come from the command line the binary parses.

use std::process::Command;

fn cellrt(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn bash_completion_is_a_script_bash_reads_and_knows_the_commands() {
    let out = cellrt(&["completions", "bash"]);
    assert!(out.status.success());
    let script = String::from_utf8(out.stdout).unwrap();
    assert!(script.contains("complete -F _cellrt"), "{script}");
    for word in ["run", "bench", "--no-record", "--summary-json"] {
        assert!(script.contains(word), "{word} missing");
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cellrt.bash");
    std::fs::write(&path, &script).unwrap();
    let check = Command::new("bash").arg("-n").arg(&path).output().unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let zsh = cellrt(&["completions", "zsh"]);
    assert!(String::from_utf8_lossy(&zsh.stdout).starts_with("#compdef cellrt"));
}

#[test]
fn an_unknown_shell_is_refused_naming_the_ones_there_are() {
    let out = cellrt(&["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("invalid value 'tcsh'") && err.contains("bash"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn the_man_pages_cover_every_command() {
    let page = cellrt(&["man"]);
    assert!(page.status.success());
    let page = String::from_utf8(page.stdout).unwrap();
    assert!(page.contains(".TH cellrt 1"), "{page}");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("man1");
    let made = cellrt(&["man", "--out", out.to_str().unwrap()]);
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let run = std::fs::read_to_string(out.join("cellrt-run.1")).unwrap();
    assert!(
        run.contains(".TH cellrt-run 1") && run.contains("no\\-record"),
        "{run}"
    );
    assert!(out.join("cellrt-bench-loop.1").exists());
    assert!(out.join("cellrt-completions.1").exists());
    let bad = cellrt(&["man", "--out", "/proc/cellrt-no-such-dir"]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr)
        .starts_with("error: cannot write the man pages to /proc/cellrt-no-such-dir"));
}
