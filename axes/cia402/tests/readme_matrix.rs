//! The README's "Supported drives" table is the one `profiles::matrix::render` produces.
//! Regenerate with `UPDATE_README=1 cargo test -p cellrt-cia402 --test readme_matrix`.

use cellrt_cia402::profiles::matrix;

#[test]
fn readme_feature_matrix_matches_the_profiles() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md");
    let readme = std::fs::read_to_string(path).expect("README.md");
    let expected = matrix::splice(&readme).expect("README.md lacks the drive-matrix markers");
    if std::env::var_os("UPDATE_README").is_some() {
        std::fs::write(path, &expected).expect("write README.md");
        return;
    }
    assert!(
        readme == expected,
        "README.md's drive matrix differs from the profiles; regenerate with \
         UPDATE_README=1 cargo test -p cellrt-cia402 --test readme_matrix"
    );
}
