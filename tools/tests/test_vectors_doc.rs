//! `docs/test-vectors.md` names only tests that exist: every test name, module and file in a
//! table's "Test" column is looked up in the workspace's sources, so a renamed or removed test
//! cannot leave a vector marked covered.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// The workspace root (this crate is `tools/`).
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Every `.rs` file under `dir`, build output and vendored crates left out.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        if path.is_dir() {
            if name != "target" && name != ".git" && name != "vendor" {
                rust_files(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The sources' function and module names, and their file paths relative to the workspace.
struct Sources {
    functions: HashSet<String>,
    modules: HashSet<String>,
    files: Vec<String>,
}

impl Sources {
    fn read(root: &Path) -> Sources {
        let mut paths = Vec::new();
        for dir in ["axes", "runtime", "tools", "trajectory", "rt-tests"] {
            rust_files(&root.join(dir), &mut paths);
        }
        let mut functions = HashSet::new();
        let mut modules = HashSet::new();
        for path in &paths {
            let text = std::fs::read_to_string(path).unwrap();
            for (keyword, set) in [("fn ", &mut functions), ("mod ", &mut modules)] {
                for (at, _) in text.match_indices(keyword) {
                    let before = text[..at].chars().next_back();
                    if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                        continue;
                    }
                    let name: String = text[at + keyword.len()..]
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    if !name.is_empty() {
                        set.insert(name);
                    }
                }
            }
        }
        let files = paths
            .iter()
            .map(|p| p.strip_prefix(root).unwrap().to_string_lossy().into_owned())
            .collect();
        Sources {
            functions,
            modules,
            files,
        }
    }

    /// True if the token names something the sources have: a test function (a trailing `…`
    /// stands for any ending), a module (`name::*`) or a file (a path or a file name).
    fn has(&self, token: &str) -> bool {
        if token.ends_with(".rs") || token.contains('/') {
            return self
                .files
                .iter()
                .any(|f| f == token || f.ends_with(&format!("/{token}")));
        }
        if let Some(module) = token.strip_suffix("::*") {
            return self.modules.contains(module);
        }
        if let Some(prefix) = token.strip_suffix('…') {
            return self.functions.iter().any(|f| f.starts_with(prefix));
        }
        self.functions.contains(token)
    }
}

/// The backquoted tokens of each table row's second column ("Test"), with the row's first
/// column (the vector) for the message.
fn named_tests(doc: &str) -> Vec<(String, String)> {
    let mut named = Vec::new();
    for line in doc.lines() {
        let line = line.trim();
        if !line.starts_with('|') || line.starts_with("|---") {
            continue;
        }
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        let (Some(vector), Some(tests)) = (cells.first(), cells.get(1)) else {
            continue;
        };
        if *tests == "Test" {
            continue;
        }
        for (k, part) in tests.split('`').enumerate() {
            if k % 2 == 1 {
                named.push((vector.to_string(), part.to_string()));
            }
        }
    }
    named
}

#[test]
fn every_test_the_vector_table_names_exists() {
    let root = workspace();
    let doc = std::fs::read_to_string(root.join("docs/test-vectors.md")).unwrap();
    let sources = Sources::read(&root);
    let named = named_tests(&doc);
    assert!(
        named.len() > 200,
        "the table names {} tests: the parser lost the table",
        named.len()
    );
    let missing: Vec<String> = named
        .iter()
        .filter(|(_, token)| !sources.has(token))
        .map(|(vector, token)| format!("{vector}: `{token}`"))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/test-vectors.md names tests that do not exist:\n{}",
        missing.join("\n")
    );
}

#[test]
fn a_name_that_is_not_in_the_sources_is_found_missing() {
    let sources = Sources::read(&workspace());
    assert!(sources.has("every_test_the_vector_table_names_exists"));
    assert!(sources.has("tv_ic_1_…"));
    assert!(sources.has("never_panics::*"));
    assert!(sources.has("tv_units.rs"));
    assert!(sources.has("mr_je_c/motion.rs"));
    assert!(!sources.has("tv_home_1_dog_methods_are_not_simulated_and_report_a_homing_error"));
    assert!(!sources.has("no_such_prefix_…"));
    assert!(!sources.has("no_such_module::*"));
    assert!(!sources.has("no_such_file.rs"));
    let rows = named_tests(
        "| V | T | S |\n|---|---|---|\n| TV-1 | `a_b`, `c` (`d.rs`) | `not_a_test` |\n",
    );
    assert_eq!(
        rows,
        [("TV-1", "a_b"), ("TV-1", "c"), ("TV-1", "d.rs")]
            .map(|(v, t)| (v.to_string(), t.to_string()))
    );
}
