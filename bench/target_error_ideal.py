#!/usr/bin/env python3
"""What sharing samples out between sensors could save over fixed -ad at equal p95 error.

From a -target_error report (rcontrib-gpu -target_report: sensor, samples, relative standard
error), each sensor's error at N samples is taken as normal with standard deviation
error x sqrt(samples / N). For each pooled 95th percentile X given, prints:
- fixed: the N whose sensors' pooled |errors| have X as their 95th percentile;
- equal: the mean samples when every sensor is given just what brings it to the standard error
  X / 1.96 (what -target_error aims at);
- optimal: the least mean samples of any allocation with that pooled 95th percentile. It leaves
  the costliest sensors noisier: sensor i's error over its standard deviation is t_i, where
  v_i t_i = lambda phi(t_i) (v_i its variance for one sample, phi the normal density).
Both savings are upper bounds where the estimates are noisy (noise widens their spread).

usage: bench/target_error_ideal.py REPORT X [X ...]
"""
import math
import sys
from statistics import NormalDist

NORMAL = NormalDist()


def within(t):
    """The chance that a normal error lies within t standard deviations."""
    return 2 * NORMAL.cdf(t) - 1


def bisect(f, lo, hi, geometric=False, steps=200):
    """The x in [lo, hi] where the increasing f(x) crosses 0."""
    for _ in range(steps):
        mid = math.sqrt(lo * hi) if geometric else (lo + hi) / 2
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    return hi


def fixed_samples(variances, x):
    share = lambda n: sum(within(x * math.sqrt(n / v)) for v in variances) / len(variances)
    return bisect(lambda n: share(n) - 0.95, 1e-6, 1e15, geometric=True)


def optimal_samples(variances, x):
    def t_of(v, lam):  # v t / phi(t) rises with t
        return bisect(lambda t: v * t / NORMAL.pdf(t) - lam, 0.0, 40.0, steps=100)

    share = lambda lam: sum(within(t_of(v, lam)) for v in variances) / len(variances)
    lam = bisect(lambda lam: share(lam) - 0.95, 1e-12, 1e12, geometric=True)
    return sum(v * t_of(v, lam) ** 2 for v in variances) / len(variances) / x**2


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__.split("usage: ")[1])
    variances = []
    for line in open(sys.argv[1]):
        fields = line.split()
        if len(fields) != 3 or line.startswith("#"):
            continue
        samples, error = float(fields[1]), float(fields[2])
        # (a sensor that saw no light has no relative error to share samples out for)
        if samples > 0 and error > 0:
            variances.append(samples * error * error)  # one sample's
    if not variances:
        sys.exit(sys.argv[1] + ": no sensor with samples and an error")
    for x in map(float, sys.argv[2:]):
        fixed = fixed_samples(variances, x)
        equal = sum(v / (x / 1.96) ** 2 for v in variances) / len(variances)
        optimal = optimal_samples(variances, x)
        print(f"p95 {x:.3f}: fixed {fixed:.0f} samples; every sensor at one sigma {equal:.0f} "
              f"({fixed / equal:.2f}x); optimal {optimal:.0f} ({fixed / optimal:.2f}x)")


if __name__ == "__main__":
    main()
