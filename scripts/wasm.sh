#!/usr/bin/env bash
# mpca in the browser: the core built for wasm32-unknown-unknown
# (web/src/wasm.rs, mpca_web.wasm), its JavaScript binding (web/page/mpca.js)
# and the page (web/page/index.html) where smoke and water run in real time.
#
#   scripts/wasm.sh                test the page in headless Chromium
#   scripts/wasm.sh --serve        build, and serve the page on 127.0.0.1
#                                  for a browser of your own (Ctrl-C ends it)
#   scripts/wasm.sh --screenshot   test, and write docs/web/page.png
#
# The test builds the page into target/web, serves it on 127.0.0.1
# (web/serve.py) and opens it in headless Chromium with ?test=STEPS&seed=SEED,
# a seed drawn now: the page steps each scene STEPS times, drawing a frame
# every tenth of the way, then times steps for half a second, and posts its
# result. It passes when each scene's world hash equals the one web_hash
# (the same scenes built natively, for this machine) prints for that seed
# and step count (M8: the same world in the browser as anywhere), and every
# frame drawn holds particles, read back from the canvas. It prints the
# steps per second each scene ran at in the browser and the sizes of the
# .wasm and the .js.
#
# Installs chromium and python3 with apt-get when missing
# (scripts/install-missing.sh) and the Rust target with rustup.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
fail() { echo "wasm: $*" >&2; exit 1; }
mode=test
case "${1:-}" in
    "") ;;
    --serve) mode=serve ;;
    --screenshot) mode=screenshot ;;
    *) echo "usage: scripts/wasm.sh [--serve | --screenshot]" >&2; exit 2 ;;
esac

need=()
command -v python3 >/dev/null 2>&1 || need+=(python3)
chrome=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
[ -n "$chrome" ] || [ "$mode" = serve ] || need+=(chromium)
scripts/install-missing.sh ${need[@]+"${need[@]}"}
[ -n "$chrome" ] || chrome=$(command -v chromium || true)
rustup target list --installed | grep -qx wasm32-unknown-unknown || rustup target add wasm32-unknown-unknown

target=${CARGO_TARGET_DIR:-$root/target}
case "$target" in /*) ;; *) target="$root/$target" ;; esac

echo "== mpca_web.wasm (cargo build -p mpca-web --target wasm32-unknown-unknown --profile wasm)"
cargo build -p mpca-web --lib --target wasm32-unknown-unknown --profile wasm
site="$target/web"
mkdir -p "$site"
cp "$target/wasm32-unknown-unknown/wasm/mpca_web.wasm" web/page/index.html web/page/mpca.js "$site/"
for f in mpca_web.wasm mpca.js; do
    echo "$f: $(stat -c %s "$site/$f") bytes, $(gzip -9 -c "$site/$f" | wc -c) gzipped"
done

tmp=$(mktemp -d "${TMPDIR:-/tmp}/mpca-wasm.XXXXXX")
pids=()
cleanup() {
    for pid in ${pids[@]+"${pids[@]}"}; do kill "$pid" 2>/dev/null || true; done
    rm -rf "$tmp"
}
trap cleanup EXIT

# serve: starts web/serve.py on target/web; sets $port.
serve() {
    python3 -u web/serve.py "$site" "$tmp/result" >"$tmp/port" &
    pids+=($!)
    for _ in $(seq 50); do [ -s "$tmp/port" ] && break; sleep 0.1; done
    port=$(head -n 1 "$tmp/port")
    [ -n "$port" ] || fail "the server did not start"
}

if [ "$mode" = serve ]; then
    serve
    echo "open http://127.0.0.1:$port/index.html (Ctrl-C ends the server)"
    wait
    exit 0
fi

# Chromium as the tests run it: headless, its own profile, no GPU needed.
browser=("$chrome" --headless --no-sandbox --disable-gpu --disable-extensions --no-first-run --window-size=840,600)

echo "== the page in $("$chrome" --version 2>/dev/null)"
steps=400
seed=$((RANDOM * 32768 + RANDOM))
serve
"${browser[@]}" --user-data-dir="$tmp/profile-test" "http://127.0.0.1:$port/index.html?test=$steps&seed=$seed" >"$tmp/chrome.log" 2>&1 &
pids+=($!)
for _ in $(seq 600); do [ -s "$tmp/result" ] && break; sleep 0.2; done
kill "${pids[-1]}" 2>/dev/null || true
[ -s "$tmp/result" ] || { tail -20 "$tmp/chrome.log" >&2; fail "the page posted no result in 120 s"; }
grep -qx done "$tmp/result" || fail "the page's result is cut short: $(cat "$tmp/result")"

cargo build --release -q -p mpca-web --bin web_hash
for scene in smoke water; do
    line=$(grep "^result $scene " "$tmp/result") || fail "the page reported no $scene"
    echo "$line"
    field() { echo "$line" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
    native=$("$target/release/web_hash" "$scene" "$seed" "$steps")
    echo "native: $native"
    [ "$(field hash)" = "${native##* hash }" ] || fail "$scene: the browser's hash $(field hash), natively ${native##* hash }"
    [ "$(field particles)" -gt 0 ] || fail "$scene: no particles"
    [ "$(field frames)" -gt 0 ] && [ "$(field lit)" = "$(field frames)" ] ||
        fail "$scene: $(field lit) of $(field frames) frames drawn hold particles"
    echo "$scene: hash equal to the native build's; $(field frames) frames drawn, none blank; $(field steps_per_s) steps/s in the browser"
done

if [ "$mode" = screenshot ]; then
    mkdir -p docs/web
    # 600 steps in, and a few frames more under virtual time.
    "${browser[@]}" --user-data-dir="$tmp/profile-shot" --virtual-time-budget=8000 --hide-scrollbars --screenshot="$root/docs/web/page.png" \
        "http://127.0.0.1:$port/index.html?seed=$seed&warm=600" >"$tmp/shot.log" 2>&1 || { tail "$tmp/shot.log" >&2; fail "no screenshot"; }
    echo "docs/web/page.png: $(stat -c %s docs/web/page.png) bytes"
fi
echo "wasm: all passed"
