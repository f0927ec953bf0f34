#!/bin/bash
# Installs the build into a fresh prefix, builds examples/cpp against it as another project
# would (find_package(mbid CONFIG REQUIRED) + mbid::mbid) and runs it and the installed mbid.
# Usage: check_install.sh BUILD_DIR SOURCE_DIR PYTHON
set -euo pipefail
build=$1
source=$2
python=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" > "$work/install.log"
for path in bin/mbid include/mbid/mbid.h lib/cmake/mbid/mbidConfig.cmake \
            share/mbid/scenarios/reference-crane.yaml share/mbid/docs/python.md \
            share/mbid/examples/cpp/crane_cycle.cc share/mbid/examples/python/crane_cycle.py; do
  [[ -e "$prefix/$path" ]] || { echo "not installed: $path"; exit 1; }
done
# The example is a C++-only project (no C compiler enabled for FindHDF5) that asks for C++14:
# mbid::mbid must raise it to the C++17 its headers need.
cmake -S "$source/examples/cpp" -B "$work/example" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_STANDARD=14 -DCMAKE_CXX_EXTENSIONS=OFF \
      > "$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/example" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
# Run from elsewhere: the default scenario must come from the installed share folder.
cd "$work"
"$work/example/crane_cycle" > "$work/example.out"
cat "$work/example.out"
grep -q "($prefix/share/mbid/scenarios/reference-crane.yaml)" "$work/example.out" ||
  { echo "the default scenario was not the installed one"; exit 1; }
grep -q '^verdict: passed$' "$work/example.out"
# The installed binary finds its scenarios beside it too.
"$prefix/bin/mbid" run --quiet -o "$work/run" > /dev/null
[[ -s "$work/run/summary.json" ]]
# The installed Python module, with the installed scenarios.
PYTHONPATH="$prefix/lib/python3/dist-packages" "$python" -c "
import mbid, sys
path = mbid.default_scenario_path()
assert path == '$prefix/share/mbid/scenarios/reference-crane.yaml', path
print('python:', mbid.load_scenario(path).name, mbid.__file__)
assert mbid.__file__.startswith('$prefix/')
"
echo "installed package OK"
