#!/usr/bin/env bash
# Opens an HTML report in a real headless browser (Debian's chromium), saves a screenshot and checks that the
# browser's DOM holds the plots. Usage: scripts/check_report_in_browser.sh REPORT.html [SCREENSHOT.png]
# (install the browser once as root: apt-get install -y chromium). Exit 0 = rendered with every plot present.
set -euo pipefail

report=${1:?usage: $0 REPORT.html [SCREENSHOT.png]}
shot=${2:-${report%.html}.png}
[[ -f $report ]] || { echo "check_report: $report: no such file" >&2; exit 2; }
browser=$(command -v chromium || command -v chromium-browser || true)
[[ -n $browser ]] || { echo "check_report: chromium not installed (apt-get install -y chromium)" >&2; exit 2; }

url="file://$(realpath "$report")"
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
flags=(--headless --no-sandbox --disable-gpu --disable-background-networking --disable-component-update
       --disable-sync --no-first-run --user-data-dir="$profile")

timeout 120 "$browser" "${flags[@]}" --screenshot="$shot" --window-size=1280,2000 "$url" >/dev/null 2>&1
[[ -s $shot ]] || { echo "check_report: no screenshot written" >&2; exit 1; }

# The DOM after parsing: a malformed page loses elements, so count what the browser really built.
dom=$(timeout 120 "$browser" "${flags[@]}" --dump-dom "$url" 2>/dev/null)
svgs=$(grep -o '<svg' <<<"$dom" | wc -l)
status=0
case $(basename "$report") in
  index.html) need=(chart-ate_rmse_cm chart-fps runs table-md) ;;
  *) need=(key-numbers plot-trajectory plot-ate-error plot-timing) ;;
esac
for id in "${need[@]}"; do
  grep -q "id=\"$id\"" <<<"$dom" || { echo "check_report: element #$id missing in the rendered page" >&2; status=1; }
done
echo "check_report: $report rendered, $svgs inline SVG plots, screenshot $shot ($(stat -c %s "$shot") bytes)"
exit $status
