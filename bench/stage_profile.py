#!/usr/bin/env python3
"""CPU time per pipeline stage from `perf record` recordings, side by side (issue #30's per-stage profile).

  perf record -F 999 -o A.data build/bin/varslam run -d ../shared/realdata/7scenes_redkitchen -q -o /tmp/a \
      --set semantic.detector=none
  bench/stage_profile.py --frames 1000 NAME_A A.data NAME_B B.data

Each sample's function (and library) names its stage; the table gives CPU milliseconds per frame, summed over
all threads (the dataset reader's included), and the ratio of the first recording to each other one.
"""
import argparse
import collections
import re
import subprocess
import sys

STAGES = [  # (stage, library pattern, function pattern; None: none), the first match wins
    ('read: decode, depth, registration', r'libpng|libz\.|libjpeg|imgcodecs',
     r'register_depth_to_colour|project_row|llround|depth_to_metres|median_valid_depth|check_depth_scale'),
    ('ORB extraction', r'features2d',
     r'rotated_brief|angle_deg|spread_keypoints|detect_fast_grid|fast_in_rect|fast_in_cells|fast_score|OrbExtractor|build_pyramid|introsort|TaskPool'),
    ('optimisation: Local BA, pose', r'libceres',
     r'SchurLm|ceres|LocalBundle|local_ba|BarronKernel|KernelLoss|whitened_residual|linearize|log1p|expm1|'
     r'__ieee754_exp|Eigen::|ReprojectionCost|dpc_dpose|optimize_pose|Cost<'),
    ('matching', None, r'match|in_area|FrameFeatures|search_by|hamming|popcount|descriptor_distance'),
    ('image processing: blur, resize, colour', r'imgproc', None),
    ('kernel', r'kernel', None),
    ('libc: allocation, threads', r'libc\.|libstdc|ld-linux|libtbb|libgomp', None),
]
OTHER = 'other: map, keyframes, covisibility'


def stage_of(dso, symbol):
    for name, dso_pattern, symbol_pattern in STAGES:
        if (dso_pattern and re.search(dso_pattern, dso)) or (symbol_pattern and re.search(symbol_pattern, symbol)):
            return name
    return OTHER


def profile(path):
    """CPU seconds per stage in one recording."""
    report = subprocess.run(['perf', 'report', '-i', path, '--no-children', '--sort', 'dso,symbol', '-g', 'none',
                             '--percent-limit', '0', '--stdio'], capture_output=True, text=True, check=True).stdout
    total = re.search(r'# Event count \(approx\.\): (\d+)', report)
    if not total:
        sys.exit(f'stage_profile: {path}: no event count (record with the cpu-clock event, the default)')
    seconds = int(total.group(1)) / 1e9  # cpu-clock counts nanoseconds
    by_stage = collections.Counter()
    for line in report.splitlines():
        m = re.match(r'\s*([\d.]+)%\s+(\S+)\s+\[.\]\s+(.*)$', line)
        if m:
            by_stage[stage_of(m.group(2), m.group(3))] += float(m.group(1)) / 100 * seconds
    return by_stage


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--frames', type=int, required=True, help='frames the runs processed')
    parser.add_argument('pairs', nargs='+', help='NAME RECORDING, repeated')
    args = parser.parse_args()
    if len(args.pairs) % 2:
        parser.error('give a name and a recording for each run')
    names, paths = args.pairs[0::2], args.pairs[1::2]
    profiles = [profile(p) for p in paths]
    order = [s for s, _, _ in STAGES] + [OTHER]
    order.sort(key=lambda s: -profiles[0][s])
    ms = lambda p, s: 1000 * (sum(p.values()) if s == 'total' else p[s]) / args.frames
    print('| stage (CPU ms per frame) | ' + ' | '.join(names) +
          ''.join(f' | {names[0]} / {n}' for n in names[1:]) + ' |')
    print('|---|' + '--:|' * (2 * len(names) - 1))
    for s in order + ['total']:
        values = [ms(p, s) for p in profiles]
        ratios = [f'{values[0] / v:.2f}x' if v else '-' for v in values[1:]]
        print(f'| {s} | ' + ' | '.join(f'{v:.2f}' for v in values) + ''.join(f' | {r}' for r in ratios) + ' |')


if __name__ == '__main__':
    main()
