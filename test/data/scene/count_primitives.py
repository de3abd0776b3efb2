#!/usr/bin/env python3
"""Counts primitives by type in RADIANCE scene text on stdin (used on RADIANCE xform's output to
make counts.txt; see make_counts.sh)."""
import collections, sys

words = []
for line in sys.stdin:
    s = line.strip()
    if not s or s.startswith('#'):
        continue
    words.extend(s.split())
counts = collections.Counter()
i = 0
while i < len(words):
    mod, typ, name = words[i:i + 3]
    i += 3
    if typ == 'alias':
        i += 1
    else:
        ns = int(words[i]); i += 1 + ns
        ni = int(words[i]); i += 1 + ni
        nf = int(words[i]); i += 1 + nf
    counts[typ] += 1
print(sum(counts.values()), ' '.join(f'{t}={n}' for t, n in sorted(counts.items())))
