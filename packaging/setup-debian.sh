#!/usr/bin/env bash
# Set up volviz on a fresh Debian/Ubuntu machine: the system libraries Qt needs under X11/Xvfb, a virtual environment
# in .venv, and the package with its test extras. Safe to run again; it installs only what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

DEBS=(xvfb xauth libgl1 libegl1 libxrender1 libxcb-icccm4 libxcb-keysyms1 libxcb-xinerama0 libxcb-randr0
      libxcb-xfixes0 libxcb-shape0 libxcb-xkb1 libxcb-cursor0 libxcb-image0 libxcb-render-util0 libxkbcommon-x11-0
      libfontconfig1 libdbus-1-3 libgomp1)
if command -v dpkg-query >/dev/null 2>&1; then
  missing=()
  for pkg in "${DEBS[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "Installing Debian packages: ${missing[*]}"
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
else
  echo "Not a Debian system: install Xvfb and the X11/xcb libraries Qt needs yourself." >&2
fi

PYTHON=${PYTHON:-python3}
[ -x .venv/bin/python ] || "$PYTHON" -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
# volviz with its test extra and its own optional plugins (plugins/*: extra readers, the Dask compression backend),
# each plugin its own distribution, in one pip run (one resolution of the whole set)
plugins=()
for plugin in plugins/*/pyproject.toml; do
  plugins+=(-e "$(dirname "$plugin")")
done
.venv/bin/python -m pip install -q -e ".[test]" "${plugins[@]}"
# Compile the Numba kernels once, now, into their on-disk cache: the first scene, first test or first benchmark does
# not pay for it (about two minutes on 2 cores; seconds when the cache is already there).
.venv/bin/volviz warmup || echo "warning: volviz warmup failed (see above); kernels will compile at first use" >&2
echo "volviz is set up in $(pwd)/.venv"
