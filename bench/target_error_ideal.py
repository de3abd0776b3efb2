#!/usr/bin/env python3
"""The most any allocation of samples could gain over fixed -ad at equal 95th-percentile error.

From a -target_error report (rcontrib-gpu -target_report: sensor, samples, relative standard
error), each sensor's error at N samples is taken as error x sqrt(samples / N). For each p95
error X given, prints the fixed N whose sensors' pooled errors (normal, zero mean) have X as their
95th percentile, and the mean samples of the ideal allocation, where every sensor is given just
what brings it to the standard error X / 1.96 (what -target_error aims at).

usage: bench/target_error_ideal.py REPORT X [X ...]
"""
import math
import sys
from statistics import NormalDist


def pooled_p95(variances, samples):
    """The 95th percentile of |error| over sensors with these variances at `samples`."""
    sigmas = [math.sqrt(v / samples) for v in variances]
    lo, hi = 0.0, 10.0
    for _ in range(60):
        mid = (lo + hi) / 2
        share = sum(2 * NormalDist(0, s).cdf(mid) - 1 for s in sigmas) / len(sigmas)
        lo, hi = (mid, hi) if share < 0.95 else (lo, mid)
    return lo


def main():
    rows = [line.split() for line in open(sys.argv[1]) if not line.startswith("#")]
    # each sensor's variance of one sample's worth (error^2 x samples); sensors that saw no light
    # have no relative error to allocate for
    variances = [float(r[1]) * float(r[2]) ** 2 for r in rows if float(r[2]) > 0]
    for x in map(float, sys.argv[2:]):
        lo, hi = 1.0, 1e9
        for _ in range(80):
            mid = math.sqrt(lo * hi)
            lo, hi = (mid, hi) if pooled_p95(variances, mid) > x else (lo, mid)
        ideal = sum(v / (x / 1.96) ** 2 for v in variances) / len(variances)
        print(f"p95 {x:.3f}: fixed {lo:.0f} samples, ideal mean {ideal:.0f}, gain {lo / ideal:.2f}x")


if __name__ == "__main__":
    main()
