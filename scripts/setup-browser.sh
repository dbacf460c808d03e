#!/usr/bin/env bash
# Installs what the browser tests need beside the Debian packages (scripts/packages.txt installs
# chromium): Node.js and npm when the machine has none (Debian's), then playwright-core from the
# committed lock file into tests/browser/node_modules (npm ci: exactly the locked versions).
# Quiet and a few milliseconds when everything is there: the lock file's hash is kept beside
# what it installed. playwright-core downloads no browser; the tests drive /usr/bin/chromium.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

dir=tests/browser
stamp="${dir}/node_modules/.chimera-lock-sha256"

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  as_root=(env)
  [[ "$(id -u)" -eq 0 ]] || as_root=(sudo env)
  log="$(mktemp)"
  if ! "${as_root[@]}" DEBIAN_FRONTEND=noninteractive apt-get install -y -q nodejs npm >"${log}" 2>&1; then
    cat "${log}" >&2
    echo "setup-browser: apt-get install nodejs npm failed" >&2
    exit 1
  fi
  rm -f "${log}"
fi

want="$(sha256sum "${dir}/package-lock.json" | cut -d' ' -f1)"
[[ -f "${stamp}" && "$(cat "${stamp}")" == "${want}" ]] && exit 0

log="$(mktemp)"
if ! npm ci --prefix "${dir}" --no-audit --no-fund >"${log}" 2>&1; then
  cat "${log}" >&2
  echo "setup-browser: npm ci in ${dir} failed" >&2
  exit 1
fi
rm -f "${log}"
echo "${want}" >"${stamp}"
