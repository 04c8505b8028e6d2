#!/usr/bin/env bash
# The crate mpca as crates.io would take it:
#
#   scripts/package.sh
#
# - cargo package -p mpca and cargo publish --dry-run -p mpca (which
#   builds the packaged crate against its dependencies from crates.io);
# - the packaged crate, unpacked apart from the workspace: its examples
#   build and run, and its doctests (the README among them) pass;
# - cargo doc opens on the README's runnable example (the crate's page
#   holds its fn main).
#
# Needs network access to crates.io (the index and the dependencies).
# A dirty working tree is refused by cargo unless ALLOW_DIRTY=1.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
fail() { echo "package: $*" >&2; exit 1; }
dirty=()
[ "${ALLOW_DIRTY:-0}" = 1 ] && dirty=(--allow-dirty)

echo "== cargo package -p mpca"
cargo package -p mpca ${dirty[@]+"${dirty[@]}"}
echo "== cargo publish --dry-run -p mpca"
cargo publish --dry-run -p mpca ${dirty[@]+"${dirty[@]}"}

version=$(cargo pkgid -p mpca)
version=${version##*[@#]}
target=${CARGO_TARGET_DIR:-$root/target}
case "$target" in /*) ;; *) target="$root/$target" ;; esac
crate="$target/package/mpca-$version.crate"
[ -f "$crate" ] || fail "$crate was not written"
echo "mpca-$version.crate: $(stat -c %s "$crate") bytes, $(tar -tzf "$crate" | wc -l) files"

echo "== the packaged crate alone: examples and doctests"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mpca-package.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
tar -xzf "$crate" -C "$tmp"
dir="$tmp/mpca-$version"
# Its own target folder, kept between runs; outside any workspace.
export CARGO_TARGET_DIR="$target/package-check"
(cd "$dir" && cargo run --release --example falling) | tee "$tmp/falling.out"
grep -q '^step 100: 64 particles' "$tmp/falling.out" || fail "the falling example printed no step 100 line"
(cd "$dir" && cargo run --release --features std --example parallel -- 2 5) | tee "$tmp/parallel.out"
(cd "$dir" && cargo test --doc --features std)

echo "== cargo doc: the crate's page opens on the README's example"
(cd "$dir" && cargo doc --no-deps --features std)
page="$CARGO_TARGET_DIR/doc/mpca/index.html"
[ -f "$page" ] || fail "no $page"
grep -q 'fn </span>main' "$page" || grep -q 'fn main' "$page" || fail "the crate's page holds no fn main"
echo "package: all passed"
