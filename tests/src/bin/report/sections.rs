//! The report's tables and the plot's panels, from the measurements.

use mpca::Quantization;
use mpca_tests::measure::walls::Wall;
use mpca_tests::measure::{drift_name, method_name, quant_name, Setting};
use mpca_tests::plot::{Panel, Point};
use mpca_tests::table::{col, time, Fmt, Table, Val};

use crate::run::Results;

fn dim(d: u32) -> Val {
    format!("{d}D").into()
}

fn setting_cells(s: Setting) -> Vec<Val> {
    vec![method_name(s.method).into(), drift_name(s.drift).into(), quant_name(s.quant).into()]
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Every table of the report, in the order of report.md.
pub fn tables(r: &Results) -> Vec<Table> {
    let mut out = vec![drift_summary(r), drift_by_speed(r), drift_groups(r), assign_summary(r), assign_by_k(r)];
    out.extend(scene_tables(r));
    out.push(conservation(r));
    out.push(cooling(r));
    out.push(reflection_summary(r));
    out.push(reflection_by_angle(r));
    out.push(sliding(r));
    out.push(inside(r));
    out.push(quantization(r));
    out.push(leave_out(r));
    out.push(additions(r));
    out
}

fn drift_summary(r: &Results) -> Table {
    let mut t = Table::new(
        "drift_summary",
        "Drift error: free flight",
        "Each particle alone in its own periodic world of 8 cells per axis (so its bytes per cell are mostly \
         header); 5 speeds (0.1 to 0.9) times 6 directions in 2D or 5 \
         in 3D. Error: |measured mean velocity - requested| / |requested|, averaged over the (speed, direction) \
         groups. *Predicted* is the same error for the stored velocity under the rule's own law, p/(2-p) per axis \
         (M5.3); *noise* is the standard error of the measurement on the same scale; *worst z* is the largest \
         deviation of any group and axis from p/(2-p), in standard errors.",
        vec![
            col("dim", "dim", Fmt::Text),
            col("drift", "rule", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("mean_rel_error", "mean error", Fmt::Pct(2)),
            col("max_rel_error", "max error", Fmt::Pct(2)),
            col("predicted_rel_error", "predicted", Fmt::Pct(2)),
            col("noise", "noise", Fmt::Pct(2)),
            col("worst_z", "worst z", Fmt::Fixed(2)),
            col("particle_steps", "particle-steps", Fmt::Count),
            col("ns_per_particle_step", "ns / particle-step", Fmt::Sig),
            col("time_ms", "run, ms", Fmt::Sig),
            col("bytes_per_cell", "B/cell", Fmt::Fixed(2)),
        ],
    );
    for d in &r.drift {
        t.row(vec![
            dim(d.dim),
            drift_name(d.drift).into(),
            quant_name(d.quant).into(),
            d.mean_relative_error().into(),
            d.max_relative_error().into(),
            d.mean_predicted_error().into(),
            d.mean_relative_noise().into(),
            d.worst_z().into(),
            d.particle_steps.into(),
            d.ns_per_particle_step().into(),
            time(&d.timing, 1.0, "ms"),
            d.bytes_per_cell.into(),
        ]);
    }
    t
}

fn drift_by_speed(r: &Results) -> Table {
    let mut t = Table::new(
        "drift_by_speed",
        "Drift error by speed",
        "Mean over the directions of |measured - requested| / |requested|, and of the measured speed along the \
         requested direction over the requested speed.",
        vec![
            col("dim", "dim", Fmt::Text),
            col("drift", "rule", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("speed", "requested speed", Fmt::Fixed(1)),
            col("mean_rel_error", "mean error", Fmt::Pct(2)),
            col("speed_ratio", "measured / requested speed", Fmt::Fixed(3)),
            col("predicted_ratio", "p/(2-p) / |v|", Fmt::Fixed(3)),
        ],
    );
    for d in &r.drift {
        for &speed in &mpca_tests::measure::drift::SPEEDS {
            let g: Vec<_> = d.groups.iter().filter(|g| (g.speed() - f64::from(speed)).abs() < 1e-6).collect();
            let n = g.len() as f64;
            let along = |v: [f64; 3], x: &mpca_tests::measure::drift::DriftGroup| {
                (v[0] * x.requested[0] + v[1] * x.requested[1] + v[2] * x.requested[2]) / (x.speed() * x.speed())
            };
            t.row(vec![
                dim(d.dim),
                drift_name(d.drift).into(),
                quant_name(d.quant).into(),
                f64::from(speed).into(),
                (g.iter().map(|x| x.relative_error()).sum::<f64>() / n).into(),
                (g.iter().map(|x| along(x.measured, x)).sum::<f64>() / n).into(),
                (g.iter().map(|x| along(x.predicted, x)).sum::<f64>() / n).into(),
            ]);
        }
    }
    t
}

fn drift_groups(r: &Results) -> Table {
    let mut t = Table::new(
        "drift_groups",
        "Drift: every group",
        "Requested, stored, measured (with standard error) and predicted (p/(2-p)) mean velocity per group.",
        vec![
            col("dim", "dim", Fmt::Text),
            col("drift", "rule", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("requested", "requested", Fmt::Text),
            col("stored", "stored", Fmt::Text),
            col("measured", "measured", Fmt::Text),
            col("se", "se", Fmt::Text),
            col("predicted", "predicted", Fmt::Text),
        ],
    );
    let v = |a: [f64; 3]| Val::Text(format!("{:.5} {:.5} {:.5}", a[0], a[1], a[2]));
    for d in &r.drift {
        for g in &d.groups {
            t.row(vec![
                dim(d.dim),
                drift_name(d.drift).into(),
                quant_name(d.quant).into(),
                v(g.requested),
                v(g.stored),
                v(g.measured),
                v(g.se),
                v(g.predicted),
            ]);
        }
    }
    t
}

fn assign_summary(r: &Results) -> Table {
    let mut t = Table::new(
        "assignment_summary",
        "Assignment error: random blocks, summary",
        "Random blocks with 1 to 4 (2D) or 1 to 8 (3D) particles, each wanting its cell shifted along each axis \
         with probability 1/2. *Extra cost*: summed distance to the desired cells (M5.6's first cost) above the \
         exhaustive optimum, per particle; *displaced*: share of particles not in their desired cell; *not optimal*: \
         share of blocks whose (first, second) cost differs from the optimum. Each filling from 1 particle to a full \
         block weighs the same: errors and time per block are the means over the fillings (time: median of runs, \
         min–max).",
        vec![
            col("dim", "dim", Fmt::Text),
            col("method", "method", Fmt::Text),
            col("blocks", "blocks", Fmt::Count),
            col("excess_cost", "extra cost / particle", Fmt::Sig),
            col("displaced", "displaced", Fmt::Pct(2)),
            col("suboptimal_blocks", "not optimal", Fmt::Pct(2)),
            col("ns_per_block", "ns / block", Fmt::Text),
        ],
    );
    for s in &r.assign_summary {
        t.row(vec![
            dim(s.dim),
            method_name(s.method).into(),
            s.blocks.into(),
            s.excess_cost.into(),
            s.displaced.into(),
            s.suboptimal_blocks.into(),
            time(&s.per_block, 1.0, "s").scaled_to_ns(),
        ]);
    }
    t
}

fn assign_by_k(r: &Results) -> Table {
    let mut t = Table::new(
        "assignment_by_k",
        "Assignment error by particles per block",
        "As above, per number of particles in the block, from dilute (1) to fully packed (4 in 2D, 8 in 3D). \
         *Mismatches*: blocks where exact-fast (or exhaustive against itself) misses the exhaustive cost; 0 is \
         required.",
        vec![
            col("dim", "dim", Fmt::Text),
            col("k", "particles", Fmt::Count),
            col("method", "method", Fmt::Text),
            col("blocks", "blocks", Fmt::Count),
            col("excess_cost", "extra cost / particle", Fmt::Sig),
            col("displaced", "displaced", Fmt::Pct(2)),
            col("suboptimal_blocks", "not optimal", Fmt::Pct(2)),
            col("mismatches", "mismatches", Fmt::Count),
            col("ns_per_block", "ns / block", Fmt::Text),
        ],
    );
    for a in &r.assign {
        t.row(vec![
            dim(a.dim),
            a.k.into(),
            method_name(a.method).into(),
            a.blocks.into(),
            a.excess_cost.into(),
            a.displaced.into(),
            a.suboptimal_blocks.into(),
            a.mismatches.into(),
            time(&a.timing, a.blocks as f64, "ns"),
        ]);
    }
    t
}

fn scene_tables(r: &Results) -> Vec<Table> {
    let scenes = ["aggregation", "cluster", "smoke", "water"];
    let about = [
        "Paper 4.1: 2D 128², density 0.3, speeds uniform in [0, 1), e = 0.5, periodic. A cooling gas: Haff's law \
         is fitted to its temperature over the first decade of cooling (see the cooling section); momentum is \
         conserved but for clamps and rounding.",
        "Paper 4.2: two discs of ~300 particles at ±0.8, e = 1, walls. Energy is conserved but for clamps and \
         rounding: ΔE/E0 is the error.",
        "Paper 4.3: emitted smoke rising into a Rankine vortex, open faces.",
        "Paper 4.4: 3D 64³ water poured on a sphere under gravity, walls. Particles found on obstacle cells must \
         be 0.",
    ];
    scenes
        .iter()
        .zip(about)
        .map(|(&name, about)| {
            let rows: Vec<_> = r.scenes.iter().filter(|s| s.scene == name).collect();
            let steps = rows.first().map_or(0, |s| s.steps);
            let mut cols = vec![
                col("method", "method", Fmt::Text),
                col("drift", "rule", Fmt::Text),
                col("bits", "bits", Fmt::Text),
                col("time_ms", "run, ms", Fmt::Text),
                col("ns_per_particle_step", "ns / particle-step", Fmt::Sig),
                col("bytes_per_cell", "B/cell", Fmt::Fixed(2)),
                col("particles", "particles (end)", Fmt::Count),
                col("displaced", "displaced", Fmt::Pct(2)),
                col("collisions", "collisions", Fmt::Count),
                col("clamps", "clamps", Fmt::Count),
                col("clamp_energy", "clamped energy", Fmt::Sig),
                col("energy_change", "ΔE / E0", Fmt::Sig),
                col("momentum_change", "|ΔP|", Fmt::Sig),
            ];
            match name {
                "aggregation" => cols.extend([
                    col("haff_tau", "Haff τ", Fmt::Sig),
                    col("haff_residual", "Haff residual", Fmt::Pct(1)),
                    col("exp_residual", "exp. residual", Fmt::Pct(1)),
                ]),
                "smoke" => cols.push(col("exited", "exited", Fmt::Count)),
                "water" => cols.push(col("inside", "inside obstacles", Fmt::Count)),
                _ => {}
            }
            let mut t = Table::new(
                if name == "aggregation" {
                    "scene_aggregation"
                } else if name == "cluster" {
                    "scene_cluster"
                } else if name == "smoke" {
                    "scene_smoke"
                } else {
                    "scene_water"
                },
                format!("Paper scene {name} ({steps} steps)"),
                about,
                cols,
            );
            for s in rows {
                let mut v = setting_cells(s.setting);
                let (e0, e1) = s.energy;
                let dp = [0, 1, 2].map(|k| s.momentum.1[k] - s.momentum.0[k]);
                v.extend([
                    time(&s.timing, 1.0, "ms"),
                    s.ns_per_particle_step().into(),
                    s.bytes_per_cell.into(),
                    s.particles.into(),
                    s.displaced.into(),
                    s.collisions.into(),
                    s.clamps.into(),
                    s.clamp_energy.into(),
                    if e0 > 0.0 { ((e1 - e0) / e0).into() } else { Val::None },
                    norm(dp).into(),
                ]);
                match name {
                    "aggregation" => {
                        let h = s.haff.unwrap_or_default();
                        v.extend([h.tau.into(), h.residual.into(), h.residual_exp.into()]);
                    }
                    "smoke" => v.push(s.exited.into()),
                    "water" => v.push(s.inside.into()),
                    _ => {}
                }
                t.row(v);
            }
            t
        })
        .collect()
}

fn conservation(r: &Results) -> Table {
    let mut t = Table::new(
        "conservation",
        "Conservation in a closed periodic box (no force, e = 1)",
        "2D 64² with 1000 particles or 3D 24³ with 2000. *slow*: speeds start in the ball of radius 0.3; *fast*: \
         radius 1, so collisions overshoot |v| = 1 and clamp. *z(ΔP)*: the largest momentum change of an axis in \
         units of the standard deviation rounding predicts (sqrt(c/3)/SCALE after c collisions; shown only without \
         clamps, which do not conserve momentum); below about 3 it is rounding noise. Energy drift per step relative \
         to E0: measured, with the clamps' removal put back, and the mean gain rounding predicts \
         (2·dim·c / (12 SCALE²)); *z(ΔE)* is the change with the clamps put back, less that bias, in the standard \
         deviations rounding predicts (sqrt(2cT/3)/SCALE, T the energy per particle).",
        vec![
            col("regime", "regime", Fmt::Text),
            col("dim", "dim", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("method", "method", Fmt::Text),
            col("collisions", "collisions", Fmt::Count),
            col("momentum_drift_per_step", "|ΔP| / step", Fmt::Sig),
            col("momentum_z", "z(ΔP)", Fmt::Fixed(2)),
            col("energy_drift_per_step", "ΔE/E0 / step", Fmt::Sig),
            col("energy_drift_without_clamps", "(ΔE + clamped)/E0 / step", Fmt::Sig),
            col("predicted_energy_drift", "rounding bias", Fmt::Sig),
            col("energy_z", "z(ΔE)", Fmt::Fixed(2)),
            col("clamps_per_particle_step", "clamps / particle-step", Fmt::Sig),
            col("clamp_energy_per_step", "clamped / E0 / step", Fmt::Sig),
            col("ms_per_step", "ms / step", Fmt::Text),
            col("bytes_per_cell", "B/cell", Fmt::Fixed(2)),
        ],
    );
    for b in &r.boxes {
        t.row(vec![
            b.regime.into(),
            dim(b.dim),
            quant_name(b.quant).into(),
            method_name(b.method).into(),
            b.collisions.into(),
            b.momentum_drift_per_step().into(),
            b.momentum_z().into(),
            b.energy_drift_per_step().into(),
            b.energy_drift_without_clamps().into(),
            b.predicted_energy_drift().into(),
            b.energy_z().into(),
            b.clamps_per_particle_step().into(),
            b.clamp_energy_per_step().into(),
            time(&b.timing, b.steps as f64, "ms"),
            b.bytes_per_cell.into(),
        ]);
    }
    t
}

fn cooling(r: &Results) -> Table {
    let mut t = Table::new(
        "cooling",
        "Cooling against Haff's law",
        "A periodic box at density 0.3, speeds uniform in the ball of radius 0.5, no force; every setting at e = 0.8, \
         the default one also at e = 0.5. \
         T = mean kinetic energy per particle. Haff's law T0/(1 + t/τ)² fitted by least squares on 1/sqrt(T) \
         (linear in t) over the first decade of cooling (window: until T < T0/10); residual = RMS of T/T_fit - 1 \
         over the window. The exponential T0 exp(-t/τ_e) is fitted on ln T over the same window; the mean-field \
         rate is (1 - e²) × collisions per particle-step, the exponential rate of uncorrelated velocities.",
        vec![
            col("dim", "dim", Fmt::Text),
            col("method", "method", Fmt::Text),
            col("drift", "rule", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("e", "e", Fmt::Sig),
            col("particles", "particles", Fmt::Count),
            col("window", "window, steps", Fmt::Count),
            col("haff_tau", "Haff τ", Fmt::Sig),
            col("haff_t0", "Haff T0", Fmt::Sig),
            col("haff_residual", "Haff residual", Fmt::Pct(1)),
            col("exp_tau", "exp. τ_e", Fmt::Sig),
            col("exp_residual", "exp. residual", Fmt::Pct(1)),
            col("exp_rate", "1/τ_e", Fmt::Sig),
            col("mean_field_rate", "mean-field rate", Fmt::Sig),
            col("cooled_to", "T_end / T0", Fmt::Sig),
            col("clamps", "clamps", Fmt::Count),
            col("time_ms", "run, ms", Fmt::Text),
            col("bytes_per_cell", "B/cell", Fmt::Fixed(2)),
        ],
    );
    for c in &r.cooling {
        let mut v = vec![dim(c.dim)];
        v.extend(setting_cells(c.setting));
        v.extend([
            f64::from(c.restitution).into(),
            c.particles.into(),
            c.fit.points.into(),
            c.fit.tau.into(),
            c.fit.t0.into(),
            c.fit.residual.into(),
            c.fit.tau_exp.into(),
            c.fit.residual_exp.into(),
            (1.0 / c.fit.tau_exp).into(),
            c.mean_field_rate().into(),
            c.cooled_to().into(),
            c.clamps.into(),
            time(&c.timing, 1.0, "ms"),
            c.bytes_per_cell.into(),
        ]);
        t.row(v);
    }
    t
}

fn reflection_summary(r: &Results) -> Table {
    let mut t = Table::new(
        "reflection_summary",
        "Reflection off a flat wall (e = 1)",
        "Particles at speed 0.6 arriving at 10° to 70° from the normal (one per z-plane, so only the wall acts). \
         *First bounce*: |outgoing - incoming| angle of the stored velocities at the first reflection (eq. 9, \
         then rounding to storage); *net*: with the velocity the particle leaves the wall with, after any further \
         change next to it in the 12 steps that follow (a tilted wall is a staircase of cells, and a particle \
         leaving it can ask for the next stair: M5.4 keeps its velocity); *kicked*: share of bounces with such a \
         further change; *missed*: particles whose first change was not next to the wall (past its end, or on the \
         domain's faces). The flat walls run along a periodic x axis; the tilted ones lie in domains with room for \
         every path. One quantum of speed at 0.6 is 0.75° (8-bit) or 0.003° (16-bit).",
        vec![
            col("wall", "wall", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("drift", "rule", Fmt::Text),
            col("bounces", "bounces", Fmt::Count),
            col("missed", "missed", Fmt::Count),
            col("first_error_deg", "first bounce, mean °", Fmt::Sig),
            col("first_error_max_deg", "max °", Fmt::Sig),
            col("net_error_deg", "net, mean °", Fmt::Sig),
            col("net_error_max_deg", "max °", Fmt::Sig),
            col("kicked", "kicked", Fmt::Pct(1)),
            col("time_ms", "run, ms", Fmt::Text),
        ],
    );
    for (rows, timing) in &r.reflect {
        let b: usize = rows.iter().map(|x| x.bounces).sum();
        let w = |f: &dyn Fn(&mpca_tests::measure::walls::ReflectRow) -> f64| {
            rows.iter().map(|x| f(x) * x.bounces as f64).sum::<f64>() / b.max(1) as f64
        };
        let max = |f: &dyn Fn(&mpca_tests::measure::walls::ReflectRow) -> f64| rows.iter().map(f).fold(0.0, f64::max);
        let x = &rows[0];
        t.row(vec![
            x.wall.name().into(),
            quant_name(x.quant).into(),
            drift_name(x.drift).into(),
            b.into(),
            rows.iter().map(|x| x.missed).sum::<usize>().into(),
            w(&|x| x.first_error).into(),
            max(&|x| x.first_error_max).into(),
            w(&|x| x.net_error).into(),
            max(&|x| x.net_error_max).into(),
            w(&|x| x.kicked).into(),
            time(timing, 1.0, "ms"),
        ]);
    }
    t
}

fn reflection_by_angle(r: &Results) -> Table {
    let mut t = Table::new(
        "reflection_by_angle",
        "Reflection by incoming angle",
        "Per incoming angle: the velocity errors as above, and the angles of the mean paths before and after the \
         bounce (from the mean displacement per step). Under the paper's rule each axis drifts at p/(2-p) of its \
         component, so a path's angle differs from its velocity's; the calibrated rule keeps them together.",
        vec![
            col("wall", "wall", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("drift", "rule", Fmt::Text),
            col("angle", "incoming °", Fmt::Fixed(0)),
            col("bounces", "bounces", Fmt::Count),
            col("first_error_deg", "first bounce °", Fmt::Sig),
            col("net_error_deg", "net °", Fmt::Sig),
            col("kicked", "kicked", Fmt::Pct(0)),
            col("speed_change", "|v_out|/|v_in| - 1", Fmt::Sig),
            col("path_in_deg", "path in °", Fmt::Fixed(1)),
            col("path_out_deg", "path out °", Fmt::Fixed(1)),
        ],
    );
    for (rows, _) in &r.reflect {
        for x in rows {
            t.row(vec![
                x.wall.name().into(),
                quant_name(x.quant).into(),
                drift_name(x.drift).into(),
                x.angle.into(),
                x.bounces.into(),
                x.first_error.into(),
                x.net_error.into(),
                x.kicked.into(),
                x.speed_change.into(),
                x.path_in.into(),
                x.path_out.into(),
            ]);
        }
    }
    t
}

fn sliding(r: &Results) -> Table {
    let mut t = Table::new(
        "sliding",
        "Sliding along staircase walls (e = 1)",
        "Walls of cells with (a x + b y) mod 64 < 12 on a periodic 64² domain, for (a, b) = (1, 3), (1, 2), (1, 1), \
         (2, 1), (3, 1) (tilts of 18° to 72°, normal (a, b)/|(a, b)|), so their staircases never end. One particle \
         per world at speed 0.6, starting next to a wall, along it both ways at -10° (into it) to 25° (away from it) \
         from its tangent; followed for the steps given, crossing to the next wall and bouncing on. *Reflections*: \
         velocity changes that are eq. 9 off the wall's normal to within one quantum per component; *kicks*: any \
         other change (what the earlier rule did to a particle that left a wall and asked for its next stair: a \
         turn off the face it came through); *worst*: the largest angle between a stored outgoing velocity and eq. 9's \
         exact one. *Longest stay*: the longest run of steps a particle spent in one cell; *bound*: the run a \
         particle that can leave reaches with probability under 1e-9 in the whole measurement (from the smallest \
         chance, over the velocities seen, of asking for a free cell in the step of two where it can); *stuck*: \
         particles beyond the bound.",
        vec![
            col("bits", "bits", Fmt::Text),
            col("drift", "rule", Fmt::Text),
            col("particles", "particles", Fmt::Count),
            col("steps", "steps each", Fmt::Count),
            col("reflections", "reflections", Fmt::Count),
            col("kicks", "kicks", Fmt::Count),
            col("worst_deg", "worst °", Fmt::Sig),
            col("longest_stay", "longest stay, steps", Fmt::Count),
            col("stay_bound", "bound, steps", Fmt::Count),
            col("stuck", "stuck", Fmt::Count),
            col("inside", "inside obstacles", Fmt::Count),
            col("time_ms", "run, ms", Fmt::Text),
        ],
    );
    for x in &r.slide {
        t.row(vec![
            quant_name(x.quant).into(),
            drift_name(x.drift).into(),
            x.particles.into(),
            x.steps.into(),
            x.reflections.into(),
            x.kicks.into(),
            x.worst_deg.into(),
            x.longest_stay.into(),
            x.stay_bound.into(),
            x.stuck.into(),
            x.inside.into(),
            time(&x.timing, 1.0, "ms"),
        ]);
    }
    t
}

fn inside(r: &Results) -> Table {
    let mut t = Table::new(
        "inside_obstacles",
        "Particles inside obstacles",
        "A 2D 64² walled box with gravity, a disc, a box and a tilted floor, filled at density 0.3 with speeds up \
         to 1, e = 0.9; every particle's cell checked after every step. Must be 0. (The water scene's count is in \
         its table.)",
        vec![
            col("method", "method", Fmt::Text),
            col("bits", "bits", Fmt::Text),
            col("particles", "particles", Fmt::Count),
            col("steps", "steps", Fmt::Count),
            col("checked", "particle-steps checked", Fmt::Count),
            col("inside", "inside obstacles", Fmt::Count),
            col("clamps", "clamps", Fmt::Count),
            col("ms_per_step", "ms / step", Fmt::Text),
            col("bytes_per_cell", "B/cell", Fmt::Fixed(2)),
        ],
    );
    for i in &r.inside {
        t.row(vec![
            method_name(i.setting.method).into(),
            quant_name(i.setting.quant).into(),
            i.particles.into(),
            i.steps.into(),
            i.checked.into(),
            i.inside.into(),
            i.clamps.into(),
            time(&i.timing, i.steps as f64, "ms"),
            i.bytes_per_cell.into(),
        ]);
    }
    t
}

/// One figure under both quantizations: (error 8, error 16, time 8, time
/// 16 in ms, bytes per cell 8, 16).
type Pair = (f64, f64, f64, f64, f64, f64);

fn quantization(r: &Results) -> Table {
    let mut t = Table::new(
        "quantization",
        "Quantization: 8-bit against 16-bit",
        "The same measurement with Bits8 and Bits16 (exact-fast, the paper's rule unless named).",
        vec![
            col("measure", "measure", Fmt::Text),
            col("error_8", "8-bit", Fmt::Sig),
            col("error_16", "16-bit", Fmt::Sig),
            col("time_8_ms", "8-bit, ms", Fmt::Sig),
            col("time_16_ms", "16-bit, ms", Fmt::Sig),
            col("bytes_per_cell_8", "B/cell 8", Fmt::Fixed(2)),
            col("bytes_per_cell_16", "B/cell 16", Fmt::Fixed(2)),
        ],
    );
    let mut add = |name: &str, p: Option<Pair>| {
        if let Some((e8, e16, t8, t16, b8, b16)) = p {
            t.row(vec![name.into(), e8.into(), e16.into(), t8.into(), t16.into(), b8.into(), b16.into()]);
        }
    };
    for dim in [2u32, 3] {
        for d in mpca_tests::measure::DRIFTS {
            let get = |q| r.drift.iter().find(|x| x.dim == dim && x.drift == d && x.quant == q);
            add(
                &format!("drift error, {dim}D {} rule", drift_name(d)),
                get(Quantization::Bits8).zip(get(Quantization::Bits16)).map(|(a, b)| {
                    (a.mean_relative_error(), b.mean_relative_error(), a.timing.median() * 1e3, b.timing.median() * 1e3, a.bytes_per_cell, b.bytes_per_cell)
                }),
            );
        }
    }
    for regime in ["slow", "fast"] {
        for dim in [2u32, 3] {
            let get = |q| r.boxes.iter().find(|x| x.dim == dim && x.quant == q && x.regime == regime && x.method == mpca::Method::ExactFast);
            let pair = get(Quantization::Bits8).zip(get(Quantization::Bits16));
            let tm = |a: &mpca_tests::measure::conservation::BoxResult| a.timing.median() * 1e3;
            add(
                &format!("|energy drift| / step, {dim}D {regime} box"),
                pair.map(|(a, b)| (a.energy_drift_per_step().abs(), b.energy_drift_per_step().abs(), tm(a), tm(b), a.bytes_per_cell, b.bytes_per_cell)),
            );
            add(
                &format!("z(ΔP), {dim}D {regime} box"),
                pair.map(|(a, b)| {
                    let z = |x: &mpca_tests::measure::conservation::BoxResult| x.momentum_z().unwrap_or(f64::NAN);
                    (z(a), z(b), tm(a), tm(b), a.bytes_per_cell, b.bytes_per_cell)
                }),
            );
            add(
                &format!("z(ΔE), {dim}D {regime} box"),
                pair.map(|(a, b)| (a.energy_z(), b.energy_z(), tm(a), tm(b), a.bytes_per_cell, b.bytes_per_cell)),
            );
            if regime == "fast" {
                add(
                    &format!("clamped energy / E0 / step, {dim}D fast box"),
                    pair.map(|(a, b)| (a.clamp_energy_per_step(), b.clamp_energy_per_step(), tm(a), tm(b), a.bytes_per_cell, b.bytes_per_cell)),
                );
            }
        }
    }
    for dim in [2u32, 3] {
        let get = |q| r.cooling.iter().find(|c| c.dim == dim && c.restitution == 0.8 && c.setting == Setting { quant: q, ..Setting::DEFAULT });
        let pair = get(Quantization::Bits8).zip(get(Quantization::Bits16));
        let tm = |c: &mpca_tests::measure::cooling::CoolingResult| c.timing.median() * 1e3;
        add(&format!("Haff residual, {dim}D gas"), pair.map(|(a, b)| (a.fit.residual, b.fit.residual, tm(a), tm(b), a.bytes_per_cell, b.bytes_per_cell)));
        add(&format!("T_end / T0, {dim}D gas"), pair.map(|(a, b)| (a.cooled_to(), b.cooled_to(), tm(a), tm(b), a.bytes_per_cell, b.bytes_per_cell)));
    }
    for (wall, d) in [("obstacle tilted 30°", mpca::Drift::Paper), ("obstacle tilted 60°", mpca::Drift::Paper), ("wall face", mpca::Drift::Paper)] {
        let get = |q| r.reflect.iter().find(|(rows, _)| rows[0].wall.name() == wall && rows[0].quant == q && rows[0].drift == d);
        let mean = |rows: &[mpca_tests::measure::walls::ReflectRow]| {
            let b: usize = rows.iter().map(|x| x.bounces).sum();
            rows.iter().map(|x| x.net_error * x.bounces as f64).sum::<f64>() / b.max(1) as f64
        };
        add(
            &format!("net reflection angle error °, {wall}"),
            get(Quantization::Bits8).zip(get(Quantization::Bits16)).map(|((a, ta), (b, tb))| (mean(a), mean(b), ta.median() * 1e3, tb.median() * 1e3, f64::NAN, f64::NAN)),
        );
    }
    let get = |q| r.inside.iter().find(|i| i.setting == Setting { quant: q, ..Setting::DEFAULT });
    add(
        "particles inside obstacles",
        get(Quantization::Bits8)
            .zip(get(Quantization::Bits16))
            .map(|(a, b)| (a.inside as f64, b.inside as f64, a.timing.median() * 1e3, b.timing.median() * 1e3, a.bytes_per_cell, b.bytes_per_cell)),
    );
    for scene in ["aggregation", "cluster", "smoke", "water"] {
        let get = |q| r.scenes.iter().find(|s| s.scene == scene && s.setting == Setting { quant: q, ..Setting::DEFAULT });
        let pair = get(Quantization::Bits8).zip(get(Quantization::Bits16));
        let tm = |s: &mpca_tests::measure::scenes::SceneRow| s.timing.median() * 1e3;
        let metric = match scene {
            "aggregation" => "Haff residual",
            "cluster" => "|ΔE| / E0",
            _ => "clamped energy",
        };
        add(
            &format!("{metric}, {scene} scene"),
            pair.map(|(a, b)| {
                let f = |s: &mpca_tests::measure::scenes::SceneRow| match scene {
                    "aggregation" => s.haff.map_or(f64::NAN, |h| h.residual),
                    "cluster" => ((s.energy.1 - s.energy.0) / s.energy.0).abs(),
                    _ => s.clamp_energy,
                };
                (f(a), f(b), tm(a), tm(b), a.bytes_per_cell, b.bytes_per_cell)
            }),
        );
    }
    t
}

fn leave_out(r: &Results) -> Table {
    let mut t = Table::new(
        "leave_out",
        "Leave out what the scene does not need (M9)",
        "Each paper scene in its own description (*as needed*) and in one that enables every part with values \
         that change nothing: per-particle masses (16 classes, every particle of the scene's mass), obstacles \
         (none placed), all four forces (the scene's gravity or zero, a zero field and potential, the scene's \
         vortex or one of zero circulation), lifetimes (none given), room for 4 emitters; the same without the \
         force terms the scene does not use; and with 16-bit velocities. Default switches otherwise. *Same result*: \
         the state hash at the end equals the as-needed one. Where it does not, the force terms are the cause: a \
         world with any force term clamps after the force step (M5.5) the up-to-one-quantum excess that storing a \
         velocity of speed 1 can leave, which a world without forces keeps until the particle collides; that \
         changes the draws that follow and adds clamps.",
        vec![
            col("scene", "scene", Fmt::Text),
            col("variant", "description", Fmt::Text),
            col("time_ms", "run, ms", Fmt::Text),
            col("time_ratio", "time ×", Fmt::Fixed(2)),
            col("bytes_per_cell", "B/cell", Fmt::Fixed(2)),
            col("bytes_ratio", "B/cell ×", Fmt::Fixed(1)),
            col("clamps", "clamps", Fmt::Count),
            col("same_result", "same result", Fmt::Text),
        ],
    );
    for x in &r.leave_out {
        let base = r.leave_out.iter().find(|b| b.scene == x.scene && b.variant == "as needed").expect("measured");
        t.row(vec![
            x.scene.into(),
            x.variant.into(),
            time(&x.timing, 1.0, "ms"),
            (x.timing.median() / base.timing.median()).into(),
            x.bytes_per_cell.into(),
            (x.bytes_per_cell / base.bytes_per_cell).into(),
            x.clamps.into(),
            if x.variant == "every part, 16-bit" {
                "(other storage)".into()
            } else if x.hash == base.hash {
                "yes".into()
            } else {
                "no".into()
            },
        ]);
    }
    t
}

fn additions(r: &Results) -> Table {
    let mut t = Table::new(
        "additions",
        "The rules beyond the paper against the paper's (docs/model.md, Additions)",
        "Each rule beyond the paper on the scene where it shows, against the paper's rule: the paper's smoke (480 \
         steps, its vortex as a force) against the smoke with flow drag (its 1,200 steps); the smoke preset's \
         plume from a vent in a 128² world, with drag alone and with the preset's turbulence (M5.1c: the \
         \"paper rule\" column is then drag alone; widths over the last 600 of 1,200 steps, the figures of \
         `tests/tests/turbulence.rs`); the e = 1 cluster with \
         the paper's collisions and with speed-limited ones; the poured water pool (e = 0.5) without and with \
         contacts, and with contacts without and with resting contact (M5.7b: the \"paper rule\" column is \
         then M5.7 alone), and 8 full rows dropped under gravity 0.02 in a 64 × 48 box, without and with \
         resting contact (the pile of `tests/tests/rest.rs`); an elastic 8-bit gas in a 128² box with walls (density 0.3, speed-limited collisions, so no \
         clamp) with unbiased and with energy-neutral rounding. The figures the tests of `tests/tests/effects.rs` \
         hold to their bounds. One timed run each.",
        vec![
            col("rule", "rule", Fmt::Text),
            col("scenes", "scene", Fmt::Text),
            col("measure", "measure", Fmt::Text),
            col("paper", "paper rule", Fmt::Sig),
            col("addition", "with the rule", Fmt::Sig),
            col("paper_steps", "steps", Fmt::Text),
            col("paper_ms", "paper rule, ms", Fmt::Sig),
            col("addition_ms", "with the rule, ms", Fmt::Sig),
        ],
    );
    for a in &r.additions {
        let steps = if a.steps.0 == a.steps.1 { a.steps.0.to_string() } else { format!("{} / {}", a.steps.0, a.steps.1) };
        t.row(vec![
            a.rule.into(),
            a.scenes.clone().into(),
            a.measure.into(),
            a.paper.into(),
            a.addition.into(),
            steps.into(),
            (a.paper_timing.median() * 1e3).into(),
            (a.addition_timing.median() * 1e3).into(),
        ]);
    }
    t
}

/// The plot's panels.
pub fn panels(r: &Results) -> Vec<Panel> {
    let mut out = vec![];
    out.push(Panel {
        title: "Drift error, free flight".into(),
        x_label: "run time, ns per particle-step".into(),
        y_label: "mean |v_measured - v_requested| / |v_requested|".into(),
        log_x: true,
        log_y: true,
        points: r
            .drift
            .iter()
            .map(|d| Point {
                label: format!("{}D {} {}", d.dim, drift_name(d.drift), quant_name(d.quant)),
                x: d.ns_per_particle_step(),
                y: d.mean_relative_error(),
            })
            .collect(),
    });
    out.push(Panel {
        title: "Assignment error, random blocks".into(),
        x_label: "run time, ns per block".into(),
        y_label: "extra distance to desired cells per particle".into(),
        log_x: true,
        log_y: true,
        points: r
            .assign_summary
            .iter()
            .map(|s| Point { label: format!("{}D {}", s.dim, method_name(s.method)), x: s.ns_per_block(), y: s.excess_cost })
            .collect(),
    });
    out.push(Panel {
        title: "Energy drift, closed box, e = 1 (slow)".into(),
        x_label: "run time, ms per step".into(),
        y_label: "|ΔE / E0| per step".into(),
        log_x: true,
        log_y: true,
        points: r
            .boxes
            .iter()
            .filter(|b| b.regime == "slow")
            .map(|b| Point {
                label: format!("{}D {} {}", b.dim, method_name(b.method), quant_name(b.quant)),
                x: b.ms_per_step(),
                y: b.energy_drift_per_step().abs(),
            })
            .collect(),
    });
    out.push(Panel {
        title: "Cooling, 2D gas e = 0.8: Haff's law".into(),
        x_label: "run time, ms per run".into(),
        y_label: "RMS of T / T_Haff - 1".into(),
        log_x: true,
        log_y: true,
        points: r
            .cooling
            .iter()
            .filter(|c| c.dim == 2 && c.restitution == 0.8)
            .map(|c| Point { label: short(c.setting), x: c.timing.median() * 1e3, y: c.fit.residual })
            .collect(),
    });
    out.push(Panel {
        title: "Reflection off walls tilted 30° and 60°".into(),
        x_label: "run time, ms per run".into(),
        y_label: "mean net angle error, degrees".into(),
        log_x: true,
        log_y: true,
        points: r
            .reflect
            .iter()
            .filter(|(rows, _)| Wall::TILTED.contains(&rows[0].wall))
            .map(|(rows, timing)| {
                let b: usize = rows.iter().map(|x| x.bounces).sum();
                Point {
                    label: format!("{:.0}° {} {}", rows[0].wall.tilt(), drift_name(rows[0].drift), quant_name(rows[0].quant)),
                    x: timing.median() * 1e3,
                    y: rows.iter().map(|x| x.net_error * x.bounces as f64).sum::<f64>() / b.max(1) as f64,
                }
            })
            .collect(),
    });
    out.push(Panel {
        title: "Paper 4.2 cluster collision: energy error".into(),
        x_label: "run time, ms per run".into(),
        y_label: "|ΔE / E0| over the run".into(),
        log_x: true,
        log_y: true,
        points: r
            .scenes
            .iter()
            .filter(|s| s.scene == "cluster")
            .map(|s| Point { label: short(s.setting), x: s.timing.median() * 1e3, y: ((s.energy.1 - s.energy.0) / s.energy.0).abs() })
            .collect(),
    });
    out
}

/// "exact-fast paper 8".
fn short(s: Setting) -> String {
    format!("{} {} {}", method_name(s.method), drift_name(s.drift), if s.quant == Quantization::Bits8 { "8" } else { "16" })
}
