#!/usr/bin/env bash
# Runs clang-tidy (config: .clang-tidy) over the sources below the given folders, using the
# compile commands of a configured build tree; fails if any file has a finding.
#
#   scripts/tidy.sh BUILD_DIR [FOLDER...]      (default folder: src)
#
# JOBS (default 2) files are checked at a time; each file's findings are printed together.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build="${1:?usage: scripts/tidy.sh BUILD_DIR [FOLDER...]}"
shift
folders=("$@")
((${#folders[@]})) || folders=(src)
[[ -f "${build}/compile_commands.json" ]] || {
  echo "tidy: ${build}/compile_commands.json not found; configure ${build} first (make build)" >&2
  exit 1
}
tidy="$(command -v clang-tidy || command -v clang-tidy-14 || true)"
[[ -n "${tidy}" ]] || { echo "tidy: clang-tidy not found (scripts/setup.sh lint installs it)" >&2; exit 1; }

mapfile -t files < <(find "${folders[@]}" -type f \( -name '*.cpp' -o -name '*.cc' \) | sort)
((${#files[@]})) || { echo "tidy: no sources below ${folders[*]}"; exit 0; }
echo "tidy: ${#files[@]} files below ${folders[*]}"

# One clang-tidy per file; its output is collected and printed in one piece so that parallel
# runs do not interleave. -Wno-unknown-warning-option: the database holds GCC's command lines.
export TIDY="${tidy}" BUILD="${build}"
printf '%s\0' "${files[@]}" | xargs -0 -P "${JOBS:-2}" -n 1 bash -c '
  out="$("${TIDY}" -p "${BUILD}" --quiet --warnings-as-errors="*" \
         --extra-arg=-Wno-unknown-warning-option "$0" 2>&1)"
  rc=$?
  out="$(grep -v -E "^[0-9]+ (warnings?|errors?)( and [0-9]+ (warnings?|errors?))? generated\.$" <<<"${out}" || true)"
  [[ -z "${out}" ]] || printf "%s\n" "${out}"
  exit $(( rc == 0 ? 0 : 1 ))' && status=0 || status=$?
if ((status == 0)); then
  echo "tidy: clean"
else
  echo "tidy: findings above" >&2
  exit 1
fi
