#!/usr/bin/env python3
"""What the live viewer costs tracking: real-time runs with and without `--viewer`, a headless chromium page
connected to the viewer for the whole run (`--viewer-wait`), interleaved in one session so both see the same
machine load. Prints a markdown table of the medians over the repeats (tracking median ms and frames per second
from metrics.json, frames the page received) and the ratios.
  bench/viewer_overhead.py --binary build/bin/varslam --dataset DIR [--dataset DIR ...] [--repeats 3] [--work /tmp/vo]
The page is opened by tests/viewer/browser_check.mjs's puppeteer-core (installed by tests/viewer/browser_test.sh in
<build>/viewer-test-npm)."""
import argparse, json, os, re, signal, statistics, subprocess, sys, time
from pathlib import Path

HOLD_PAGE = r"""
import puppeteer from 'puppeteer-core';
const browser = await puppeteer.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'] });
const page = await browser.newPage();
await page.setViewport({ width: 1600, height: 950 });
await page.goto(process.argv[2]);
await page.waitForFunction(() => window.viewerStatus && viewerStatus.done, { timeout: 0, polling: 250 });
console.log(JSON.stringify(await page.evaluate(() => window.viewerStatus)));
await browser.close();
"""


def run(binary, dataset, out, viewer, npm_dir, extra):
    cmd = [binary, "run", "-d", dataset, "-o", str(out), "--realtime", "-q"] + extra
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
    return m["timings"]["tracking"]["median_ms"], m["fps"], received, m["frames"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--dataset", action="append", required=True)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--work", default="/tmp/varslam_viewer_overhead")
    ap.add_argument("--npm-dir", default=None, help="folder with puppeteer-core (default <build>/viewer-test-npm)")
    ap.add_argument("--set", action="append", default=[])
    a = ap.parse_args()
    binary = Path(a.binary).resolve()
    npm_dir = Path(a.npm_dir) if a.npm_dir else binary.parent.parent / "viewer-test-npm"
    if not (npm_dir / "node_modules" / "puppeteer-core").exists():
        sys.exit(f"puppeteer-core not in {npm_dir}: run tests/viewer/browser_test.sh (ctest -R Viewer) once")
    (npm_dir / "hold_page.mjs").write_text(HOLD_PAGE)
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    extra = sum((["--set", s] for s in a.set), [])
    print("| dataset | frames | tracking median ms, no viewer | with viewer + browser | ratio | fps, no viewer | "
          "with viewer + browser | ratio | frames the page got |")
    print("|---|---|---|---|---|---|---|---|---|")
    for ds in a.dataset:
        rows = {False: [], True: []}
        for r in range(a.repeats):
            for viewer in (False, True):  # interleaved: both see the same load
                out = work / f"{Path(ds).name}_{'viewer' if viewer else 'plain'}_{r}"
                rows[viewer].append(run(str(binary), ds, out, viewer, npm_dir, extra))
                print(f"  {Path(ds).name} repeat {r} viewer={viewer}: {rows[viewer][-1]}", file=sys.stderr)
        med = lambda v, k: statistics.median(x[k] for x in rows[v])
        t0, t1, f0, f1 = med(False, 0), med(True, 0), med(False, 1), med(True, 1)
        print(f"| {Path(ds).name} | {rows[False][0][3]} | {t0:.2f} | {t1:.2f} | {t1 / t0:.3f} | {f0:.1f} | {f1:.1f} | "
              f"{f1 / f0:.3f} | {int(med(True, 2))} |")


if __name__ == "__main__":
    main()
