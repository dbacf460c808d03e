#!/usr/bin/env bash
# Builds and tests the trees `make test` runs, then prints one summary for all of them.
#
#   scripts/test.sh [main] [asan] [tsan] [fuzz]     (no argument: all four, in that order)
#
#   main  build/       RelWithDebInfo; every test
#   asan  build-asan/  AddressSanitizer + UndefinedBehaviorSanitizer; every test except those
#                      labelled realtime or benchmark (timing means nothing under ASAN)
#   tsan  build-tsan/  ThreadSanitizer; the tests labelled concurrency, and only what they need, are
#                      built and run, except those also labelled realtime (their timing cannot
#                      hold in a build 5 to 15 times slower: a hard task misses its first deadline;
#                      sanitizer trees do not build them either)
#   fuzz  build-fuzz/  clang, libFuzzer + ASAN + UBSAN: only the fuzz targets of tests/fuzz are
#                      built; each fuzzes for FUZZ_SECONDS (default here 15) from its seed corpus
#                      and fails on any crash, leak or hang (`make fuzz`: 60 s each)
#
# A tree that fails does not stop the others; the exit status is non-zero if any tree failed.
# Environment: JOBS (default 2), TEST_TIMEOUT (seconds per test, default 300; sanitizer trees
# get three times that), BUILD_DIR / ASAN_DIR / TSAN_DIR / FUZZ_DIR to move the trees, CI=true
# for -Werror.
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

jobs="${JOBS:-2}"
timeout="${TEST_TIMEOUT:-300}"
san_timeout=$((timeout * 3))

stages=("$@")
((${#stages[@]})) || stages=(main asan tsan fuzz)

# Sanitized trees: asserts on (Debug defines no NDEBUG) at -O1, which the sanitizer manuals
# recommend for usable speed. Warnings stay on but are not errors there: GCC's instrumentation
# produces false -Wmaybe-uninitialized / -Wstringop-* reports, and the main tree already
# compiles the same sources with -Werror in CI. Debug information is line tables only (-g1): a
# sanitizer's report names every frame's file and line with it, and the full -g cost a sixth of
# the sanitizer trees' compile time (control_api.cpp under ASAN: 25.4 s, 20.9 s with -g1) on a
# clean CI machine, which has 45 minutes for all four trees.
san_build=(-DCMAKE_BUILD_TYPE=Debug "-DCMAKE_C_FLAGS_DEBUG=-g1 -O1" "-DCMAKE_CXX_FLAGS_DEBUG=-g1 -O1"
  -DCHIMERA_WERROR=OFF)

declare -A build_status test_summary stage_time failed_tests BUILD_DIRS
total_passed=0
total_failed=0
any_failed=0

# run_stage NAME DIR "CMAKE_ARGS" "CTEST_ARGS" [ENV=VALUE...]
run_stage() {
  local name="$1" dir="$2"
  local -a cmake_args ctest_args
  read -r -a cmake_args <<<"$3"
  read -r -a ctest_args <<<"$4"
  shift 4
  local start=${SECONDS}
  BUILD_DIRS[${name}]="${dir}"
  echo
  echo "=== ${name}: build ${dir}"
  (
    # The sanitizer options must be set for the build too: gtest_discover_tests runs each test
    # program at build time to list its tests.
    for kv in "$@"; do export "${kv?}"; done
    scripts/build.sh "${dir}" "${cmake_args[@]}" "${extra_cmake[@]+"${extra_cmake[@]}"}"
  )
  if (($? != 0)); then
    build_status[${name}]="FAILED"
    test_summary[${name}]="not run"
    stage_time[${name}]=$((SECONDS - start))
    total_failed=$((total_failed + 1))
    any_failed=1
    return
  fi
  build_status[${name}]="ok"

  echo "=== ${name}: ctest ${ctest_args[*]}"
  local log="${dir}/chimera-ctest.log"
  (
    for kv in "$@"; do export "${kv?}"; done
    ctest --test-dir "${dir}" --output-on-failure -j "${jobs}" "${ctest_args[@]}"
  ) 2>&1 | tee "${log}"
  local rc=${PIPESTATUS[0]}

  # ctest closes with "NN% tests passed, F tests failed out of T", or says it found none.
  local line passed=0 failed=0
  line="$(grep -E '^[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "${log}" | tail -n 1)"
  if [[ -n "${line}" ]]; then
    failed="$(sed -E 's/.* ([0-9]+) tests? failed out of.*/\1/' <<<"${line}")"
    passed=$(($(sed -E 's/.*failed out of ([0-9]+).*/\1/' <<<"${line}") - failed))
    test_summary[${name}]="${passed} passed, ${failed} failed"
    # ctest lists each failure as "  N - NAME (Failed)" after "The following tests FAILED:".
    failed_tests[${name}]="$(sed -n '/^The following tests FAILED:/,/^[^[:space:]]/p' "${log}" |
      sed -nE 's/^[[:space:]]+[0-9]+ - (.*)$/\1/p')"
  else
    test_summary[${name}]="no tests"
  fi
  if ((rc != 0 && failed == 0)); then
    failed=1  # ctest failed without a failing test (no tests where some were required, a crash)
    test_summary[${name}]+=" (ctest exit ${rc})"
  fi
  total_passed=$((total_passed + passed))
  total_failed=$((total_failed + failed))
  ((rc == 0)) || any_failed=1
  stage_time[${name}]=$((SECONDS - start))
}

extra_cmake=()
for stage in "${stages[@]}"; do
  case "${stage}" in
    main)
      # In CI (CI=true) the main tree, too, has line tables only: CI's clean machine has 45
      # minutes for the four trees and no compiler cache. A developer's `make test` keeps -g.
      [[ "${CI:-}" == true ]] && extra_cmake=("-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"
        "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG")
      run_stage main "${BUILD_DIR:-build}" "-DCMAKE_BUILD_TYPE=RelWithDebInfo" \
        "--timeout ${timeout} --no-tests=error"
      extra_cmake=()
      ;;
    asan)
      # detect_leaks=1: LeakSanitizer starts fine on the project's machines, where CI runs too
      # (checked with a deliberate leak); were ptrace ever denied, it would fail loudly, not pass.
      extra_cmake=("${san_build[@]}")
      run_stage asan "${ASAN_DIR:-build-asan}" "-DCHIMERA_SANITIZE=address,undefined" \
        "--timeout ${san_timeout} --no-tests=ignore -LE realtime|benchmark" \
        "ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}" \
        "UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
      extra_cmake=()
      ;;
    tsan)
      extra_cmake=("${san_build[@]}")
      run_stage tsan "${TSAN_DIR:-build-tsan}" "-DCHIMERA_SANITIZE=thread" \
        "--timeout ${san_timeout} --no-tests=ignore -L concurrency -LE realtime" \
        "TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}" "BUILD_TARGETS=tests_concurrency"
      extra_cmake=()
      ;;
    fuzz)
      # The fuzzers' own budget bounds each test; the ctest timeout only catches a stuck one.
      extra_cmake=("${san_build[@]}")
      run_stage fuzz "${FUZZ_DIR:-build-fuzz}" \
        "-DCHIMERA_FUZZ=ON -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14" \
        "--timeout ${san_timeout} --no-tests=error -L fuzz" \
        "FUZZ_SECONDS=${FUZZ_SECONDS:-15}" "BUILD_TARGETS=fuzz_targets"
      extra_cmake=()
      ;;
    *)
      echo "test: unknown stage '${stage}' (main, asan, tsan, fuzz)" >&2
      exit 2
      ;;
  esac
done

echo
echo "=== summary"
printf '  %-6s %-7s %-40s %s\n' tree build tests time
for stage in "${stages[@]}"; do
  t=${stage_time[${stage}]}
  printf '  %-6s %-7s %-40s %dm%02ds\n' "${stage}" "${build_status[${stage}]}" "${test_summary[${stage}]}" \
    $((t / 60)) $((t % 60))
done
# Named again here because CI shows only the end of the log: which test failed must be in it.
for stage in "${stages[@]}"; do
  [[ -n "${failed_tests[${stage}]:-}" ]] || continue
  echo "  failed in ${stage}:"
  sed 's/^/    /' <<<"${failed_tests[${stage}]}"
  # And what they said: GoogleTest's "FILE:LINE: Failure" lines with the few after each, and
  # node --test's "✖ TEST" with its error (the browser tests), so that a failure seen once
  # in CI can be read without the middle of the log.
  grep -E -A4 ': Failure$' "${BUILD_DIRS[${stage}]}/chimera-ctest.log" 2>/dev/null | head -n 40 | sed 's/^/      | /'
  grep -A8 '^✖ [^f]' "${BUILD_DIRS[${stage}]}/chimera-ctest.log" 2>/dev/null | awk '!seen[$0]++' | head -n 40 | sed 's/^/      | /'
done
# The closing line counts the tests of all trees; a tree that did not build counts as one failure.
echo "chimera: ${total_passed} passed, ${total_failed} failed"
exit "${any_failed}"
