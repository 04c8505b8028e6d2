//! The error report of docs/model.md M10: error against run time for every
//! assignment method, drift rule and quantization, on the paper's four
//! scenes and on purpose-built ones.
//!
//! ```sh
//! cargo run --release -p mpca-tests --bin report            # full: docs/
//! cargo run --release -p mpca-tests --bin report -- --quick # CI: target/report-quick/
//! ```
//!
//! Writes `report.md` (tables), `report.json` (every figure) and
//! `error-vs-time.svg` (the plot) into the output folder (`--out DIR` to
//! choose). The README's section goes into README.md itself, between its
//! `<!-- report:begin -->` and `<!-- report:end -->` lines, when the full
//! report is written to docs/; any other run writes it beside the rest as
//! `report-readme-section.md`.
//! Timings are the median of several runs with the spread (min–max); error
//! figures come from seeded runs and are the same on every run.

mod prose;
mod run;
mod sections;

use std::path::PathBuf;
use std::time::Instant;

/// What the command line asked for.
struct Args {
    quick: bool,
    out: PathBuf,
    /// The published report: full mode into docs/, which also rewrites the
    /// README's section.
    publish: bool,
}

fn usage() -> ! {
    eprintln!("usage: report [--quick] [--out DIR]");
    eprintln!("  --quick    small runs for CI (default output target/report-quick)");
    eprintln!("  --out DIR  where to write the report (default docs/ in full mode)");
    std::process::exit(2)
}

fn args() -> Args {
    let mut quick = false;
    let mut out = None;
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--quick" => quick = true,
            "--out" => out = Some(PathBuf::from(it.next().unwrap_or_else(|| usage()))),
            _ => usage(),
        }
    }
    // The workspace root: this crate's manifest sits in tests/.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).parent().map(PathBuf::from).unwrap_or_default();
    let publish = !quick && out.is_none();
    let out = out.unwrap_or_else(|| if quick { root.join("target/report-quick") } else { root.join("docs") });
    Args { quick, out, publish }
}

/// The machine and the moment, for the report's header.
pub struct Machine {
    /// `/proc/cpuinfo`'s model name.
    pub cpu: String,
    /// Logical processors listed in `/proc/cpuinfo`.
    pub cores: usize,
    /// Threads this process may use.
    pub parallelism: usize,
    /// The operating system's name.
    pub os: String,
    /// `rustc --version`.
    pub rustc: String,
    /// Today, `YYYY-MM-DD` (UTC).
    pub date: String,
}

/// Days since 1970-01-01 to a civil date (proleptic Gregorian calendar).
fn civil(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

fn machine() -> Machine {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let cpu = cpuinfo
        .lines()
        .find_map(|l| l.strip_prefix("model name").and_then(|r| r.split_once(':')).map(|(_, v)| v.trim().to_string()))
        .unwrap_or_else(|| "unknown".into());
    let cores = cpuinfo.lines().filter(|l| l.starts_with("processor")).count();
    let os = std::fs::read_to_string("/etc/os-release")
        .ok()
        .and_then(|s| s.lines().find_map(|l| l.strip_prefix("PRETTY_NAME=").map(|v| v.trim_matches('"').to_string())))
        .unwrap_or_else(|| std::env::consts::OS.into());
    let rustc = std::process::Command::new("rustc")
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let (y, m, d) = civil((secs / 86_400) as i64);
    Machine {
        cpu,
        cores,
        parallelism: std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        os,
        rustc,
        date: format!("{y:04}-{m:02}-{d:02}"),
    }
}

fn main() {
    let args = args();
    let started = Instant::now();
    let cfg = if args.quick { run::Config::quick() } else { run::Config::full() };
    let results = run::all(&cfg);
    let elapsed = started.elapsed().as_secs_f64();
    let machine = machine();
    let tables = sections::tables(&results);
    let panels = sections::panels(&results);
    let head = prose::Header { quick: args.quick, elapsed, machine: &machine, cfg: &cfg };

    std::fs::create_dir_all(&args.out).unwrap_or_else(|e| panic!("cannot create {}: {e}", args.out.display()));
    let write = |name: &str, text: &str| {
        let path = args.out.join(name);
        std::fs::write(&path, text).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
        eprintln!("wrote {}", path.display());
    };
    let figure = mpca_tests::plot::svg("mpca: error against run time (M10)", &panels, 2).unwrap_or_else(|e| panic!("cannot draw the figure: {e}"));
    write("error-vs-time.svg", &figure);
    write("report.md", &prose::report(&head, &results, &tables));
    write("report.json", &prose::json(&head, &results, &tables, &panels));
    let section = prose::readme_section(&head, &results);
    if args.publish {
        splice_readme(&section);
    } else {
        write("report-readme-section.md", &section);
    }
    eprintln!("report done in {elapsed:.1} s");
}

/// Replaces the lines between the README's report markers with `section`.
fn splice_readme(section: &str) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    let readme = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let (begin, end) = ("<!-- report:begin -->\n", "<!-- report:end -->");
    let (Some(a), Some(b)) = (readme.find(begin), readme.find(end)) else {
        panic!("README.md lacks the lines {begin:?} and {end:?}");
    };
    let spliced = format!("{}{}\n{}", &readme[..a + begin.len()], section.trim_end(), &readme[b..]);
    std::fs::write(&path, spliced).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
    eprintln!("rewrote the report section of {}", path.display());
}

#[cfg(test)]
mod tests {
    use super::civil;

    #[test]
    fn civil_dates() {
        assert_eq!(civil(0), (1970, 1, 1));
        assert_eq!(civil(11_016), (2000, 2, 29));
        assert_eq!(civil(20_454), (2026, 1, 1));
        assert_eq!(civil(-1), (1969, 12, 31));
    }
}
