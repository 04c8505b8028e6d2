#!/usr/bin/env bash
# What the PNG compression level costs and saves: runs the six runs of
# scripts/run-scenes.sh at each zlib level given (default: 6 and 9),
# REPEAT times each (default 3), and prints per level the bytes of every
# PNG written (frames and contact sheets) and the time spent writing them,
# as the programs report it (their `png:` line), the fastest repeat.
#
#   scripts/png-level.sh [LEVEL...]        e.g. scripts/png-level.sh 1 6 9
#
# Needs the programs built: run scripts/run-scenes.sh once first.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
target=${CARGO_TARGET_DIR:-$root/target}
case "$target" in /*) ;; *) target="$root/$target" ;; esac
bin="$target/c_examples"
[ -x "$bin/aggregation" ] || { echo "no $bin/aggregation: run scripts/run-scenes.sh first" >&2; exit 1; }
levels=("$@")
[ ${#levels[@]} -gt 0 ] || levels=(6 9)
repeat=${REPEAT:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run_all() { # LEVEL DIR: the six runs; prints the total milliseconds spent writing PNGs
    local level=$1 dir=$2 ms=0
    for run in aggregation cluster smoke water smoke-long smoke-flow; do
        case "$run" in
            smoke-long) args=(smoke --steps 480 --every 40 --name smoke-long) ;;
            *) args=("$run") ;;
        esac
        line=$("$bin/${args[0]}" "${args[@]:1}" --png-level "$level" --gif 0 --quiet --out "$dir" | grep '^sim: ')
        ms=$(echo "$line" | awk -v ms="$ms" '{ for (i = 1; i <= NF; i++) if ($i == "png:") { per = $(i + 1); files = $(i + 3) } }
            END { gsub(/\(/, "", files); printf "%.1f", ms + per * files }')
    done
    echo "$ms"
}

printf '%-6s %12s %14s\n' level "PNG bytes" "PNG writing ms"
for level in "${levels[@]}"; do
    best=""
    for _ in $(seq "$repeat"); do
        rm -rf "$work/out"
        ms=$(run_all "$level" "$work/out")
        best=$(awk -v a="$ms" -v b="$best" 'BEGIN { print (b == "" || a < b) ? a : b }')
    done
    bytes=$(cat "$work"/out/*.png | wc -c)
    printf '%-6s %12s %14s\n' "$level" "$bytes" "$best"
done
