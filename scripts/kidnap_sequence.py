#!/usr/bin/env python3
"""Writes a "kidnapped camera" remix of a TUM-layout sequence: frames [0, END) and then [FROM, FROM+COUNT) again,
re-stamped at 30 Hz, with image folders linked (not copied) and the ground truth of each original frame.
The camera jumps from frame END-1 back to frame FROM: only relocalization or loop closing can put it back into the
map it built. Usage: kidnap_sequence.py SRC DST END FROM COUNT"""
import os
import sys


def rows(path):
    with open(path) as f:
        return [line.split() for line in f if line.strip() and not line.startswith('#')]


def main():
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    src, dst = sys.argv[1], sys.argv[2]
    end, start, count = (int(a) for a in sys.argv[3:6])
    os.makedirs(dst, exist_ok=True)
    for sub in ('rgb', 'depth'):
        link = os.path.join(dst, sub)
        if not os.path.exists(link):
            os.symlink(os.path.abspath(os.path.join(src, sub)), link)
    with open(os.path.join(src, 'settings.yaml')) as f, open(os.path.join(dst, 'settings.yaml'), 'w') as g:
        g.write(f.read())
    rgb, depth = rows(os.path.join(src, 'rgb.txt')), rows(os.path.join(src, 'depth.txt'))
    gt = {r[0]: r[1:] for r in rows(os.path.join(src, 'groundtruth.txt'))}
    order = list(range(end)) + list(range(start, start + count))
    t0 = float(rgb[0][0])
    out = {'rgb.txt': [], 'depth.txt': [], 'groundtruth.txt': []}
    for k, i in enumerate(order):
        t = '%.6f' % (t0 + k / 30.0)
        out['rgb.txt'].append(f'{t} {rgb[i][1]}')
        out['depth.txt'].append(f'{t} {depth[i][1]}')
        if rgb[i][0] in gt:
            out['groundtruth.txt'].append(' '.join([t] + gt[rgb[i][0]]))
    for name, lines in out.items():
        with open(os.path.join(dst, name), 'w') as f:
            f.write('\n'.join(lines) + '\n')


if __name__ == '__main__':
    main()
