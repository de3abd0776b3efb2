#!/usr/bin/env bash
# Splits a sensor (ray) file into shards of LINES lines each, named by the record each starts
# at (shard_000000001000.pts starts at record 1000), so that every engine that runs them can
# tell rcontrib-gpu where the shard sits in the whole run (-first_record) from the name alone.
# usage: split_sensors.sh SENSORS LINES DIR [RAYS_PER_RECORD]
#   RAYS_PER_RECORD: rcontrib's -c (1 by default); LINES must be a multiple of it.
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: $0 SENSORS LINES DIR [RAYS_PER_RECORD]" >&2; exit 2; }
sensors=$1 lines=$2 dir=$3 rays=${4:-1}
[ -r "$sensors" ] || { echo "$0: cannot read '$sensors'" >&2; exit 1; }
if ! [ "$lines" -gt 0 ] 2>/dev/null || ! [ "$rays" -gt 0 ] 2>/dev/null ||
    [ $((lines % rays)) -ne 0 ]; then
    echo "$0: LINES ($lines) must be a positive multiple of RAYS_PER_RECORD ($rays)" >&2
    exit 1
fi
mkdir -p "$dir"
rm -f "$dir"/shard_*.pts "$dir"/shard_*.mtx "$dir"/part_*
split -l "$lines" -d -a 6 "$sensors" "$dir/part_"
k=0
for f in "$dir"/part_*; do
    mv "$f" "$(printf '%s/shard_%012d.pts' "$dir" $((k * lines / rays)))"
    k=$((k + 1))
done
echo "$k shards of $lines lines in $dir"
