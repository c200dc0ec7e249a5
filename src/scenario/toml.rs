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
//! [box]                     # optional, in place of cushions and pockets: a rectangle
//! size = [40.0, 30.0]
//! origin = [0.0, 0.0]       # optional, default [0, 0]: the lower-left corner
//! boundary = "periodic"     # "periodic" (a torus) or "walled" (four elastic cushions)
//! ```
//!
//! In a periodic box a ball's position is taken into the box by whole sides (so a crystal
//! may be written unwrapped).
//!
//! Every error is one line, `file:line: field: message`: serde reports unknown keys, missing keys
//! and wrong types with a byte span that we turn into a line, and [`Scenario::validate`] reports
//! a field path (`ball[3].radius`) that we map back to the span kept by [`toml::Spanned`].
//! Nothing here panics, whatever the input.

use super::{BallSpec, CushionSpec, Invalid, PocketSpec, Scenario, ScenarioError, SectorSpec};
use crate::geometry::{PeriodicBox, Vec2};
use ::toml::Spanned;
use serde::de::{self, IgnoredAny, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::fmt;
use std::io::Read;
use std::marker::PhantomData;
use std::ops::Range;
use std::path::Path;
use toml_edit::{ImDocument, Item, Table, TableLike};

/// The end time of a run when the file has no `[run] until`.
pub const DEFAULT_UNTIL: f64 = 4.0;

/// Parses and validates a scenario from TOML text; `source` names the file in errors.
///
/// The scenario's `name` is `source`. Any problem (bad TOML, an unknown or missing key, a wrong
/// type, or a rule of [`Scenario::validate`]) comes back as a [`ScenarioError`] whose line is the
/// 1-based line of the offending field where one can be found.
pub fn parse(text: &str, source: &str) -> Result<Scenario, ScenarioError> {
    let raw: RawFile = ::toml::from_str(text).map_err(|e| toml_error(text, source, &e))?;
    let scenario = raw.to_scenario(source).map_err(|(inv, span)| {
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

/// The most a scenario file may hold: a million balls take about a tenth of it.
pub const MAX_SCENARIO_BYTES: u64 = 1 << 30;

/// Reads a file and parses it with [`parse`], naming the file by its path.
///
/// I/O errors (a missing file, text that is not UTF-8, a file over [`MAX_SCENARIO_BYTES`],
/// which bounds what reading `/dev/zero` may take) become a [`ScenarioError`] with no line and
/// an empty field.
pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
    let source = path.display().to_string();
    match std::fs::File::open(path) {
        Ok(file) => load_from(file, &source),
        Err(e) => Err(io_error(&source, format!("cannot read the file: {e}"))),
    }
}

/// Reads scenario text from `reader` (a file, stdin) and parses it with [`parse`]; `source`
/// names it in errors. Reads at most [`MAX_SCENARIO_BYTES`].
pub fn load_from(reader: impl Read, source: &str) -> Result<Scenario, ScenarioError> {
    let mut text = String::new();
    match reader
        .take(MAX_SCENARIO_BYTES + 1)
        .read_to_string(&mut text)
    {
        Err(e) => Err(io_error(source, format!("cannot read the file: {e}"))),
        Ok(n) if n as u64 > MAX_SCENARIO_BYTES => Err(io_error(
            source,
            format!(
                "the file is over {} MiB, more than a scenario may hold",
                MAX_SCENARIO_BYTES >> 20
            ),
        )),
        // no TOML starts with a brace: this is a final state (JSON) to start from
        Ok(_) if text.trim_start().starts_with('{') => from_final_state(&text, source),
        // nor with a count line: samples (extended XYZ) to start from
        Ok(_) if crate::samples::is_xyz(&text) => from_samples(&text, source),
        Ok(_) => parse(&text, source),
    }
}

/// The scenario that starts where a final state file (`poolsim run --final-state`) ends: its
/// balls at time 0 where they were at its end, on its table, until [`DEFAULT_UNTIL`].
fn from_final_state(text: &str, source: &str) -> Result<Scenario, ScenarioError> {
    let state: crate::output::FinalState =
        serde_json::from_str(text).map_err(|e| ScenarioError {
            source: source.to_string(),
            line: Some(e.line()),
            field: String::new(),
            message: format!("not a final state: {e}"),
        })?;
    let fail = |e: super::Invalid| ScenarioError {
        source: source.to_string(),
        line: None,
        field: e.field,
        message: e.message,
    };
    let s = state.to_scenario(source, DEFAULT_UNTIL).map_err(fail)?;
    s.validate().map_err(fail)?;
    Ok(s)
}

/// The scenario that starts from the last sample of a samples file (`poolsim run --samples`,
/// extended XYZ): its balls at time 0 where they are in it, in a box of elastic cushions around
/// its lattice, until [`DEFAULT_UNTIL`].
fn from_samples(text: &str, source: &str) -> Result<Scenario, ScenarioError> {
    let samples = crate::samples::read(text).map_err(|e| ScenarioError {
        source: source.to_string(),
        line: Some(e.line),
        field: String::new(),
        message: format!("not samples poolsim reads: {}", e.message),
    })?;
    let last = samples
        .last()
        .ok_or_else(|| io_error(source, "no sample in it".into()))?;
    let s = last.to_scenario(source, DEFAULT_UNTIL);
    s.validate().map_err(|e| ScenarioError {
        source: source.to_string(),
        line: None,
        field: e.field,
        message: e.message,
    })?;
    Ok(s)
}

/// An error reading `source`, before any line of it is known.
fn io_error(source: &str, message: String) -> ScenarioError {
    ScenarioError {
        source: source.to_string(),
        line: None,
        field: String::new(),
        message: one_line(&message),
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
    #[serde(rename = "box")]
    rect: Option<RawBox>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBox {
    size: Spanned<Pair<f64>>,
    origin: Option<Spanned<Pair<f64>>>,
    boundary: Option<Spanned<String>>,
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
    colour: Option<Spanned<String>>,
    label: Option<Spanned<String>>,
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
                    velocity: b
                        .velocity
                        .as_ref()
                        .map_or(Vec2::ZERO, |v| v.get_ref().vec()),
                    radius: *b.radius.get_ref(),
                    mass: opt(&b.mass, 1.0),
                    fixed: None,
                    pocket: None,
                    colour: b.colour.as_ref().map(|c| c.get_ref().clone()),
                    label: b.label.as_ref().map(|l| l.get_ref().clone()),
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
        let sectors = self.sectors()?;
        let mut scenario = Scenario {
            name: source.to_string(),
            until: self
                .run
                .as_ref()
                .map_or(DEFAULT_UNTIL, |r| opt(&r.until, DEFAULT_UNTIL)),
            balls,
            cushions,
            pockets,
            sectors,
            periodic: None,
        };
        if let Some(rect) = &self.rect {
            rect.apply(&mut scenario)?;
        }
        Ok(scenario)
    }

    /// The `[sectors]` table as a layout; only its shape can fail here.
    fn sectors(&self) -> Result<Option<SectorSpec>, (Invalid, Option<Range<usize>>)> {
        Ok(match &self.sectors {
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
                        .map(|p| {
                            p.get_ref()
                                .points
                                .get_ref()
                                .iter()
                                .map(|q| q.vec())
                                .collect()
                        })
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
                        Some("colour") => b.colour.as_ref().map(span),
                        Some("label") => b.label.as_ref().map(span),
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
                        Some("elasticity" | "corner_elasticity") => p.elasticity.as_ref().map(span),
                        _ => None,
                    };
                    s.or_else(|| Some(e.span()))
                }
                _ => None,
            };
        }
        match (head, rest) {
            ("run", Some("until")) => self.run.as_ref()?.until.as_ref().map(span),
            ("box", Some("origin")) => self.rect.as_ref()?.origin.as_ref().map(span),
            ("box", _) => Some(span(&self.rect.as_ref()?.size)),
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

impl RawBox {
    /// Gives `s` this box: a periodic boundary (every ball taken into the box), or four elastic
    /// cushions around it. Refused beside cushions or pockets of the file's own.
    fn apply(&self, s: &mut Scenario) -> Result<(), (Invalid, Option<Range<usize>>)> {
        let lo = self
            .origin
            .as_ref()
            .map_or(Vec2::ZERO, |o| o.get_ref().vec());
        let size = self.size.get_ref().vec();
        let refuse = |message: String, at: Range<usize>| {
            Err((
                Invalid {
                    field: "box".into(),
                    message,
                },
                Some(at),
            ))
        };
        if !s.cushions.is_empty() || !s.pockets.is_empty() {
            return refuse(
                "a box brings its own boundary: give either [box] or cushions and pockets".into(),
                span(&self.size),
            );
        }
        let periodic = match self
            .boundary
            .as_ref()
            .map(|b| (b.get_ref().as_str(), b.span()))
        {
            None | Some(("walled", _)) => false,
            Some(("periodic", _)) => true,
            Some((other, at)) => {
                return refuse(
                    format!("boundary must be \"periodic\" or \"walled\", got {other:?}"),
                    at,
                )
            }
        };
        if !(lo.is_finite() && size.is_finite() && size.x > 0.0 && size.y > 0.0) {
            return refuse(
                format!(
                    "size must be two positive numbers and origin finite, got size [{}, {}]",
                    size.x, size.y
                ),
                span(&self.size),
            );
        }
        if periodic {
            let b = PeriodicBox { lo, size };
            for ball in &mut s.balls {
                ball.position = b.wrap(ball.position);
            }
            s.periodic = Some(b);
        } else {
            s.cushions = super::builtin::box_cushions_at(lo, size);
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// Errors.

/// The 1-based line holding byte `offset` of `text` (an offset past the end counts as the end).
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&c| c == b'\n')
        .count()
        + 1
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
/// comes from its span; the field is the key or table whose text holds that span.
fn toml_error(text: &str, source: &str, e: &::toml::de::Error) -> ScenarioError {
    if let Some(wrong) = wrong_header(text, source) {
        return wrong;
    }
    let span = e.span();
    let syntax = ::toml::from_str::<IgnoredAny>(text).is_err();
    let line = span.as_ref().map(|s| line_of(text, s.start));
    let (field, message) = match (&span, syntax) {
        // the line toml names may be past the statement at fault: name no field
        (_, true) => (
            String::new(),
            format!("not valid TOML: {}", one_line(e.message())),
        ),
        (Some(s), false) => (field_at(text, s.start), clarify(&one_line(e.message()))),
        (None, false) => (String::new(), clarify(&one_line(e.message()))),
    };
    ScenarioError {
        source: source.to_string(),
        line,
        field,
        message,
    }
}

/// A table header of the wrong kind: `[[run]]` or `[[sectors]]` (one table each), or `[ball]`,
/// `[cushion]`, `[pocket]` or `[sectors.polygon]` (one table per item). Serde would report
/// these as a type mismatch inside the table; the earliest such header in the file is named.
fn wrong_header(text: &str, source: &str) -> Option<ScenarioError> {
    let doc = valid_prefix(text)?;
    let root = doc.as_table();
    let single = |name: &str| {
        let start = root.get(name)?.as_array_of_tables()?.span()?.start;
        let message =
            format!("`[[{name}]]` makes a list of tables; the file has one: write `[{name}]`");
        Some((start, name.to_string(), message))
    };
    let listed = |parent: &Table, name: &str, full: &str| {
        let start = written_table(parent.get(name)?)?.span()?.start;
        let message = format!("`[{full}]` is a single table; write `[[{full}]]` once per item");
        Some((start, full.to_string(), message))
    };
    let sectors = root.get("sectors").and_then(Item::as_table);
    let found = [
        single("run"),
        single("sectors"),
        listed(root, "ball", "ball"),
        listed(root, "cushion", "cushion"),
        listed(root, "pocket", "pocket"),
        sectors.and_then(|t| listed(t, "polygon", "sectors.polygon")),
    ];
    let (start, field, message) = found.into_iter().flatten().min_by_key(|f| f.0)?;
    Some(ScenarioError {
        source: source.to_string(),
        line: Some(line_of(text, start)),
        field,
        message,
    })
}

/// The document as far as it is valid TOML: all of it, or the lines before the statement
/// toml_edit rejects (such as `[[ball]]` after a `[ball]`).
fn valid_prefix(text: &str) -> Option<ImDocument<&str>> {
    match ImDocument::parse(text) {
        Ok(doc) => Some(doc),
        Err(e) => {
            let bad = e.span()?.start.min(text.len());
            let cut = text[..bad].rfind('\n').map_or(0, |n| n + 1);
            ImDocument::parse(&text[..cut]).ok()
        }
    }
}

/// The table of `item` if the file writes it with a `[header]` of its own (not one made
/// implicitly by a longer header or by dotted keys).
fn written_table(item: &Item) -> Option<&Table> {
    item.as_table()
        .filter(|t| !t.is_implicit() && !t.is_dotted())
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

/// The field path (like `ball[2].radius`) of the deepest key, table or list entry whose text
/// holds byte `offset`, read from toml_edit's spans; empty where none does.
fn field_at(text: &str, offset: usize) -> String {
    let path = ImDocument::parse(text)
        .ok()
        .and_then(|doc| path_in(doc.as_table(), offset));
    one_line(&path.unwrap_or_default())
}

/// Whether `span` holds byte `offset` (an empty span holds its start).
fn holds(span: Option<Range<usize>>, offset: usize) -> bool {
    span.is_some_and(|s| s.start <= offset && offset < s.end.max(s.start + 1))
}

/// The path, below `table`, of the deepest entry whose text holds byte `offset`.
fn path_in(table: &dyn TableLike, offset: usize) -> Option<String> {
    table.iter().find_map(|(name, item)| {
        if let Some(list) = item.as_array_of_tables() {
            return list.iter().enumerate().find_map(|(i, entry)| {
                let here = format!("{name}[{}]", i + 1);
                match path_in(entry, offset) {
                    Some(below) => Some(format!("{here}.{below}")),
                    None => holds(entry.span(), offset).then_some(here),
                }
            });
        }
        if let Some(below) = item.as_table_like().and_then(|t| path_in(t, offset)) {
            return Some(format!("{name}.{below}"));
        }
        // A `[table]` spans its header and statements; a value spans from its key.
        let key = table.get_key_value(name).and_then(|(k, _)| k.span());
        let span = match (key, item.span()) {
            (Some(k), Some(v)) if !item.is_table() => Some(k.start..v.end),
            (_, span) => span,
        };
        holds(span, offset).then(|| name.to_string())
    })
}

/// The 1-based line of the header `[name]`, if the text has one.
fn header_line(text: &str, name: &str) -> Option<usize> {
    let doc = ImDocument::parse(text).ok()?;
    let table = written_table(doc.as_table().get(name)?)?;
    Some(line_of(text, table.span()?.start))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid file; the tests below replace one numbered line to break it.
    const BASE: &str = "\
[run]
until = 3.0

[[ball]]
position = [100.0, 100.0]
velocity = [10.0, 0.0]
radius = 20.0

[[ball]]
position = [200.0, 100.0]
radius = 20.0
mass = 2.0

[[cushion]]
from = [0.0, 0.0]
to = [0.0, 400.0]
[[cushion]]
from = [0.0, 400.0]
to = [400.0, 400.0]
elasticity = 0.5
[[cushion]]
from = [400.0, 400.0]
to = [400.0, 0.0]
[[cushion]]
from = [400.0, 0.0]
to = [220.0, 0.0]
[[cushion]]
from = [180.0, 0.0]
to = [0.0, 0.0]

[[pocket]]
from = [220.0, 0.0]
to = [180.0, 0.0]
elasticity = 0.8

[sectors]
grid = [2, 3]
";

    /// `BASE` with its 1-based line `n` replaced by `text`.
    fn with_line(n: usize, text: &str) -> String {
        let mut lines: Vec<&str> = BASE.lines().collect();
        lines[n - 1] = text;
        lines.join("\n") + "\n"
    }

    /// A closed unit square of cushions, to follow a text whose sectors cover it.
    const UNIT_SQUARE: &str =
        "[[cushion]]\nfrom = [0, 0]\nto = [0, 1]\n[[cushion]]\nfrom = [0, 1]\nto = [1, 1]\n\
        [[cushion]]\nfrom = [1, 1]\nto = [1, 0]\n[[cushion]]\nfrom = [1, 0]\nto = [0, 0]\n";

    fn fails(text: &str) -> ScenarioError {
        match parse(text, "t.toml") {
            Ok(_) => panic!("expected an error for:\n{text}"),
            Err(e) => e,
        }
    }

    /// Asserts the error's line, field and a piece of its message, and that it is one line.
    fn assert_error(e: &ScenarioError, line: usize, field: &str, part: &str) {
        let shown = e.to_string();
        assert_eq!(e.line, Some(line), "{shown}");
        assert_eq!(e.field, field, "{shown}");
        assert!(e.message.contains(part), "{shown} lacks {part:?}");
        assert!(
            shown.starts_with(&format!("t.toml:{line}: {field}: ")),
            "{shown}"
        );
        assert!(!shown.contains('\n'), "{shown}");
    }

    #[test]
    fn base_file_round_trips() {
        let s = parse(BASE, "t.toml").unwrap();
        assert_eq!(s.name, "t.toml");
        assert_eq!(s.until, 3.0);
        assert_eq!(s.balls.len(), 2);
        assert_eq!(
            s.balls[0],
            BallSpec {
                position: Vec2::new(100.0, 100.0),
                velocity: Vec2::new(10.0, 0.0),
                radius: 20.0,
                mass: 1.0,
                fixed: None,
                pocket: None,
                colour: None,
                label: None,
            }
        );
        assert_eq!(s.balls[1].velocity, Vec2::ZERO);
        assert_eq!(s.balls[1].mass, 2.0);
        assert_eq!(s.cushions.len(), 5);
        assert_eq!(s.cushions[0].elasticity, 1.0);
        assert_eq!(s.cushions[1].elasticity, 0.5);
        assert_eq!(s.cushions[3].to, Vec2::new(220.0, 0.0));
        assert_eq!(
            s.pockets,
            vec![PocketSpec {
                from: Vec2::new(220.0, 0.0),
                to: Vec2::new(180.0, 0.0),
                corner_elasticity: 0.8,
            }]
        );
        assert_eq!(s.corner_count(), 2);
        assert_eq!(s.corner_position(0), Vec2::new(220.0, 0.0));
        assert_eq!(s.corner_position(1), Vec2::new(180.0, 0.0));
        assert_eq!(s.sectors, Some(SectorSpec::Grid { nx: 2, ny: 3 }));
    }

    #[test]
    fn defaults_apply() {
        let s = parse("[[ball]]\nposition = [0, 0]\nradius = 1\n", "d.toml").unwrap();
        assert_eq!(s.until, DEFAULT_UNTIL);
        assert_eq!(s.balls[0].velocity, Vec2::ZERO);
        assert_eq!(s.balls[0].mass, 1.0);
        assert!(s.cushions.is_empty() && s.pockets.is_empty() && s.sectors.is_none());
        let s = parse(
            "[[pocket]]\nfrom = [0, 0]\nto = [0, 1]\n[[cushion]]\nfrom = [2, 1]\nto = [2, 0]\n\
             [[ball]]\nposition = [1, 0.5]\nradius = 0.1\n",
            "d.toml",
        )
        .unwrap();
        assert_eq!(s.pockets[0].corner_elasticity, 1.0);
        assert_eq!(s.cushions[0].elasticity, 1.0);
        assert_eq!(fails("").field, "ball");
    }

    #[test]
    fn polygon_sectors_round_trip() {
        let text = &("[[sectors.polygon]]\npoints = [[0, 0], [0, 1], [1, 1]]\n\
                    [[sectors.polygon]]\npoints = [\n  [1, 1],\n  [1, 0], # comment\n  [0, 0],\n]\n\
                    [[ball]]\nposition = [0.5, 0.5]\nradius = 0.1\n"
            .to_string()
            + UNIT_SQUARE);
        let s = parse(text, "p.toml").unwrap();
        let Some(SectorSpec::Polygons(polys)) = s.sectors else {
            panic!("no polygons")
        };
        assert_eq!(polys.len(), 2);
        assert_eq!(polys[1][1], Vec2::new(1.0, 0.0));
    }

    #[test]
    fn overlapping_balls_name_both() {
        let e = fails(&with_line(10, "position = [130.0, 100.0]"));
        assert_error(&e, 10, "ball[2].position", "Ball-2 overlaps Ball-1");
    }

    #[test]
    fn ball_off_the_table() {
        let e = fails(&with_line(10, "position = [500.0, 100.0]"));
        assert_error(&e, 10, "ball[2].position", "off the table");
    }

    #[test]
    fn ball_through_a_cushion() {
        let e = fails(&with_line(5, "position = [10.0, 100.0]"));
        assert_error(&e, 5, "ball[1].position", "Ball-1 overlaps Cushion-1");
    }

    #[test]
    fn radius_not_positive() {
        let e = fails(&with_line(7, "radius = 0.0"));
        assert_error(&e, 7, "ball[1].radius", "must be positive, got 0");
    }

    #[test]
    fn mass_not_positive() {
        let e = fails(&with_line(12, "mass = -2.0"));
        assert_error(&e, 12, "ball[2].mass", "must be positive, got -2");
    }

    #[test]
    fn nan_position() {
        let e = fails(&with_line(5, "position = [nan, 100.0]"));
        assert_error(&e, 5, "ball[1].position", "finite");
    }

    #[test]
    fn infinite_velocity() {
        let e = fails(&with_line(6, "velocity = [10.0, -inf]"));
        assert_error(&e, 6, "ball[1].velocity", "finite");
    }

    #[test]
    fn elasticity_above_one() {
        let e = fails(&with_line(20, "elasticity = 1.5"));
        assert_error(
            &e,
            20,
            "cushion[2].elasticity",
            "must lie in [0, 1], got 1.5",
        );
    }

    #[test]
    fn pocket_elasticity_is_named_as_in_the_file() {
        let e = fails(&with_line(34, "elasticity = -0.1"));
        assert_error(&e, 34, "pocket[1].elasticity", "must lie in [0, 1]");
    }

    #[test]
    fn zero_length_cushion() {
        let e = fails(&with_line(19, "to = [0.0, 400.0]"));
        assert_error(&e, 17, "cushion[2]", "zero length");
    }

    #[test]
    fn a_header_of_the_wrong_kind_says_which_to_write() {
        let e = fails(&with_line(1, "[[run]]"));
        assert_error(&e, 1, "run", "write `[run]`");
        let e = fails(&with_line(4, "[ball]"));
        assert_error(&e, 4, "ball", "write `[[ball]]` once per item");
        let e = fails(&with_line(36, "[[sectors]]"));
        assert_error(&e, 36, "sectors", "write `[sectors]`");
        let polygon = "[[run]]\nuntil = 1\n[sectors.polygon]\npoints = [[0, 0], [0, 1], [1, 1]]\n";
        let e = fails(&polygon.replace("[[run]]", "[run]"));
        assert_error(&e, 3, "sectors.polygon", "write `[[sectors.polygon]]`");
    }

    #[test]
    fn a_syntax_error_says_so() {
        let e = fails(&with_line(2, "until = 1.0.0"));
        assert_eq!(
            e.to_string(),
            "t.toml:2: not valid TOML: expected newline, `#`"
        );
    }

    #[test]
    fn unknown_key() {
        let e = fails(&with_line(8, "spin = 3"));
        assert_error(&e, 8, "ball[1].spin", "unknown field `spin`");
        let e = fails(&with_line(3, "speed = 3"));
        assert_error(&e, 3, "run.speed", "unknown field `speed`");
        let e = fails(&with_line(35, "[table]"));
        assert_error(&e, 35, "table", "unknown field `table`");
    }

    #[test]
    fn missing_key() {
        let e = fails(&with_line(7, "# no radius"));
        assert_error(&e, 4, "ball[1]", "missing field `radius`");
    }

    #[test]
    fn wrong_types() {
        let e = fails(&with_line(7, "radius = \"big\""));
        assert_error(
            &e,
            7,
            "ball[1].radius",
            "invalid type: string \"big\", expected f64",
        );
        let e = fails(&with_line(10, "position = [1.0, 2.0, 3.0]"));
        assert_error(&e, 10, "ball[2].position", "invalid length 3");
        let e = fails(&with_line(37, "grid = [2, -3]"));
        assert_error(&e, 37, "sectors.grid", "invalid value: integer `-3`");
        let e = fails(&with_line(7, "radius.x = 1"));
        assert_error(&e, 7, "ball[1].radius.x", "table, expected a single value");
    }

    #[test]
    fn malformed_toml() {
        let e = fails(&with_line(15, "from = [0.0, 0.0"));
        assert_eq!(e.field, "");
        assert_eq!(e.line, Some(16), "{e}");
        assert_eq!(
            e.to_string(),
            "t.toml:16: not valid TOML: invalid array; expected `]`"
        );
        let e = fails(&with_line(7, "radius = = 20"));
        assert_eq!((e.line, e.field.as_str()), (Some(7), ""), "{e}");
        assert!(!e.to_string().contains('\n'));
        let e = fails(&with_line(11, "radius = 20.0\nradius = 21.0"));
        assert_eq!(e.line, Some(12), "{e}");
        assert!(e.message.contains("duplicate key `radius`"), "{e}");
    }

    #[test]
    fn negative_until() {
        let e = fails(&with_line(2, "until = -1.0"));
        assert_error(&e, 2, "run.until", "must not be negative, got -1");
        let e = fails(&with_line(2, "until = nan"));
        assert_error(&e, 2, "run.until", "finite");
    }

    #[test]
    fn sector_errors() {
        let e = fails(&with_line(37, "grid = [0, 3]"));
        assert_error(&e, 37, "sectors.grid", "at least one sector");
        let e = fails(&format!(
            "{BASE}[[sectors.polygon]]\npoints = [[0, 0], [1, 1]]\n"
        ));
        assert_error(&e, 37, "sectors", "not both");
        let e = fails(&with_line(37, "# no grid"));
        assert_error(&e, 36, "sectors", "needs grid");
        let text = &("[[sectors.polygon]]\npoints = [[0, 0], [0, 1], [1, 1]]\n\
                    [[sectors.polygon]]\npoints = [\n  [0, 0],\n  [1, 1],\n]\n\
                    [[ball]]\nposition = [0.5, 0.5]\nradius = 0.1\n"
            .to_string()
            + UNIT_SQUARE);
        let e = fails(text);
        assert_error(&e, 4, "sectors.polygon[2].points", "at least 3 points");
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_crash() {
        let text = format!("a = {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
        assert_eq!(fails(&text).line, Some(1));
        let text = format!("a = {}\n", "{b = ".repeat(100_000));
        assert_eq!(fails(&text).line, Some(1));
    }

    #[test]
    fn field_paths_skip_strings_and_multiline_values() {
        let text = "a = \"\"\"\n[x]\n\"\"\"\nb = [\n [1],\n]\n[[ball]]\nc = '['\nd = 1\n";
        let at = text.find("d = 1").unwrap();
        assert_eq!(field_at(text, at), "ball[1].d");
        assert_eq!(field_at(text, 0), "a");
        assert_eq!(line_of(text, usize::MAX), text.lines().count() + 1);
    }
}
