#!/usr/bin/env bash
# Merges the shards' matrices (DIR/shard_*.mtx, in record order) into OUTPUT with rmtxcat, after
# checking that every shard of DIR/shard_*.pts has its matrix: a missing or failed shard stops
# the merge with its name, and OUTPUT is not written.
# usage: merge_shards.sh DIR OUTPUT [rmtxcat options]
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 DIR OUTPUT [rmtxcat options]" >&2; exit 2; }
dir=$1 out=$2
shift 2
shards=("$dir"/shard_*.pts)
[ -e "${shards[0]}" ] || { echo "$0: no shards in '$dir'" >&2; exit 1; }
mtx=()
for s in "${shards[@]}"; do
    m=${s%.pts}.mtx
    [ -f "$m" ] || { echo "$0: shard '$s' has no matrix '$m' (not run, or failed)" >&2; exit 1; }
    mtx+=("$m")
done
rmtxcat "$@" "${mtx[@]}" > "$out.partial"
mv "$out.partial" "$out"
