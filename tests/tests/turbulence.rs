//! M5.1c turbulence (docs/model.md): a flow that breaks a plume up, moves
//! particles without heaping them, costs nothing when off, and refuses
//! settings out of range.

mod common;

use common::{mean_and_se, Z};
use mpca::{Boundary, Description, Drag, ErrorKind, Turbulence, World};
use mpca_tests::measure::plume;
use mpca_tests::scenes;

/// The statistic: the plume's width high up. The smoke preset's
/// column (drag alone) rises at its terminal speed and widens only by
/// collisions; with turbulence it breaks up and spreads. Six seeds of
/// each: the difference of the mean widths in the top band is more than
/// `Z` standard errors (from the seeds' own spread), turbulence widens the
/// plume with height, and neither clamps.
#[test]
fn turbulence_breaks_up_a_rising_plume() {
    let seeds = 1..=6u64;
    let runs = |turbulent: bool| seeds.clone().map(|s| plume::measure(&scenes::plume(turbulent, s)).0).collect::<Vec<_>>();
    let (calm, stirred) = (runs(false), runs(true));
    let top = |r: &[plume::Plume], band: usize| mean_and_se(&r.iter().map(|p| p.width[band]).collect::<Vec<_>>());
    let (calm_top, stirred_top) = (top(&calm, 3), top(&stirred, 3));
    let (stirred_low, _) = top(&stirred, 0);
    println!("top band width: drag alone {calm_top:.2?}, turbulent {stirred_top:.2?}; turbulent lowest band {stirred_low:.2}");
    let gap = stirred_top.0 - calm_top.0;
    assert!(gap > Z * (calm_top.1.powi(2) + stirred_top.1.powi(2)).sqrt(), "widths {calm_top:?} and {stirred_top:?}");
    let (widening, se) = mean_and_se(&stirred.iter().map(|p| p.width[3] - p.width[0]).collect::<Vec<_>>());
    assert!(widening > Z * se, "the turbulent plume widens with height: {widening} +- {se}");
    for p in calm.iter().chain(&stirred) {
        assert_eq!(p.clamps, 0.0, "{p:?}");
    }
}

/// The index of dispersion of the particle counts in 8 x 8 boxes: their
/// variance over the binomial variance `64 p (1 - p)` of cells occupied
/// independently with the world's density `p`.
fn dispersion(w: &World) -> f64 {
    let [nx, ny, _] = w.description().size;
    let (bx, by) = (nx as usize / 8, ny as usize / 8);
    let mut counts = vec![0.0f64; bx * by];
    for p in w.particles() {
        counts[p.pos[0] as usize / 8 + bx * (p.pos[1] as usize / 8)] += 1.0;
    }
    let k = counts.len() as f64;
    let mean = counts.iter().sum::<f64>() / k;
    let var = counts.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (k - 1.0);
    let p = mean / 64.0;
    var / (64.0 * p * (1.0 - p))
}

/// A periodic gas at density 0.3 dragged (rate 0.2) towards `flow`:
/// turbulence, or the wind plane set by `wind`; its dispersion after 400
/// steps.
fn stirred_gas(turbulence: Turbulence, wind: Option<fn([f32; 2]) -> [f32; 2]>) -> f64 {
    let mut desc = Description::new_2d(128, 128);
    desc.drag = Drag { rate: 0.2, field: wind.is_some(), turbulence, ..Drag::OFF };
    desc.seed = 5;
    let mut memory = common::memory(&desc);
    let w = World::init(&desc, &mut memory).unwrap();
    let mut rng = common::test_rng(9);
    for y in 0..128 {
        for x in 0..128 {
            if rng.unit() < 0.3 {
                w.add_particle([x, y, 0], rng.velocity(2, 0.3)).unwrap();
            }
        }
    }
    if let Some(wind) = wind {
        let plane: Vec<f32> = (0..128 * 128).flat_map(|i| wind([(i % 128) as f32 + 0.5, (i / 128) as f32 + 0.5])).collect();
        w.set_wind_field(&plane).unwrap();
    }
    let start = dispersion(w);
    assert!((start - 1.0).abs() < Z * (2.0 / 255.0f64).sqrt(), "the gas starts binomial: {start}");
    w.step(400);
    dispersion(w)
}

/// A flow without divergence moves particles without gathering them: a
/// gas stirred by turbulence for 400 steps keeps counts in 8 x 8 boxes
/// within `Z` standard errors of the binomial dispersion (the sample
/// variance of 256 boxes has a relative standard error of
/// `sqrt(2 / 255)`), while a flow of the same speed with divergence (the
/// gradient of `sin sin` of wavelength 32, which gathers the gas at its
/// 16 sinks) heaps it far beyond that band.
#[test]
fn turbulence_moves_a_gas_without_heaping_it() {
    let band = 1.0 + Z * (2.0 / 255.0f64).sqrt();
    let turbulent = stirred_gas(Turbulence { amplitude: 0.3, scale: 16, rate: 0.05 }, None);
    fn sinks(p: [f32; 2]) -> [f32; 2] {
        let k = std::f32::consts::TAU / 32.0;
        let a = 0.3 / k;
        [a * k * (k * p[0]).cos() * (k * p[1]).sin(), a * k * (k * p[0]).sin() * (k * p[1]).cos()]
    }
    let heaped = stirred_gas(Turbulence::OFF, Some(sinks));
    println!("dispersion after 400 steps: turbulence {turbulent:.3}, a flow into sinks {heaped:.3}, band {band:.3}");
    assert!(turbulent < band, "turbulence heaped the gas: {turbulent}");
    assert!(heaped > band, "the statistic sees a flow with divergence: {heaped}");
}

/// M9: turbulence of amplitude 0 is off whatever its other settings, the
/// same world step for step as none; turbulence needs no memory.
#[test]
fn turbulence_off_is_no_turbulence() {
    let calm = scenes::plume(false, 3);
    let mut zero = scenes::plume(false, 3);
    zero.desc.drag.turbulence = Turbulence { amplitude: 0.0, scale: 16, rate: 0.5 };
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let (wa, wb) = (scenes::build(&calm, &mut a).unwrap(), scenes::build(&zero, &mut b).unwrap());
    wa.step(300);
    wb.step(300);
    assert_eq!(wa.state_hash(), wb.state_hash());
    let stirred = scenes::plume(true, 3);
    assert_eq!(mpca::world_bytes(&stirred.desc), mpca::world_bytes(&calm.desc));
}

/// Every setting out of its range is refused with `BadDrag`, naming it;
/// `-0` is an amplitude of 0.
#[test]
fn turbulence_out_of_range_is_refused_by_name() {
    let base = {
        let mut d = Description::new_2d(32, 16);
        d.drag = Drag { rate: 0.1, turbulence: Turbulence { amplitude: 0.2, scale: 8, rate: 0.05 }, ..Drag::OFF };
        d
    };
    base.validate().unwrap();
    let refused = |edit: &dyn Fn(&mut Description)| {
        let mut d = base;
        edit(&mut d);
        d.validate().map(|_| ()).map_err(|e| (e.kind(), e.detail()))
    };
    let bad = |detail: &'static str| Err((ErrorKind::BadDrag, detail));
    let amplitude = "desc.drag.turbulence.amplitude (0 to 1)";
    assert_eq!(refused(&|d| d.drag.turbulence.amplitude = 1.01), bad(amplitude));
    assert_eq!(refused(&|d| d.drag.turbulence.amplitude = -0.1), bad(amplitude));
    assert_eq!(refused(&|d| d.drag.turbulence.amplitude = f32::NAN), Err((ErrorKind::NotFinite, "desc.drag.turbulence")));
    let scale = "desc.drag.turbulence.scale (a power of two, 1 to 1024)";
    for s in [0, 3, 24, 2048] {
        assert_eq!(refused(&|d| d.drag.turbulence.scale = s), bad(scale), "scale {s}");
    }
    // Periodic axes of 32 and 16 cells: 16 divides both, 32 not the second.
    assert_eq!(refused(&|d| d.drag.turbulence.scale = 16), Ok(()));
    assert_eq!(refused(&|d| d.drag.turbulence.scale = 32), bad("desc.drag.turbulence.scale (must divide the size of every periodic axis)"));
    assert_eq!(refused(&|d| {
        d.drag.turbulence.scale = 32;
        d.boundary[1] = [Boundary::Wall; 2];
    }), Ok(()));
    for r in [-0.01, 1.5] {
        assert_eq!(refused(&|d| d.drag.turbulence.rate = r), bad("desc.drag.turbulence.rate (0 to 1)"), "rate {r}");
    }
    assert_eq!(refused(&|d| d.drag.rate = 0.0), bad("desc.drag.turbulence (needs desc.drag.rate above 0)"));
    assert_eq!(refused(&|d| d.drag.turbulence = Turbulence { amplitude: -0.0, scale: 0, rate: 7.0 }), Ok(()));
}
