#!/usr/bin/env bash
# Runs `.ci/run` on fresh clones of HEAD RUNS times in a row (default 3) while
# `stress-ng --cpu 2` loads the machine, and prints each run's verdict and duration: the
# proof that the logic tests give the same verdict on a loaded machine as on an idle one.
#
#   tools/ci-under-load.sh [RUNS]
#
# Needs stress-ng (installed with apt-get when running as root). Each clone is made next to
# this repository (so `../shared` resolves as in CI) and removed after a passing run; a failing
# run's clone and log are kept. Exits 1 if any run failed. With CELLRT_CI_TARGET=DIR each
# clone builds into DIR (a warm target directory: the runs then judge the tests, not a cold
# build); by default each builds from scratch, as CI does.
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

stress-ng --cpu 2 --quiet &
stress=$!
trap 'kill "$stress" 2>/dev/null || true' EXIT

failed=0
printf '%-4s %-8s %10s  %s\n' run verdict seconds log
for k in $(seq 1 "$runs"); do
  clone="$(dirname "$repo")/ci-under-load-$k-$$"
  log="$clone.log"
  git clone --quiet "$repo" "$clone"
  if [ -n "${CELLRT_CI_TARGET:-}" ]; then
    ln -s "$CELLRT_CI_TARGET" "$clone/target"
  fi
  start=$(date +%s)
  if (cd "$clone" && CI=1 ./.ci/run) >"$log" 2>&1; then
    verdict=passed
    rm -rf "$clone"
  else
    verdict=FAILED
    failed=1
  fi
  printf '%-4s %-8s %10s  %s\n' "$k" "$verdict" "$(( $(date +%s) - start ))" "$log"
done
exit "$failed"
