#!/usr/bin/env bash
# The project's test command: installs the programs the tests drive, where it can, then runs
# every test of the workspace (`cargo test --workspace`, with any arguments given here).
#
# The tests compare exports and the editor against independent programs, and fail (never skip)
# when one is missing: Chromium and chromedriver (the editor's page), MuPDF, poppler and
# Ghostscript (PDF), Inkscape (SVG), and Python's venv (the bindings). On Debian and Ubuntu the
# missing ones are installed with apt-get (through sudo when not root); elsewhere, or when that
# fails, the script names what is missing and runs the tests anyway.
set -euo pipefail
cd "$(dirname "$0")/.."

# Each needed program: "command to find it|Debian package".
needs=(
  "command -v chromium || command -v chromium-browser|chromium"
  "command -v chromedriver|chromium-driver"
  "command -v mutool|mupdf-tools"
  "command -v pdftoppm|poppler-utils"
  "command -v gs|ghostscript"
  "command -v inkscape|inkscape"
  "python3 -c 'import ensurepip, venv'|python3-venv"
)

missing() { # the Debian packages whose program is not found
  local need
  for need in "${needs[@]}"; do
    if ! bash -c "${need%|*}" >/dev/null 2>&1; then echo "${need##*|}"; fi
  done
}

mapfile -t wanted < <(missing)
if [ ${#wanted[@]} -gt 0 ]; then
  echo "test.sh: installing ${wanted[*]}" >&2
  sudo=()
  if [ "$(id -u)" != 0 ]; then sudo=(sudo); fi
  if ! command -v apt-get >/dev/null; then
    echo "test.sh: no apt-get here: install the programs of ${wanted[*]} yourself" >&2
  elif [ ${#sudo[@]} -gt 0 ] && ! command -v sudo >/dev/null; then
    echo "test.sh: not root and no sudo: cannot install ${wanted[*]}" >&2
  else
    export DEBIAN_FRONTEND=noninteractive
    "${sudo[@]}" apt-get update -qq || echo "test.sh: apt-get update failed" >&2
    "${sudo[@]}" apt-get install -y -qq "${wanted[@]}" >/dev/null ||
      echo "test.sh: apt-get install failed" >&2
  fi
  mapfile -t still < <(missing)
  if [ ${#still[@]} -gt 0 ]; then
    echo "test.sh: could not install ${still[*]}: the tests that need them will fail, naming them" >&2
  fi
fi

if [ ! -d ../shared/realdata ]; then
  echo "test.sh: ../shared/realdata is missing beside the repository: the tests that read it will fail" >&2
fi

exec cargo test --workspace "$@"
