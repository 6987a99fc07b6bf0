#!/usr/bin/env bash
# Install softrne's build, test and plotting dependencies on Debian 12 / Ubuntu 22.04+.
#
#   tools/install-deps.sh            apt packages (skips apt entirely when all are present)
#   tools/install-deps.sh --python   also numpy, scipy, matplotlib for the python3 on PATH
#                                    (pip into a venv/pyenv/user site; Debian's packages for
#                                    the system python3, which forbids pip, PEP 668)
#   tools/install-deps.sh --check    only report what is missing (exit 1 if anything is)
#
# Idempotent; works as root or through sudo; never prompts (CI, no stdin).
set -euo pipefail

APT_PACKAGES=(
  libeigen3-dev      # Eigen 3.4: softrne::softrne
  libsundials-dev    # SUNDIALS 6 CVODE: softrne::sim
  libnlopt-cxx-dev   # NLopt (C and C++ API): softrne::fit
  nlohmann-json3-dev # JSON robot descriptions and reports: io, tools
  libcli11-dev       # CLI11, the command lines of tools/ (header-only; not the library's)
  libgtest-dev       # tests
  libbenchmark-dev   # softrne-bench
  doxygen            # API docs (docs/Doxyfile, tools/build-docs.sh; CI phase 1)
  cmake
  ninja-build
  g++
  python3
  python3-venv       # the Python package's build and tests (tools/setup-python.sh: a venv)
  python3-dev        # Python.h for the extension
  python3-numpy      # plotting scripts
  python3-matplotlib
)
PY_MODULES=(numpy scipy matplotlib)

want_python=0
check_only=0
for arg in "$@"; do
  case "$arg" in
    --python) want_python=1 ;;
    --check) check_only=1 ;;
    -h | --help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "install-deps.sh: unknown argument '$arg' (try --help)" >&2; exit 2 ;;
  esac
done

log() { echo "[install-deps] $*"; }

# Root runs commands directly; others go through sudo (non-interactive without a tty).
as_root() {
  if [[ $(id -u) -eq 0 ]]; then
    "$@"
  elif command -v sudo >/dev/null 2>&1; then
    if [[ -t 0 ]]; then sudo "$@"; else sudo -n "$@"; fi
  else
    echo "install-deps.sh: need root or sudo to run: $*" >&2
    return 1
  fi
}

apt_missing() {  # prints the packages of "$@" that are not installed
  local p
  for p in "$@"; do
    if ! dpkg-query -W -f='${db:Status-Status}\n' "$p" 2>/dev/null | grep -qx installed; then
      echo "$p"
    fi
  done
}

apt_install() {  # installs "$@"; apt-get update first
  log "apt-get update"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get update -q
  log "apt-get install $*"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "$@"
}

install_apt_packages() {
  if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
    log "not a Debian/Ubuntu system: install these (or equivalents) yourself:"
    log "  ${APT_PACKAGES[*]}"
    return 0
  fi
  local missing
  mapfile -t missing < <(apt_missing "${APT_PACKAGES[@]}")
  if [[ ${#missing[@]} -eq 0 ]]; then
    log "all ${#APT_PACKAGES[@]} apt packages present"
    return 0
  fi
  log "missing: ${missing[*]}"
  if [[ $check_only -eq 1 ]]; then return 1; fi
  apt_install "${missing[@]}"
}

install_python_modules() {
  local py=${PYTHON:-python3} m missing=()
  for m in "${PY_MODULES[@]}"; do
    "$py" -c "import $m" >/dev/null 2>&1 || missing+=("$m")
  done
  if [[ ${#missing[@]} -eq 0 ]]; then
    log "python modules present for $(command -v "$py"): ${PY_MODULES[*]}"
    return 0
  fi
  log "python modules missing for $(command -v "$py"): ${missing[*]}"
  if [[ $check_only -eq 1 ]]; then return 1; fi
  # A Debian-managed interpreter (PEP 668 marker, not in a venv) gets Debian's packages.
  local managed
  managed=$("$py" -c 'import os, sys, sysconfig
in_venv = sys.prefix != getattr(sys, "base_prefix", sys.prefix)
marker = os.path.join(sysconfig.get_path("stdlib"), "EXTERNALLY-MANAGED")
print(int(os.path.exists(marker) and not in_venv))')
  if [[ "$managed" == 1 ]] && command -v apt-get >/dev/null 2>&1; then
    apt_install "${missing[@]/#/python3-}"
    return 0
  fi
  if ! "$py" -m pip --version >/dev/null 2>&1; then
    "$py" -m ensurepip --upgrade >/dev/null 2>&1 || apt_install python3-pip
  fi
  local user=()
  if [[ $(id -u) -ne 0 ]] && [[ "$("$py" -c 'import sys; print(int(sys.prefix == sys.base_prefix))')" == 1 ]] \
    && [[ ! -w "$("$py" -c 'import sysconfig; print(sysconfig.get_path("purelib"))')" ]]; then
    user=(--user)
  fi
  log "pip install ${user[*]} ${missing[*]}"
  "$py" -m pip install --disable-pip-version-check --no-input -q "${user[@]}" "${missing[@]}"
}

status=0
install_apt_packages || status=1
if [[ $want_python -eq 1 ]]; then
  install_python_modules || status=1
fi
exit $status
