#!/usr/bin/env python3
"""Relative RMS difference of two RADIANCE float matrices (rcontrib -faf output) or two BSDF
XML files (genBSDF's); with
--plot CSV SVG, a log-log plot of wall time against error per case and program (plain SVG, so
the benchmark needs nothing beyond Python); with --mean OUT IN..., the mean of matrices (a
reference from several runs), written with the first one's header."""
import csv
import math
import struct
import sys


def load(path):
    data = open(path, 'rb').read()
    if data.startswith(b'<?xml'):  # a BSDF (genBSDF): every <ScatteringData> value in order
        import re
        return [float(v) for block in re.findall(rb'<ScatteringData>(.*?)</ScatteringData>',
                                                  data, re.S) for v in block.split()]
    body = data.index(b'\n\n') + 2
    n = (len(data) - body) // 4
    return struct.unpack('<%df' % n, data[body:body + 4 * n])


def mean(out_path, paths):
    data = open(paths[0], 'rb').read()
    header = data[:data.index(b'\n\n') + 2]
    runs = [load(p) for p in paths]
    if len(set(len(r) for r in runs)) != 1:
        sys.exit('sizes differ')
    avg = [sum(v) / len(runs) for v in zip(*runs)]
    with open(out_path, 'wb') as f:
        f.write(header + struct.pack('<%df' % len(avg), *avg))


def rel_rms(a, b):
    if len(a) != len(b):
        sys.exit('sizes differ: %d and %d' % (len(a), len(b)))
    num = sum((x - y) ** 2 for x, y in zip(a, b))
    den = sum(y * y for y in b)
    return math.sqrt(num / den)


def plot(csv_path, svg_path):
    rows = list(csv.DictReader(open(csv_path)))
    series = {}
    for r in rows:
        err = max(float(r['rel_rms']), 1e-8)
        series.setdefault((r['case'], r['program']), []).append((float(r['wall_s']), err))
    ts = [max(t, 0.01) for s in series.values() for t, _ in s]
    es = [e for s in series.values() for _, e in s]
    lt0, lt1 = math.log10(min(ts)) - .1, math.log10(max(ts)) + .1
    le0, le1 = math.log10(min(es)) - .1, math.log10(max(es)) + .1
    w, h, m = 640, 420, 60
    X = lambda t: m + (math.log10(max(t, 0.01)) - lt0) / (lt1 - lt0) * (w - 2 * m)
    Y = lambda e: h - m - (math.log10(e) - le0) / (le1 - le0) * (h - 2 * m)
    colours = {'dayflux': '#1b7837', 'dayflux-vulkan': '#e08214', 'radiance': '#762a83',
               'dayflux-asub2': '#5aae61', 'dayflux-asub3': '#2166ac',
               'dayflux-embree': '#1b7837'}
    marks = {'V': 'circle', 'DC': 'rect', 'Cds': 'diamond'}
    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="12">' % (w, h),
           '<rect width="100%" height="100%" fill="white"/>',
           '<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' % (m, h - m, w - m, h - m),
           '<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' % (m, m, m, h - m),
           '<text x="%d" y="%d" text-anchor="middle">wall time, s (log)</text>' % (w / 2, h - 15),
           '<text x="15" y="%d" transform="rotate(-90 15 %d)" text-anchor="middle">relative RMS error (log)</text>' % (h / 2, h / 2)]
    for d in range(math.floor(lt0), math.ceil(lt1) + 1):
        if lt0 <= d <= lt1:
            out.append('<text x="%.0f" y="%d" text-anchor="middle">%g</text>' % (X(10 ** d), h - m + 15, 10 ** d))
    for d in range(math.floor(le0), math.ceil(le1) + 1):
        if le0 <= d <= le1:
            out.append('<text x="%d" y="%.0f" text-anchor="end">1e%d</text>' % (m - 5, Y(10 ** d) + 4, d))
    for (case, prog), pts in sorted(series.items()):
        pts.sort()
        c = colours.get(prog, 'black')
        path = ' '.join('%.1f,%.1f' % (X(t), Y(e)) for t, e in pts)
        out.append('<polyline points="%s" fill="none" stroke="%s"/>' % (path, c))
        for t, e in pts:
            out.append('<circle cx="%.1f" cy="%.1f" r="4" fill="%s"/>' % (X(t), Y(e), c))
        t, e = pts[-1]
        out.append('<text x="%.1f" y="%.1f" fill="%s">%s %s</text>' % (X(t) + 6, Y(e) - 6, c, case, prog))
    out.append('</svg>')
    open(svg_path, 'w').write('\n'.join(out) + '\n')


if __name__ == '__main__':
    if sys.argv[1] == '--plot':
        plot(sys.argv[2], sys.argv[3])
    elif sys.argv[1] == '--mean':
        mean(sys.argv[2], sys.argv[3:])
    else:
        print('%.4g' % rel_rms(load(sys.argv[1]), load(sys.argv[2])))
