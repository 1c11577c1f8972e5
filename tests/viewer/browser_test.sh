#!/usr/bin/env bash
# The viewer as a user sees it: `varslam run --viewer --dense-map` on a short synthetic walking scene (real-time,
# paced, started once the browser is connected; the dense map's layer drawn and toggled) and `varslam view` on the
# finished run, each opened in headless chromium
# (browser_check.mjs checks the drawn page). Screenshots: <build>/viewer-screenshots/.
# Usage: browser_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1
build=$2
bin="$build/bin/varslam"
work=$(mktemp -d /tmp/varslam_browser_test.XXXXXX)
shots="$build/viewer-screenshots"
mkdir -p "$shots"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "browser test: $*" >&2; exit 1; }

export CHROMIUM=${CHROMIUM:-$(command -v chromium || command -v chromium-browser || true)}
[ -x "$CHROMIUM" ] || fail "chromium is not installed (apt-get install chromium; scripts/setup.sh installs it)"
command -v node >/dev/null || fail "node is not installed (apt-get install nodejs npm)"

# puppeteer-core, pinned by tests/viewer/package-lock.json, installed once into the build tree.
npmdir="$build/viewer-test-npm"
mkdir -p "$npmdir"
if ! cmp -s "$src/tests/viewer/package-lock.json" "$npmdir/package-lock.json" ||
   [ ! -f "$npmdir/node_modules/puppeteer-core/package.json" ]; then
  cp "$src/tests/viewer/package.json" "$src/tests/viewer/package-lock.json" "$npmdir/"
  npm ci --prefix "$npmdir" --no-audit --no-fund --loglevel=error
fi
cp "$src/tests/viewer/browser_check.mjs" "$npmdir/"

url_of() {  # log file -> the URL the viewer printed
  for _ in $(seq 150); do
    u=$(grep -o 'http://[^ ]*/' "$1" | head -1 || true)
    [ -n "$u" ] && { echo "$u"; return; }
    sleep 0.2
  done
  cat "$1" >&2
  fail "no viewer address in $1"
}

"$bin" synth --scenario walking --seconds 5 --seed 2 --out "$work/walk" --no-preview >/dev/null

echo "[browser] live run"
"$bin" run -d "$work/walk" -o "$work/run" --realtime --pace --viewer --viewer-wait --viewer-hold -q \
  --dense-map --set semantic.detector=boxes >"$work/run.out" 2>"$work/run.err" &
run_pid=$!
pids+=("$run_pid")
url=$(url_of "$work/run.err")
node "$npmdir/browser_check.mjs" "$url" "$shots/live_walking.png" --live --dense | tee "$work/live.json"
kill -INT "$run_pid"
wait "$run_pid" || fail "varslam run --viewer exited with $? after Ctrl+C while holding"
grep -q "keeps showing it until Ctrl+C" "$work/run.err" || fail "the run did not say it holds the viewer"

echo "[browser] finished run"
"$bin" view --run "$work/run" >"$work/view.out" 2>"$work/view.err" &
view_pid=$!
pids+=("$view_pid")
url=$(url_of "$work/view.err")
node "$npmdir/browser_check.mjs" "$url" "$shots/finished_walking.png" --finished | tee "$work/finished.json"
kill -INT "$view_pid"
wait "$view_pid" || fail "varslam view exited with $? on Ctrl+C"
echo "[browser] ok; screenshots in $shots"
