#!/usr/bin/env bash
# Runs every fuzz target (fuzz/fuzz_targets/) under libFuzzer for SECONDS each (default 60)
# and prints the executions and crashes per target.
#
#   tools/fuzz.sh [SECONDS] [TARGET...]
#
# Needs cargo-fuzz (`cargo install cargo-fuzz`). Runs on the stable toolchain without a
# sanitizer (`-s none`: the decoders are safe Rust, the findings are panics, overflows, hangs
# and unbounded allocations); FUZZ_SANITIZER=address with FUZZ_TOOLCHAIN=nightly adds
# AddressSanitizer where a nightly toolchain is installed. Builds with debug assertions
# (overflow checks). New inputs go to target/fuzz-corpus/TARGET (the committed seeds in
# fuzz/corpus/TARGET are read, not written); a crashing input is kept in
# fuzz/artifacts/TARGET/. Exits 1 if any target crashed.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${1:-60}"
shift || true
case "$seconds" in '' | *[!0-9]*) echo "usage: tools/fuzz.sh [SECONDS] [TARGET...]" >&2; exit 2 ;; esac
sanitizer="${FUZZ_SANITIZER:-none}"
toolchain=()
[ -n "${FUZZ_TOOLCHAIN:-}" ] && toolchain=("+$FUZZ_TOOLCHAIN")

if ! cargo fuzz --version >/dev/null 2>&1; then
  echo "cargo-fuzz is missing: cargo install cargo-fuzz --locked" >&2
  exit 2
fi
if [ "$#" -gt 0 ]; then
  targets=("$@")
else
  mapfile -t targets < <(ls fuzz/fuzz_targets | sed 's/\.rs$//')
fi

cargo "${toolchain[@]}" fuzz build --fuzz-dir fuzz -s "$sanitizer" --debug-assertions \
  --features libfuzzer >&2
host=$(rustc "${toolchain[@]}" -vV | sed -n 's/^host: //p')
bin="${CARGO_TARGET_DIR:-target}/$host/release"

work="${CARGO_TARGET_DIR:-target}/fuzz-corpus"
logs="${CARGO_TARGET_DIR:-target}/fuzz-logs"
mkdir -p "$logs"
crashed=0
printf '%-20s %8s %14s %10s %8s\n' target seconds execs execs/s crashes
for t in "${targets[@]}"; do
  mkdir -p "$work/$t" "fuzz/artifacts/$t"
  before=$(ls "fuzz/artifacts/$t" | wc -l)
  status=0
  "$bin/$t" "$work/$t" "fuzz/corpus/$t" -artifact_prefix="fuzz/artifacts/$t/" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    >"$logs/$t.log" 2>&1 || status=$?
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$logs/$t.log" | grep -o '[0-9]*$' || true)
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$logs/$t.log" | grep -o '[0-9]*$' || true)
  crashes=$(( $(ls "fuzz/artifacts/$t" | wc -l) - before ))
  if [ "$status" -ne 0 ] && [ "$crashes" -eq 0 ]; then crashes=1; fi
  printf '%-20s %8s %14s %10s %8s\n' "$t" "$seconds" "${execs:-?}" "${rate:-?}" "$crashes"
  if [ "$crashes" -gt 0 ]; then
    crashed=1
    echo "  $t: see $logs/$t.log and fuzz/artifacts/$t/" >&2
  fi
done
exit "$crashed"
