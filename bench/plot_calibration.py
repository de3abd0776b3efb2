#!/usr/bin/env python3
"""-target_error's calibration plot (issue 45): each sensor's estimated relative standard error
against its measured error (|ours / converged - 1|), on log axes, with the lines measured =
estimate and measured = 2 x estimate. An SVG written by hand: no plotting library is installed.

usage: bench/plot_calibration.py PAIRS.csv OUT.svg [TITLE]
PAIRS.csv: a header line, then "estimate,measured" per sensor and run.
"""
import csv
import math
import sys

W, H, LEFT, BOTTOM, TOP, RIGHT = 720, 480, 70, 60, 40, 20
LO, HI = 1e-3, 1.0  # both axes, relative errors


def pos(x, y):
    """SVG coordinates of (x, y) on the log-log axes."""
    fx = (math.log10(max(x, LO)) - math.log10(LO)) / (math.log10(HI) - math.log10(LO))
    fy = (math.log10(max(y, LO)) - math.log10(LO)) / (math.log10(HI) - math.log10(LO))
    return LEFT + fx * (W - LEFT - RIGHT), H - BOTTOM - fy * (H - BOTTOM - TOP)


def main():
    pairs = []
    with open(sys.argv[1]) as f:
        rows = csv.reader(f)
        next(rows)
        for estimate, measured in rows:
            pairs.append((float(estimate), abs(float(measured))))
    title = sys.argv[3] if len(sys.argv) > 3 else "-target_error calibration"
    within = sum(1 for e, m in pairs if m <= 2 * e) / max(1, len(pairs))
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
           'font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>']
    for decade in (1e-3, 1e-2, 1e-1, 1.0):
        x, y0 = pos(decade, LO)
        _, y1 = pos(decade, HI)
        out.append(f'<line x1="{x:.1f}" y1="{y0:.1f}" x2="{x:.1f}" y2="{y1:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{x:.1f}" y="{y0 + 16:.1f}" text-anchor="middle">'
                   f'{100 * decade:g} %</text>')
        x0, y = pos(LO, decade)
        x1, _ = pos(HI, decade)
        out.append(f'<line x1="{x0:.1f}" y1="{y:.1f}" x2="{x1:.1f}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{x0 - 6:.1f}" y="{y + 4:.1f}" text-anchor="end">'
                   f'{100 * decade:g} %</text>')
    for factor, dash, label in ((1, "", "measured = estimate"), (2, "6,4", "measured = 2 x estimate")):
        (x0, y0), (x1, y1) = pos(LO, factor * LO), pos(HI / factor, HI)
        out.append(f'<line x1="{x0:.1f}" y1="{y0:.1f}" x2="{x1:.1f}" y2="{y1:.1f}" '
                   f'stroke="#c33" stroke-dasharray="{dash}"/>')
        out.append(f'<text x="{x1 - 4:.1f}" y="{y1 + 14:.1f}" text-anchor="end" fill="#c33">'
                   f'{label}</text>')
    step = max(1, -(-len(pairs) // 1500))  # at most 1500 points drawn (the share counts all)
    for e, m in pairs[::step]:
        x, y = pos(e, m)
        out.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="1.6" fill="#246" fill-opacity="0.35"/>')
    out.append(f'<text x="{W / 2:.0f}" y="{H - 14}" text-anchor="middle">'
               'estimated relative standard error</text>')
    out.append(f'<text x="16" y="{H / 2:.0f}" text-anchor="middle" '
               f'transform="rotate(-90 16 {H / 2:.0f})">measured error |ours / converged - 1|</text>')
    out.append(f'<text x="{LEFT}" y="24">{title}: {len(pairs)} sensor runs '
               f'(1 in {step} drawn), {100 * within:.0f} % within twice the estimate</text>')
    out.append('</svg>')
    with open(sys.argv[2], "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
