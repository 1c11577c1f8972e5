#!/usr/bin/env python3
"""What the live viewer costs tracking: real-time runs without the viewer, with `--viewer` and no browser, and with a
headless chromium page connected for the whole run (`--viewer-wait`), interleaved in one session so all see the same
machine load (the browser renders WebGL in software on the same cores). Prints a markdown table of the medians over the repeats (tracking median ms and frames per second
from metrics.json, frames the page received) and the ratios.
  bench/viewer_overhead.py --binary build/bin/varslam --dataset DIR [--dataset DIR ...] [--repeats 3] [--work /tmp/vo]
The page is opened by tests/viewer/browser_check.mjs's puppeteer-core (installed by tests/viewer/browser_test.sh in
<build>/viewer-test-npm)."""
import argparse, json, os, re, signal, statistics, subprocess, sys, time
from pathlib import Path

HOLD_PAGE = r"""
import puppeteer from 'puppeteer-core';
const browser = await puppeteer.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'] });
const page = await browser.newPage();
await page.setViewport({ width: 1600, height: 950 });
await page.goto(process.argv[2]);
await page.waitForFunction(() => window.viewerStatus && viewerStatus.done, { timeout: 0, polling: 250 });
console.log(JSON.stringify(await page.evaluate(() => window.viewerStatus)));
await browser.close();
"""


def run(binary, dataset, out, mode, npm_dir, extra):
    """mode: "plain", "viewer" (no browser) or "browser" (viewer and a connected page)."""
    viewer = mode == "browser"
    cmd = [binary, "run", "-d", dataset, "-o", str(out), "--realtime", "-q"] + extra
    if mode == "viewer":
        cmd += ["--viewer"]
    if viewer:
        cmd += ["--viewer", "--viewer-wait", "--viewer-hold"]
    err = open(str(out) + ".err", "w")
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
    page = None
    if viewer:
        url = None
        for _ in range(300):
            m = re.search(r"http://\S+/", Path(str(out) + ".err").read_text())
            if m:
                url = m.group(0)
                break
            time.sleep(0.1)
        if not url:
            p.kill()
            sys.exit(f"no viewer address from {cmd}")
        page = subprocess.run(["node", str(npm_dir / "hold_page.mjs"), url], capture_output=True, text=True,
                              timeout=1800)
        p.send_signal(signal.SIGINT)
    rc = p.wait(timeout=1800)
    if rc != 0:
        sys.exit(f"{cmd} exited {rc}: see {out}.err")
    m = json.loads((out / "metrics.json").read_text())
    received = json.loads(page.stdout.strip().splitlines()[-1])["frames"] if page else 0
    cost = re.search(r"([0-9.]+) ms per frame on the tracking thread", Path(str(out) + ".err").read_text())
    return (m["timings"]["tracking"]["median_ms"], m["fps"], received, m["frames"],
            float(cost.group(1)) if cost else 0.0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--dataset", action="append", required=True)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--work", default="/tmp/varslam_viewer_overhead")
    ap.add_argument("--npm-dir", default=None, help="folder with puppeteer-core (default <build>/viewer-test-npm)")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--viewer-fps", type=float, default=None, help="--viewer-fps for the viewer runs")
    a = ap.parse_args()
    binary = Path(a.binary).resolve()
    npm_dir = Path(a.npm_dir) if a.npm_dir else binary.parent.parent / "viewer-test-npm"
    if not (npm_dir / "node_modules" / "puppeteer-core").exists():
        sys.exit(f"puppeteer-core not in {npm_dir}: run tests/viewer/browser_test.sh (ctest -R Viewer) once")
    (npm_dir / "hold_page.mjs").write_text(HOLD_PAGE)
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    extra = sum((["--set", s] for s in a.set), [])
    print("| dataset | frames | configuration | tracking median ms | ratio | fps | ratio | viewer ms/frame on the "
          "tracking thread | frames the page got |")
    print("|---|---|---|---|---|---|---|---|---|")
    modes = ("plain", "viewer", "browser")
    names = {"plain": "no viewer", "viewer": "--viewer, no browser", "browser": "--viewer, chromium connected"}
    for ds in a.dataset:
        rows = {m: [] for m in modes}
        for r in range(a.repeats):
            for mode in modes:  # interleaved: every configuration sees the same load
                out = work / f"{Path(ds).name}_{mode}_{r}"
                vextra = extra + (["--viewer-fps", str(a.viewer_fps)] if a.viewer_fps and mode != "plain" else [])
                rows[mode].append(run(str(binary), ds, out, mode, npm_dir, vextra))
                print(f"  {Path(ds).name} repeat {r} {mode}: {rows[mode][-1]}", file=sys.stderr)
        med = lambda v, k: statistics.median(x[k] for x in rows[v])
        for mode in modes:
            print(f"| {Path(ds).name} | {rows[mode][0][3]} | {names[mode]} | {med(mode, 0):.2f} | "
                  f"{med(mode, 0) / med('plain', 0):.3f} | {med(mode, 1):.1f} | {med(mode, 1) / med('plain', 1):.3f} | "
                  f"{med(mode, 4):.3f} | {int(med(mode, 2))} |")


if __name__ == "__main__":
    main()
