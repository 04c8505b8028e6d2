#!/usr/bin/env bash
# libmpca for 64-bit Windows, cross-built on Linux with mingw-w64 and tested
# under Wine:
#
#   scripts/windows.sh
#
#   target/x86_64-pc-windows-gnu/release/mpca.dll       the DLL (rustc's name
#                                                       for the cdylib mpca)
#   target/x86_64-pc-windows-gnu/release/libmpca.dll.a  its import library
#   target/x86_64-pc-windows-gnu/release/libmpca.a      the static library
#
# Then it builds with x86_64-w64-mingw32-gcc (-std=c99 -Wall -Wextra
# -Wpedantic -Werror, as the Linux C tests) the C tests of tests/c that
# need only C99 and the library: errors.c, scenes.c, snapshots.c and
# edges.c against the DLL, edges.c again statically, parallel.c statically
# on winpthreads; and the example c_examples/threads.c against the DLL. Each
# runs under wine and must exit 0 and report no failed check; scenes.c's
# hashes and statistics and threads.c's hashes must equal those of the same
# programs built for Linux and run here (M8: the same worlds everywhere).
# The DLL must export the mpca_ functions of include/mpca.h and nothing else,
# and need nothing beyond KERNEL32.dll and the C runtime, msvcrt.dll.
#
# Not tried here: reuse.c (it relies on glibc's allocator handing a freed
# block back) and panic.c (it checks a line on stderr and SIGABRT), MSVC's
# own linker and a real Windows machine.
#
# Installs mingw-w64 and wine with apt-get when they are missing
# (scripts/install-missing.sh) and the Rust target with rustup.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
fail() { echo "windows: $*" >&2; exit 1; }

need=()
command -v x86_64-w64-mingw32-gcc >/dev/null 2>&1 || need+=(mingw-w64)
command -v wine >/dev/null 2>&1 || need+=(wine wine64)
scripts/install-missing.sh ${need[@]+"${need[@]}"}
rustup target list --installed | grep -qx x86_64-pc-windows-gnu || rustup target add x86_64-pc-windows-gnu

target=${CARGO_TARGET_DIR:-$root/target}
case "$target" in /*) ;; *) target="$root/$target" ;; esac
win="$target/x86_64-pc-windows-gnu/release"

echo "== libmpca for x86_64-pc-windows-gnu, and for this machine"
cargo build --release -p mpca-ffi --target x86_64-pc-windows-gnu
cargo build --release -p mpca-ffi
for f in mpca.dll libmpca.dll.a libmpca.a; do [ -f "$win/$f" ] || fail "$win/$f was not built"; done
stripped=$(mktemp)
x86_64-w64-mingw32-strip -o "$stripped" "$win/mpca.dll"
echo "mpca.dll: $(stat -c %s "$win/mpca.dll") bytes, $(stat -c %s "$stripped") stripped; libmpca.dll.a $(stat -c %s "$win/libmpca.dll.a"); libmpca.a $(stat -c %s "$win/libmpca.a")"
rm -f "$stripped"

dlls=$(x86_64-w64-mingw32-objdump -p "$win/mpca.dll" | sed -n 's/^\tDLL Name: //p' | sort | paste -sd ' ')
echo "mpca.dll needs: $dlls"
[ "$dlls" = "KERNEL32.dll msvcrt.dll" ] || fail "mpca.dll needs $dlls, not KERNEL32.dll and msvcrt.dll alone"
exports=$(x86_64-w64-mingw32-objdump -p "$win/mpca.dll" |
    sed -n '/\[Ordinal\/Name Pointer\] Table/,/^$/s/^\t\[ *[0-9]*\] //p' | sort)
header=$(grep -o '\bmpca_[a-z0-9_]*(' include/mpca.h | tr -d '(' | grep -vx mpca_debug_panic | sort -u)
[ "$exports" = "$header" ] || fail "mpca.dll's exports differ from include/mpca.h's functions:
$(diff <(echo "$header") <(echo "$exports") || true)"
echo "mpca.dll exports the $(echo "$exports" | wc -l) functions of include/mpca.h and nothing else"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/mpca-windows.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
flags=(-std=c99 -O2 -Wall -Wextra -Wpedantic -Werror -Iinclude -Itests/c)
cp "$win/mpca.dll" "$tmp/"

# build NAME LINK SOURCES...: the program for Windows (LINK: dll or static;
# the C runtime and winpthreads linked in statically either way, so that
# the program needs no MinGW DLL beside mpca.dll)
# and for Linux (as the Linux C tests link it).
build() {
    local name=$1 link=$2
    shift 2
    case "$link" in
        dll) x86_64-w64-mingw32-gcc "${flags[@]}" -static -pthread -o "$tmp/$name.exe" "$@" -L"$win" -lmpca.dll ;;
        static) x86_64-w64-mingw32-gcc "${flags[@]}" -static -pthread -o "$tmp/$name.exe" "$@" "$win/libmpca.a" ;;
    esac
    cc "${flags[@]}" -pthread -o "$tmp/$name" "$@" "$target/release/libmpca.a" -lm -ldl
}

echo "== the C tests and c_examples/threads.c, built with x86_64-w64-mingw32-gcc"
build errors dll tests/c/errors.c tests/c/check.c
build scenes dll tests/c/scenes.c tests/c/check.c
build snapshots dll tests/c/snapshots.c tests/c/check.c
build edges dll tests/c/edges.c tests/c/check.c
build edges-static static tests/c/edges.c tests/c/check.c
build parallel static tests/c/parallel.c tests/c/check.c
build threads dll c_examples/threads.c

echo "== run under $(wine --version 2>/dev/null)"
export WINEPREFIX=${WINEPREFIX:-$tmp/wine} WINEDEBUG=${WINEDEBUG:--all}
# Wine creates its prefix on the first start and says so on stderr; the
# check below is each program's exit status and its own output.
wine cmd /c exit >/dev/null 2>&1 || true
# run NAME ARGS...: the Windows build under wine and the Linux one; both
# must exit 0.
run() {
    local name=$1
    shift
    (cd "$tmp" && wine "./$name.exe" "$@" >"$name.win.out" 2>"$name.win.err") ||
        { tail -20 "$tmp/$name.win.out" "$tmp/$name.win.err" >&2; fail "$name.exe exited with $? under wine"; }
    "$tmp/$name" "$@" >"$tmp/$name.linux.out" 2>/dev/null || fail "$name (Linux) exited with $?"
    tr -d '\r' <"$tmp/$name.win.out" >"$tmp/$name.win"
}
for t in errors scenes snapshots edges edges-static parallel; do
    run "$t"
    line=$(grep -E '^checks: [0-9]+, failed: ' "$tmp/$t.win" || true)
    [ -n "$line" ] || fail "$t.exe printed no checks line"
    case "$line" in *", failed: 0") ;; *) grep FAILED "$tmp/$t.win" | head -20 >&2; fail "$t.exe: $line" ;; esac
    echo "$t.exe: $line"
done
diff <(grep -E '^(hash|stats)' "$tmp/scenes.linux.out") <(grep -E '^(hash|stats)' "$tmp/scenes.win") ||
    fail "scenes.exe's worlds differ from Linux's"
echo "scenes.exe: $(grep -c -E '^(hash|stats)' "$tmp/scenes.win") hash and statistics lines equal to Linux's"
run threads --threads 2 --steps 20
grep -q 'equal=yes' "$tmp/threads.win" || fail "threads.exe: $(grep hash "$tmp/threads.win")"
diff <(grep '^hash' "$tmp/threads.linux.out") <(grep '^hash' "$tmp/threads.win") || fail "threads.exe's hashes differ from Linux's"
echo "threads.exe: $(grep '^hash' "$tmp/threads.win"), as on Linux"
echo "windows: all passed"
