#!/usr/bin/env bash
# Traces one shard made by split_sensors.sh: rcontrib-gpu with the options and scene given,
# told by -first_record where the shard starts (from its name), so that with a fixed -seed its
# rows are byte for byte those a single run over the whole sensor file writes. The matrix goes
# to OUTPUT.partial and is renamed to OUTPUT when complete.
# usage: trace_shard.sh SHARD OUTPUT rcontrib-gpu-options... scene...
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: $0 SHARD OUTPUT rcontrib-gpu-options... scene..." >&2; exit 2; }
shard=$1 out=$2
shift 2
name=$(basename "$shard" .pts)
first=${name#shard_}
[[ $first =~ ^[0-9]+$ ]] || { echo "$0: '$shard' is not named shard_<first record>.pts" >&2; exit 1; }
rcontrib-gpu -first_record $((10#$first)) "$@" < "$shard" > "$out.partial"
mv "$out.partial" "$out"
