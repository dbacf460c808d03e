#!/usr/bin/env bash
# Fuzzes one libFuzzer target for a bounded time (the fuzz tree's ctest tests run this).
#
#   scripts/fuzz_one.sh PROGRAM NAME INPUT_DIR...
#
# The INPUT_DIRs (the checked-in seed corpus and regressions) are read, never written: what the
# run adds to the corpus goes to $FUZZ_WORK/NAME/corpus (default: fuzz-work/ in the current
# directory, the build tree under ctest), and a crash, leak or hang to $FUZZ_WORK/NAME/ as
# crash-*, leak-*, timeout-* or oom-*, with libFuzzer's report on stderr. Exit 0 only if none was
# found. Environment: FUZZ_SECONDS (default 60) bounds the run; one input taking longer than
# FUZZ_INPUT_TIMEOUT seconds (default 10) is a hang.
set -euo pipefail
(($# >= 3)) || {
  echo "usage: scripts/fuzz_one.sh PROGRAM NAME INPUT_DIR..." >&2
  exit 2
}
program="$1"
name="$2"
shift 2

work="${FUZZ_WORK:-${PWD}/fuzz-work}/${name}"
mkdir -p "${work}/corpus"
# The targets run in the work folder: anything they create stays out of the source tree.
cd "${work}"
echo "fuzz ${name}: ${FUZZ_SECONDS:-60} s, findings in ${work}"
# -rss_limit_mb: a target that takes gigabytes for a small input is a finding, not a slow run.
exec "${program}" -max_total_time="${FUZZ_SECONDS:-60}" -timeout="${FUZZ_INPUT_TIMEOUT:-10}" \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="${work}/" corpus "$@"
