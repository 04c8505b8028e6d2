//! Runs every measurement of the report, sized by the mode.

use mpca::{Method, Quantization};
use mpca_tests::measure::additions::{self, AdditionRow};
use mpca_tests::measure::assignment::{self, AssignRow, AssignSummary};
use mpca_tests::measure::conservation::{self, BoxConfig, BoxResult};
use mpca_tests::measure::cooling::{self, CoolingConfig, CoolingResult};
use mpca_tests::measure::drift::{self, DriftConfig, DriftResult};
use mpca_tests::measure::scenes::{self, LeaveOutRow, SceneRow};
use mpca_tests::measure::walls::{self, InsideRow, ReflectRow, SlideRow, Wall};
use mpca_tests::measure::{Setting, Timing, DRIFTS, METHODS, QUANTS};
use mpca_tests::scenes::paper_scenes;

/// Sizes of every run.
pub struct Config {
    /// Timed runs per setting.
    pub runs: usize,
    /// Free flight.
    pub drift: DriftConfig,
    /// Random blocks per (dimension, particles per block).
    pub blocks_2d: usize,
    /// Random 3D blocks for up to 5 particles.
    pub blocks_3d: usize,
    /// Random 3D blocks for 6 to 8 particles (exhaustive search of a full
    /// block visits 8! leaves).
    pub blocks_3d_dense: usize,
    /// Steps of the closed boxes.
    pub box_steps: u64,
    /// The 2D cooling gas.
    pub cooling_2d: CoolingConfig,
    /// The 3D cooling gas.
    pub cooling_3d: CoolingConfig,
    /// Particles per incoming angle.
    pub per_angle: usize,
    /// Steps of each particle sliding along a staircase.
    pub slide_steps: u64,
    /// Steps of the obstacle-filled box.
    pub inside_steps: u64,
    /// Share of each paper scene's step count that is run.
    pub scene_share: f64,
    /// Timed runs of the leave-out comparison.
    pub leave_out_runs: usize,
    /// Steps of the elastic box of M1b (the other additions run `scene_share`
    /// of their scenes' steps, once each).
    pub elastic_steps: u64,
}

impl Config {
    /// For CI: every measurement, small.
    pub fn quick() -> Config {
        Config {
            runs: 3,
            drift: DriftConfig { particles: 12, steps: 400, runs: 3 },
            blocks_2d: 4000,
            blocks_3d: 1000,
            blocks_3d_dense: 40,
            box_steps: 150,
            cooling_2d: CoolingConfig { n: 48, steps: 250, runs: 3 },
            cooling_3d: CoolingConfig { n: 16, steps: 150, runs: 3 },
            per_angle: 4,
            slide_steps: 300,
            inside_steps: 100,
            scene_share: 0.25,
            leave_out_runs: 3,
            elastic_steps: 1000,
        }
    }

    /// For the published figures.
    pub fn full() -> Config {
        Config {
            runs: 5,
            drift: DriftConfig { particles: 64, steps: 2000, runs: 3 },
            blocks_2d: 40_000,
            blocks_3d: 10_000,
            blocks_3d_dense: 400,
            box_steps: 1000,
            cooling_2d: CoolingConfig { n: 64, steps: 1000, runs: 5 },
            cooling_3d: CoolingConfig { n: 24, steps: 500, runs: 5 },
            per_angle: 32,
            slide_steps: 2000,
            inside_steps: 500,
            scene_share: 1.0,
            leave_out_runs: 7,
            elastic_steps: 20_000,
        }
    }
}

/// Everything measured.
pub struct Results {
    /// Free flight, per (dimension, rule, quantization).
    pub drift: Vec<DriftResult>,
    /// Random blocks, per (dimension, k, method).
    pub assign: Vec<AssignRow>,
    /// Random blocks, per (dimension, method).
    pub assign_summary: Vec<AssignSummary>,
    /// Paper scenes, per (scene, setting).
    pub scenes: Vec<SceneRow>,
    /// Closed boxes.
    pub boxes: Vec<BoxResult>,
    /// Cooling gases.
    pub cooling: Vec<CoolingResult>,
    /// Reflections, per (wall, quantization, rule, angle), with the time
    /// of each (wall, quantization, rule).
    pub reflect: Vec<(Vec<ReflectRow>, Timing)>,
    /// Particles sliding along staircases, per (quantization, rule).
    pub slide: Vec<SlideRow>,
    /// Obstacle-filled box, per setting.
    pub inside: Vec<InsideRow>,
    /// Leave out what the scene does not need.
    pub leave_out: Vec<LeaveOutRow>,
    /// The rules beyond the paper against the paper's.
    pub additions: Vec<AdditionRow>,
}

fn say(what: &str) {
    eprintln!("[report] {what}");
}

/// Runs everything; progress goes to stderr.
pub fn all(cfg: &Config) -> Results {
    say("drift: free flight");
    let mut drift = vec![];
    for dim in [2u32, 3] {
        for d in DRIFTS {
            for q in QUANTS {
                drift.push(drift::measure(dim, d, q, cfg.drift));
            }
        }
    }

    say("assignment: random blocks");
    let mut assign = assignment::measure(2, |_| cfg.blocks_2d, cfg.runs);
    assign.extend(assignment::measure(3, |k| if k <= 5 { cfg.blocks_3d } else { cfg.blocks_3d_dense }, cfg.runs));
    let assign_summary =
        [2u32, 3].iter().flat_map(|&dim| METHODS.map(|m| assignment::summarise(&assign, dim, m))).collect();

    say("paper scenes");
    let mut scene_rows = vec![];
    for scene in paper_scenes() {
        let steps = ((scene.steps as f64 * cfg.scene_share).round() as u64).max(1);
        for setting in Setting::all() {
            say(&format!("  {} {}", scene.name, setting.label()));
            scene_rows.push(scenes::measure(&scene, setting, steps, cfg.runs));
        }
    }

    say("conservation: closed boxes");
    let mut boxes = vec![];
    for regime in ["slow", "fast"] {
        for dim in [2u32, 3] {
            for q in QUANTS {
                for m in METHODS {
                    boxes.push(conservation::measure(dim, q, m, regime, BoxConfig { steps: cfg.box_steps, runs: cfg.runs }));
                }
            }
        }
    }

    say("cooling: Haff's law");
    let mut cooling = vec![];
    // Every setting at e = 0.8; the default one also at e = 0.5, since
    // which law fits better depends on e.
    for setting in Setting::all() {
        cooling.push(cooling::measure(2, setting, 0.8, cfg.cooling_2d));
    }
    for m in [Method::ExactFast, Method::Greedy] {
        for q in QUANTS {
            cooling.push(cooling::measure(3, Setting { method: m, quant: q, ..Setting::DEFAULT }, 0.8, cfg.cooling_3d));
        }
    }
    cooling.push(cooling::measure(2, Setting::DEFAULT, 0.5, cfg.cooling_2d));
    cooling.push(cooling::measure(3, Setting::DEFAULT, 0.5, cfg.cooling_3d));

    say("obstacles: reflection and particles inside");
    let mut reflect = vec![];
    for wall in Wall::ALL {
        for q in QUANTS {
            for d in DRIFTS {
                reflect.push(walls::reflect(wall, q, d, cfg.per_angle, cfg.runs));
            }
        }
    }
    let mut slide = vec![];
    for q in QUANTS {
        for d in DRIFTS {
            slide.push(walls::slide(q, d, cfg.slide_steps, cfg.runs));
        }
    }
    let mut inside = vec![];
    for m in METHODS {
        for q in [Quantization::Bits8, Quantization::Bits16] {
            inside.push(walls::inside(Setting { method: m, quant: q, ..Setting::DEFAULT }, cfg.inside_steps, cfg.runs));
        }
    }

    say("leave out what the scene does not need");
    let mut leave_out = vec![];
    for scene in paper_scenes() {
        let steps = ((scene.steps as f64 * cfg.scene_share).round() as u64).max(1);
        leave_out.extend(scenes::leave_out(&scene, steps, cfg.leave_out_runs));
    }

    say("the rules beyond the paper against the paper's");
    let additions = additions::measure(cfg.scene_share, cfg.elastic_steps, 1);

    Results { drift, assign, assign_summary, scenes: scene_rows, boxes, cooling, reflect, slide, inside, leave_out, additions }
}
