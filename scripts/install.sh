#!/usr/bin/env bash
# Builds libmpca in release mode and installs it the way C and C++ projects
# expect a library (Linux):
#
#   scripts/install.sh --prefix DIR
#
#   DIR/include/mpca.h, mpca.hpp               the C header, the C++ wrapper
#   DIR/lib/libmpca.a                          static library
#   DIR/lib/libmpca.so.X.Y.Z                   shared library, SONAME libmpca.so.X,
#                                                stripped
#   DIR/lib/libmpca.so.X.Y.Z.debug             its symbols and debug information,
#                                                found by gdb through the library's
#                                                .gnu_debuglink
#   DIR/lib/libmpca.so.X -> libmpca.so.X.Y.Z   what programs load
#   DIR/lib/libmpca.so -> libmpca.so.X         what -lmpca finds
#   DIR/lib/pkgconfig/mpca.pc                  pkg-config --cflags --libs mpca
#   DIR/lib/cmake/mpca/mpcaConfig.cmake        find_package(mpca CONFIG): the
#   DIR/lib/cmake/mpca/mpcaConfigVersion.cmake   targets mpca::mpca (shared)
#                                                and mpca::mpca_static
#
# DESTDIR, when set, is put before every path written (for packaging); the
# files still name DIR. The CMake files find the prefix from where they lie,
# so an installed tree can be moved; mpca.pc names DIR.
#
# The libraries a static link needs (mpca.pc's Libs.private and the static
# target's link interface) are the ones rustc names for this toolchain
# (--print native-static-libs), read while building.
set -euo pipefail

usage() { sed -n '2,27p' "$0" | sed 's/^# \{0,1\}//'; }
prefix=
while [ $# -gt 0 ]; do
    case "$1" in
        --prefix) [ $# -ge 2 ] && [ -n "$2" ] || { echo "--prefix needs a folder" >&2; exit 2; }; prefix=$2; shift 2 ;;
        --prefix=*) prefix=${1#--prefix=}; shift ;;
        -h|--help) usage; exit 0 ;;
        *) echo "unknown option: $1 (try --help)" >&2; exit 2 ;;
    esac
done
[ -n "$prefix" ] || { echo "usage: scripts/install.sh --prefix DIR" >&2; exit 2; }
[ "$(uname -s)" = Linux ] || { echo "install.sh installs ELF shared libraries: Linux only" >&2; exit 1; }
case "$prefix" in /*) ;; *) prefix="$PWD/$prefix" ;; esac
prefix=${prefix%/}

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

echo "== libmpca (cargo rustc --release -p mpca-ffi)"
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# cargo replays the note when the build is fresh, so it is always there.
cargo rustc --release -p mpca-ffi -- --print native-static-libs 2>&1 | tee "$log" >&2
static_libs=$(sed -n 's/^note: native-static-libs: //p' "$log" | tail -n 1)
[ -n "$static_libs" ] || { echo "install.sh: rustc named no native-static-libs" >&2; exit 1; }

version=$(cargo pkgid -p mpca-ffi)
version=${version##*[@#]}
major=${version%%.*}
case "$version" in [0-9]*.[0-9]*.[0-9]*) ;; *) echo "install.sh: no version in $(cargo pkgid -p mpca-ffi)" >&2; exit 1 ;; esac
pointer_bytes=$(( $(rustc --print cfg | sed -n 's/^target_pointer_width="\(.*\)"/\1/p') / 8 ))
target=${CARGO_TARGET_DIR:-$root/target}
case "$target" in /*) ;; *) target="$root/$target" ;; esac
built="$target/release"

dest=${DESTDIR:-}$prefix
real="libmpca.so.$version"
echo "== installing mpca $version under ${DESTDIR:+$DESTDIR}$prefix"
install -d "$dest/include" "$dest/lib/pkgconfig" "$dest/lib/cmake/mpca"
install -m 644 include/mpca.h include/mpca.hpp "$dest/include/"
install -m 644 "$built/libmpca.a" "$dest/lib/libmpca.a"
# Stripped, as distributions ship libraries: the symbols and line tables
# (the release profile's debug = "line-tables-only") go to a file apart,
# which the stripped library names in its .gnu_debuglink.
objcopy --only-keep-debug "$built/libmpca.so" "$dest/lib/$real.debug"
chmod 644 "$dest/lib/$real.debug"
strip -o "$dest/lib/$real" "$built/libmpca.so"
(cd "$dest/lib" && objcopy --add-gnu-debuglink="$real.debug" "$real")
chmod 755 "$dest/lib/$real"
ln -sfn "$real" "$dest/lib/libmpca.so.$major"
ln -sfn "libmpca.so.$major" "$dest/lib/libmpca.so"

cat > "$dest/lib/pkgconfig/mpca.pc" <<EOF
prefix=$prefix
exec_prefix=\${prefix}
libdir=\${exec_prefix}/lib
includedir=\${prefix}/include

Name: mpca
Description: Particles on a Margolus-neighbourhood cellular automaton (C ABI of the Rust crate mpca)
Version: $version
Cflags: -I\${includedir}
Libs: -L\${libdir} -lmpca
Libs.private: $static_libs
EOF

# "-lgcc_s -lm" -> "gcc_s;m"
cmake_libs=$(printf '%s\n' $static_libs | sed -n 's/^-l//p' | paste -sd ';')
cat > "$dest/lib/cmake/mpca/mpcaConfig.cmake" <<EOF
# mpca $version for CMake, written by scripts/install.sh:
#   find_package(mpca CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE mpca::mpca)          # libmpca.so
#   target_link_libraries(app PRIVATE mpca::mpca_static)   # libmpca.a
# Both targets carry the include folder (mpca.h, mpca.hpp). Paths are found
# from this file's place, DIR/lib/cmake/mpca, so the tree can move.
get_filename_component(_mpca_prefix "\${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

if(NOT TARGET mpca::mpca)
  add_library(mpca::mpca SHARED IMPORTED)
  set_target_properties(mpca::mpca PROPERTIES
    IMPORTED_LOCATION "\${_mpca_prefix}/lib/$real"
    IMPORTED_SONAME "libmpca.so.$major"
    INTERFACE_INCLUDE_DIRECTORIES "\${_mpca_prefix}/include")
endif()

if(NOT TARGET mpca::mpca_static)
  add_library(mpca::mpca_static STATIC IMPORTED)
  set_target_properties(mpca::mpca_static PROPERTIES
    IMPORTED_LOCATION "\${_mpca_prefix}/lib/libmpca.a"
    IMPORTED_LINK_INTERFACE_LANGUAGES "C"
    INTERFACE_INCLUDE_DIRECTORIES "\${_mpca_prefix}/include"
    INTERFACE_LINK_LIBRARIES "$cmake_libs")
endif()

unset(_mpca_prefix)
EOF

cat > "$dest/lib/cmake/mpca/mpcaConfigVersion.cmake" <<EOF
# mpca $version: any request for $major.x up to $version is met (the SONAME,
# libmpca.so.$major, makes the same promise); a $((pointer_bytes * 8))-bit build only.
set(PACKAGE_VERSION "$version")
if(PACKAGE_VERSION VERSION_LESS PACKAGE_FIND_VERSION)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
elseif(NOT "\${PACKAGE_FIND_VERSION_MAJOR}" STREQUAL "" AND NOT PACKAGE_FIND_VERSION_MAJOR STREQUAL "$major")
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
else()
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
  if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
    set(PACKAGE_VERSION_EXACT TRUE)
  endif()
endif()
if(NOT "\${CMAKE_SIZEOF_VOID_P}" STREQUAL "" AND NOT CMAKE_SIZEOF_VOID_P STREQUAL "$pointer_bytes")
  set(PACKAGE_VERSION "\${PACKAGE_VERSION} ($((pointer_bytes * 8))-bit)")
  set(PACKAGE_VERSION_UNSUITABLE TRUE)
endif()
EOF

echo "installed:"
for f in include/mpca.h include/mpca.hpp lib/libmpca.a lib/$real lib/$real.debug lib/libmpca.so.$major lib/libmpca.so \
    lib/pkgconfig/mpca.pc lib/cmake/mpca/mpcaConfig.cmake lib/cmake/mpca/mpcaConfigVersion.cmake; do
    if [ -L "$dest/$f" ]; then echo "  $prefix/$f -> $(readlink "$dest/$f")"; else echo "  $prefix/$f"; fi
done
