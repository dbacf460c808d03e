#!/usr/bin/env bash
# Configures one build tree with Ninja and builds everything in it.
#
#   scripts/build.sh DIR [CMAKE_ARG...]
#
# Uses ccache when it is installed. Warnings become errors when CI=true (or CHIMERA_WERROR=ON is
# set in the environment); both are passed on every call, so a tree follows the current setting.
# JOBS (default 2) bounds the parallel compile jobs; CONFIGURE_ONLY=1 stops after configuring;
# BUILD_TARGETS (space-separated) builds only those targets and what they need.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

(($# >= 1)) || {
  echo "usage: scripts/build.sh DIR [CMAKE_ARG...]" >&2
  exit 2
}
dir="$1"
shift

werror="${CHIMERA_WERROR:-}"
[[ -n "${werror}" ]] || { [[ "${CI:-}" == "true" ]] && werror=ON || werror=OFF; }

args=(-G Ninja -DCHIMERA_WERROR="${werror}")
if command -v ccache >/dev/null 2>&1; then
  args+=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  # Paths below the source tree are hashed relative to it, so a fresh clone elsewhere (CI) still
  # hits the cache filled by an earlier one.
  export CCACHE_BASEDIR="${PWD}"
else
  args+=(-UCMAKE_C_COMPILER_LAUNCHER -UCMAKE_CXX_COMPILER_LAUNCHER)
fi

# A tree first configured by another generator cannot be switched to Ninja in place.
if [[ -f "${dir}/CMakeCache.txt" ]] && ! grep -qx 'CMAKE_GENERATOR:INTERNAL=Ninja' "${dir}/CMakeCache.txt"; then
  echo "build: ${dir} was configured with another generator; remove it (make clean) and retry" >&2
  exit 1
fi

# Re-running cmake on a configured tree takes about a second and changes nothing that is already
# up to date; it is what makes a changed CI or ccache setting take effect.
mkdir -p "${dir}"
log="${dir}/chimera-configure.log"
cmake -S . -B "${dir}" "${args[@]}" "$@" >"${log}" 2>&1 || {
  cat "${log}" >&2
  echo "build: configuring ${dir} failed" >&2
  exit 1
}
[[ "${CONFIGURE_ONLY:-0}" == 1 ]] && exit 0
targets=()
for t in ${BUILD_TARGETS:-}; do targets+=(--target "${t}"); done
cmake --build "${dir}" --parallel "${JOBS:-2}" "${targets[@]+"${targets[@]}"}"
