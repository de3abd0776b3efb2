#!/usr/bin/env python3
"""Generate the input matrices of the dctimestep benchmark (bench/dctimestep_bench.sh).

usage: make_dctimestep_inputs.py [OUTDIR]      (default /tmp/dayflux-bench)

Writes RADIANCE float matrices (NCOMP=3, little-endian float32, rows x cols x 3 interleaved)
filled with fixed-seed pseudo-random positive values:
    V.fmx   14250 x 145     view matrix
    T.fmx     145 x 145     BSDF transmission matrix
    D.fmx     145 x 146     daylight matrix
    S.fmx     146 x 8760    sky matrix (hours 19:00-04:59 all zero, 41.7% of columns)
    DC.fmx  14250 x 146     daylight coefficients
    Cds.fmx  1425 x 5186    direct-sun coefficients (MF:6 sun patches)
and the sun matrix sun_m6.fmx (5186 x 8760) made by RADIANCE's gendaymtx from the Oakland TMY3
weather file: epw2wea, then gendaymtx -5 0.533 -d -m 6 -of. Standard library only.
"""
import array
import os
import random
import subprocess
import sys

RADIANCE_BIN = os.environ.get('RADIANCE_BIN', '/opt/radiance/bin')
EPW = '/work/shared/data/weather/USA_CA_Oakland.Intl.AP.724930_TMY3.epw'
SEED = 20261121
CHUNK = 1 << 20  # values generated and written per chunk


def header(nrows, ncols):
    return ('#?RADIANCE\nNROWS=%d\nNCOLS=%d\nNCOMP=3\nBigEndian=0\nFORMAT=float\n\n'
            % (nrows, ncols)).encode('ascii')


def write_matrix(path, nrows, ncols, rng, scale=1.0, zero_col=None):
    """Writes nrows x ncols x 3 floats in (0.001, 1.001) * scale; columns with zero_col(j) true are 0."""
    n = nrows * ncols * 3
    rnd = rng.random
    if sys.byteorder != 'little':
        raise SystemExit('this script writes little-endian data on a little-endian machine only')
    with open(path, 'wb') as f:
        f.write(header(nrows, ncols))
        if zero_col is None:
            done = 0
            while done < n:
                m = min(CHUNK, n - done)
                f.write(array.array('f', [(rnd() + 0.001) * scale for _ in range(m)]).tobytes())
                done += m
        else:
            mask = [bool(zero_col(j)) for j in range(ncols)]
            zero3 = [0.0, 0.0, 0.0]
            rows_per_chunk = max(1, CHUNK // (3 * ncols))
            for r0 in range(0, nrows, rows_per_chunk):
                vals = []
                for _ in range(min(rows_per_chunk, nrows - r0)):
                    for z in mask:
                        if z:
                            vals += zero3
                        else:
                            vals += [(rnd() + 0.001) * scale, (rnd() + 0.001) * scale, (rnd() + 0.001) * scale]
                f.write(array.array('f', vals).tobytes())
    print('wrote %s (%d x %d)' % (path, nrows, ncols), flush=True)


def make_sun(outdir):
    env = dict(os.environ, RAYPATH='.:/opt/radiance/lib')
    wea = os.path.join(outdir, 'oak.wea')
    sun = os.path.join(outdir, 'sun_m6.fmx')
    subprocess.run([os.path.join(RADIANCE_BIN, 'epw2wea'), EPW, wea], check=True, env=env)
    log = os.path.join(outdir, 'gendaymtx.log')
    with open(sun + '.tmp', 'wb') as f, open(log, 'wb') as err:  # its many warnings go to the log
        subprocess.run([os.path.join(RADIANCE_BIN, 'gendaymtx'), '-5', '0.533', '-d', '-m', '6', '-of', wea],
                       check=True, stdout=f, stderr=err, env=env)
    os.replace(sun + '.tmp', sun)
    print('wrote %s (gendaymtx -5 0.533 -d -m 6 -of; messages in %s)' % (sun, log), flush=True)


def main(argv):
    outdir = os.path.abspath(argv[1] if len(argv) > 1 else '/tmp/dayflux-bench')
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.path.commonpath([outdir, repo]) == repo:
        raise SystemExit('refusing to write inside the repository: ' + outdir)
    os.makedirs(outdir, exist_ok=True)
    rng = random.Random(SEED)
    write_matrix(os.path.join(outdir, 'V.fmx'), 14250, 145, rng, 0.01)
    write_matrix(os.path.join(outdir, 'T.fmx'), 145, 145, rng, 0.01)
    write_matrix(os.path.join(outdir, 'D.fmx'), 145, 146, rng, 0.01)
    write_matrix(os.path.join(outdir, 'S.fmx'), 146, 8760, rng, 100.0,
                 zero_col=lambda j: j % 24 < 5 or j % 24 >= 19)
    write_matrix(os.path.join(outdir, 'DC.fmx'), 14250, 146, rng, 0.01)
    write_matrix(os.path.join(outdir, 'Cds.fmx'), 1425, 5186, rng, 0.01)
    make_sun(outdir)


if __name__ == '__main__':
    main(sys.argv)
