#!/bin/sh
# Long fuzzing runs: builds the harnesses with clang, libFuzzer, ASan and UBSan in build-fuzz/
# (MBID_FUZZ=ON) and runs one of them (docs/reliability.md).
#   fuzz/run.sh <csv|logger|mat|hdf5|scenario|machine> [seconds, default 600] [libFuzzer flags...]
# New inputs go to build-fuzz/corpus/<reader> (seeded from the repository's corpus); findings
# to build-fuzz/findings/<reader>/ (crash-*, timeout-*, oom-*), each reproducible with
#   build-fuzz/fuzz/fuzz_<reader> <file>
set -eu
reader=${1:?usage: fuzz/run.sh <csv|logger|mat|hdf5|scenario|machine> [seconds] [flags...]}
seconds=${2:-600}
[ $# -ge 2 ] && shift 2 || shift $#
source_dir=$(cd "$(dirname "$0")/.." && pwd)
build=${MBID_FUZZ_BUILD:-$source_dir/build-fuzz}

if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$source_dir" -B "$build" -DCMAKE_BUILD_TYPE=Release \
    -DMBID_FUZZ=ON -DBUILD_TESTING=OFF
fi
cmake --build "$build" -j"${MBID_FUZZ_JOBS:-2}" --target "fuzz_$reader"

corpus="$build/corpus/$reader"
findings="$build/findings/$reader"
mkdir -p "$corpus" "$findings"
case $reader in
  csv | mat | hdf5) seeds="$source_dir/fuzz/corpus/$reader" ;;
  logger) seeds="$source_dir/fuzz/corpus/logger $source_dir/tests/data/records" ;;
  scenario | machine) seeds="$source_dir/scenarios" ;;
  *) echo "unknown reader '$reader'" >&2; exit 2 ;;
esac
# Dictionaries guide the mutations of text formats towards their keywords.
dict=""
[ -f "$source_dir/fuzz/$reader.dict" ] && dict="-dict=$source_dir/fuzz/$reader.dict"

# The first finding stops the run; a reader that returns NULL from a huge malloc is tested
# rather than killed by ASan.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:allocator_may_return_null=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$source_dir/fuzz/lsan.supp}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
# shellcheck disable=SC2086
exec "$build/fuzz/fuzz_$reader" "$corpus" $seeds $dict \
  -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=32768 \
  -artifact_prefix="$findings/" -print_final_stats=1 "$@"
