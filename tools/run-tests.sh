#!/usr/bin/env bash
# One command on a new machine: install the dependencies, configure, build, run the tests.
#
#   ./tools/run-tests.sh [extra cmake -D options]
#
# Environment: BUILD_DIR (default build), BUILD_TYPE (default Release), JOBS (default nproc),
#              SOFTRNE_SKIP_DEPS=1 to skip tools/install-deps.sh (not a Debian machine),
#              SOFTRNE_PYTHON: auto (default) builds the Python package (python/) and runs its
#              pytest suite (ctest python.pytest) when tools/setup-python.sh can set up a
#              venv (<build>/py-venv: numpy, nanobind, pytest from PyPI), else says why and
#              goes on without; 1 requires it; 0 leaves it out.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir=${BUILD_DIR:-build}
build_type=${BUILD_TYPE:-Release}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}

if [[ "${SOFTRNE_SKIP_DEPS:-0}" != 1 ]]; then
  ./tools/install-deps.sh
fi

python_mode=${SOFTRNE_PYTHON:-auto}
py_args=()
if [[ $python_mode != 0 ]]; then
  # An absolute path: CMake resolves a relative Python_EXECUTABLE against nothing useful and
  # then quietly finds another python.
  case $build_dir in /*) venv_dir=$build_dir/py-venv ;; *) venv_dir=$PWD/$build_dir/py-venv ;; esac
  if py=$(./tools/setup-python.sh "$venv_dir"); then
    echo "[run-tests] Python package: on ($py)"
    py_args=(-DSOFTRNE_BUILD_PYTHON=ON "-DPython_EXECUTABLE=$py")
  elif [[ $python_mode == 1 ]]; then
    echo "[run-tests] SOFTRNE_PYTHON=1 but no Python could be set up (see above)" >&2
    exit 1
  else
    echo "[run-tests] Python package: OFF (no Python could be set up, see above; SOFTRNE_PYTHON=1 requires it)"
    py_args=(-DSOFTRNE_BUILD_PYTHON=OFF)
  fi
else
  py_args=(-DSOFTRNE_BUILD_PYTHON=OFF)
fi

gen=()
if [[ ! -f "$build_dir/CMakeCache.txt" ]] && command -v ninja >/dev/null 2>&1; then
  gen=(-G Ninja)
fi
echo "[run-tests] configure $build_dir ($build_type)"
cmake -S . -B "$build_dir" "${gen[@]}" -DCMAKE_BUILD_TYPE="$build_type" \
  -DSOFTRNE_REQUIRE_ALL=ON -DSOFTRNE_BUILD_TESTS=ON -DSOFTRNE_BUILD_EXAMPLES=ON \
  -DSOFTRNE_BUILD_TOOLS=ON -DSOFTRNE_BUILD_BENCH=ON "${py_args[@]}" "$@"
echo "[run-tests] build ($jobs jobs)"
cmake --build "$build_dir" -j "$jobs"
echo "[run-tests] ctest"
ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" --timeout "${TEST_TIMEOUT:-900}"
