#!/usr/bin/env bash
# Proves that the README's two commands work on a fresh Debian 12: builds a minimal Debian 12 root
# with debootstrap (build-essential, cmake, git, GoogleTest and Google Benchmark, nothing else: the
# machine the issue describes), clones this repository's HEAD into it and runs a make target there,
# so that every package the build needs must come from scripts/packages.txt through `make`.
#
#   sudo scripts/fresh-debian-check.sh [--target TARGET] [--root DIR] [--keep] [--mirror URL]
#
#   --target   what to run in the root (default `test`: the whole `make test`, about an hour on two
#              cores); `configure` runs `make setup` and configures the main tree only (minutes),
#              which is what catches a package missing from the list; any other make target runs
#              as `make TARGET` (e.g. demo)
#   --root     where the root goes (default /var/tmp/chimera-fresh-debian); reused when present,
#              so a second run skips debootstrap; --keep leaves it after the run
#   --mirror   the Debian mirror (default http://deb.debian.org/debian)
#
# Not run by CI (it downloads a Debian system and takes longer than CI's budget); run it before a
# release and after any change to the build's dependencies (README, Requirements).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

target=test
root=/var/tmp/chimera-fresh-debian
keep=0
mirror=http://deb.debian.org/debian
while (($#)); do
  case "$1" in
    --target) target="$2"; shift 2 ;;
    --root) root="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    --mirror) mirror="$2"; shift 2 ;;
    -h | --help) sed -n '2,18p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "fresh-debian-check: unknown argument $1 (try --help)" >&2; exit 2 ;;
  esac
done

((EUID == 0)) || { echo "fresh-debian-check: needs root (debootstrap and chroot)" >&2; exit 2; }
if ! command -v debootstrap >/dev/null 2>&1; then
  echo "fresh-debian-check: installing debootstrap"
  apt-get install -y -qq debootstrap >/dev/null
fi

# What the issue's fresh machine had, and nothing more.
base_packages=build-essential,cmake,git,libgtest-dev,libbenchmark-dev,ca-certificates

if [[ ! -x "${root}/usr/bin/cmake" ]]; then
  echo "fresh-debian-check: debootstrap bookworm into ${root} (a few minutes)"
  mkdir -p "${root}"
  debootstrap --variant=minbase --include="${base_packages}" bookworm "${root}" "${mirror}" \
    >"${root}.debootstrap.log" 2>&1 || {
    tail -20 "${root}.debootstrap.log" >&2
    exit 1
  }
fi

mounted=()
cleanup() {
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[i]}" 2>/dev/null || true; done
  if ((keep == 0)); then rm -rf "${root}/src"; fi
}
trap cleanup EXIT
# What the tests need of a running system: /proc, /dev (and its POSIX shared memory), /sys for
# CPU counts, the host's resolver for apt.
for m in proc sys dev dev/shm dev/pts; do
  mkdir -p "${root}/${m}"
  mount --bind "/${m}" "${root}/${m}"
  mounted+=("${root}/${m}")
done
cp /etc/resolv.conf "${root}/etc/resolv.conf"

# A clean clone of HEAD: what CI sees, without this tree's build directories or uncommitted files.
rm -rf "${root}/src"
git clone -q --no-hardlinks "$(pwd)" "${root}/src/chimera"
echo "fresh-debian-check: $(git rev-parse --short HEAD) cloned into the root; running ${target}"

case "${target}" in
  configure) inner='make setup && CONFIGURE_ONLY=1 bash scripts/build.sh build -DCMAKE_BUILD_TYPE=RelWithDebInfo' ;;
  *) inner="make ${target}" ;;
esac
start=${SECONDS}
if chroot "${root}" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin TERM=dumb CI=true \
  bash -c "cd /src/chimera && ${inner}"; then
  echo "fresh-debian-check: ${target} passed in a fresh Debian 12 root ($((SECONDS - start)) s)"
else
  status=$?
  echo "fresh-debian-check: ${target} FAILED in a fresh Debian 12 root (exit ${status}); the root is ${root}" >&2
  exit 1
fi
