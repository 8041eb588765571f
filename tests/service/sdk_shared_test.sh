#!/usr/bin/env bash
# The SDK as shared libraries (issue 12: BUILD_SHARED_LIBS honoured), configured as a consumer
# would (issue 22, point 5): this source tree again with -DBUILD_SHARED_LIBS=ON and without the
# tests, the benchmarks and feeddrive-fit, with GTest, Google Benchmark and Ceres made unfindable
# (CMAKE_DISABLE_FIND_PACKAGE_*: as if not installed; a REQUIRED search for one fails). It builds
# only what `cmake --install` installs (the drive model, the plant, the controllers, the
# trajectories and the generated message headers), checks that the installed libraries are shared
# objects, and runs the SDK checks of sdk_test.sh on it: the out-of-tree example built against the
# installed prefix, linking libfeeddrive_controller.so and no SUNDIALS library, as the controller
# of a four-process run.
source "$(dirname "$0")/lib.sh" "$@"
source "$(dirname "$0")/sdk_check.sh"
tree=$TMP/shared
launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
consumer=(-DBUILD_TESTING=OFF -DFEEDDRIVE_BUILD_BENCHMARKS=OFF -DFEEDDRIVE_WITH_FIT=OFF
          -DCMAKE_DISABLE_FIND_PACKAGE_GTest=ON -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON
          -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON)
cmake -S "$SRC" -B "$tree" -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON "${consumer[@]}" "${launcher[@]}" > "$TMP/shared-configure.log" 2>&1 ||
  { tail -30 "$TMP/shared-configure.log" >&2; fail "configure as a consumer (shared, no GTest, Benchmark or Ceres) failed"; }
cmake --build "$tree" -j"$(nproc)" --target feeddrive_model feeddrive_plant feeddrive_controller feeddrive_trajectory \
  feeddrive_lcmtypes_gen > "$TMP/shared-build.log" 2>&1 || { tail -30 "$TMP/shared-build.log" >&2; fail "shared build failed"; }
# The three options took effect: no target of the tests, the benchmarks or the fit.
cmake --build "$tree" --target help > "$TMP/targets.txt"
if grep -E '\.\.\. (feeddrive-fit|feeddrive_fit|fit_sweep|bench_feeddrive|test_[a-z_]+|fd_drivegen)$' "$TMP/targets.txt"; then
  fail "the consumer's tree has the targets above (tests, benchmarks or fit) though they are off"
fi
sdk_check "$tree"
prefix=$TMP/sdk-shared/prefix
for l in model plant controller trajectory; do
  f=$prefix/lib/libfeeddrive_$l.so
  [ -f "$f" ] || fail "not installed: $f"
  readelf -h "$f" | grep -q 'Type: *DYN' || fail "not a shared object: $f"
  # Each finds the others next to it: a program linking only libfeeddrive_controller.so (whose
  # RUNPATH does not reach its libraries' dependencies) once failed to start with
  # "libfeeddrive_model.so: cannot open shared object file".
  ldd "$f" > "$TMP/ldd-$l.txt"
  if grep -q "not found" "$TMP/ldd-$l.txt"; then cat "$TMP/ldd-$l.txt" >&2; fail "$f: a library it needs is not found"; fi
  case $l in plant | controller) ;; *) continue ;; esac  # the two built on the model
  grep -q "libfeeddrive_model.so => $prefix/lib" "$TMP/ldd-$l.txt" ||
    { cat "$TMP/ldd-$l.txt" >&2; fail "$f does not find libfeeddrive_model.so next to it"; }
done
# ldd into a file first: `ldd | grep -q` fails under pipefail when grep exits at the first match
# and ldd gets SIGPIPE (it did, 1 run in 3 under ctest -j4).
ldd "$exe" > "$TMP/ldd.txt"
grep -q "libfeeddrive_controller.so => $prefix/lib" "$TMP/ldd.txt" || { cat "$TMP/ldd.txt" >&2; fail "the example does not load the installed libfeeddrive_controller.so"; }
pass "shared SDK: libfeeddrive_{model,plant,controller,trajectory}.so installed, each finding the others next to it; the example loads libfeeddrive_controller.so from the prefix, no SUNDIALS"
