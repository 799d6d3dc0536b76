//! Who may command a cell, tested as another local user: root runs the cell, `nobody` (through
//! `setpriv`) tries to command it, block it, cut root's operator off, keep it from starting and
//! make root overwrite a file through a planted link; a member of the cell's `[operator] group`
//! may command it. Needs root (and `setpriv`); says so and skips otherwise.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::cell::Cell;
use common::demo_cell;

/// The user the tests act as.
const OTHER: &str = "nobody";
/// Its primary group.
const OTHER_GROUP: &str = "nogroup";

/// Whether the tests can switch users; prints why not.
fn can_switch_users(test: &str) -> bool {
    if !nix::unistd::getuid().is_root() {
        eprintln!("SKIPPED {test}: needs root to act as another user");
        return false;
    }
    if Command::new("setpriv").arg("--version").output().is_err() {
        eprintln!("SKIPPED {test}: setpriv (util-linux) is not installed");
        return false;
    }
    let user = nix::unistd::User::from_name(OTHER).ok().flatten();
    let group = nix::unistd::Group::from_name(OTHER_GROUP).ok().flatten();
    if user.is_none() || group.is_none() {
        eprintln!("SKIPPED {test}: no user '{OTHER}' or group '{OTHER_GROUP}' on this machine");
        return false;
    }
    true
}

/// `setpriv` as `nobody`, with `groups` as its supplementary groups (none when empty).
fn as_other(groups: &str) -> Command {
    let mut c = Command::new("setpriv");
    c.args(["--reuid", OTHER, "--regid", OTHER_GROUP]);
    if groups.is_empty() {
        c.arg("--clear-groups");
    } else {
        c.arg(format!("--groups={groups}"));
    }
    c
}

/// Runs `cellrt ARGS --cell CELL` as `nobody` in `groups`.
fn cellrt_as_other(groups: &str, cell: &str, args: &[&str]) -> Output {
    as_other(groups)
        .arg(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .args(["--cell", cell])
        .output()
        .unwrap()
}

/// Runs a shell command as `nobody`; true when it succeeded.
fn sh_as_other(script: &str) -> bool {
    as_other("")
        .args(["sh", "-c", script])
        .output()
        .unwrap()
        .status
        .success()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Expects `cellrt ARGS` as `nobody` to be refused as not permitted, naming the cell and root.
fn refused_as_not_permitted(cell: &str, args: &[&str]) {
    let o = cellrt_as_other("", cell, args);
    let err = stderr(&o);
    assert_eq!(
        o.status.code(),
        Some(4),
        "cellrt {args:?} as {OTHER}: {err}"
    );
    assert!(
        err.contains(&format!("cell '{cell}' runs as root (uid 0)"))
            && err.contains("is not permitted to command it"),
        "cellrt {args:?} as {OTHER}: {err}"
    );
}

/// A demo cell config in a directory root alone may write.
fn config(dir: &Path, extra: &str) -> PathBuf {
    let cfg = demo_cell(dir, "");
    let text = std::fs::read_to_string(&cfg).unwrap() + extra;
    std::fs::write(&cfg, text).unwrap();
    cfg
}

/// root's lock file of `cell`.
fn lock_file(cell: &str) -> PathBuf {
    PathBuf::from(format!("/run/cellrt/{cell}.lock"))
}

/// root's operator socket of `cell`.
fn socket_file(cell: &str) -> PathBuf {
    PathBuf::from(format!("/run/cellrt-operator/{cell}.sock"))
}

#[test]
fn another_user_is_told_it_is_not_permitted_and_changes_nothing() {
    if !can_switch_users("another_user_is_told_it_is_not_permitted_and_changes_nothing") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cell = Cell::start(&config(dir.path(), ""), &dir.path().join("run.mcap"));
    for args in [
        &["status"][..],
        &["power", "on"],
        &["move", "x=100"],
        &["stop"],
        &["halt"],
    ] {
        refused_as_not_permitted(&cell.name, args);
    }
    // Nothing changed: the cell is still unpowered and answers its user.
    assert!(!cell.axis_status("x").powered);
    cell.ok(&["power", "on"]);
    cell.wait_state("idle");
    cell.end();
    assert!(
        !lock_file(&cell_name_of(&dir)).exists(),
        "lock removed at the end"
    );
    assert!(
        !socket_file(&cell_name_of(&dir)).exists(),
        "socket removed at the end"
    );
}

/// The cell name written into `dir`'s config.
fn cell_name_of(dir: &tempfile::TempDir) -> String {
    let text = std::fs::read_to_string(dir.path().join("cell.toml")).unwrap();
    text.lines()
        .find_map(|l| l.strip_prefix("name = \""))
        .and_then(|l| l.strip_suffix('"'))
        .unwrap()
        .to_string()
}

#[test]
fn another_user_can_neither_block_the_cell_nor_reach_its_files() {
    if !can_switch_users("another_user_can_neither_block_the_cell_nor_reach_its_files") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cell = Cell::start(&config(dir.path(), ""), &dir.path().join("run.mcap"));
    let name = &cell.name;
    // The runtime and operator directories: no listing, no new files, no links, no lock, no
    // iceoryx2 files, no removing the socket.
    for script in [
        "ls /run/cellrt".to_string(),
        "touch /run/cellrt/planted".to_string(),
        "ls /run/cellrt-operator".to_string(),
        "touch /run/cellrt-operator/planted".to_string(),
        format!("ln -s /etc/hostname /run/cellrt-operator/{name}-2.sock"),
        format!("ln -s /etc/hostname /run/cellrt/{name}-2.lock"),
        format!("cat /run/cellrt/{name}.lock"),
        "ls /run/cellrt/iceoryx2".to_string(),
        format!(
            "rm -f /run/cellrt-operator/{name}.sock && test ! -e /run/cellrt-operator/{name}.sock"
        ),
    ] {
        assert!(!sh_as_other(&script), "{OTHER} could: {script}");
    }
    // root's iceoryx2 objects in /dev/shm, the global management object among them: nobody may
    // open them, let alone overwrite them.
    let shm: Vec<PathBuf> = std::fs::read_dir("/dev/shm")
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("iox2_cellrt_u0_"))
        })
        .collect();
    assert!(
        shm.iter()
            .any(|p| p.to_string_lossy().ends_with("global_mgmt")),
        "{shm:?}"
    );
    for p in &shm {
        // Never created: an object of another cell may be gone by now.
        let script = format!(
            "printf x | dd of='{}' conv=notrunc,nocreat status=none",
            p.display()
        );
        assert!(!sh_as_other(&script), "{OTHER} could write {}", p.display());
    }
    // Twenty refused clients at once do not keep root's operator from its cell.
    let others: Vec<_> = (0..20)
        .map(|_| {
            as_other("")
                .arg(env!("CARGO_BIN_EXE_cellrt"))
                .args(["status", "--cell", name])
                .stderr(std::process::Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    cell.ok(&["power", "on"]);
    cell.wait_state("idle");
    cell.ok(&["stop"]);
    for mut o in others {
        assert_eq!(o.wait().unwrap().code(), Some(4));
    }
    cell.end();
}

#[test]
fn planted_objects_and_files_do_not_keep_roots_cell_from_starting_or_cut_it_off() {
    if !can_switch_users(
        "planted_objects_and_files_do_not_keep_roots_cell_from_starting_or_cut_it_off",
    ) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "");
    let name = cell_name_of(&dir);
    // Before root's cell starts, nobody plants where it can: an object with root's iceoryx2
    // prefix in /dev/shm, the places older versions used in /tmp. It cannot plant in root's
    // runtime directory at all.
    let planted = PathBuf::from(format!(
        "/dev/shm/iox2_cellrt_u0_planted_{}.dynamic",
        std::process::id()
    ));
    assert!(sh_as_other(&format!("touch '{}'", planted.display())));
    let _ = sh_as_other(&format!(
        "mkdir -p /tmp/cellrt-u0 /tmp/cellrt-iceoryx2-u0; touch /tmp/cellrt-u0-{name}.lock"
    ));
    assert!(!sh_as_other(&format!("touch /run/cellrt/{name}.lock")));
    // A lock a killed controller of root left behind.
    std::fs::create_dir_all("/run/cellrt").unwrap();
    std::fs::write(lock_file(&name), "999999999").unwrap();

    let cell = Cell::start(&cfg, &dir.path().join("run.mcap"));
    assert!(!planted.exists(), "the planted object is removed");
    cell.ok(&["power", "on"]);
    cell.wait_state("idle");
    cell.end();
    assert!(!lock_file(&name).exists());
    let _ = std::fs::remove_file(format!("/tmp/cellrt-u0-{name}.lock"));
}

#[test]
fn a_link_planted_where_root_writes_is_refused_and_its_target_kept() {
    if !can_switch_users("a_link_planted_where_root_writes_is_refused_and_its_target_kept") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "");
    // A directory everyone may write, like /tmp; a file only root may write.
    let shared = tempfile::tempdir().unwrap();
    std::fs::set_permissions(
        shared.path(),
        std::os::unix::fs::PermissionsExt::from_mode(0o1777),
    )
    .unwrap();
    let target = dir.path().join("precious");
    std::fs::write(&target, "precious").unwrap();
    for (i, flag) in ["--record", "--summary-json"].iter().enumerate() {
        let link = shared.path().join(format!("out-{i}"));
        assert!(sh_as_other(&format!(
            "ln -s '{}' '{}'",
            target.display(),
            link.display()
        )));
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_cellrt"));
        cmd.arg("run")
            .arg(&cfg)
            .args(["--no-program", "--duration", "0.2"]);
        if *flag == "--summary-json" {
            cmd.arg("--no-record");
        }
        let o = cmd.arg(flag).arg(&link).output().unwrap();
        let err = stderr(&o);
        // The recording and the summary's file are opened before the cell starts: refused as
        // bad input.
        assert_eq!(o.status.code(), Some(2), "{flag} through a link: {err}");
        assert!(err.contains("symbolic link"), "{flag}: {err}");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
    }
}

#[test]
fn a_member_of_the_operator_group_may_command_the_cell() {
    if !can_switch_users("a_member_of_the_operator_group_may_command_the_cell") {
        return;
    }
    // A group that exists on the machine and that nobody is not in by default.
    let group = "daemon";
    if nix::unistd::Group::from_name(group)
        .ok()
        .flatten()
        .is_none()
    {
        eprintln!(
            "SKIPPED a_member_of_the_operator_group_may_command_the_cell: no group '{group}'"
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let extra = format!("\n[operator]\ngroup = \"{group}\"\n");
    let cell = Cell::start(&config(dir.path(), &extra), &dir.path().join("run.mcap"));
    let name = &cell.name;
    let o = cellrt_as_other("", name, &["power", "on"]);
    assert_eq!(o.status.code(), Some(4));
    assert!(
        stderr(&o).contains(&format!("members of its operator group '{group}' may")),
        "{}",
        stderr(&o)
    );
    assert!(!cell.axis_status("x").powered);
    let member = |args: &[&str]| {
        let o = cellrt_as_other(group, name, args);
        assert!(
            o.status.success(),
            "cellrt {args:?} as a member: {}",
            stderr(&o)
        );
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    member(&["power", "on"]);
    assert!(cell.axis_status("x").powered);
    assert!(member(&["status"]).contains(&format!("cell {name}")));
    member(&["move", "x=120"]);
    let x = cell.axis_status("x");
    assert!((x.position - 120.0).abs() < 0.01, "{x:?}");
    member(&["stop"]);
    cell.end();
}
