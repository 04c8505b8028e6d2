//! The C scene programs of `c_examples/`: the paper's four scenes rendered
//! off-screen with OSMesa and written as PNG with libpng. Built with their
//! own Makefile against the real `libmpca.a`, run, and their images read
//! back through `pngstat` (c_examples/pngstat.c, also libpng), so this
//! needs no image crate.
//!
//! - Each program runs a few steps at a small size; every frame, the
//!   contact sheet and the animated GIF must have the size the program
//!   printed, frames must be numbered 0, 1, 2, ..., and the pixels must
//!   account for the particles it reported (bands derived below).
//! - Each program runs a few steps at the paper's size, and its world's
//!   hash must equal that of the same scene built by `tests/src/scenes.rs`:
//!   the C scenes are the Rust scenes, placement and seeds included.
//! - `threads` and `cpp_example` (the C++ wrapper), which draw nothing,
//!   end equal on any thread count; every program answers `--version`.
//!
//! Needs `make`, a C and a C++ compiler and the OSMesa and libpng headers;
//! the test fails, naming the packages, when they are missing.
#![cfg(target_os = "linux")]

mod clib;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use clib::{library, root};

use mpca_tests::scenes::{Scene, build, paper_scenes};

/// What to install when the headers are missing (Debian, Ubuntu).
const INSTALL: &str = "apt-get install -y libosmesa6-dev libpng-dev libgif-dev libbox2d-dev";

/// The C compiler cc picks for this target, or its C++ compiler (for
/// cpp_example.cpp).
fn compiler(cpp: bool) -> cc::Tool {
    cc::Build::new()
        .cargo_metadata(false)
        .cargo_warnings(false)
        .target(env!("MPCA_TEST_TARGET"))
        .host(env!("MPCA_TEST_HOST"))
        .opt_level(2)
        .cpp(cpp)
        .get_compiler()
}

/// Fails with what to install when make or the headers are missing.
fn check_build_dependencies(cc: &cc::Tool, dir: &Path) {
    let make = Command::new("make").arg("--version").output();
    assert!(
        make.is_ok_and(|o| o.status.success()),
        "`make` is missing; the C examples need it and the OSMesa, libpng and giflib headers: apt-get install -y \
         make libosmesa6-dev libpng-dev libgif-dev"
    );
    let probe = dir.join("probe.c");
    std::fs::write(
        &probe,
        "#include <GL/gl.h>\n#include <GL/osmesa.h>\n#include <png.h>\n#include <gif_lib.h>\nint main(void) { return 0; }\n",
    )
    .expect("write the probe");
    let out = cc.to_command().arg("-fsyntax-only").arg(&probe).output().expect("the C compiler runs");
    assert!(
        out.status.success(),
        "the C examples need the OSMesa, libpng and giflib headers, which {} cannot find: {INSTALL}\n{}",
        cc.path().display(),
        String::from_utf8_lossy(&out.stderr)
    );
    // Box2D (box2d-wheel) is C++ only.
    let cxx = compiler(true);
    let probe = dir.join("probe.cpp");
    std::fs::write(&probe, "#include <box2d/box2d.h>\nint main() { return 0; }\n").expect("write the probe");
    let out = cxx.to_command().arg("-fsyntax-only").arg(&probe).output().expect("the C++ compiler runs");
    assert!(
        out.status.success(),
        "box2d-wheel needs Box2D 2.4's headers, which {} cannot find: {INSTALL}\n{}",
        cxx.path().display(),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The folder holding the four programs and pngstat, built once per test
/// process by `make` in c_examples/ (which compiles with -std=c99 -Wall
/// -Wextra -Wpedantic -Werror).
fn programs() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("c_examples");
        std::fs::create_dir_all(&dir).expect("create the build folder");
        let cc = compiler(false);
        check_build_dependencies(&cc, &dir);
        let lib = library();
        let out = Command::new("make")
            .current_dir(root().join("c_examples"))
            .arg(format!("MPCA_LIB={}", lib.display()))
            .arg(format!("BUILD={}", dir.display()))
            .arg(format!("CC={}", cc.path().display()))
            .arg(format!("CXX={}", compiler(true).path().display()))
            .output()
            .expect("make runs");
        assert!(
            out.status.success(),
            "make in c_examples failed ({INSTALL} installs the libraries it needs):\n{}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        dir
    })
}

/// Runs a scene program; its stdout on success.
fn run(scene: &str, args: &[&str]) -> String {
    let exe = programs().join(scene);
    let out = Command::new(&exe).args(args).output().expect("the scene program runs");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{scene} {} exited with {}:\n{stdout}{}",
        args.join(" "),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// The `key=value` fields of a line.
fn fields(line: &str) -> BTreeMap<&str, &str> {
    line.split_whitespace().filter_map(|kv| kv.split_once('=')).collect()
}

fn number<T: std::str::FromStr>(f: &BTreeMap<&str, &str>, key: &str, line: &str) -> T {
    f.get(key).and_then(|v| v.parse().ok()).unwrap_or_else(|| panic!("no number {key}= in `{line}`"))
}

/// `WxH`.
fn dims(f: &BTreeMap<&str, &str>, line: &str) -> (u64, u64) {
    let s = f.get("size").unwrap_or_else(|| panic!("no size= in `{line}`"));
    let (w, h) = s.split_once('x').unwrap_or_else(|| panic!("size={s}"));
    (w.parse().unwrap(), h.parse().unwrap())
}

/// What pngstat counted in one PNG.
#[derive(Debug)]
struct Pixels {
    width: u64,
    height: u64,
    /// Pixels that differ from the background.
    nonbg: u64,
    /// Pixels in a saturated colour: particles (everything else is grey).
    coloured: u64,
    /// An animated GIF's frame count (its counts are of the last frame).
    frames: Option<u64>,
}

fn pngstat(path: &Path) -> Pixels {
    let out = Command::new(programs().join("pngstat")).arg(path).output().expect("pngstat runs");
    let line = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "pngstat {}: {}", path.display(), String::from_utf8_lossy(&out.stderr));
    let f = fields(&line);
    Pixels {
        width: number(&f, "width", &line),
        height: number(&f, "height", &line),
        nonbg: number(&f, "nonbg", &line),
        coloured: number(&f, "coloured", &line),
        frames: f.get("frames").map(|v| v.parse().expect("frames")),
    }
}

/// One image a program reported: a `frame:` line (a PNG of its own) or a
/// `tile:` line (a part of the contact sheet).
#[derive(Debug)]
struct Drawn {
    path: Option<PathBuf>,
    step: u64,
    particles: u64,
    width: u64,
    height: u64,
    /// 2D: the side of a particle's square, in pixels.
    point_px: Option<u64>,
    /// 3D: the largest sprite diameter, in pixels.
    sprite_max_px: Option<f64>,
}

fn drawn(line: &str) -> Drawn {
    let f = fields(line);
    let (width, height) = dims(&f, line);
    Drawn {
        path: line.strip_prefix("frame: ").map(|r| PathBuf::from(r.split_whitespace().next().unwrap())),
        step: number(&f, "step", line),
        particles: number(&f, "particles", line),
        width,
        height,
        point_px: f.get("point_px").map(|v| v.parse().expect("point_px")),
        sprite_max_px: f.get("sprite_px").map(|v| v.split_once("..").expect("min..max").1.parse().expect("max")),
    }
}

/// Bounds on the particle pixels of one image, from the particles drawn.
///
/// 2D: no two particles share a cell (M1) and each is a square point of
/// `point_px` pixels inside its cell, drawn last in a saturated colour, so
/// the coloured pixels are exactly `particles * point_px^2`.
/// 3D: sprites overlap and hide one another, so the count lies between one
/// pixel (something is drawn when a particle exists) and `particles`
/// sprites of the largest size the box allows, rounded up, plus one pixel
/// of rasterisation slack per side.
fn particle_pixels(d: &Drawn) -> (u64, u64) {
    match (d.point_px, d.sprite_max_px) {
        (Some(s), None) => (d.particles * s * s, d.particles * s * s),
        (None, Some(max)) => {
            let side = max.ceil() as u64 + 1;
            (d.particles.min(1), d.particles * side * side)
        }
        _ => panic!("{d:?} gives neither point_px nor sprite_px"),
    }
}

/// Pixels of the fixed parts of a frame (walls, obstacles, guides: all
/// grey) that a scene draws, for frames of `w x h`.
#[derive(Clone, Copy, Debug)]
enum Fixed {
    /// Nothing but particles (aggregation: periodic, no obstacles).
    Nothing,
    /// A wall two pixels wide along every border (cluster).
    Border,
    /// Measured from the frame at step 0, which must hold no particle
    /// (smoke, water: emitters place their first particles in step 1),
    /// and must cover more than nothing and at most this share.
    AtStepZero(f64),
}

/// A small run of `scene`: every frame and the sheet checked.
///
/// Per frame, with C the coloured pixels and F the fixed pixels: particles
/// are drawn over the fixed parts and are never the background, so
/// `nonbg = |fixed ∪ particles|` lies in `[max(F, C), F + C]`.
fn check_small_run(scene: &str, size: u32, steps: u32, every: u32, fixed: Fixed) {
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join(scene);
    let _ = std::fs::remove_dir_all(&out_dir);
    let (size_s, steps_s, every_s) = (size.to_string(), steps.to_string(), every.to_string());
    let out_s = out_dir.to_string_lossy().into_owned();
    let px = "256";
    let stdout = run(
        scene,
        &["--size", &size_s, "--steps", &steps_s, "--every", &every_s, "--tiles", "4", "--px", px, "--out", &out_s],
    );
    println!("{stdout}");
    assert!(stdout.lines().any(|l| l.starts_with("sim: ") && l.contains(" ms/step") && l.contains("render: ")));

    let frames: Vec<Drawn> = stdout.lines().filter(|l| l.starts_with("frame: ")).map(drawn).collect();
    let tiles: Vec<Drawn> = stdout.lines().filter(|l| l.starts_with("tile: ")).map(drawn).collect();
    let expected_frames = (steps / every + u32::from(steps % every != 0) + 1) as usize;
    assert_eq!(frames.len(), expected_frames, "{scene}: frames at every {every} steps and at the end");
    assert_eq!(tiles.len(), 4, "{scene}: contact sheet tiles");
    assert_eq!((tiles[0].step, tiles[3].step), (0, u64::from(steps)), "{scene}: the sheet spans the run");

    for (i, d) in frames.iter().enumerate() {
        let name = d.path.as_ref().unwrap().file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(name, format!("{scene}-frame-{i:04}.png"), "frames numbered in order, for tools that read sequences");
    }

    let zero = pngstat(frames[0].path.as_ref().unwrap());
    let fixed_px = match fixed {
        Fixed::Nothing => 0,
        Fixed::Border => 4 * (zero.width + zero.height) - 16,
        Fixed::AtStepZero(max_share) => {
            assert_eq!(frames[0].particles, 0, "{scene}: step 0 should hold no particle");
            let share = zero.nonbg as f64 / (zero.width * zero.height) as f64;
            assert!(zero.nonbg > 0 && share <= max_share, "{scene}: fixed parts cover {share:.4} of the frame");
            zero.nonbg
        }
    };
    for d in &frames {
        let path = d.path.as_ref().unwrap();
        let p = pngstat(path);
        assert_eq!((p.width, p.height), (d.width, d.height), "{}: dimensions", path.display());
        if d.point_px.is_some() {
            // 2D frames are whole cells: size x cell_px, cell_px = px / size.
            let cell_px = 256 / u64::from(size);
            assert_eq!(p.width, u64::from(size) * cell_px, "{}: width", path.display());
        } else {
            assert_eq!(p.width, 256, "{}: width", path.display());
        }
        let (lo, hi) = particle_pixels(d);
        assert!(
            (lo..=hi).contains(&p.coloured),
            "{}: {} particle pixels for {} particles, expected {lo}..={hi}",
            path.display(),
            p.coloured,
            d.particles
        );
        assert!(
            p.nonbg >= p.coloured.max(fixed_px) && p.nonbg <= p.coloured + fixed_px,
            "{}: {} non-background pixels, {} of them particles, {fixed_px} fixed",
            path.display(),
            p.nonbg,
            p.coloured
        );
    }
    assert!(frames.last().unwrap().particles > 0, "{scene}: no particles at the end");

    // The sheet: the tiles side by side, their particles and nothing else
    // coloured (labels and gaps are grey or background).
    let sheet_line = stdout.lines().find(|l| l.starts_with("sheet: ")).expect("a sheet: line");
    let f = fields(sheet_line);
    let sheet = PathBuf::from(sheet_line["sheet: ".len()..].split_whitespace().next().unwrap());
    let p = pngstat(&sheet);
    assert_eq!((p.width, p.height), dims(&f, sheet_line), "{}: dimensions", sheet.display());
    let (tw, th) = (tiles[0].width, tiles[0].height);
    assert!(p.width >= 4 * tw && p.height >= th, "{}: 4 tiles of {tw}x{th} do not fit", sheet.display());
    let (lo, hi) = tiles.iter().map(particle_pixels).fold((0, 0), |(a, b), (l, h)| (a + l, b + h));
    assert!(
        (lo..=hi).contains(&p.coloured),
        "{}: {} particle pixels, expected {lo}..={hi}",
        sheet.display(),
        p.coloured
    );
    assert!(p.nonbg > p.coloured, "{}: no labels or fixed parts drawn", sheet.display());

    // The animated GIF: 40 frames by default, fewer when the run has fewer
    // steps; the tiles' size plus a label strip; its last frame as shown is
    // the last tile (step `steps`), whose particles keep their colours
    // through the palette (gif.c), so the same bounds hold.
    let gif_line = stdout.lines().find(|l| l.starts_with("gif: ")).expect("a gif: line");
    let f = fields(gif_line);
    let gif = PathBuf::from(gif_line["gif: ".len()..].split_whitespace().next().unwrap());
    assert_eq!(gif, out_dir.join(format!("{scene}.gif")));
    let g = pngstat(&gif);
    let expected = u64::from(steps + 1).min(40);
    assert_eq!(g.frames, Some(expected), "{}: frames", gif.display());
    assert_eq!(number::<u64>(&f, "frames", gif_line), expected, "{gif_line}");
    assert_eq!((g.width, g.height), dims(&f, gif_line), "{}: dimensions", gif.display());
    assert!(g.width == tw && g.height > th, "{}: {}x{} for tiles of {tw}x{th}", gif.display(), g.width, g.height);
    let (lo, hi) = particle_pixels(&tiles[3]);
    assert!(
        (lo..=hi).contains(&g.coloured),
        "{}: last frame: {} particle pixels, expected {lo}..={hi}",
        gif.display(),
        g.coloured
    );
    assert!(g.nonbg > g.coloured, "{}: no label drawn", gif.display());
}

#[test]
fn aggregation_small_run_draws_every_particle() {
    check_small_run("aggregation", 32, 20, 10, Fixed::Nothing);
}

#[test]
fn cluster_small_run_draws_every_particle_and_the_walls() {
    check_small_run("cluster", 32, 20, 10, Fixed::Border);
}

#[test]
fn smoke_small_run_draws_every_particle_the_vortex_and_the_ground() {
    // Rings of radius 1, 2 and 3 core radii (3 x 10/128 of the side), one
    // pixel wide, the ground, the emitter: well under 10 % of the frame.
    check_small_run("smoke", 32, 30, 10, Fixed::AtStepZero(0.10));
}

#[test]
fn water_small_run_draws_the_sphere_the_box_and_the_water() {
    // The floor seen from above covers about a quarter of the frame, the
    // sphere a twentieth: under half in any case.
    check_small_run("water", 32, 40, 10, Fixed::AtStepZero(0.5));
}

/// `smoke-ids` (M6b): smoke drawn between steps by following each
/// particle's id and faded by its age. The program checks M6b's promises
/// itself as it tracks the particles (ids unique and never 0, new ids above
/// the old, one step older when seen again, at most a cell away or wrapped
/// round the periodic edge) and exits 1 when one fails; here it must run
/// through, follow particles from step to step, see some wrap, and write
/// its frames, its sheet, and a GIF of four frames a step whose last is the
/// end of the run.
#[test]
fn smoke_ids_follows_every_particle_by_id_and_draws_between_steps() {
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join("smoke-ids");
    let _ = std::fs::remove_dir_all(&out_dir);
    let out_s = out_dir.to_string_lossy().into_owned();
    let stdout = run(
        "smoke-ids",
        &["--size", "32", "--steps", "200", "--every", "100", "--tiles", "3", "--gif", "10", "--px", "256", "--out", &out_s],
    );
    println!("{stdout}");
    let ids_line = stdout.lines().find(|l| l.starts_with("ids: ")).expect("an ids: line");
    let ids = fields(ids_line);
    let end_line = stdout.lines().find(|l| l.starts_with("end: ")).expect("an end: line");
    let end = fields(end_line);
    let emitted: u64 = number(&end, "emitted", end_line);
    let particles: u64 = number(&end, "particles", end_line);
    assert!(emitted > 0 && particles > 0, "{end_line}");
    assert_eq!(number::<u64>(&ids, "appeared", ids_line), emitted, "every emitted particle appears once: {ids_line}");
    assert_eq!(number::<u64>(&ids, "last_id", ids_line), emitted, "ids 1 to the emitted count: {ids_line}");
    assert_eq!(
        number::<u64>(&ids, "gone", ids_line),
        emitted - particles,
        "the particles that left or died are those not seen again: {ids_line}"
    );
    assert!(number::<u64>(&ids, "moved", ids_line) > 10 * particles, "particles followed from step to step: {ids_line}");
    assert!(number::<u64>(&ids, "wrapped", ids_line) > 0, "the breeze carries smoke round the periodic edge: {ids_line}");

    let frames: Vec<&str> = stdout.lines().filter(|l| l.starts_with("frame: ")).collect();
    assert_eq!(frames.len(), 3, "frames at 0, 100 and 200");
    for (i, line) in frames.iter().enumerate() {
        let f = fields(line);
        let path = PathBuf::from(line["frame: ".len()..].split_whitespace().next().unwrap());
        assert_eq!(path, out_dir.join(format!("smoke-ids-frame-{i:04}.png")));
        let p = pngstat(&path);
        assert_eq!((p.width, p.height), dims(&f, line), "{}", path.display());
        let drawn: u64 = number(&f, "particles", line);
        assert_eq!(drawn > 0, p.coloured > 0, "{}: {drawn} particles, {} coloured pixels", path.display(), p.coloured);
    }
    let sheet_line = stdout.lines().find(|l| l.starts_with("sheet: ")).expect("a sheet: line");
    let sheet = pngstat(&PathBuf::from(sheet_line["sheet: ".len()..].split_whitespace().next().unwrap()));
    assert_eq!((sheet.width, sheet.height), dims(&fields(sheet_line), sheet_line));
    assert!(sheet.coloured > 0, "{sheet_line}");
    let gif_line = stdout.lines().find(|l| l.starts_with("gif: ")).expect("a gif: line");
    let g = pngstat(&out_dir.join("smoke-ids.gif"));
    assert_eq!(g.frames, Some(10), "{gif_line}");
    assert!(g.coloured > 0, "{gif_line}");
}

/// `looks-smoke`, `looks-water` and `looks-sand` (issue 28): each effect
/// drawn as a game engine draws it, from the particles followed by id
/// between steps. A small run of each: frames numbered in order, the sheet
/// and the GIF at the sizes printed; at step 0 (no particle yet) a frame
/// holds the fixed parts only, and at the end the effect covers more than
/// them. The drawing owes nothing to a particle's square, so the bound on
/// what it covers is loose: a quarter of a cell a particle. Water is a blue
/// body and sand tinted grains (coloured pixels), smoke grey (none). Every
/// emitted particle appeared once in the follower, and particles were
/// followed from step to step.
#[test]
fn looks_draw_smoke_water_and_sand_from_the_particles_followed_by_id() {
    for (effect, coloured) in [("smoke", false), ("water", true), ("sand", true)] {
        let scene = format!("looks-{effect}");
        let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join(&scene);
        let _ = std::fs::remove_dir_all(&out_dir);
        let out_s = out_dir.to_string_lossy().into_owned();
        let args =
            ["--size", "32", "--steps", "200", "--every", "100", "--tiles", "3", "--gif", "10", "--px", "256", "--out", &out_s];
        let stdout = run(&scene, &args);
        println!("{stdout}");
        let frames: Vec<&str> = stdout.lines().filter(|l| l.starts_with("frame: ")).collect();
        assert_eq!(frames.len(), 3, "{scene}: frames at 0, 100 and 200");
        let mut stats = Vec::new();
        for (i, line) in frames.iter().enumerate() {
            let f = fields(line);
            let path = PathBuf::from(line["frame: ".len()..].split_whitespace().next().unwrap());
            assert_eq!(path, out_dir.join(format!("{scene}-frame-{i:04}.png")), "frames numbered in order");
            let p = pngstat(&path);
            assert_eq!((p.width, p.height), dims(&f, line), "{}", path.display());
            stats.push((number::<u64>(&f, "particles", line), p));
        }
        let (zero, fixed) = (&stats[0].0, &stats[0].1);
        assert_eq!(*zero, 0, "{scene}: no particle at step 0");
        assert!(fixed.nonbg > 0 && fixed.coloured == 0, "{scene}: step 0 shows the grey fixed parts only: {fixed:?}");
        let (particles, last) = (&stats[2].0, &stats[2].1);
        let cell_px = 256 / 32;
        assert!(*particles > 0, "{scene}: particles at the end");
        assert!(
            last.nonbg >= fixed.nonbg + particles * cell_px * cell_px / 4,
            "{scene}: {particles} particles cover {} pixels beside the {} fixed",
            last.nonbg - fixed.nonbg.min(last.nonbg),
            fixed.nonbg
        );
        if coloured {
            assert!(last.coloured >= particles * cell_px * cell_px / 4, "{scene}: {particles} particles, {last:?}");
        } else {
            assert_eq!(last.coloured, 0, "{scene}: smoke is grey: {last:?}");
        }
        let sheet_line = stdout.lines().find(|l| l.starts_with("sheet: ")).expect("a sheet: line");
        let sheet = pngstat(&out_dir.join(format!("{scene}-sheet.png")));
        assert_eq!((sheet.width, sheet.height), dims(&fields(sheet_line), sheet_line));
        let gif_line = stdout.lines().find(|l| l.starts_with("gif: ")).expect("a gif: line");
        let g = pngstat(&out_dir.join(format!("{scene}.gif")));
        assert_eq!(g.frames, Some(10), "{gif_line}");
        assert_eq!((g.width, g.height), dims(&fields(gif_line), gif_line));
        assert!(g.nonbg > fixed.nonbg / 4, "{gif_line}: the last frame drawn: {g:?}");

        let end_line = stdout.lines().find(|l| l.starts_with("end: ")).expect("an end: line");
        let look_line = stdout.lines().find(|l| l.starts_with("look: ")).expect("a look: line");
        let (end, look) = (fields(end_line), fields(look_line));
        assert_eq!(
            number::<u64>(&look, "appeared", look_line),
            number::<u64>(&end, "emitted", end_line),
            "every emitted particle appeared once: {look_line}"
        );
        assert_eq!(number::<u64>(&look, "particles", look_line), *particles, "{look_line}");
        assert!(number::<u64>(&look, "followed", look_line) > 10 * particles, "followed from step to step: {look_line}");
    }
}

/// A small run of a 2D scene whose fixed parts (bodies, walls, haze) are
/// all grey: every frame, tile and the GIF's last frame hold exactly
/// `particles * point_px^2` coloured pixels (no two particles share a cell,
/// and bodies are drawn under them), and the sheet and the GIF have the
/// sizes printed. Returns the program's stdout.
fn check_body_scene(scene: &str, args: &[&str]) -> String {
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join(scene);
    let _ = std::fs::remove_dir_all(&out_dir);
    let out_s = out_dir.to_string_lossy().into_owned();
    let mut all = args.to_vec();
    all.extend(["--tiles", "3", "--gif", "10", "--px", "256", "--out", &out_s]);
    let stdout = run(scene, &all);
    println!("{stdout}");
    let frames: Vec<Drawn> = stdout.lines().filter(|l| l.starts_with("frame: ")).map(drawn).collect();
    let tiles: Vec<Drawn> = stdout.lines().filter(|l| l.starts_with("tile: ")).map(drawn).collect();
    assert!(frames.len() >= 2 && tiles.len() == 3, "{scene}: frames and tiles");
    for (i, d) in frames.iter().enumerate() {
        let path = d.path.as_ref().unwrap();
        assert_eq!(path, &out_dir.join(format!("{scene}-frame-{i:04}.png")), "frames numbered in order");
        let p = pngstat(path);
        assert_eq!((p.width, p.height), (d.width, d.height), "{}: dimensions", path.display());
        let (lo, hi) = particle_pixels(d);
        assert!((lo..=hi).contains(&p.coloured), "{}: {} particle pixels, expected {lo}", path.display(), p.coloured);
        assert!(p.nonbg > p.coloured, "{}: no body or wall drawn", path.display());
    }
    let sheet_line = stdout.lines().find(|l| l.starts_with("sheet: ")).expect("a sheet: line");
    let sheet = pngstat(&out_dir.join(format!("{scene}-sheet.png")));
    assert_eq!((sheet.width, sheet.height), dims(&fields(sheet_line), sheet_line));
    let (lo, hi) = tiles.iter().map(particle_pixels).fold((0, 0), |(a, b), (l, h)| (a + l, b + h));
    assert!((lo..=hi).contains(&sheet.coloured), "{sheet_line}: {} particle pixels, expected {lo}", sheet.coloured);
    let gif_line = stdout.lines().find(|l| l.starts_with("gif: ")).expect("a gif: line");
    let g = pngstat(&out_dir.join(format!("{scene}.gif")));
    assert_eq!(g.frames, Some(10), "{gif_line}");
    assert_eq!((g.width, g.height), dims(&fields(gif_line), gif_line));
    let (lo, hi) = particle_pixels(&tiles[2]);
    assert!((lo..=hi).contains(&g.coloured), "{gif_line}: last frame: {} particle pixels, expected {lo}", g.coloured);
    stdout
}

/// `wake` (M13): a disc body moved through rising smoke every step. The
/// strip just behind the disc holds less smoke than the same rows ahead of
/// it, the disc pushed and reflected smoke and handed it momentum along its
/// motion (+x), and the world is the same on threads (the moves are calls
/// between steps, the step the parallel one).
#[test]
fn wake_moves_a_disc_through_smoke_and_leaves_a_clear_strip_behind_it() {
    let stdout = check_body_scene("wake", &["--size", "32", "--steps", "60", "--every", "30"]);
    let line = stdout.lines().find(|l| l.starts_with("wake: ")).expect("a wake: line");
    let f = fields(line);
    let (behind, ahead): (f64, f64) = (number(&f, "behind", line), number(&f, "ahead", line));
    assert!(behind < ahead, "{line}");
    assert!(number::<u64>(&f, "pushed", line) > 0 && number::<u64>(&f, "reflected", line) > 0, "{line}");
    let momentum = f["momentum_per_step"].trim_matches(|c| c == '(' || c == ')');
    let x: f64 = momentum.split(',').next().unwrap().parse().expect("a number");
    assert!(x > 0.0, "the disc moves right and pushes the smoke right: {line}");
    let end = |stdout: &str| stdout.lines().find(|l| l.starts_with("end: ")).expect("an end: line").to_string();
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join("wake-threads");
    let out_s = out_dir.to_string_lossy().into_owned();
    let args = ["--size", "32", "--steps", "60", "--every", "0", "--tiles", "1", "--gif", "0", "--out", &out_s];
    let serial = run("wake", &args);
    let mut threaded = args.to_vec();
    threaded.extend(["--threads", "2"]);
    assert_eq!(end(&serial), end(&run("wake", &threaded)), "serial and 2 threads");
    assert_eq!(end(&serial), end(&stdout), "drawing changes nothing");
}

/// `box2d-wheel` (M13 with Box2D): the falling water turns the Box2D wheel
/// through the impulses its blades' momentum gives, so after a second it
/// turns clockwise (negative), while its twin in a Box2D world without the
/// water stands still.
#[test]
fn box2d_wheel_is_turned_by_the_water_and_its_dry_twin_is_not() {
    let stdout = check_body_scene("box2d-wheel", &["--size", "32", "--steps", "120", "--every", "60"]);
    let line = stdout.lines().find(|l| l.starts_with("wheel: t=1s")).expect("a wheel: line at 1 s");
    let f = fields(line);
    let (wet, dry): (f64, f64) = (number(&f, "rpm", line), number(&f, "dry_rpm", line));
    assert!(wet < -1.0, "the water turns the wheel clockwise: {line}");
    assert_eq!(dry.abs(), 0.0, "nothing turns the dry wheel: {line}");
    let water = stdout.lines().find(|l| l.starts_with("water: ")).expect("a water: line");
    assert!(number::<u64>(&fields(water), "reflected", water) > 0, "{water}");
}

/// Progress: `--progress` reports on stderr at each tenth of the steps, in
/// order, up to 100 %; `--quiet`, and the default when stderr is not a
/// terminal (as here), say nothing. The world ends the same either way,
/// though with progress the steps are taken in tenths.
#[test]
fn progress_reports_tenths_on_stderr_and_changes_nothing() {
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join("progress");
    let out_s = out_dir.to_string_lossy().into_owned();
    let args = ["--size", "32", "--steps", "95", "--every", "0", "--tiles", "1", "--gif", "0", "--out", &out_s];
    let mut ends = Vec::new();
    for extra in [&[][..], &["--progress"], &["--quiet"], &["--progress", "--quiet"]] {
        let out = Command::new(programs().join("aggregation")).args(args).args(extra).output().expect("runs");
        assert!(out.status.success(), "aggregation {extra:?}: {}", String::from_utf8_lossy(&out.stderr));
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        if extra == ["--progress"] {
            let reported: Vec<(u64, u64)> = stderr
                .lines()
                .map(|l| {
                    let rest = l.strip_prefix("aggregation: ").unwrap_or_else(|| panic!("`{l}`"));
                    let (pct, rest) = rest.split_once(" % (step ").unwrap_or_else(|| panic!("`{l}`"));
                    let step = rest.split_whitespace().next().unwrap();
                    (pct.parse().unwrap(), step.parse().unwrap())
                })
                .collect();
            // Tenth k is reached at step ceil(95 k / 10).
            let expected: Vec<(u64, u64)> = (1..=10u64).map(|k| (10 * k, (95 * k).div_ceil(10))).collect();
            assert_eq!(reported, expected, "{stderr}");
        } else {
            assert!(stderr.is_empty(), "{extra:?} should report nothing:\n{stderr}");
        }
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        ends.push(stdout.lines().find(|l| l.starts_with("end: ")).expect("an end: line").to_string());
    }
    assert!(ends.iter().all(|e| e == &ends[0]), "{ends:#?}");
}

/// `--density N`: the density uploaded into a texture and drawn as haze
/// under the particles (c_examples/gpu.c). The haze is grey, so the
/// particles' pixels stay exactly theirs; where nothing is near it is the
/// background, so the frame at step 0 (no particle yet) shows the fixed
/// parts only, as without haze; once smoke has risen it covers more than
/// the particles and the fixed parts.
#[test]
fn density_haze_is_grey_background_where_empty_and_under_the_particles() {
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join("density");
    let _ = std::fs::remove_dir_all(&out_dir);
    let out_s = out_dir.to_string_lossy().into_owned();
    let common =
        ["--size", "32", "--steps", "60", "--every", "30", "--tiles", "2", "--px", "256", "--gif", "0", "--out", &out_s];
    let runs: Vec<Vec<Drawn>> = [("plain", "0"), ("haze", "4")]
        .iter()
        .map(|(name, bin)| {
            let mut args = common.to_vec();
            args.extend(["--name", name, "--density", bin]);
            let stdout = run("smoke-flow", &args);
            stdout.lines().filter(|l| l.starts_with("frame: ")).map(drawn).collect()
        })
        .collect();
    let (plain, haze) = (&runs[0], &runs[1]);
    assert_eq!(haze.len(), 3, "frames at 0, 30 and 60");
    let fixed = pngstat(plain[0].path.as_ref().unwrap());
    let zero = pngstat(haze[0].path.as_ref().unwrap());
    assert_eq!((haze[0].particles, zero.nonbg), (0, fixed.nonbg), "step 0: no particle, so no haze");
    for d in haze {
        let p = pngstat(d.path.as_ref().unwrap());
        let (lo, hi) = particle_pixels(d);
        assert!((lo..=hi).contains(&p.coloured), "{:?}: {} particle pixels, expected {lo}", d.path, p.coloured);
    }
    let last = haze.last().unwrap();
    let p = pngstat(last.path.as_ref().unwrap());
    assert!(last.particles > 0, "smoke rose");
    assert!(
        p.nonbg > p.coloured + fixed.nonbg,
        "no haze: {} non-background pixels, {} particle pixels, {} fixed",
        p.nonbg,
        p.coloured,
        fixed.nonbg
    );
}

/// Each program at the paper's size for a few steps: the same world, bit for
/// bit (`mpca_world_hash` against `World::state_hash`), as the scene of
/// tests/src/scenes.rs after the same steps; stepped serially, and in the
/// parallel step (M11) on 1, 2 and 3 POSIX threads (4, 8 and 12 tasks).
/// The same for `smoke-flow`, the smoke with flow drag (M5.1b), and
/// `water-pool`, the water poured into a pool with contacts (M5.7).
#[test]
fn the_c_scenes_are_the_rust_scenes() {
    const STEPS: u64 = 6;
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join("paper-size");
    let out_s = out_dir.to_string_lossy().into_owned();
    let mut scenes: Vec<Scene> = paper_scenes().into();
    scenes.push(mpca_tests::scenes::smoke_flow());
    scenes.push(mpca_tests::scenes::water_pool());
    let mut memory = Vec::new();
    for scene in &scenes {
        let world = build(scene, &mut memory).expect("the Rust scene builds");
        world.step(STEPS);
        for threads in [None, Some("1"), Some("2"), Some("3")] {
            let steps = STEPS.to_string();
            let mut args = vec!["--steps", &steps, "--every", "0", "--tiles", "1", "--gif", "0", "--out", &out_s];
            args.extend(threads.map(|t| ["--threads", t]).into_iter().flatten());
            let stdout = run(scene.name, &args);
            let line = stdout.lines().find(|l| l.starts_with("end: ")).expect("an end: line");
            let f = fields(line);
            let what = format!("{} ({} threads)", scene.name, threads.unwrap_or("no"));
            assert_eq!(number::<u64>(&f, "step", line), STEPS, "{what}");
            assert_eq!(number::<u64>(&f, "particles", line), world.particle_count(), "{what}: particles");
            let hash = u64::from_str_radix(f["hash"], 16).expect("a hex hash");
            assert_eq!(hash, world.state_hash(), "{what}: C {hash:016x}, Rust {:016x}", world.state_hash());
        }
    }
}

#[test]
fn every_program_documents_and_checks_its_options() {
    for scene in ["aggregation", "cluster", "smoke", "water", "wake", "looks-smoke", "looks-water", "looks-sand", "box2d-wheel"] {
        let help = run(scene, &["--help"]);
        for option in
            ["--size N", "--steps N", "--seed N", "--every N", "--tiles N", "--px N", "--out DIR", "--name S", "--threads N", "--density N", "--png-level N", "--gif N", "--progress", "--quiet", "--version"]
        {
            assert!(help.contains(option), "{scene} --help does not mention {option}:\n{help}");
        }
        for bad in [&["--size", "7"][..], &["--steps", "-1"], &["--bogus"], &["--every"], &["--threads", "0"], &["--threads", "17"], &["--png-level", "10"], &["--gif", "1001"]] {
            let out = Command::new(programs().join(scene)).args(bad).output().expect("runs");
            assert_eq!(out.status.code(), Some(2), "{scene} {bad:?} should be refused");
        }
    }
    // The density haze is 2D only, and the looks draw the effect instead.
    for scene in ["water", "looks-smoke", "looks-water", "looks-sand"] {
        let out = Command::new(programs().join(scene)).args(["--density", "4"]).output().expect("runs");
        assert_eq!(out.status.code(), Some(2), "{scene} --density 4 should be refused");
    }
}

/// `c_examples/threads.c`: the 1024^2 gas stepped on 1, 2 and 3 POSIX
/// threads of the program's own pool (mpca_world_step_parallel) hashes
/// equal to the serial step; the program says so and exits 1 otherwise.
#[test]
fn the_threads_example_equals_the_serial_step() {
    for threads in ["1", "2", "3"] {
        let out = run("threads", &["--threads", threads, "--steps", "3"]);
        assert!(out.contains("particles=") && out.contains("equal=yes"), "{threads} threads:\n{out}");
    }
    let version = run("threads", &["--version"]);
    assert!(version.starts_with("threads (libmpca "), "{version}");
}

/// Every program of c_examples/ (not pngstat, a tool of these tests)
/// answers `--version` with its name and the version of the libmpca it
/// was linked with, and does nothing else.
#[test]
fn every_example_program_prints_its_version() {
    let expected = env!("CARGO_PKG_VERSION"); // the workspace's, as mpca-ffi's
    for program in
        ["aggregation", "cluster", "smoke", "water", "smoke-ids", "wake", "looks-smoke", "looks-water", "looks-sand", "box2d-wheel", "threads", "cpp_example"]
    {
        let out = run(program, &["--version"]);
        assert_eq!(out, format!("{program} (libmpca {expected})\n"), "{program} --version");
    }
}

/// `c_examples/cpp_example.cpp`, the hourglass through include/mpca.hpp:
/// it pours three grains a step, prints the box as text, and ends with
/// the same world on 1 and on 3 threads (its step_parallel host).
#[test]
fn the_cpp_example_pours_the_same_hourglass_on_any_thread_count() {
    let mut finals = Vec::new();
    for threads in ["1", "3"] {
        let out = run("cpp_example", &["--steps", "120", "--every", "60", "--threads", threads]);
        let pictures = out.lines().filter(|l| l.starts_with('|') && l.ends_with('|') && l.len() == 66).count();
        assert_eq!(pictures, 2 * 32, "two pictures of 32 rows of 64 bins:\n{out}");
        let last = out.lines().last().unwrap_or_default().to_string();
        let f = fields(&last);
        let emitted: u64 = number(&f, "emitted", &last);
        let particles: u64 = number(&f, "particles", &last);
        assert!(emitted == 3 * 120 && particles == emitted, "a rate of 3 a step for 120 steps, in a closed box: {last}");
        assert_eq!(f.get("threads"), Some(&threads), "{last}");
        finals.push(last.replace(&format!("threads={threads} "), ""));
    }
    assert_eq!(finals[0], finals[1], "1 thread against 3");
    let bad = Command::new(programs().join("cpp_example")).args(["--threads", "0"]).output().expect("runs");
    assert_eq!(bad.status.code(), Some(2), "--threads 0 should be refused");
}
