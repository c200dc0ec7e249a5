//! TOML scenarios: the file format of DESIGN.md ("Scenario TOML").
//!
//! ```toml
//! [run]
//! until = 4.0               # optional, default 4
//! [[ball]]                  # Ball-1, Ball-2, ... in file order
//! position = [150.0, 150.0]
//! velocity = [40.0, -10.0]  # optional, default [0, 0]
//! radius = 30.0
//! mass = 1.0                # optional, default 1
//! [[cushion]]               # the table lies on the right going from -> to (clockwise)
//! from = [0.0, 0.0]
//! to = [0.0, 600.0]
//! elasticity = 1.0          # optional, default 1
//! [[pocket]]                # a line the ball's centre crosses; a corner stands at each end
//! from = [0.0, 540.0]
//! to = [0.0, 600.0]
//! elasticity = 1.0          # optional, default 1: the elasticity of the two corners
//! [sectors]                 # optional: grid = [nx, ny] or [[sectors.polygon]] points = [...]
//! grid = [3, 3]
//! ```
//!
//! Every error is one line, `file:line: field: message`: serde reports unknown keys, missing keys
//! and wrong types with a byte span that we turn into a line, and [`Scenario::validate`] reports
//! a field path (`ball[3].radius`) that we map back to the span kept by [`toml::Spanned`].
//! Nothing here panics, whatever the input.

use super::{BallSpec, CushionSpec, Invalid, PocketSpec, Scenario, ScenarioError, SectorSpec};
use crate::geometry::Vec2;
use ::toml::Spanned;
use serde::de::{self, IgnoredAny, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::collections::HashMap;
use std::fmt;
use std::marker::PhantomData;
use std::ops::Range;
use std::path::Path;

/// The end time of a run when the file has no `[run] until`.
pub const DEFAULT_UNTIL: f64 = 4.0;

/// Parses and validates a scenario from TOML text; `source` names the file in errors.
///
/// The scenario's `name` is `source`. Any problem (bad TOML, an unknown or missing key, a wrong
/// type, or a rule of [`Scenario::validate`]) comes back as a [`ScenarioError`] whose line is the
/// 1-based line of the offending field where one can be found.
pub fn parse(text: &str, source: &str) -> Result<Scenario, ScenarioError> {
    let raw: RawFile = ::toml::from_str(text).map_err(|e| toml_error(text, source, &e))?;
    let scenario = raw
        .to_scenario(source)
        .map_err(|(inv, span)| {
            let mut e = located(text, source, span, inv);
            if e.line.is_none() {
                e.line = header_line(text, "sectors");
            }
            e
        })?;
    scenario.validate().map_err(|inv| {
        let span = raw.span_of(&inv.field);
        located(text, source, span, inv)
    })?;
    Ok(scenario)
}

/// Reads a file and parses it with [`parse`], naming the file by its path.
///
/// I/O errors (a missing file, text that is not UTF-8) become a [`ScenarioError`] with no line
/// and an empty field.
pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
    let source = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => parse(&text, &source),
        Err(e) => Err(ScenarioError {
            source,
            line: None,
            field: String::new(),
            message: one_line(&format!("cannot read the file: {e}")),
        }),
    }
}

// ---------------------------------------------------------------------------------------------
// The file as serde sees it. Leaves and array-of-table entries are spanned; plain tables are not,
// because toml cannot span a table that is only implied by a dotted key (`[[sectors.polygon]]`
// alone, or `run.until = 3`).

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    run: Option<RawRun>,
    #[serde(default)]
    ball: Vec<Spanned<RawBall>>,
    #[serde(default)]
    cushion: Vec<Spanned<RawCushion>>,
    #[serde(default)]
    pocket: Vec<Spanned<RawPocket>>,
    sectors: Option<RawSectors>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRun {
    until: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBall {
    position: Spanned<Pair<f64>>,
    velocity: Option<Spanned<Pair<f64>>>,
    radius: Spanned<f64>,
    mass: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCushion {
    from: Spanned<Pair<f64>>,
    to: Spanned<Pair<f64>>,
    elasticity: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPocket {
    from: Spanned<Pair<f64>>,
    to: Spanned<Pair<f64>>,
    elasticity: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSectors {
    grid: Option<Spanned<Pair<u32>>>,
    polygon: Option<Vec<Spanned<RawPolygon>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPolygon {
    points: Spanned<Vec<Pair<f64>>>,
}

/// Exactly two values, `[a, b]`: toml would otherwise let `[f64; 2]` ignore a third element.
#[derive(Clone, Copy)]
struct Pair<T>(T, T);

impl Pair<f64> {
    fn vec(self) -> Vec2 {
        Vec2::new(self.0, self.1)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Pair<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct PairVisitor<T>(PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for PairVisitor<T> {
            type Value = Pair<T>;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an array of two numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Pair<T>, A::Error> {
                let a = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let b = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(1, &self))?;
                let mut n = 2;
                while seq.next_element::<IgnoredAny>()?.is_some() {
                    n += 1;
                }
                if n == 2 {
                    Ok(Pair(a, b))
                } else {
                    Err(de::Error::invalid_length(n, &self))
                }
            }
        }
        d.deserialize_seq(PairVisitor(PhantomData))
    }
}

fn opt(v: &Option<Spanned<f64>>, default: f64) -> f64 {
    v.as_ref().map_or(default, |s| *s.get_ref())
}

fn span<T>(s: &Spanned<T>) -> Range<usize> {
    s.span()
}

/// Splits `name[i]` into `("name", i)`.
fn indexed(s: &str) -> Option<(&str, usize)> {
    let (name, rest) = s.split_once('[')?;
    let i = rest.strip_suffix(']')?.parse().ok()?;
    Some((name, i))
}

impl RawFile {
    /// Builds the scenario (not yet validated). Only the shape of `[sectors]` can fail here.
    fn to_scenario(&self, source: &str) -> Result<Scenario, (Invalid, Option<Range<usize>>)> {
        let balls = self
            .ball
            .iter()
            .map(|b| {
                let b = b.get_ref();
                BallSpec {
                    position: b.position.get_ref().vec(),
                    velocity: b.velocity.as_ref().map_or(Vec2::ZERO, |v| v.get_ref().vec()),
                    radius: *b.radius.get_ref(),
                    mass: opt(&b.mass, 1.0),
                }
            })
            .collect();
        let cushions = self
            .cushion
            .iter()
            .map(|c| {
                let c = c.get_ref();
                CushionSpec {
                    from: c.from.get_ref().vec(),
                    to: c.to.get_ref().vec(),
                    elasticity: opt(&c.elasticity, 1.0),
                }
            })
            .collect();
        let pockets = self
            .pocket
            .iter()
            .map(|p| {
                let p = p.get_ref();
                PocketSpec {
                    from: p.from.get_ref().vec(),
                    to: p.to.get_ref().vec(),
                    corner_elasticity: opt(&p.elasticity, 1.0),
                }
            })
            .collect();
        let sectors = match &self.sectors {
            None => None,
            Some(s) => Some(match (&s.grid, &s.polygon) {
                (Some(g), Some(_)) => {
                    return Err((
                        Invalid {
                            field: "sectors".into(),
                            message: "give either grid = [nx, ny] or [[sectors.polygon]] \
                                      entries, not both"
                                .into(),
                        },
                        Some(span(g)),
                    ))
                }
                (Some(g), None) => {
                    let Pair(nx, ny) = *g.get_ref();
                    SectorSpec::Grid { nx, ny }
                }
                (None, Some(polys)) if !polys.is_empty() => SectorSpec::Polygons(
                    polys
                        .iter()
                        .map(|p| p.get_ref().points.get_ref().iter().map(|q| q.vec()).collect())
                        .collect(),
                ),
                (None, _) => {
                    return Err((
                        Invalid {
                            field: "sectors".into(),
                            message: "needs grid = [nx, ny] or at least one \
                                      [[sectors.polygon]] entry"
                                .into(),
                        },
                        None,
                    ))
                }
            }),
        };
        Ok(Scenario {
            name: source.to_string(),
            until: self
                .run
                .as_ref()
                .map_or(DEFAULT_UNTIL, |r| opt(&r.until, DEFAULT_UNTIL)),
            balls,
            cushions,
            pockets,
            sectors,
        })
    }

    /// The span of a field named the way [`Scenario::validate`] names it (`ball[3].radius`,
    /// `cushion[2]`, `run.until`, `sectors.polygon[1].points`), or of its enclosing entry.
    fn span_of(&self, field: &str) -> Option<Range<usize>> {
        let (head, rest) = match field.split_once('.') {
            Some((h, r)) => (h, Some(r)),
            None => (field, None),
        };
        if let Some((name, i)) = indexed(head) {
            let i = i.checked_sub(1)?;
            return match name {
                "ball" => {
                    let e = self.ball.get(i)?;
                    let b = e.get_ref();
                    let s = match rest {
                        Some("position") => Some(span(&b.position)),
                        Some("velocity") => b.velocity.as_ref().map(span),
                        Some("radius") => Some(span(&b.radius)),
                        Some("mass") => b.mass.as_ref().map(span),
                        _ => None,
                    };
                    s.or_else(|| Some(e.span()))
                }
                "cushion" => {
                    let e = self.cushion.get(i)?;
                    let c = e.get_ref();
                    let s = match rest {
                        Some("from") => Some(span(&c.from)),
                        Some("to") => Some(span(&c.to)),
                        Some("elasticity") => c.elasticity.as_ref().map(span),
                        _ => None,
                    };
                    s.or_else(|| Some(e.span()))
                }
                "pocket" => {
                    let e = self.pocket.get(i)?;
                    let p = e.get_ref();
                    let s = match rest {
                        Some("from") => Some(span(&p.from)),
                        Some("to") => Some(span(&p.to)),
                        Some("elasticity" | "corner_elasticity") => {
                            p.elasticity.as_ref().map(span)
                        }
                        _ => None,
                    };
                    s.or_else(|| Some(e.span()))
                }
                _ => None,
            };
        }
        match (head, rest) {
            ("run", Some("until")) => self.run.as_ref()?.until.as_ref().map(span),
            ("sectors", Some(rest)) => {
                let sectors = self.sectors.as_ref()?;
                if rest == "grid" {
                    return sectors.grid.as_ref().map(span);
                }
                let (poly, tail) = match rest.split_once('.') {
                    Some((p, t)) => (p, Some(t)),
                    None => (rest, None),
                };
                let (name, i) = indexed(poly)?;
                if name != "polygon" {
                    return None;
                }
                let e = sectors.polygon.as_ref()?.get(i.checked_sub(1)?)?;
                match tail {
                    Some("points") => Some(span(&e.get_ref().points)),
                    _ => Some(e.span()),
                }
            }
            _ => None,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Errors.

/// The 1-based line holding byte `offset` of `text` (an offset past the end counts as the end).
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end].iter().filter(|&&c| c == b'\n').count() + 1
}

/// Joins a possibly multi-line message into one line.
fn one_line(message: &str) -> String {
    let parts: Vec<&str> = message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    parts.join("; ")
}

/// The name a TOML user knows a validated field by (the pocket's corner elasticity is written
/// `elasticity` in the file).
fn file_field(field: &str) -> String {
    match field.strip_suffix(".corner_elasticity") {
        Some(head) if head.starts_with("pocket[") => format!("{head}.elasticity"),
        _ => field.to_string(),
    }
}

fn located(text: &str, source: &str, span: Option<Range<usize>>, inv: Invalid) -> ScenarioError {
    ScenarioError {
        source: source.to_string(),
        line: span.map(|s| line_of(text, s.start)),
        field: one_line(&file_field(&inv.field)),
        message: one_line(&inv.message),
    }
}

/// Turns toml's error (which names no key once it has the source text) into one line: the line
/// comes from its span; the field is found by scanning the text for the table and key there.
fn toml_error(text: &str, source: &str, e: &::toml::de::Error) -> ScenarioError {
    let span = e.span();
    let syntax = ::toml::from_str::<IgnoredAny>(text).is_err();
    let field = match (&span, syntax) {
        (Some(s), false) => field_at(text, s.start),
        _ => String::new(),
    };
    ScenarioError {
        source: source.to_string(),
        line: span.map(|s| line_of(text, s.start)),
        field,
        message: clarify(&one_line(e.message())),
    }
}

/// Rewrites the one confusing message toml gives: a table written where a single value belongs
/// (`radius.x = 1`) fails inside [`Spanned`], which then asks for "a borrowed string".
fn clarify(message: &str) -> String {
    if message.contains("expected a borrowed string") {
        "invalid type: table, expected a single value".to_string()
    } else {
        message.to_string()
    }
}

/// A table header or a `key = value` statement found by [`scan`], with its starting byte.
enum Item {
    Header {
        start: usize,
        name: String,
        array: bool,
    },
    Key {
        name: String,
    },
}

/// Lists the headers and top-level statements that start at or before byte `until`.
///
/// A light scan of the bytes that knows just enough TOML (strings, comments, nesting of arrays
/// and inline tables) not to mistake a line inside a value for a header; it is only used to name
/// the field of an error in a file that toml has already parsed, and never panics.
fn scan(text: &str, until: usize) -> Vec<Item> {
    let b = text.as_bytes();
    let mut items = Vec::new();
    let mut i = 0;
    while i < b.len() && i <= until {
        match b[i] {
            b' ' | b'\t' | b'\r' | b'\n' => i += 1,
            b'#' => i = line_end(b, i),
            b'[' => {
                let start = i;
                let array = b.get(i + 1) == Some(&b'[');
                let from = i + if array { 2 } else { 1 };
                let end = line_end(b, i);
                let mut close = from;
                while close < end && b[close] != b']' {
                    close = if b[close] == b'"' || b[close] == b'\'' {
                        skip_string(b, close).min(end)
                    } else {
                        close + 1
                    };
                }
                items.push(Item::Header {
                    start,
                    name: normalize_key(&b[from.min(close)..close]),
                    array,
                });
                i = end;
            }
            _ => {
                let start = i;
                let mut j = i;
                while j < b.len() && b[j] != b'=' && b[j] != b'\n' {
                    j = if b[j] == b'"' || b[j] == b'\'' {
                        skip_string(b, j)
                    } else {
                        j + 1
                    };
                }
                let j = j.min(b.len());
                items.push(Item::Key {
                    name: normalize_key(&b[start..j]),
                });
                i = if j < b.len() && b[j] == b'=' {
                    skip_value(b, j + 1)
                } else {
                    j.max(i + 1)
                };
            }
        }
    }
    items
}

/// The index of the newline ending the line that holds `i`, or the length.
fn line_end(b: &[u8], i: usize) -> usize {
    b[i.min(b.len())..]
        .iter()
        .position(|&c| c == b'\n')
        .map_or(b.len(), |p| i + p)
}

/// The index just past the string that opens at `i` (a quote), or the end of the line or text
/// where it is not closed. Always greater than `i`.
fn skip_string(b: &[u8], i: usize) -> usize {
    let q = b[i];
    let basic = q == b'"';
    if b.len() >= i + 3 && b[i + 1] == q && b[i + 2] == q {
        let mut j = i + 3;
        while j < b.len() {
            if basic && b[j] == b'\\' {
                j += 2;
            } else if b[j] == q && j + 2 < b.len() && b[j + 1] == q && b[j + 2] == q {
                let mut k = j + 3;
                while k < b.len() && k < j + 5 && b[k] == q {
                    k += 1;
                }
                return k;
            } else {
                j += 1;
            }
        }
        return b.len();
    }
    let mut j = i + 1;
    while j < b.len() {
        if b[j] == q {
            return j + 1;
        }
        if b[j] == b'\n' {
            return j;
        }
        j += if basic && b[j] == b'\\' { 2 } else { 1 };
    }
    b.len()
}

/// The index of the newline that ends the value starting at `i`, skipping strings, comments and
/// the lines of multi-line arrays and inline tables.
fn skip_value(b: &[u8], mut i: usize) -> usize {
    let mut depth = 0usize;
    while i < b.len() {
        match b[i] {
            b'"' | b'\'' => {
                i = skip_string(b, i);
                continue;
            }
            b'#' => {
                i = line_end(b, i);
                continue;
            }
            b'[' | b'{' => depth += 1,
            b']' | b'}' => depth = depth.saturating_sub(1),
            b'\n' if depth == 0 => return i,
            _ => {}
        }
        i += 1;
    }
    b.len()
}

/// A key or header name as written, with the spaces around its dots removed.
fn normalize_key(bytes: &[u8]) -> String {
    let s = String::from_utf8_lossy(bytes);
    let parts: Vec<&str> = s.split('.').map(str::trim).collect();
    parts.join(".")
}

/// The field path (like `ball[2].radius`) of the statement or header that holds byte `offset`.
fn field_at(text: &str, offset: usize) -> String {
    let mut counts: HashMap<String, usize> = HashMap::new();
    let mut table = String::new();
    let mut key: Option<String> = None;
    for item in scan(text, offset) {
        match item {
            Item::Header { name, array, .. } => {
                key = None;
                table = if array {
                    let c = counts.entry(name.clone()).or_insert(0);
                    *c += 1;
                    format!("{name}[{c}]")
                } else {
                    // A sub-table of an array entry (`[ball.extra]`) belongs to the last entry.
                    let mut best = name.clone();
                    for (array_name, c) in &counts {
                        if let Some(tail) = name.strip_prefix(&format!("{array_name}.")) {
                            best = format!("{array_name}[{c}].{tail}");
                        }
                    }
                    best
                };
            }
            Item::Key { name } => key = Some(name),
        }
    }
    let field = match key {
        Some(k) if table.is_empty() => k,
        Some(k) => format!("{table}.{k}"),
        None => table,
    };
    one_line(&field)
}

/// The 1-based line of the header `[name]`, if the text has one.
fn header_line(text: &str, name: &str) -> Option<usize> {
    scan(text, text.len()).into_iter().find_map(|item| match item {
        Item::Header { start, name: n, .. } if n == name => Some(line_of(text, start)),
        _ => None,
    })
}
