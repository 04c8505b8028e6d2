//! Tables of the report: one definition gives both the Markdown table
//! (numbers rounded for reading) and the JSON array (every figure at full
//! precision, under the column's key, written by serde).

use serde::ser::{Serialize, SerializeMap, SerializeStruct, Serializer};

use crate::measure::Timing;

/// How a numeric column is shown in Markdown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fmt {
    /// Three significant digits, scientific notation outside 0.001..10^5.
    Sig,
    /// Fixed decimals.
    Fixed(usize),
    /// A share, as a percentage with this many decimals.
    Pct(usize),
    /// An integer count with thousands separators.
    Count,
    /// Text as it is.
    Text,
}

/// One cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    /// Text.
    Text(String),
    /// A number.
    Num(f64),
    /// An exact count.
    Count(u64),
    /// Run times in seconds, shown as the median and min..max in `unit`
    /// ("s", "ms", "us", "ns") after dividing by `per` (e.g. the steps).
    Time {
        /// The runs.
        timing: Timing,
        /// Divisor (1 for whole runs).
        per: f64,
        /// Unit shown.
        unit: &'static str,
    },
    /// Nothing to show.
    None,
}

impl From<f64> for Val {
    fn from(v: f64) -> Self {
        Val::Num(v)
    }
}

impl From<u64> for Val {
    fn from(v: u64) -> Self {
        Val::Count(v)
    }
}

impl From<usize> for Val {
    fn from(v: usize) -> Self {
        Val::Count(v as u64)
    }
}

impl From<&str> for Val {
    fn from(v: &str) -> Self {
        Val::Text(v.to_string())
    }
}

impl From<String> for Val {
    fn from(v: String) -> Self {
        Val::Text(v)
    }
}

impl<T: Into<Val>> From<Option<T>> for Val {
    fn from(v: Option<T>) -> Self {
        v.map_or(Val::None, Into::into)
    }
}

/// Run times per `per` in `unit`.
pub fn time(timing: &Timing, per: f64, unit: &'static str) -> Val {
    Val::Time { timing: timing.clone(), per, unit }
}

impl Val {
    /// A time in seconds shown in nanoseconds.
    pub fn scaled_to_ns(self) -> Val {
        match self {
            Val::Time { timing, per, .. } => Val::Time { timing, per, unit: "ns" },
            v => v,
        }
    }
}

/// A column: JSON key, Markdown header, format.
#[derive(Clone, Debug)]
pub struct Column {
    /// Key in the JSON rows.
    pub key: &'static str,
    /// Header in Markdown.
    pub label: &'static str,
    /// Markdown format.
    pub fmt: Fmt,
}

/// A column.
pub const fn col(key: &'static str, label: &'static str, fmt: Fmt) -> Column {
    Column { key, label, fmt }
}

/// A table of the report.
#[derive(Clone, Debug)]
pub struct Table {
    /// Key of the table in the JSON file.
    pub key: &'static str,
    /// Heading.
    pub title: String,
    /// What the table shows and how it was measured (Markdown).
    pub about: String,
    /// Columns.
    pub columns: Vec<Column>,
    /// Rows, one value per column.
    pub rows: Vec<Vec<Val>>,
}

/// Three significant digits.
pub fn sig(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let digits = (2 - a.log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

fn thousands(n: u64) -> String {
    let s = n.to_string();
    let groups: Vec<&str> = s.as_bytes().rchunks(3).rev().map(|g| std::str::from_utf8(g).unwrap_or("?")).collect();
    groups.join(",")
}

impl Val {
    fn markdown(&self, fmt: Fmt) -> String {
        match self {
            Val::Text(s) => s.clone(),
            Val::None => "–".into(),
            Val::Count(n) => thousands(*n),
            Val::Num(v) if !v.is_finite() => "–".into(),
            Val::Num(v) => match fmt {
                Fmt::Fixed(d) => format!("{v:.d$}"),
                Fmt::Pct(d) => format!("{:.d$} %", 100.0 * v),
                Fmt::Count => thousands(v.round() as u64),
                Fmt::Sig | Fmt::Text => sig(*v),
            },
            Val::Time { timing, per, unit } => {
                let f = unit_factor(unit, *per);
                format!("{} ({}–{})", sig(timing.median() * f), sig(timing.min() * f), sig(timing.max() * f))
            }
        }
    }
}

/// A run time as JSON: the unit, the median, min and max, and every run.
#[derive(serde::Serialize)]
struct TimeJson {
    unit: &'static str,
    median: f64,
    min: f64,
    max: f64,
    runs: Vec<f64>,
}

/// Text as a string, a missing value as `null`, a count exactly, a number
/// at full precision (serde_json writes a non-finite one as `null`), a time
/// as an object.
impl Serialize for Val {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Val::Text(t) => s.serialize_str(t),
            Val::None => s.serialize_none(),
            Val::Count(n) => s.serialize_u64(*n),
            Val::Num(v) => s.serialize_f64(*v),
            Val::Time { timing, per, unit } => {
                let f = unit_factor(unit, *per);
                TimeJson {
                    unit,
                    median: timing.median() * f,
                    min: timing.min() * f,
                    max: timing.max() * f,
                    runs: timing.seconds.iter().map(|s| s * f).collect(),
                }
                .serialize(s)
            }
        }
    }
}

/// One row as an object keyed by the columns, in column order.
struct Row<'a>(&'a [Column], &'a [Val]);

impl Serialize for Row<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (c, v) in self.0.iter().zip(self.1) {
            map.serialize_entry(c.key, v)?;
        }
        map.end()
    }
}

/// `{"title", "about", "rows": [{key: value}]}`.
impl Serialize for Table {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let rows: Vec<Row> = self.rows.iter().map(|r| Row(&self.columns, r)).collect();
        let mut t = s.serialize_struct("Table", 3)?;
        t.serialize_field("title", &self.title)?;
        t.serialize_field("about", &self.about)?;
        t.serialize_field("rows", &rows)?;
        t.end()
    }
}

impl Table {
    /// A table with these columns and no rows yet.
    pub fn new(key: &'static str, title: impl Into<String>, about: impl Into<String>, columns: Vec<Column>) -> Table {
        Table { key, title: title.into(), about: about.into(), columns, rows: vec![] }
    }

    /// Adds a row; it must have one value per column.
    pub fn row(&mut self, values: Vec<Val>) {
        assert_eq!(values.len(), self.columns.len(), "{}: row of {} values", self.key, values.len());
        self.rows.push(values);
    }

    /// The table as Markdown, with its heading and description.
    pub fn markdown(&self, level: usize) -> String {
        let mut out = format!("{} {}\n\n", "#".repeat(level), self.title);
        if !self.about.is_empty() {
            out.push_str(&self.about);
            out.push_str("\n\n");
        }
        out.push('|');
        for c in &self.columns {
            out.push_str(&format!(" {} |", c.label));
        }
        out.push_str("\n|");
        for c in &self.columns {
            out.push_str(if c.fmt == Fmt::Text { "---|" } else { "---:|" });
        }
        out.push('\n');
        for r in &self.rows {
            out.push('|');
            for (v, c) in r.iter().zip(&self.columns) {
                out.push_str(&format!(" {} |", v.markdown(c.fmt)));
            }
            out.push('\n');
        }
        out.push('\n');
        out
    }

}


/// Seconds-to-`unit` factor for one of `per` items (`s`, `ms`, `us`, else ns).
fn unit_factor(unit: &str, per: f64) -> f64 {
    let scale = match unit {
        "s" => 1.0,
        "ms" => 1e3,
        "us" => 1e6,
        _ => 1e9,
    };
    scale / per
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.0), "0");
        assert_eq!(sig(123.456), "123");
        assert_eq!(sig(1.23456), "1.23");
        assert_eq!(sig(0.0123456), "0.0123");
        assert_eq!(sig(-0.5), "-0.500");
        assert_eq!(sig(1.5e-7), "1.50e-7");
        assert_eq!(sig(2.5e9), "2.50e9");
    }

    #[test]
    fn markdown_and_json_agree_on_rows() {
        let mut t = Table::new("t", "T", "", vec![col("a", "A", Fmt::Text), col("b", "B", Fmt::Pct(1)), col("c", "C", Fmt::Count)]);
        t.row(vec!["x".into(), 0.1234.into(), 12345u64.into()]);
        assert!(t.markdown(3).contains("| x | 12.3 % | 12,345 |"), "{}", t.markdown(3));
        let j = serde_json::to_string(&t).expect("serialises");
        assert!(j.contains(r#"{"a":"x","b":0.1234,"c":12345}"#), "{j}");
    }
}
