#!/usr/bin/env bash
# Runs the benchmarks of a Release build tree and writes the report (see bench/run.py).
#
#   bench/run.sh [BUILD_DIR] [--quick] [--only NAME,...]
#
# Debian's python3 (with python3-matplotlib from scripts/packages.txt), not whatever python3
# comes first on PATH.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
build="${1:-build-bench}"
shift || true
exec /usr/bin/python3 bench/run.py "${build}" "$@"
