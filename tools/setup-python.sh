#!/usr/bin/env bash
# A Python for building and testing the softrne package (python/): a venv with numpy,
# nanobind and pytest from PyPI. Prints the venv's interpreter on stdout (the only line
# there); progress and errors go to stderr. Exits non-zero, saying why, when it cannot.
#
#   tools/setup-python.sh VENV_DIR
#
# The base interpreter is $PYTHON (default python3). A venv because Debian's own python3
# refuses pip outside one (PEP 668); it needs Debian's python3-venv and python3-dev (the
# headers), which tools/install-deps.sh installs. An existing venv is reused (pip then only
# checks the packages).
set -euo pipefail
if [[ $# -ne 1 ]]; then
  echo "usage: $0 VENV_DIR" >&2
  exit 2
fi
venv=$1
base=${PYTHON:-python3}
log() { echo "[setup-python] $*" >&2; }
PACKAGES=("numpy" "nanobind>=2.0,<4" "pytest")

if [[ ! -x "$venv/bin/python" ]]; then
  if ! command -v "$base" >/dev/null 2>&1; then
    log "no $base on PATH"
    exit 1
  fi
  if ! "$base" -c 'import os, sysconfig, sys; sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))'; then
    log "$(command -v "$base") has no headers (Python.h): apt-get install python3-dev"
    exit 1
  fi
  log "python -m venv $venv ($(command -v "$base"), $("$base" --version 2>&1))"
  if ! "$base" -m venv "$venv" >&2; then
    log "cannot create a venv with $(command -v "$base"): apt-get install python3-venv"
    rm -rf "$venv"
    exit 1
  fi
fi
py=$venv/bin/python
if ! "$py" -c 'import numpy, nanobind, pytest' >/dev/null 2>&1; then
  log "pip install ${PACKAGES[*]}"
  if ! "$py" -m pip install --disable-pip-version-check --no-input -q "${PACKAGES[@]}" >&2; then
    log "pip install failed (no network, or no wheel for this Python)"
    exit 1
  fi
fi
# Pinocchio (pip `pin`, ~80 MB of wheels) for the cross-check tests/pinocchio runs with this
# Python (ctest pinocchio.python_check): optional, so a failure here only leaves that test out.
if [[ "${SOFTRNE_PINOCCHIO:-1}" != 0 ]] && ! "$py" -c 'import pinocchio' >/dev/null 2>&1; then
  log "pip install pin  (Pinocchio, for the cross-check; SOFTRNE_PINOCCHIO=0 skips it)"
  "$py" -m pip install --disable-pip-version-check --no-input -q pin >&2 \
    || log "pip install pin failed: the Pinocchio cross-check is left out"
fi
echo "$(cd "$venv" && pwd)/bin/python"
