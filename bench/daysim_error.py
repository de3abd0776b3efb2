#!/usr/bin/env python3
"""Errors of DAYSIM-style diffuse coefficient files (a line per sensor, 148 values; '#' lines
skipped; rcontrib's RGB triplets with --rgb: the first of each) against a reference:
  per-sensor sums (the irradiance under a uniform sky): relative RMS and mean (bias);
  every entry: relative RMS (sqrt(sum d^2 / sum ref^2)).
usage: daysim_error.py reference.dc file[:rgb] ...  -> one CSV line per file"""
import math
import sys


def load(spec):
    path, _, kind = spec.partition(':')
    rows = []
    for line in open(path):
        if line.startswith('#') or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        rows.append(v[::3] if kind == 'rgb' else v[:148])
    return path, rows


def main():
    _, ref = load(sys.argv[1])
    print('file,sensor_rms,sensor_mean,entry_rms')
    for spec in sys.argv[2:]:
        path, rows = load(spec)
        if len(rows) != len(ref) or any(len(r) != 148 for r in rows):
            sys.exit('%s: %d rows of %s values for %d sensors' %
                     (path, len(rows), sorted(set(len(r) for r in rows)), len(ref)))
        rel = [sum(a) / sum(b) - 1 for a, b in zip(rows, ref)]
        num = sum((x - y) ** 2 for a, b in zip(rows, ref) for x, y in zip(a, b))
        den = sum(y * y for b in ref for y in b)
        print('%s,%.4f,%+.4f,%.4f' % (path, math.sqrt(sum(r * r for r in rel) / len(rel)),
                                      sum(rel) / len(rel), math.sqrt(num / den)))


if __name__ == '__main__':
    main()
