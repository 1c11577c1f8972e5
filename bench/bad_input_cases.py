#!/usr/bin/env python3
"""The bad-input cases of the reliability issue, run against one or more varslam binaries side by side.

Prints a markdown table: case | per binary: exit code and the line that explains it (the first 'error'/'warn'
line, else the last line). The cases break a 3-s synthetic walking sequence the way a hostile but fair user would.
  bench/bad_input_cases.py --work /tmp/badin BINARY [BINARY ...]
"""
import argparse, os, shutil, signal, struct, subprocess, sys, time, zlib
from pathlib import Path


def png(path, w, h, bits, channels, value):
    row = b"\x00" + (struct.pack(">H", value) if bits == 16 else bytes([value])) * (w * channels)
    def chunk(k, d):
        return struct.pack(">I", len(d)) + k + d + struct.pack(">I", zlib.crc32(k + d) & 0xFFFFFFFF)
    ct = {1: 0, 3: 2}[channels]
    data = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bits, ct, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(row * h)) + chunk(b"IEND", b""))
    Path(path).write_bytes(data)


def copy_base(base, work, name):
    d = work / name
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(base, d)
    return d


def fill_images(seq, sub, w, h, bits, channels, value):
    for f in (seq / sub).iterdir():
        png(f, w, h, bits, channels, value)


def explain(out):
    lines = [l.strip() for l in out.splitlines() if l.strip()]
    for l in lines:
        if any(k in l.lower() for k in ("error", "warn", "failed", "interrupted", "refus")):
            return l
    return lines[-1] if lines else ""


def cases(base, work):
    """(name, description, args builder(binary, out) -> argv, optional setup returning extra state)."""
    c = []
    def add(name, desc, argv_fn, post=None):
        c.append((name, desc, argv_fn, post))

    z = copy_base(base, work, "zero_depth"); fill_images(z, "depth", 640, 480, 16, 1, 0)
    add("zero_depth", "every depth image all zeros", lambda b, o: [b, "run", "-q", "-d", z, "-o", o])
    add("zero_depth_rt", "the same, --realtime", lambda b, o: [b, "run", "-q", "--realtime", "-d", z, "-o", o])
    s = copy_base(base, work, "sat_depth"); fill_images(s, "depth", 640, 480, 16, 1, 65535)
    add("saturated_depth", "every depth image all 65535", lambda b, o: [b, "run", "-q", "-d", s, "-o", o])
    k = copy_base(base, work, "black"); fill_images(k, "rgb", 640, 480, 8, 3, 0)
    add("black_frames", "every colour frame black", lambda b, o: [b, "run", "-q", "-d", k, "-o", o])
    t = copy_base(base, work, "tiny"); fill_images(t, "rgb", 40, 30, 8, 3, 90); fill_images(t, "depth", 40, 30, 16, 1, 5000)
    add("tiny_frames", "40x30 frames with a matching camera",
        lambda b, o: [b, "run", "-q", "-d", t, "-o", o, "--set", "camera.width=40", "--set", "camera.height=30",
                      "--set", "camera.cx=19.5", "--set", "camera.cy=14.5"])
    add("one_feature", "--set orb.n_features=1", lambda b, o: [b, "run", "-q", "-d", base, "-o", o, "--set", "orb.n_features=1"])
    add("metrics_is_folder", "metrics.json is a folder",
        lambda b, o: (os.makedirs(Path(o) / "metrics.json", exist_ok=True), [b, "run", "-q", "-d", base, "-o", o])[1])
    add("one_frame", "a 1-frame run with groundtruth.txt", lambda b, o: [b, "run", "-q", "-d", base, "-o", o, "-n", "1"])
    add("gt_folder", "a folder as --groundtruth", lambda b, o: [b, "run", "-q", "-d", base, "-o", o, "--groundtruth", work])
    for name, desc, line in (("gt_7_columns", "ground truth line with 7 columns", "1311870436.8 0 0 0 0 0 1\n"),
                             ("gt_nan", "ground truth NaN", "1311870436.81 nan 0 0 0 0 0 1\n"),
                             ("gt_zero_quat", "ground truth zero quaternion", "1311870499.82 0 0 0 0 0 0 0\n")):
        g = work / f"{name}.txt"
        g.write_text((base / "groundtruth.txt").read_text() + line)
        add(name, desc, lambda b, o, g=g: [b, "run", "-q", "-d", base, "-o", o, "--groundtruth", g])
    blocker = work / "a_file"; blocker.write_text("x")
    add("out_uncreatable", "--out under a regular file", lambda b, o: [b, "run", "-q", "-d", base, "-o", blocker / "out"])
    add("set_broken_yaml", "--set camera.fx=[1, 2", lambda b, o: [b, "run", "-q", "-d", base, "-o", o, "--set", "camera.fx=[1, 2"])
    lv = copy_base(base, work, "n_levels"); (lv / "settings.yaml").write_text((lv / "settings.yaml").read_text().replace("n_levels: 8", "n_levels: 1000"))
    add("n_levels_1000", "orb.n_levels: 1000 in the settings file", lambda b, o: [b, "run", "-q", "-d", lv, "-o", o])
    add("n_minus_1", "-n -1", lambda b, o: [b, "run", "-q", "-d", base, "-o", o, "-n", "-1"])
    est = work / "huge_estimate.txt"
    est.write_text("".join(l if i != 3 else l.split()[0] + " 1e300 0 0 0 0 0 1\n"
                           for i, l in enumerate((base / "groundtruth.txt").read_text().splitlines(True))))
    add("eval_1e300", "varslam eval, estimate with a 1e300 coordinate",
        lambda b, o: [b, "eval", "--gt", base / "groundtruth.txt", "--est", est])
    bx = copy_base(base, work, "huge_box"); (bx / "boxes.txt").write_text((bx / "boxes.txt").read_text() + "1311870436.8 person 1 1e300 0 10 10\n")
    add("box_1e300", "a boxes value of 1e300", lambda b, o: [b, "run", "-q", "-d", bx, "-o", o, "--set", "semantic.detector=boxes"])
    for name, desc, yaml in (("yaml_key_typo", "settings key typo (tracking.kernl)", "tracking:\n  kernl: huber\n"),
                             ("yaml_nan", "settings NaN (tracking.barron_alpha: .nan)", "tracking:\n  barron_alpha: .nan\n"),
                             ("yaml_negative", "negative count (tracking.close_keyframe_gap: -5)", "tracking:\n  close_keyframe_gap: -5\n")):
        d = copy_base(base, work, name); (d / "settings.yaml").write_text((d / "settings.yaml").read_text() + yaml)
        add(name, desc, lambda b, o, d=d: [b, "run", "-q", "-d", d, "-o", o])
    add("set_key_typo", "--set tracking.kernl=huber", lambda b, o: [b, "run", "-q", "-d", base, "-o", o, "--set", "tracking.kernl=huber"])
    return c


def stale_after_gtless(binary, base, work, o):
    """A run with ground truth, then one without into the same --out: does the old metrics.json stay?"""
    ng = copy_base(base, work, "no_gt"); (ng / "groundtruth.txt").unlink()
    subprocess.run([binary, "run", "-q", "-d", base, "-o", o], capture_output=True)
    r = subprocess.run([binary, "run", "-q", "-d", ng, "-o", o, "-n", "1"], capture_output=True, text=True)
    left = [f for f in ("CameraTrajectory_aligned.txt",) if (Path(o) / f).exists()]
    return r.returncode, ("stale from the first run: " + ", ".join(left)) if left else "earlier outputs removed"


def sigint(binary, base, work, o):
    # A shell's background job inherits SIGINT ignored: give the child the default, as a terminal would.
    p = subprocess.Popen([binary, "run", "-q", "-d", base, "-o", o], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(2.0)
    p.send_signal(signal.SIGINT)
    try:
        out, _ = p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        p.kill()
        return "-", "did not stop within 30 s of SIGINT"
    traj = Path(o) / "CameraTrajectory.txt"
    return p.returncode, (explain(out) + f" | CameraTrajectory.txt {'written' if traj.exists() else 'missing'}")


def concurrent(binary, base, work, o):
    ps = [subprocess.Popen([binary, "run", "-q", "-d", base, "-o", o], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
          for _ in range(2)]
    outs = [p.communicate(timeout=300)[0] for p in ps]
    return ",".join(str(p.returncode) for p in ps), " / ".join(explain(x)[:80] for x in outs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--work", default="/tmp/varslam_bad_input")
    ap.add_argument("--only", nargs="*", help="case names to run (default: all)")
    ap.add_argument("binaries", nargs="+")
    a = ap.parse_args()
    work = Path(a.work); work.mkdir(parents=True, exist_ok=True)
    base = work / "base"
    if not base.exists():
        subprocess.run([a.binaries[-1], "synth", "--scenario", "walking", "--seconds", "3", "--out", base, "--no-preview"],
                       check=True, capture_output=True)
    rows = []
    a.only = set(a.only or [])
    for name, desc, argv_fn, _ in cases(base, work):
        if a.only and name not in a.only:
            continue
        row = [name, desc]
        for i, b in enumerate(a.binaries):
            o = work / f"out_{i}_{name}"
            shutil.rmtree(o, ignore_errors=True)
            r = subprocess.run([str(x) for x in argv_fn(b, str(o))], capture_output=True, text=True, timeout=600)
            row.append(f"{r.returncode}: {explain(r.stdout + r.stderr)[:160]}")
        rows.append(row)
        print(name, file=sys.stderr)
    for name, desc, fn in (("stale_out", "ground-truth-less run into an earlier run's --out", stale_after_gtless),
                           ("sigint", "SIGINT 2 s into a run", sigint),
                           ("concurrent_out", "two concurrent runs into one --out", concurrent)):
        if a.only and name not in a.only:
            continue
        row = [name, desc]
        for i, b in enumerate(a.binaries):
            o = work / f"out_{i}_{name}"
            shutil.rmtree(o, ignore_errors=True)
            code, msg = fn(b, base, work, str(o))
            row.append(f"{code}: {msg[:160]}")
        rows.append(row)
    print("| case | input | " + " | ".join(f"binary {i + 1}: exit: message" for i in range(len(a.binaries))) + " |")
    print("|" + "---|" * (2 + len(a.binaries)))
    for r in rows:
        print("| " + " | ".join(x.replace("|", "\\|") for x in r) + " |")


if __name__ == "__main__":
    main()
