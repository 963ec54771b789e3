#!/usr/bin/env bash
# cites: REQ-LIB-001
# ci/install_test.sh BUILD_DIR [EXTRA_FLAGS] [python|no-python] — the library as a user consumes it: installs the
# build into a scratch prefix, checks what landed there (tool, static libraries, headers,
# CMake package, weights), builds examples/ against the prefix with find_package(miner)
# (nothing from the source or build tree on the include path) and runs each example.
# EXTRA_FLAGS go to the consumer's compile and link lines (the sanitizer/coverage flags of
# an instrumented build, whose static libraries need their runtimes).
set -euo pipefail
build=$(cd "$1" && pwd)
extra=${2:-}
# python: the build has the bindings (MINER_PYTHON), so the prefix must hold them and they must
# plan; no-python: a build without them (the step is skipped, saying so).
python=${3:-python}
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/install.log"
for f in bin/miner include/miner/plan/rrt_star.hpp include/miner/traj/minco.hpp lib/cmake/miner/minerConfig.cmake \
         lib/cmake/miner/minerTargets.cmake share/miner/sgan/sgan.bin share/miner/maps/sim-1.json; do
  [ -e "$prefix/$f" ] || { echo "install_test: $f was not installed" >&2; exit 1; }
done
if [ -e "$prefix/include/miner/world/octree_leaves.hpp" ] || [ -d "$prefix/include/miner/testing" ]; then
  echo "install_test: internal headers were installed" >&2
  exit 1
fi
"$prefix/bin/miner" --version
cmake -S "$src/examples" -B "$work/examples" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_CXX_FLAGS="$extra" -DCMAKE_EXE_LINKER_FLAGS="$extra" >"$work/configure.log" \
  || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/examples" -j2 >"$work/build.log" 2>&1 || { tail -50 "$work/build.log"; exit 1; }
# The consumer saw only the prefix: no include path into the source tree.
if grep -q -- "-I$src/src" "$work/examples/compile_commands.json" 2>/dev/null; then
  echo "install_test: the examples were compiled against the source tree" >&2
  exit 1
fi
"$work/examples/minco_waypoints"
"$work/examples/plan_with_sgan" "$prefix/share/miner/maps/sim-1.json"
"$work/examples/fly_scenario"
# Python from the prefix (REQ-LIB-002), with Debian's python3 (numpy); an instrumented build's
# extension needs its sanitizer runtime preloaded.
if [ "$python" = python ] && [ ! -e "$prefix/lib/python3/dist-packages/miner/__init__.py" ]; then
  echo "install_test: the build has Python bindings but the prefix holds no lib/python3/dist-packages/miner" >&2
  exit 1
fi
if [ "$python" = no-python ]; then
  echo "install_test: built without MINER_PYTHON: the Python step is skipped"
else
  preload=""
  case "$extra" in *-fsanitize=address*) preload="$(g++ -print-file-name=libasan.so) $(g++ -print-file-name=libstdc++.so)" ;; esac
  (cd "$work" && LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=0 PYTHONPATH="$prefix/lib/python3/dist-packages" \
     /usr/bin/python3 -c "
import miner
m = miner.Map.load('$prefix/share/miner/maps/sim-1.json')
r = miner.plan(m, planner='miner', region=miner.sgan_region(m), seed=1, iterations=2000)
assert r.solved, r.reason
t = miner.minco(r.path)
print('python: miner', r.cost, 'm,', round(t.total_duration, 2), 's trajectory')
")
fi
echo "install_test: installed, found with find_package(miner), three examples built and run"
