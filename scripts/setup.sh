#!/usr/bin/env bash
# Installs the Debian packages from scripts/packages.txt that are not installed yet.
#
#   scripts/setup.sh            every group not marked optional
#   scripts/setup.sh lint       those plus the optional group `lint`
#   scripts/setup.sh --check    install nothing; list what is missing, exit 1 if anything is
#
# Silent when nothing is missing, so `make` can run it every time (the check is one dpkg-query,
# a few milliseconds). apt's output goes to a log that is shown only when apt fails.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
list="${here}/packages.txt"

die() {
  echo "setup: $*" >&2
  exit 1
}

check_only=0
extra_groups=()
for arg in "$@"; do
  case "${arg}" in
    --check) check_only=1 ;;
    -h | --help)
      sed -n '2,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    -*) die "unknown option ${arg} (try --help)" ;;
    *) extra_groups+=("${arg}") ;;
  esac
done

[[ -r "${list}" ]] || die "cannot read ${list}"
command -v dpkg-query >/dev/null 2>&1 || die "dpkg-query not found: this script is for Debian 12 (apt/dpkg)"

# Collect the wanted packages: every non-optional group, plus optional groups named on the command line.
wanted=()
known_groups=()
while read -r group pkgs; do
  [[ -z "${group}" || "${group}" == \#* ]] && continue
  name="${group%\?}"
  known_groups+=("${name}")
  if [[ "${group}" == *\? ]]; then
    selected=0
    for g in "${extra_groups[@]+"${extra_groups[@]}"}"; do [[ "${g}" == "${name}" ]] && selected=1; done
    ((selected)) || continue
  fi
  read -r -a words <<<"${pkgs}"
  wanted+=("${words[@]}")
done <"${list}"
for g in "${extra_groups[@]+"${extra_groups[@]}"}"; do
  printf '%s\n' "${known_groups[@]}" | grep -qx -- "${g}" || die "no group '${g}' in ${list}"
done

# One dpkg-query for all of them; a package dpkg has never heard of is simply absent from the output.
installed="$(dpkg-query -W -f='${Package} ${Status}\n' "${wanted[@]}" 2>/dev/null | awk '$NF == "installed" {print $1}' || true)"
missing=()
for p in "${wanted[@]}"; do
  grep -qx -- "${p}" <<<"${installed}" || missing+=("${p}")
done

((${#missing[@]} == 0)) && exit 0

if ((check_only)); then
  echo "setup: missing packages: ${missing[*]}" >&2
  exit 1
fi

# Root runs apt directly; anyone else goes through sudo (which may ask for a password).
if [[ "$(id -u)" -eq 0 ]]; then
  as_root=(env)
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo env)
else
  die "missing packages: ${missing[*]}
       Installing them needs root and sudo is not available. As root, run:
       apt-get update && apt-get install ${missing[*]}"
fi

log="$(mktemp "${TMPDIR:-/tmp}/chimera-setup.XXXXXX.log")"
apt=("${as_root[@]}" DEBIAN_FRONTEND=noninteractive apt-get -qq -o Dpkg::Use-Pty=0
  -o DPkg::Lock::Timeout=600)  # wait for another apt (unattended upgrades, a parallel setup) instead of failing

echo "setup: installing ${#missing[@]} missing package(s): ${missing[*]}"
fail() {
  echo "setup: $1 failed; the last lines of ${log}:" >&2
  tail -n 40 "${log}" >&2
  exit 1
}
"${apt[@]}" update >"${log}" 2>&1 || fail "apt-get update"
"${apt[@]}" install -y --no-install-recommends "${missing[@]}" >>"${log}" 2>&1 || fail "apt-get install"
rm -f "${log}"
echo "setup: done"
