#!/usr/bin/env bash
# The paper's four scenes, rendered: installs what is missing (Debian or
# Ubuntu), builds libmpca and the C programs of c_examples/, runs the four
# scenes at full size (and the smoke scene a second, longer time, and with
# flow drag, M5.1b; and smoke-ids, smoke drawn between steps by id and
# faded by age, M6b; and the moving bodies of M13: wake, a disc through
# smoke, and box2d-wheel, a Box2D water wheel under a waterfall; and smoke,
# water and sand drawn as a game engine draws them, looks-*), and says
# where the images (PNG frames, contact sheets, animated GIFs) are and how
# long the simulation took.
#
#   scripts/run-scenes.sh [--out DIR] [--docs]
#
#   --out DIR   where the images go (default out/scenes, git-ignored)
#   --docs      also copy the contact sheets and the GIFs to docs/scenes/
#               (each at most 300 KB) and rewrite the README's scenes
#               section (between its <!-- scenes:begin --> and
#               <!-- scenes:end --> lines) with this machine's timings
#
# Needs only the Rust toolchain; make, libosmesa6-dev, libpng-dev,
# libgif-dev and libbox2d-dev are installed with apt-get when missing (as
# root, or through sudo).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out="$root/out/scenes"
docs=0
while [ $# -gt 0 ]; do
    case "$1" in
        --out) [ $# -ge 2 ] || { echo "--out needs a folder" >&2; exit 2; }; out=$2; shift 2 ;;
        --docs) docs=1; shift ;;
        -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "unknown option: $1 (try --help)" >&2; exit 2 ;;
    esac
done
mkdir -p "$out"
out=$(cd "$out" && pwd)

echo "== what the C programs need"
cc=${CC:-cc}
"$root/scripts/setup-c.sh"

echo "== libmpca (cargo build --release -p mpca-ffi)"
cd "$root"
cargo build --release -p mpca-ffi
target=${CARGO_TARGET_DIR:-$root/target}
case "$target" in /*) ;; *) target="$root/$target" ;; esac
lib="$target/release"
bin="$target/c_examples"

echo "== the C programs (make -C c_examples)"
make -C c_examples --no-print-directory MPCA_LIB="$lib" BUILD="$bin" CC="$cc"

echo "== the scenes, full size, images in $out"
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
# The effects drawn as a game would: their own subsection of the README.
looks=(looks-smoke looks-water looks-sand)
runs=(aggregation cluster smoke water smoke-long smoke-flow water-pool smoke-ids wake box2d-wheel "${looks[@]}")
is_look() { case "$1" in looks-*) return 0;; *) return 1;; esac; }
# Images to be checked in are compressed harder: size matters there, the
# time does not.
png=()
[ "$docs" -eq 0 ] || png=(--png-level 9)
# The program and arguments of a run, into the array `args`.
run_args() {
    case "$1" in
        smoke-long) args=(smoke --steps 480 --every 40 --name smoke-long) ;;
        *) args=("$1") ;;
    esac
}
for run in "${runs[@]}"; do
    run_args "$run"
    echo "-- ${args[*]}"
    "$bin/${args[0]}" "${args[@]:1}" "${png[@]}" --out "$out" | tee "$logs/$run.log"
done

# One row per run: the program's own figures.
cpu=$(awk -F': ' '/^model name/{print $2; exit}' /proc/cpuinfo 2>/dev/null || true)
cores=$(nproc 2>/dev/null || echo "?")
machine="${cpu:-unknown CPU}, $cores cores"
summary() {
    for run in "${runs[@]}"; do
        awk -v run="$run" '
            NR == 1 { match($0, /[0-9x]+ cells/); cells = substr($0, RSTART, RLENGTH - 6) }
            /^end: / { for (i = 2; i <= NF; i++) { split($i, kv, "="); e[kv[1]] = kv[2] } }
            /^sim: / { per_step = $2; match($0, /in [0-9.]+ ms/); total = substr($0, RSTART + 3, RLENGTH - 6) }
            /^sheet: / { sheet = $2 }
            END { printf "%s|%s|%s|%s|%s|%s|%s\n", run, cells, e["particles"], e["step"], per_step, total, sheet }
        ' "$logs/$run.log"
    done
}
echo
echo "== done: simulation time on $machine (rendering and PNG writing not included)"
printf '%-12s %-8s %10s %6s %10s %10s  %s\n' scene cells particles steps ms/step total_ms "contact sheet"
summary | while IFS='|' read -r run cells particles steps per_step total sheet; do
    printf '%-12s %-8s %10s %6s %10s %10s  %s\n' "$run" "$cells" "$particles" "$steps" "$per_step" "$total" "$sheet"
done
echo
echo "frames (NAME-frame-0000.png, ...), contact sheets (NAME-sheet.png) and animations (NAME.gif): $out"

if [ "$docs" -eq 1 ]; then
    echo "== docs/scenes and the README's scenes section"
    mkdir -p "$root/docs/scenes"
    for run in "${runs[@]}"; do
        sheet="$out/$run-sheet.png"
        # Keep committed images small: re-render at half the resolution
        # while the sheet is over 300 KB.
        px=512
        while [ "$(stat -c %s "$sheet")" -gt 307200 ] && [ $px -gt 64 ]; do
            px=$((px / 2))
            small="$logs/px$px"
            case "$run" in
                smoke-long) "$bin/smoke" --steps 480 --every 0 --name smoke-long --px $px "${png[@]}" --out "$small" >/dev/null ;;
                *) "$bin/$run" --every 0 --px $px "${png[@]}" --out "$small" >/dev/null ;;
            esac
            sheet="$small/$run-sheet.png"
        done
        cp "$sheet" "$root/docs/scenes/$run.png"
        echo "docs/scenes/$run.png: $(stat -c %s "$sheet") bytes"
        # The GIF, with fewer frames while it is over 300 KB: its size grows
        # with the frames, since every frame stores what changed.
        gif="$out/$run.gif"
        gif_line=$(grep '^gif: ' "$logs/$run.log")
        frames=$(echo "$gif_line" | sed 's/.* frames=\([0-9]*\).*/\1/')
        while [ "$(stat -c %s "$gif")" -gt 307200 ] && [ "$frames" -gt 8 ]; do
            frames=$((frames * 300 * 1024 / $(stat -c %s "$gif")))
            [ "$frames" -ge 8 ] || frames=8
            fewer="$logs/gif$frames"
            run_args "$run"
            gif_line=$("$bin/${args[0]}" "${args[@]:1}" --every 0 --tiles 1 --gif "$frames" --out "$fewer" | grep '^gif: ')
            gif="$fewer/$run.gif"
        done
        cp "$gif" "$root/docs/scenes/$run.gif"
        echo "docs/scenes/$run.gif: $(stat -c %s "$gif") bytes, $frames frames"
        echo "$frames|$(stat -c %s "$gif")" > "$logs/$run.gif-info"
    done
    paper_s() { case "$1" in aggregation) echo 800;; cluster) echo 70;; smoke) echo 8;; water) echo 270;; *) echo "";; esac; }
    section() { case "$1" in aggregation) echo "4.1 aggregation";; cluster) echo "4.2 cluster collision";;
        smoke) echo "4.3 smoke";; water) echo "4.4 water";; smoke-long) echo "4.3 smoke, longer run";;
        smoke-flow) echo "4.3 smoke with flow drag (M5.1b, beyond the paper)";;
        water-pool) echo "4.4 water poured into a pool (M5.7 contacts, beyond the paper)";;
        smoke-ids) echo "smoke tracked by id, faded by age (M6b, beyond the paper)";;
        wake) echo "a ball through smoke (M13 bodies, beyond the paper)";;
        box2d-wheel) echo "a Box2D water wheel under a waterfall (M13 bodies with Box2D, beyond the paper)";;
        looks-smoke) echo "smoke drawn as a game would";;
        looks-water) echo "water drawn as a game would";;
        looks-sand) echo "sand drawn as a game would";; esac; }
    # A field of a program's own line in its log: field LOG PREFIX KEY.
    field() { grep "^$2" "$1" | head -n 1 | tr ' ' '\n' | sed -n "s/^$3=//p"; }
    # -46.6 -> 46.6
    unsign() { echo "${1#-}"; }
    caption() { case "$1" in
        aggregation) echo "a gas at density 0.3 with e = 0.5 cools and gathers into clusters (slow, blue);";;
        cluster) echo "two discs meet at v = (±0.8, 0) and scatter, mostly across the line of flight;";;
        smoke) echo "one particle a step rises from the ground and the vortex (grey guides) bends the plume;";;
        water) echo "water poured on the sphere splashes off it and spreads over the floor;";;
        smoke-long) echo "the same smoke for 480 steps: the vortex bends the plume round its right side and flings it out at the top right;";;
        smoke-flow) echo "the smoke as buoyancy plus drag towards the air's flow, 1,200 steps. The air is a vortex fed through its core (the vortex's flow plus an inflow of the same profile, set per cell in the wind plane), so its streamlines spiral in: the plume rises at its terminal speed (slow colours, no clamp), winds up round the vortex's right side and over it into the core, and gathers there (22 % of the particles within 1.5 core radii at the end, against 1 % when the flow is the vortex's alone and the plume passes its side). Its density, in bins of 8 × 8 cells, is drawn as grey haze under the particles.";;
        smoke-ids) echo "buoyant smoke in a breeze (the figures of docs/model.md, Units: buoyancy 0.0069, drag 0.033 towards a wind of 0.25 cells per step, a lifetime of 240 steps), periodic across, with ids and ages (M6b). After every step \`mpca_world_export_particles\` writes positions, ids and ages in one pass; the renderer sorts the particles by id and merges them with the last step's, and draws four frames a step, each particle sliding from its old cell to its new one (a new one appears where it is; one that wraps round the periodic edge jumps), as a soft puff that cools from yellow to violet and fades out with its age. The sheet is at whole steps; the GIF is the run's last frames, four a step (t=358.25 is a quarter of the way from step 358 to 359).";;
        water-pool) echo "a block of 9,216 particles released above the sphere under gravity 0.002, e = 0.5 and contacts on: it splashes off the sphere and, by step 1,000, lies as a pool on the floor (mean speed 0.07, no clamp), where the paper's rules (e = 1, no contacts) keep it bouncing round the box.";;
        wake) l="$logs/wake.log"
            echo "a disc body (radius 6 cells, e = 0.5) moved across at 0.4 cells per step through smoke that rises with the air at 0.15 cells per step (drag 0.05 towards it, a density of 0.3 kept by a vent along the ground, periodic across). Before every step \`mpca_world_move_body\` puts the disc a step further on; the smoke it takes is pushed out ahead of it and the smoke it meets bounces off it, and the channel it leaves rises with the smoke: over the crossing the 8 cells behind the disc held $(field "$l" 'wake: ' behind) particles a cell against $(field "$l" 'wake: ' ahead) in the same rows ahead of it, and the disc handed the smoke $(field "$l" 'wake: ' momentum_per_step) (mass × cells per step) a step, from $(field "$l" 'wake: ' reflected) reflections and $(field "$l" 'wake: ' pushed) push-outs ($(field "$l" 'wake: ' crushed) particles crushed). The haze is the density in bins of 8 × 8 cells.";;
        box2d-wheel) l="$logs/box2d-wheel.log"
            echo "C++ (\`c_examples/box2d_wheel.cpp\`, Box2D 2.4 from Debian's \`libbox2d-dev\`): a Box2D wheel (six blades, radius 1.2 m, on a pin whose friction holds back 100 N m) under a waterfall of 3 particles a step at cells of 5 cm and 120 steps a second (two a Box2D step at 60 Hz; a particle is 1 kg). Each blade is a capsule body moved from Box2D's pose before every step; the water's momentum on it, negated, is an impulse at the blade's middle. It turns the wheel clockwise (the program prints clockwise speeds and torques as negative): $(unsign "$(field "$l" 'wheel: t=1s' rpm)") turns a minute after 1 s and $(unsign "$(field "$l" 'wheel: t=5s' rpm)") after 5 s, against $(unsign "$(field "$l" 'wheel: t=5s' dry_rpm)") for the same wheel in a Box2D world without the water; over the last second the water's torque averaged $(unsign "$(field "$l" 'water: ' torque)") N m, against the pin's load of 100. The section on bodies below says why a waterfall and not a pool.";;
        looks-smoke) l="$logs/looks-smoke.log"
            echo "soft sprites: each particle a puff of a radial falloff broken up by noise, turned by an angle of its own, growing from 2.5 to 10 cells and fading out as its age nears its lifetime of 240 steps (the ages of M6b), laid over the others with premultiplied alpha, part of the way between its last two cells. The world: the smoke preset (\`mpca_desc_preset(&d, MPCA_PRESET_SMOKE, ...)\`: buoyancy 0.0069, drag 0.033 with turbulence of amplitude 0.5 in eddies of 16 cells (M5.1c), speed-limited collisions, lifetimes, ids and ages) with a breeze of 0.04 cells per step; a vent 8 cells wide puffs at 0.6 cells per step ($(commas "$(field "$l" 'end: ' emitted)") particles emitted over $(field "$l" 'end: ' step) steps, $(field "$l" 'end: ' clamps) clamps).";;
        looks-water) l="$logs/looks-water.log"
            echo "a surface: every particle splatted as a blurred disc (radius 2.5 cells) into an offscreen density image behind a framebuffer object, mirrored behind the walls; a second pass keeps where the density passes half a packed body's, tints it darker with the water above it, lights it by its slope, whitens it where the particles travel (foam) and draws a lone particle as a faint drop. The world: the water preset (\`MPCA_PRESET_WATER\`: gravity 0.005, e = 0.95 for water and walls, contacts and resting contact, M5.7b; the stones' e is 0.95 too); a tap pours into a pool with two stones and closes at step $(field "$l" 'tap: ' step); at the end $(commas "$(field "$l" 'end: ' particles)") particles, a mean speed of $(field "$l" 'look: ' mean_speed) and a share of $(field "$l" 'look: ' changed_cell) changing cell in a step.";;
        looks-sand) l="$logs/looks-sand.log"
            echo "grains: each particle an opaque bead about a cell wide, lit from the upper left, coloured by its tag (M6b) as one of four materials (the spout's tag changes every 250 steps, so the mound shows its layers), its brightness, hue, size and place jittered by its id. The world: the sand preset (\`MPCA_PRESET_SAND\`: gravity 0.0136, e = 0.1 for grains and walls, contacts and resting contact, M5.7b); at the end a mean speed of $(field "$l" 'look: ' mean_speed) with the spout still pouring; a slot 24 cells wide pours a grain a step ($(commas "$(field "$l" 'end: ' particles)") grains).";;
    esac; }
    # 12345 -> 12,345
    commas() { echo "$1" | sed ':a;s/\B[0-9]\{3\}\>/,&/;ta'; }
    {
        echo "## The paper's scenes, rendered"
        echo
        echo "The four scenes of the paper's section 4, as C programs in \`c_examples/\`"
        echo "that use only \`include/mpca.h\` and \`libmpca\`, drawn off-screen with OpenGL"
        echo "through OSMesa (no window, no display) and written as PNG with libpng."
        echo "The particles take the path a real-time engine would: the library exports"
        echo "their positions and velocities straight into a vertex buffer object, and"
        echo "GLSL 1.20 shaders draw them; the density goes into a texture"
        echo "(\`c_examples/gpu.c\`, OpenGL 2.1, so also OpenGL ES 2 and WebGL)."
        echo "Particles are coloured by speed (2D: blue slow, through green and yellow,"
        echo "to red at 1 cell per step; 3D: dark blue to light cyan, darker farther"
        echo "away); walls, the sphere and the vortex's guide circles are grey."
        echo "Each program writes a PNG frame every few steps, numbered in order"
        echo "(\`water-frame-0000.png\`, \`water-frame-0001.png\`, ..., so tools that read"
        echo "sequences, such as \`ffmpeg -i water-frame-%04d.png\`, take them as they are),"
        echo "a contact sheet and an animated GIF (written with giflib, 40 frames at the"
        echo "sheet's size, one 255-colour palette, each frame storing only what changed):"
        echo
        echo "<!-- scenes: the main command -->"
        echo '```sh'
        echo "scripts/run-scenes.sh"
        echo '```'
        echo
        echo "It installs what is missing (\`make\`, \`libosmesa6-dev\`, \`libpng-dev\`,"
        echo "\`libgif-dev\`, \`libbox2d-dev\`, with \`apt-get\` as root or through \`sudo\`), builds \`libmpca\` in release"
        echo "mode and the programs with \`make\`, runs the four scenes at full size (and"
        echo "the smoke scene a second time, for 480 steps, and with flow drag, and the water poured into a pool; and smoke drawn between steps by id; and two scenes of moving bodies, one of them coupled with Box2D; and smoke, water and sand drawn as a game would) and prints where the images"
        echo "are: \`out/scenes/\`. Each program also runs alone, e.g."
        echo "\`target/c_examples/water --size 32 --steps 200 --every 20 --out /tmp/w\`;"
        echo "\`--help\` lists its options (\`--size --steps --seed --every --tiles --px --out --name --threads --density --gif --png-level --progress --quiet --version\`);"
        echo "on a terminal, a run that takes over a second reports its progress on"
        echo "stderr every 10 % (\`--quiet\` turns that off)."
        echo
        # A run's caption, sheet and GIF.
        show() {
            echo "**$(section "$1")**: $(caption "$1")"
            echo
            echo "![$(section "$1"): contact sheet](docs/scenes/$1.png)"
            echo
            IFS='|' read -r frames bytes < "$logs/$1.gif-info"
            echo "Animated: [\`docs/scenes/$1.gif\`](docs/scenes/$1.gif) ($frames frames, $((bytes / 1024)) KB)"
            echo
        }
        for run in "${runs[@]}"; do
            is_look "$run" || show "$run"
        done
        echo "### Drawn as a game would: smoke, water, sand"
        echo
        echo "The scenes above draw every particle as itself, a point coloured by speed."
        echo "These draw the same library's particles as a game engine draws the three"
        echo "effects (\`c_examples/looks.c\`, one source built as \`looks-smoke\`,"
        echo "\`looks-water\` and \`looks-sand\`; the drawing in \`c_examples/engine.c\`,"
        echo "reusable through \`draw.h\`). After every step the program exports the"
        echo "particles with their ids, sorts them by id and matches them with the last"
        echo "step's (\`c_examples/follow.c\`), so any frame may be drawn part of the way"
        echo "between two steps; GLSL 1.20 shaders and, for the water, a framebuffer object"
        echo "draw them. Each effect's world starts from the library's preset for it"
        echo "(\`mpca_desc_preset\`, in \`smoke_desc\`, \`water_desc\`, \`sand_desc\`). The sheets are at whole"
        echo "steps; the smoke's GIF spans its last 60 steps, the others the whole run,"
        echo "their frames labelled with fractional steps where they fall between two."
        echo
        for run in "${looks[@]}"; do
            show "$run"
        done
        echo "Simulation time only (\`mpca_world_step\`; building the world, drawing and"
        echo "writing PNGs not included; for wake and box2d-wheel, moving the bodies and reading"
        echo "what they gave included, and for wake measuring its wake, but not Box2D's step), one run each, on $machine,"
        echo "beside the paper's time on a Sun SPARCstation 2GS:"
        echo
        echo "| scene | cells | particles (end) | steps | this library, per step | this library, total | paper (SPARCstation 2GS) | paper / this |"
        echo "|---|---|---|---|---|---|---|---|"
        summary | while IFS='|' read -r run cells particles steps per_step total _; do
            p=$(paper_s "$run")
            if [ -n "$p" ]; then
                ratio=$(awk -v p="$p" -v t="$total" 'BEGIN { r = p * 1000 / t; e = 10 ^ (int(log(r) / log(10)) - 1); printf "%d", int(r / e + 0.5) * e }')
                paper="~$p s"; ratio="~$(commas "$ratio")×"
            else
                paper="—"; ratio="—"
            fi
            echo "| $(section "$run") | ${cells//x/ × } | $(commas "$particles") | $steps | $per_step ms | $total ms | $paper | $ratio |"
        done
        echo
        echo "The scenes are those of \`tests/src/scenes.rs\` (sizes, seeds, boundaries,"
        echo "forces, emitters, obstacles, step counts): \`cargo test\` runs each C program"
        echo "for a few steps at full size and checks that its world hashes equal to the"
        echo "Rust scene's, and runs each at a small size and checks its images"
        echo "(wake, box2d-wheel and the three looks, which have no Rust twin, only the"
        echo "latter, with their own figures: the clear strip behind the disc, the wheel"
        echo "the water turns, the effect drawn over the fixed parts and every emitted"
        echo "particle followed by id)."
    } > "$logs/section.md"
    # Splice the section into README.md between its markers.
    awk -v section="$logs/section.md" '
        /^<!-- scenes:end -->$/ { skip = 0 }
        !skip { print }
        /^<!-- scenes:begin -->$/ { while ((getline line < section) > 0) print line; skip = 1 }
    ' "$root/README.md" > "$logs/README.md"
    grep -q '^<!-- scenes:end -->$' "$logs/README.md" || { echo "README.md lacks the scenes markers" >&2; exit 1; }
    cp "$logs/README.md" "$root/README.md"
    echo "README.md: scenes section rewritten"
fi
