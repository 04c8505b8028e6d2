#!/usr/bin/env bash
# Instructions per processed block of the paper's scenes, counted by
# valgrind's callgrind inside World::step_forward only (building the world
# and the benchmark's own loop are not counted). Instruction counts do not
# depend on the machine's load, unlike times, so they are the figure to
# compare between commits.
#
#   scripts/instructions.sh                 every scene
#   scripts/instructions.sh aggregation     one scene (aggregation, cluster, smoke, water)
#   scripts/instructions.sh --assign        M5.6 alone: instructions per 3D block
#                                           by particles per block, exact-fast
#                                           against greedy (issue 8's ratio)
#   scripts/instructions.sh --classes       M5.6 by occupancy class: instructions per
#                                           3D block for every K particles and F free
#                                           cells (K <= F <= 8), exact-fast against
#                                           exhaustive and greedy; a wish for a blocked
#                                           cell is staying, as M5.4 makes it
#   scripts/instructions.sh --classes raw   the same, such wishes kept (a direct
#                                           caller of assign_moves may pose them)
#   scripts/instructions.sh --classes [raw] searched
#                                           only the blocks where two particles want
#                                           one cell or one wants a blocked cell: those
#                                           that need a search
#   scripts/instructions.sh --per-block [raw] [searched]
#                                           the same classes of up to 5 free cells block
#                                           by block (400 each): how many blocks cost
#                                           exact-fast more than exhaustive, by how much
#   scripts/instructions.sh --streams       M8: instructions per block to start a block's
#                                           stream and draw two outputs, the step's
#                                           counter-based stream against a PCG32 seeded
#                                           per block (tests/src/bin/stream_seeding.rs)
#
# Installs valgrind with apt-get when it is missing.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
command -v valgrind >/dev/null || scripts/install-missing.sh valgrind
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# The M5.6 modes count inside the assign_blocks programme.
case "${1:-}" in
    --assign | --classes | --per-block) cargo build --release -q -p mpca-tests --bin assign_blocks ;;
esac
# `assign_blocks 3 ARG...` under callgrind, counting inside `solve` only,
# into $out/cg; $dump, where set, is one more callgrind option.
solve_counted() {
    valgrind --tool=callgrind --callgrind-out-file="$out/cg" --collect-atstart=no \
        --toggle-collect='*assign_blocks*solve*' ${dump:+"$dump"} target/release/assign_blocks 3 "$@"
}

if [ "${1:-}" = "--streams" ]; then
    blocks=100000
    cargo build --release -q -p mpca-tests --bin stream_seeding
    printf '%-8s %16s\n' stream "instr/block"
    for which in counter pcg; do
        valgrind --tool=callgrind --callgrind-out-file="$out/$which.cg" --collect-atstart=no \
            --toggle-collect="*stream_seeding*${which}_streams*" target/release/stream_seeding "$which" $blocks >/dev/null 2>&1
        awk -v w="$which" -v n=$blocks '/^(summary|totals):/{printf "%-8s %16.1f\n", w, $2 / n; exit}' "$out/$which.cg"
    done
    exit 0
fi

if [ "${1:-}" = "--classes" ]; then
    blocks=4000
    shift
    # Instructions per block of `solve` for (K, FREE, METHOD, words), 3D
    # random blocks, or "-" where there are no such blocks.
    per_block() {
        local k=$1 f=$2 method=$3 solved
        shift 3
        solved=$(solve_counted "$k" "$method" $blocks "$f" "$@" 2>/dev/null | awk '$2 == "blocks" {print $1}')
        [ -n "$solved" ] || { printf -- -; return; }
        awk -v n="$solved" '/^(summary|totals):/{printf "%.0f", $2 / n; exit}' "$out/cg"
    }
    printf '%-9s %5s %11s %11s %11s %8s %8s\n' particles free exact-fast exhaustive greedy ef/exh ef/gr
    for k in 1 2 3 4 5 6 7 8; do
        for f in $(seq "$k" 8); do
            e=$(per_block "$k" "$f" exact-fast "$@")
            x=$(per_block "$k" "$f" exhaustive "$@")
            g=$(per_block "$k" "$f" greedy "$@")
            awk -v k="$k" -v f="$f" -v e="$e" -v x="$x" -v g="$g" 'BEGIN {
                if (e == "-") { printf "%-9s %5s %11s %11s %11s\n", k, f, e, x, g; exit }
                printf "%-9s %5s %11d %11d %11d %8.2f %8.2f%s\n", k, f, e, x, g, e / x, e / g, (e > x ? "  slower than exhaustive" : "") }'
        done
    done
    exit 0
fi

if [ "${1:-}" = "--per-block" ]; then
    blocks=400
    shift
    # Instructions of each block of `solve` for (K, FREE, METHOD, words), one
    # a line, less those of a call with no block: callgrind dumps a profile
    # before every call, the first after the call with no block.
    each_block() {
        local k=$1 f=$2 method=$3 files
        shift 3
        rm -f "$out"/cg*
        dump=--dump-before=assign_blocks::solve solve_counted "$k" "$method" $blocks "$f" "$@" each >/dev/null 2>&1
        files=$(find "$out" -name 'cg*' | wc -l)
        [ "$files" -gt 2 ] || return 0
        for i in $(seq 2 $((files - 1))) cg; do
            [ "$i" = cg ] && file="$out/cg" || file="$out/cg.$i"
            awk '/^(summary|totals):/{print $2; exit}' "$file"
        done | awk 'NR == 1 {call = $1; next} {print $1 - call}'
    }
    printf '%-9s %5s %7s %13s %12s %10s\n' particles free blocks "ef>exhaustive" "most extra" "most ratio"
    for k in 1 2 3 4 5; do
        for f in $(seq "$k" 5); do
            each_block "$k" "$f" exact-fast "$@" >"$out/ef"
            each_block "$k" "$f" exhaustive "$@" >"$out/exh"
            [ -s "$out/ef" ] || { printf '%-9s %5s %7s\n' "$k" "$f" -; continue; }
            paste "$out/ef" "$out/exh" | awk -v k="$k" -v f="$f" '{
                n++; if ($1 > $2) { slower++; if ($1 - $2 > extra) extra = $1 - $2 }
                if ($1 / $2 > ratio) ratio = $1 / $2 }
                END { printf "%-9s %5s %7d %13d %12d %10.2f\n", k, f, n, slower, extra, ratio }'
        done
    done
    exit 0
fi

if [ "${1:-}" = "--assign" ]; then
    blocks=4000
    # Instructions per block of `solve` for (K, METHOD), 3D random blocks.
    per_block() {
        solve_counted "$1" "$2" $blocks >/dev/null 2>&1
        awk -v n=$blocks '/^(summary|totals):/{printf "%.0f", $2 / n; exit}' "$out/cg"
    }
    printf '%-10s %12s %12s %8s\n' particles exact-fast greedy ratio
    for k in 1 2 3 4 5 6 7 8; do
        e=$(per_block "$k" exact-fast)
        g=$(per_block "$k" greedy)
        awk -v k="$k" -v e="$e" -v g="$g" 'BEGIN { printf "%-10s %12d %12d %8.2f\n", k, e, g, e / g }'
    done
    exit 0
fi

bench=$(cargo bench -p mpca-tests --bench scenes --no-run --message-format=json 2>/dev/null |
    grep '"kind":\["bench"\]' | sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -1)
[ -x "$bench" ] || { echo "instructions: the benchmark did not build" >&2; exit 1; }

scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(aggregation cluster smoke water)
printf '%-12s %14s %12s %16s\n' scene instructions blocks "instr/block"
for scene in "${scenes[@]}"; do
    line=$(MPCA_BENCH_SCENE=$scene MPCA_BENCH_RUNS=1 valgrind --tool=callgrind \
        --callgrind-out-file="$out/$scene.cg" --collect-atstart=no \
        --toggle-collect='*World*step_forward*' "$bench" 2>/dev/null | awk -v s="$scene" '$1 == s')
    [ -n "$line" ] || { echo "instructions: no benchmark line for '$scene'" >&2; exit 1; }
    blocks=$(echo "$line" | awk '{print $NF}')
    instr=$(awk '/^(summary|totals):/{print $2; exit}' "$out/$scene.cg")
    awk -v s="$scene" -v i="$instr" -v b="$blocks" 'BEGIN { printf "%-12s %14.0f %12.0f %16.1f\n", s, i, b, i / b }'
done
