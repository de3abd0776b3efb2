# Sourced by the benchmarks on the flagship example's year (after their `set -euo pipefail`): the
# paths they share, the example's DC and sky matrices (made if missing), and a temporary folder
# removed on exit.
# usage: source "$(dirname "$0")/example_common.sh" NAME
# environment: BUILD (build), RUNS (3), OUT (/tmp/dayflux-example-products: the example's output
# folder); sets here, root, bin, runs, out, tmp and csv (bench/results/NAME.csv)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(dirname "$here")
bin=$root/${BUILD:-build}/bin
runs=${RUNS:-3}
out=${OUT:-/tmp/dayflux-example-products}
csv=$here/results/$1.csv
make -s --no-print-directory -C "$root/examples/reference-office" BIN="$bin" OUT="$out" \
    "$out/dc.mtx" "$out/sky.smx" > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
