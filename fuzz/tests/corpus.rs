//! Replays every fuzz target's committed corpus, then a fixed number of deterministic
//! mutations of each seed: the short fuzz smoke `cargo test` (and so CI) runs on the stable
//! toolchain. `tools/fuzz.sh` runs the targets under libFuzzer.

use std::path::{Path, PathBuf};

use cellrt_fuzz::mutate::{mutate, Rng};
use cellrt_fuzz::{Target, TARGETS};

/// Mutated inputs per target.
const MUTATIONS: usize = 3000;

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

fn seeds(target: &str) -> Vec<Vec<u8>> {
    let dir = fuzz_dir().join("corpus").join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("corpus entry").path())
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| std::fs::read(f).expect("corpus file"))
        .collect()
}

#[test]
fn every_target_has_an_entry_point_and_seeds() {
    let manifest = std::fs::read_to_string(fuzz_dir().join("Cargo.toml")).unwrap();
    for t in TARGETS {
        let entry = fuzz_dir()
            .join("fuzz_targets")
            .join(format!("{}.rs", t.name));
        let source = std::fs::read_to_string(&entry).unwrap_or_else(|e| panic!("{}: {e}", t.name));
        assert!(source.contains("fuzz_target!"), "{}", t.name);
        assert!(
            manifest.contains(&format!("name = \"{}\"", t.name)),
            "{} has no [[bin]] in fuzz/Cargo.toml",
            t.name
        );
        assert!(!seeds(t.name).is_empty(), "{} has no seeds", t.name);
    }
}

#[test]
fn every_seed_and_its_mutations_decode_without_a_panic() {
    for (k, t) in TARGETS.iter().enumerate() {
        let seeds = seeds(t.name);
        for seed in &seeds {
            run_or_keep(t, seed);
        }
        let mut rng = Rng::new(0x5EED + k as u64);
        for _ in 0..MUTATIONS {
            let seed = &seeds[rng.below(seeds.len())];
            run_or_keep(t, &mutate(seed, &mut rng));
        }
    }
}

/// Runs `input` through `t`; an input that panics is kept in the test's temporary directory
/// and named in the failure.
fn run_or_keep(t: &Target, input: &[u8]) {
    if std::panic::catch_unwind(|| (t.run)(input)).is_err() {
        let kept = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("crash-{}", t.name));
        std::fs::write(&kept, input).expect("keep the input");
        panic!(
            "{} panicked on the input kept in {}",
            t.name,
            kept.display()
        );
    }
}
