#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (gcc), every project
# file instrumented. Usage: tools/sanitize.sh [build-folder] [extra ctest arguments...]
# Takes about an hour on 2 cores (a cold build, then tests 2-5x slower): not part of .ci/run,
# whose budget it would break. Findings in third-party code are suppressed in
# tools/sanitizers/*.supp, each with its reason; a project finding fails its test.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-asan}
shift || true
sanitize="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
# Debian's libceres.a was built with EIGEN_MALLOC_ALREADY_ALIGNED on, which Eigen turns off under
# ASan: Eigen objects allocated by Ceres and freed by project code (BDCSVD under the covariance)
# would then be freed with the wrong function.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g" -DCMAKE_C_FLAGS_RELEASE="-O1 -g" \
  -DCMAKE_CXX_FLAGS="$sanitize -DEIGEN_MALLOC_ALREADY_ALIGNED=1" -DCMAKE_C_FLAGS="$sanitize" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON
cmake --build "$build" -j2
here=$(pwd)
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
export LSAN_OPTIONS="suppressions=$here/tools/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$here/tools/sanitizers/ubsan.supp"
# Left out, with the reason:
#   python_module, example_python: the interpreter is not instrumented and cannot load an ASan
#     module unless libasan is preloaded into Python itself (its own allocations then leak);
#   install_package, example_cpp: configure and build other projects (with their own flags).
#   the MPI campaign test runs on its own below, without leak checks: OpenMPI unloads its
#     components (dlclose) in MPI_Finalize, so their leftovers at exit have no library name a
#     suppression could match; memory errors are still checked.
#   OutputSafetyTest.AWorkerThreadThatCannotStart... skips itself: it runs under ulimit -v,
#     where ASan cannot map its shadow memory.
status=0
ctest --test-dir "$build" -j2 --timeout 3600 --output-on-failure \
  -E '^(python_module|example_python|install_package|example_cpp)$|Mpi' "$@" || status=1
ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" \
  ctest --test-dir "$build" --timeout 3600 --output-on-failure -R 'Mpi' "$@" || status=1
exit $status
