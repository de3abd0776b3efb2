#!/usr/bin/env bash
# The README's main command: set up, build, and run the flagship example.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/tools/build.sh"
exec "$root/examples/reference-office/run.sh" "$@"
