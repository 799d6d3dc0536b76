#!/usr/bin/env bash
# Runs `.ci/run` on fresh clones of HEAD RUNS times in a row (default 3) while
# `stress-ng --cpu 2` loads the machine, and prints each run's verdict and duration: the
# proof that the logic tests give the same verdict on a loaded machine as on an idle one.
#
#   tools/ci-under-load.sh [RUNS]
#
# Needs stress-ng (installed with apt-get when running as root). Each clone is made next to
# this repository (so `../shared` resolves as in CI) and removed after a passing run; a failing
# run's clone and log are kept. Exits 1 if any run failed.
#
# By default each run builds from scratch, as CI does. With CELLRT_CI_TARGET=DIR the runs
# judge the tests, not a cold build: every clone is made at one path, its files get the
# commit's time, and it builds into DIR, so cargo finds the build of the clone before fresh.
# DIR is warmed first, without load (the builds of `.ci/run`), and that time is printed apart.
# DIR then holds artifacts that name the clone's path (env!("CARGO_MANIFEST_DIR") in tests):
# before testing another checkout with it, touch that checkout's sources (or cargo clean -p).
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"
runs="${1:-3}"
case "$runs" in '' | *[!0-9]*) echo "usage: tools/ci-under-load.sh [RUNS]" >&2; exit 2 ;; esac

if ! command -v stress-ng >/dev/null; then
  if [ "$(id -u)" = 0 ]; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq stress-ng
  else
    echo "stress-ng is missing (apt-get install stress-ng)" >&2
    exit 2
  fi
fi

# The commit judged: HEAD when the script starts, even if main moves on meanwhile.
head="$(git rev-parse HEAD)"
commit_time="$(git log -1 --format=%ct "$head")"
# A fresh clone of HEAD for run $1 (or "warm"); prints its path.
fresh_clone() {
  local clone
  if [ -n "${CELLRT_CI_TARGET:-}" ]; then
    clone="$(dirname "$repo")/ci-under-load"
  else
    clone="$(dirname "$repo")/ci-under-load-$1-$$"
  fi
  rm -rf "$clone"
  git clone --quiet --no-checkout "$repo" "$clone"
  git -C "$clone" checkout --quiet "$head"
  if [ -n "${CELLRT_CI_TARGET:-}" ]; then
    mkdir -p "$CELLRT_CI_TARGET"
    ln -s "$CELLRT_CI_TARGET" "$clone/target"
    # cargo judges local crates by mtime: the same commit's files, the same times.
    (cd "$clone" && git ls-files -z | xargs -0 touch -h -d "@$commit_time" \
      && find . -path ./.git -prune -o -type d -exec touch -d "@$commit_time" {} +)
  fi
  echo "$clone"
}

if [ -n "${CELLRT_CI_TARGET:-}" ]; then
  clone="$(fresh_clone warm)"
  start=$(date +%s)
  (
    cd "$clone"
    cargo clippy --workspace --all-targets --locked
    cargo clippy -p cellrt-trajectory --features ruckig-oracle --all-targets --locked
    cargo test -p cellrt-trajectory --features ruckig-oracle --locked --test ruckig_oracle --no-run
    cargo test --workspace --locked --no-run
    cargo build --release --locked -p cellrt
  ) >"$clone.warm.log" 2>&1 || { echo "warming $CELLRT_CI_TARGET failed: $clone.warm.log" >&2; exit 1; }
  echo "warmed $CELLRT_CI_TARGET without load in $(( $(date +%s) - start )) s"
  rm -rf "$clone" "$clone.warm.log"
fi

stress-ng --cpu 2 --quiet &
stress=$!
trap 'kill "$stress" 2>/dev/null || true' EXIT

failed=0
echo "judging $head"
printf '%-4s %-8s %10s  %s\n' run verdict seconds log
for k in $(seq 1 "$runs"); do
  clone="$(fresh_clone "$k")"
  log="$(dirname "$repo")/ci-under-load-$k-$$.log"
  start=$(date +%s)
  if (cd "$clone" && CI=1 ./.ci/run) >"$log" 2>&1; then
    verdict=passed
    rm -rf "$clone"
  else
    verdict=FAILED
    failed=1
    if [ -n "${CELLRT_CI_TARGET:-}" ]; then
      mv "$clone" "$clone-$k-$$"
    fi
  fi
  printf '%-4s %-8s %10s  %s\n' "$k" "$verdict" "$(( $(date +%s) - start ))" "$log"
done
if [ -n "${CELLRT_CI_TARGET:-}" ]; then
  echo "note: $CELLRT_CI_TARGET now holds builds of $clone; touch the sources of another checkout before testing it with this target" >&2
fi
exit "$failed"
