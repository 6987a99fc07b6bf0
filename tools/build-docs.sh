#!/usr/bin/env bash
# API documentation of include/softrne (docs/Doxyfile) with every Doxygen warning an error:
# an undocumented public entry point, parameter or return value fails, and so does a \param
# that names no parameter. Internal helpers live in namespace detail and are not documented.
#
#   tools/build-docs.sh [OUT_DIR]    HTML in OUT_DIR/docs-html (default: build; a relative
#                                    OUT_DIR is relative to the repository root)
#
# Run from anywhere; needs doxygen (Debian package doxygen, in tools/install-deps.sh). CI runs
# it in phase 1 of .ci/run; `cmake --build build --target docs` does the same through CMake.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

out_dir=${1:-build}
if ! command -v doxygen >/dev/null 2>&1; then
  echo "build-docs.sh: doxygen not found (tools/install-deps.sh installs it)" >&2
  exit 2
fi
mkdir -p "$out_dir"
start_ns=$(date +%s%N)
# docs/Doxyfile's paths are relative to the repository root (the working directory); only
# the output directory is overridden. WARN_AS_ERROR = FAIL_ON_WARNINGS: doxygen lists every
# warning, then exits non-zero.
status=0
{ cat docs/Doxyfile; echo "OUTPUT_DIRECTORY = $out_dir"; } | doxygen - || status=$?
ms=$((($(date +%s%N) - start_ns) / 1000000))
if [[ $status -ne 0 ]]; then
  echo "build-docs.sh: doxygen failed (status $status): document what it lists above" >&2
  exit "$status"
fi
echo "[build-docs] $out_dir/docs-html/index.html, no warnings, $ms ms"
