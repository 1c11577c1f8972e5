#!/usr/bin/env bash
# The fuzz stage of the test suite (scripts/run_tests.sh runs it): builds the libFuzzer harnesses of fuzz/
# with clang (AddressSanitizer + UndefinedBehaviorSanitizer, build-fuzz/) and runs each for
# VARSLAM_FUZZ_SECONDS (default 10) from its corpus in fuzz/corpus/<name>/. New inputs go to a scratch folder,
# not to the repository. A crash, a leak, a sanitizer report or a broken reader contract fails the stage and
# leaves the input in build-fuzz/findings/<name>/.
#   scripts/fuzz.sh [name ...]            (default: every harness)
#   VARSLAM_FUZZ_RUNS=1000000 scripts/fuzz.sh   (a fixed number of executions instead of a time)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
JOBS=$(nproc 2>/dev/null || echo 2)
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root}

if ! command -v clang++ >/dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "[fuzz] installing clang"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends clang
fi

flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined"
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -fno-omit-frame-pointer" -DCMAKE_CXX_FLAGS="$flags" \
  -DVARSLAM_BUILD_FUZZ=ON -DVARSLAM_BUILD_TESTS=OFF -DVARSLAM_BUILD_BENCH=OFF -DCMAKE_UNITY_BUILD=ON >/dev/null
cmake --build build-fuzz -j"$JOBS" --target fuzzers

names=("$@")
if ((${#names[@]} == 0)); then
  for f in fuzz/*_fuzz.cpp; do n=$(basename "$f" _fuzz.cpp); names+=("$n"); done
fi
limit=(-max_total_time="${VARSLAM_FUZZ_SECONDS:-10}")
[[ -n ${VARSLAM_FUZZ_RUNS:-} ]] && limit=(-runs="$VARSLAM_FUZZ_RUNS")
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
for n in "${names[@]}"; do
  scratch=build-fuzz/scratch/$n findings=build-fuzz/findings/$n
  rm -rf "$scratch"; mkdir -p "$scratch" "$findings" "fuzz/corpus/$n"
  log=build-fuzz/$n.log
  if ! build-fuzz/fuzz/fuzz_"$n" "${limit[@]}" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$findings/" -print_final_stats=1 "$scratch" "fuzz/corpus/$n" >"$log" 2>&1; then
    tail -n 60 "$log"
    echo "[fuzz] $n: FAILED (input kept in $findings/)"
    exit 1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo "?")
  echo "[fuzz] $n: $runs executions, coverage $cov edges, no findings"
done
