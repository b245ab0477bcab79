#!/usr/bin/env bash
# The whole test suite under AddressSanitizer and UndefinedBehaviorSanitizer:
# configures build-asan/ (optimised, with debug information), builds it and
# runs CTest there. Any sanitizer report fails its test: UBSan stops at the
# first error (-fno-sanitize-recover=all), ASan at any invalid access or leak,
# and the catalogue and fuzz tests also fail on a report in a program's output.
# Needs the dependencies (scripts/install-deps.sh); the build takes about 12
# minutes and the tests about an hour on 2 cores (the coupled runs and the
# Mandel test 10-40x slower than in the Release build): not part of CI.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p build-asan
sanitizers="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DOUTBURST_BUILD_BENCHMARKS=OFF \
  -DCMAKE_CXX_FLAGS="$sanitizers" -DCMAKE_EXE_LINKER_FLAGS="$sanitizers" > build-asan/build.log 2>&1 ||
  { cat build-asan/build.log; exit 1; }
cmake --build build-asan -j "$(nproc)" >> build-asan/build.log 2>&1 || { tail -50 build-asan/build.log; exit 1; }
echo "sanitize: built (log in build-asan/build.log); running the tests"
cd build-asan
# Not detect_stack_use_after_return: every Eigen temporary on the stack would
# go through its fake stacks, and the Mandel test alone then outran 30 minutes.
export ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# A leak inside HDF5's own error path (tests/lsan.supp says which).
export LSAN_OPTIONS="suppressions=$(cd .. && pwd)/tests/lsan.supp:print_suppressions=0"
ctest --output-on-failure --timeout 3600 -j "$(nproc)"
