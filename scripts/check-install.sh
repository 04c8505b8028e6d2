#!/usr/bin/env bash
# Installs libmpca into a temporary prefix with scripts/install.sh, checks
# the installed tree (files, links, SONAME, what the programs record), then
# builds the consumer of tests/install/ from a copy outside the source tree
# every way a C or C++ project links a library, and runs each build:
#
#   pkg-config     cc consumer.c $(pkg-config --cflags --libs mpca),
#                  run with LD_LIBRARY_PATH
#   static         libmpca.a plus pkg-config --static's Libs.private
#   CMake          find_package(mpca CONFIG REQUIRED): mpca::mpca (C and
#                  C++ through mpca.hpp) and mpca::mpca_static
#   plain cc       -I$prefix/include -L$prefix/lib -lmpca, with an rpath
#   README.md      every line of its blocks marked <!-- link-lines: ... -->,
#                  as shown (PREFIX the temporary prefix), with the consumer
#                  as app.c and app.cpp, and every app they build run
#
# It also checks that the installed libmpca.so is stripped, with its
# symbols and debug information in the file its .gnu_debuglink names.
#
# Every build must print the same line: the installed version, the
# particles and the world's hash. Installs cmake and pkg-config with
# apt-get when they are missing (scripts/install-missing.sh).
#
#   scripts/check-install.sh [--keep]    --keep leaves the temporary folder
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
keep=0
case "${1:-}" in
    --keep) keep=1 ;;
    "") ;;
    *) echo "usage: scripts/check-install.sh [--keep]" >&2; exit 2 ;;
esac

need=()
command -v pkg-config >/dev/null 2>&1 || need+=(pkg-config)
command -v cmake >/dev/null 2>&1 || need+=(cmake)
command -v readelf >/dev/null 2>&1 || need+=(binutils)
"$root/scripts/install-missing.sh" ${need[@]+"${need[@]}"}
cc=${CC:-cc}
cxx=${CXX:-c++}

tmp=$(mktemp -d "${TMPDIR:-/tmp}/mpca-install.XXXXXX")
if [ "$keep" -eq 1 ]; then echo "keeping $tmp"; else trap 'rm -rf "$tmp"' EXIT; fi
prefix="$tmp/prefix"
fail() { echo "check-install: $*" >&2; exit 1; }

"$root/scripts/install.sh" --prefix "$prefix"

echo "== the installed tree"
version=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --modversion mpca)
major=${version%%.*}
for f in include/mpca.h include/mpca.hpp lib/libmpca.a "lib/libmpca.so.$version" \
    lib/pkgconfig/mpca.pc lib/cmake/mpca/mpcaConfig.cmake lib/cmake/mpca/mpcaConfigVersion.cmake; do
    [ -f "$prefix/$f" ] && [ ! -L "$prefix/$f" ] || fail "$f is not a file"
done
[ "$(readlink "$prefix/lib/libmpca.so.$major")" = "libmpca.so.$version" ] || fail "libmpca.so.$major does not link to libmpca.so.$version"
[ "$(readlink "$prefix/lib/libmpca.so")" = "libmpca.so.$major" ] || fail "libmpca.so does not link to libmpca.so.$major"
soname=$(readelf -d "$prefix/lib/libmpca.so.$version" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
[ "$soname" = "libmpca.so.$major" ] || fail "SONAME is '$soname', not libmpca.so.$major"
echo "mpca $version: SONAME $soname; libmpca.so -> libmpca.so.$major -> libmpca.so.$version"
readelf -d "$prefix/lib/libmpca.so.$version" | grep -E '\((NEEDED|SONAME)\)'
sections() { readelf -S -W "$1" | sed -n 's/^ *\[ *[0-9]*\] \([^ ]*\) .*/\1/p'; }
! sections "$prefix/lib/libmpca.so.$version" | grep -qE '^\.(symtab|debug_)' || fail "the installed libmpca.so is not stripped"
sections "$prefix/lib/libmpca.so.$version.debug" | grep -qx .symtab || fail "libmpca.so.$version.debug holds no symbols"
link=$(readelf -p .gnu_debuglink "$prefix/lib/libmpca.so.$version" | sed -n 's/^ *\[ *0\] *//p')
[ "$link" = "libmpca.so.$version.debug" ] || fail "the .gnu_debuglink of libmpca.so names '$link'"
echo "stripped: $(stat -c %s "$prefix/lib/libmpca.so.$version") bytes; symbols and debug information: libmpca.so.$version.debug, $(stat -c %s "$prefix/lib/libmpca.so.$version.debug") bytes"

# needed EXE: its DT_NEEDED libraries, one a line.
needed() { readelf -d "$1" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'; }

# The consumer, copied out of the source tree; every build runs from here.
mkdir -p "$tmp/src" "$tmp/bin"
cp "$root/tests/install/consumer.c" "$root/tests/install/consumer.cpp" "$root/tests/install/CMakeLists.txt" "$tmp/src/"
cd "$tmp/src"
flags=(-Wall -Wextra -Wpedantic -Werror)
expected="mpca $version: "
outputs=()

# run NAME EXE [ENV...]: runs EXE with only the given loader path and
# records its line.
run() {
    local name=$1 exe=$2
    shift 2
    local line
    line=$(env -u LD_LIBRARY_PATH "$@" "$exe") || fail "$name: $exe failed"
    echo "$name: $line"
    case "$line" in "$expected"*) ;; *) fail "$name printed '$line', not '$expected...'" ;; esac
    outputs+=("$line")
}

echo "== pkg-config (PKG_CONFIG_PATH=$prefix/lib/pkgconfig)"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
echo "cflags: $(pkg-config --cflags mpca)  libs: $(pkg-config --libs mpca)  static: $(pkg-config --static --libs mpca)"
"$cc" -std=c99 "${flags[@]}" consumer.c $(pkg-config --cflags --libs mpca) -o "$tmp/bin/pkg-config"
needed "$tmp/bin/pkg-config" | grep -qx "libmpca.so.$major" || fail "the pkg-config build does not record libmpca.so.$major: $(needed "$tmp/bin/pkg-config" | paste -sd ' ')"
run pkg-config "$tmp/bin/pkg-config" LD_LIBRARY_PATH="$prefix/lib"

echo "== static, with Libs.private"
static_libs=$(pkg-config --static --libs mpca)
"$cc" -std=c99 "${flags[@]}" consumer.c $(pkg-config --cflags mpca) ${static_libs/-lmpca/-l:libmpca.a} -o "$tmp/bin/static"
! needed "$tmp/bin/static" | grep -q '^libmpca' || fail "the static build needs libmpca.so"
run static "$tmp/bin/static"

echo "== plain cc, -I -L -lmpca and an rpath"
"$cc" -std=c99 "${flags[@]}" consumer.c -I"$prefix/include" -L"$prefix/lib" -lmpca -Wl,-rpath,"$prefix/lib" -o "$tmp/bin/plain"
run plain "$tmp/bin/plain"
unset PKG_CONFIG_PATH

echo "== CMake, find_package(mpca CONFIG REQUIRED)"
cmake -S . -B "$tmp/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" >"$tmp/cmake.log" 2>&1 \
    || { cat "$tmp/cmake.log" >&2; fail "cmake could not configure the consumer"; }
grep 'mpca .* from' "$tmp/cmake.log"
cmake --build "$tmp/build" >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log" >&2; fail "the CMake build failed"; }
! needed "$tmp/build/consumer_static" | grep -q '^libmpca' || fail "mpca::mpca_static linked libmpca.so"
needed "$tmp/build/consumer_shared" | grep -qx "libmpca.so.$major" || fail "mpca::mpca did not link libmpca.so.$major"
# CMake's build tree carries the prefix's lib folder as an rpath.
run cmake-shared "$tmp/build/consumer_shared"
run cmake-static "$tmp/build/consumer_static"
run cmake-cpp "$tmp/build/consumer_cpp"

# readme_block MARKER: the lines of the ```sh block after <!-- link-lines: MARKER -->.
readme_block() {
    awk -v m="<!-- link-lines: $1 -->" '$0 == m {on = 1; next} on && /^```sh/ {inside = 1; next} inside && /^```/ {exit} inside {print}' "$root/README.md"
}
# run_readme_block MARKER DIR: runs the block's lines in DIR as shown, PREFIX
# replaced, in one shell (an export holds for the lines after it); after
# each line that builds app, app runs without LD_LIBRARY_PATH.
run_readme_block() {
    local marker=$1 dir=$2 script="$tmp/readme-$1.sh" n=0
    [ -n "$(readme_block "$marker")" ] || fail "README.md has no block after <!-- link-lines: $marker -->"
    echo "set -euo pipefail" > "$script"
    while IFS= read -r line; do
        line=${line//PREFIX/$prefix}
        printf 'echo %q\n%s\n' "\$ $line" "$line" >> "$script"
        case "$line" in *" -o app"*) n=$((n + 1)); echo "env -u LD_LIBRARY_PATH ./app > \"$tmp/readme-$marker-$n.out\"" >> "$script" ;; esac
    done < <(readme_block "$marker")
    (cd "$dir" && env -u LD_LIBRARY_PATH bash "$script") || fail "a line of README.md's '$marker' block failed"
    for i in $(seq 1 "$n"); do
        line=$(cat "$tmp/readme-$marker-$i.out")
        echo "README $marker, build $i: $line"
        case "$line" in "$expected"*) ;; *) fail "README $marker build $i printed '$line', not '$expected...'" ;; esac
        outputs+=("$line")
    done
}

echo "== README.md's link lines, as shown"
mkdir -p "$tmp/readme"
cp "$tmp/src/consumer.c" "$tmp/readme/app.c"
cp "$tmp/src/consumer.cpp" "$tmp/readme/app.cpp"
run_readme_block installed "$tmp/readme"
unset PKG_CONFIG_PATH
# The build folder's lines run from the repository's root: a folder of
# links to its entries (the build folder's included), so app lands apart.
mkdir -p "$tmp/tree"
for entry in "$root"/*; do ln -s "$entry" "$tmp/tree/"; done
build_dir=${CARGO_TARGET_DIR:-$root/target}
case "$build_dir" in /*) ;; *) build_dir="$root/$build_dir" ;; esac
ln -sfn "$build_dir" "$tmp/tree/target"
cp "$tmp/src/consumer.c" "$tmp/tree/app.c"
run_readme_block "build folder" "$tmp/tree"

for line in "${outputs[@]}"; do
    [ "$line" = "${outputs[0]}" ] || fail "the builds disagree: '$line' against '${outputs[0]}'"
done
echo "check-install: ${#outputs[@]} builds of the consumer against mpca $version agree"
