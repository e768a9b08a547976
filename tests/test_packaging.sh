#!/bin/sh
# test_packaging.sh - the CMake and pkg-config packaging (issue 17): a tiny consumer
# (tests/consumer/) built once with add_subdirectory of this tree (with SOFTBODY_OPENMP=ON
# when the compiler has OpenMP), once with find_package after `cmake --install` into a
# temporary prefix, and once with the flags of `pkg-config --cflags --libs softbody` from
# that prefix; each build must run and print "consumer ok". Prints PASS/FAIL per case and
# `RESULT <passed> <failed>` (tests/summarize.sh); without cmake prints one line and
# `RESULT 0 0`; without pkg-config the pkg-config case is skipped with a line.
#
#   sh tests/test_packaging.sh TMP_DIR [name-filter]
#
# Run by the Makefile as build/packaging/test_packaging.result; about 5 s.
tmp=$1
filter=$2
src=$(pwd)
passed=0
failed=0

report() {
    if [ "$2" -eq 0 ]; then
        passed=$((passed + 1)); echo "PASS $1"
    else
        failed=$((failed + 1)); echo "FAIL $1: $3"
        [ -f "$tmp/$1.out" ] && tail -n 15 "$tmp/$1.out" | sed 's/^/    /'
    fi
}

# want NAME: 0 when the case is selected by the filter
want() { case "$1" in *"$filter"*) return 0 ;; esac; return 1; }

# the consumer binary $1 runs and prints "consumer ok"
runs_ok() { [ -x "$1" ] && "$1" 2>&1 | grep -q '^consumer ok'; }

if ! command -v cmake >/dev/null 2>&1; then
    echo "(cmake not found: the CMake and pkg-config packaging tests are skipped)"
    echo "RESULT 0 0"
    exit 0
fi
rm -rf "$tmp"
mkdir -p "$tmp" || exit 1
tmp=$(cd "$tmp" && pwd)   # absolute: CMake reads relative prefixes from its build directory
prefix="$tmp/prefix"
quiet="-Wno-dev"   # no optimisation: the compile is most of the time

if want cmake_add_subdirectory; then
    b="$tmp/sub"
    { cmake -S tests/consumer -B "$b" $quiet -DSOFTBODY_SOURCE="$src" -DSOFTBODY_OPENMP=ON &&
      cmake --build "$b"; } > "$tmp/cmake_add_subdirectory.out" 2>&1
    if runs_ok "$b/consumer"; then report cmake_add_subdirectory 0 ""
    else report cmake_add_subdirectory 1 "the consumer did not build or run"; fi
fi

# the install feeds the two cases after it
{ cmake -S . -B "$tmp/lib" $quiet -DCMAKE_INSTALL_PREFIX="$prefix" &&
  cmake --install "$tmp/lib"; } > "$tmp/cmake_install.out" 2>&1
st=$?
if want cmake_install; then
    if [ "$st" -eq 0 ] && [ -f "$prefix/include/softbody/frames.h" ] &&
       [ -f "$prefix/share/cmake/softbody/softbodyConfig.cmake" ] &&
       [ -f "$prefix/share/pkgconfig/softbody.pc" ]; then report cmake_install 0 ""
    else report cmake_install 1 "cmake --install failed or left out a file"; fi
fi

if want cmake_find_package; then
    b="$tmp/pkg"
    { cmake -S tests/consumer -B "$b" $quiet -DCMAKE_PREFIX_PATH="$prefix" &&
      cmake --build "$b"; } > "$tmp/cmake_find_package.out" 2>&1
    if runs_ok "$b/consumer"; then report cmake_find_package 0 ""
    else report cmake_find_package 1 "the consumer did not build or run"; fi
fi

if want pkg_config; then
    if command -v pkg-config >/dev/null 2>&1; then
        export PKG_CONFIG_PATH="$prefix/share/pkgconfig"
        { flags=$(pkg-config --cflags softbody) && libs=$(pkg-config --libs softbody) &&
          echo "cflags: $flags; libs: $libs" &&
          cc -std=c99 $flags -o "$tmp/pc_consumer" tests/consumer/main.c $libs; } > "$tmp/pkg_config.out" 2>&1
        if runs_ok "$tmp/pc_consumer" && grep -q "include/softbody" "$tmp/pkg_config.out"; then
            report pkg_config 0 ""
        else report pkg_config 1 "pkg-config's flags did not build a working consumer"; fi
    else
        echo "(pkg-config not found: the pkg-config case is skipped)"
    fi
fi

echo "RESULT $passed $failed"
[ "$failed" -eq 0 ]
