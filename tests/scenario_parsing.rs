//! Scenario files from the outside: `load` on real files, and `parse` on arbitrary and mangled
//! text, which must never panic and must always answer in one line naming the file.

use poolsim::scenario::builtin::{self, Params};
use poolsim::scenario::toml::{load, parse};
use proptest::prelude::*;
use std::io::Write;

const SOURCE: &str = "fuzz.toml";

/// A valid scenario using every part of the format.
const VALID: &str = r#"# a small table
[run]
until = 2.5

[[ball]]
position = [150.0, 150.0]
velocity = [40.0, -10.0]
radius = 30.0
mass = 1.0

[[ball]]
position = [400, 300]
radius = 30

[[cushion]]
from = [0.0, 0.0]
to = [0.0, 600.0]
elasticity = 1.0
[[cushion]]
from = [0.0, 600.0]
to = [600.0, 600.0]
[[cushion]]
from = [600.0, 600.0]
to = [600.0, 0.0]
[[cushion]]
from = [600.0, 0.0]
to = [60.0, 0.0]

[[pocket]]
from = [60.0, 0.0]
to = [0.0, 0.0]
elasticity = 0.9

[[sectors.polygon]]
points = [[0.0, 0.0], [0.0, 600.0], [300.0, 600.0], [300.0, 0.0]]
[[sectors.polygon]]
points = [
  [300.0, 0.0],
  [300.0, 600.0],
  [600.0, 600.0],
  [600.0, 0.0],  # last
]
"#;

/// Parses `text` and checks the contract: no panic (the caller would see it), and an error is one
/// line that starts with the source name.
fn check(text: &str) -> Result<(), TestCaseError> {
    if let Err(e) = parse(text, SOURCE) {
        let shown = e.to_string();
        prop_assert!(
            !shown.contains('\n') && !shown.contains('\r'),
            "more than one line: {shown:?}"
        );
        prop_assert!(shown.starts_with(&format!("{SOURCE}:")), "{shown:?}");
        prop_assert_eq!(&e.source, SOURCE);
        if let Some(line) = e.line {
            prop_assert!(line >= 1 && line <= text.split('\n').count(), "{shown:?}");
        }
    }
    Ok(())
}

/// One edit of a text: where (taken modulo the length), what, and which character.
#[derive(Clone, Debug)]
enum Edit {
    Delete(usize),
    Insert(usize, char),
    Replace(usize, char),
    DuplicateLine(usize),
    DeleteLine(usize),
}

fn toml_char() -> impl Strategy<Value = char> {
    prop_oneof![
        prop::sample::select(vec![
            '[', ']', '{', '}', '=', '"', '\'', '\n', '#', '.', ',', '-', '+', '0', '1', '9', 'e',
            'n', 'a', 'i', ' ', '_', '\\', '\r', '\t',
        ]),
        any::<char>(),
    ]
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        any::<usize>().prop_map(Edit::Delete),
        (any::<usize>(), toml_char()).prop_map(|(i, c)| Edit::Insert(i, c)),
        (any::<usize>(), toml_char()).prop_map(|(i, c)| Edit::Replace(i, c)),
        any::<usize>().prop_map(Edit::DuplicateLine),
        any::<usize>().prop_map(Edit::DeleteLine),
    ]
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for e in edits {
        let n = chars.len();
        match *e {
            Edit::Delete(i) if n > 0 => {
                chars.remove(i % n);
            }
            Edit::Insert(i, c) => chars.insert(i % (n + 1), c),
            Edit::Replace(i, c) if n > 0 => chars[i % n] = c,
            Edit::DuplicateLine(i) | Edit::DeleteLine(i) => {
                let s: String = chars.iter().collect();
                let mut lines: Vec<String> = s.split('\n').map(str::to_string).collect();
                let k = i % lines.len();
                if matches!(e, Edit::DuplicateLine(_)) {
                    lines.insert(k, lines[k].clone());
                } else {
                    lines.remove(k);
                }
                chars = lines.join("\n").chars().collect();
            }
            _ => {}
        }
    }
    chars.into_iter().collect()
}

#[test]
fn the_valid_text_parses() {
    let s = parse(VALID, SOURCE).unwrap();
    assert_eq!(s.balls.len(), 2);
    assert_eq!(s.until, 2.5);
    assert_eq!(s.pockets[0].corner_elasticity, 0.9);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn mutated_valid_text_never_panics(edits in prop::collection::vec(edit(), 1..8)) {
        check(&apply(VALID, &edits))?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        check(&text)?;
    }

    #[test]
    fn toml_like_text_never_panics(
        text in "([\\[\\]{}=\"'#.,+\\-\n \t]|[0-9]|e|nan|inf|ball|radius|position|velocity|mass|cushion|pocket|from|to|sectors|grid|polygon|points|run|until){0,120}"
    ) {
        check(&text)?;
    }

    #[test]
    fn lines_of_valid_text_in_any_order_never_panic(
        order in Just((0..VALID.lines().count()).collect::<Vec<_>>()).prop_shuffle()
    ) {
        let lines: Vec<&str> = VALID.lines().collect();
        let text: Vec<&str> = order.iter().map(|&i| lines[i]).collect();
        check(&text.join("\n"))?;
    }
}

#[test]
fn load_reads_a_file_and_names_it() {
    let mut file = tempfile::NamedTempFile::new().unwrap();
    file.write_all(VALID.as_bytes()).unwrap();
    let s = load(file.path()).unwrap();
    assert_eq!(s.name, file.path().display().to_string());
    assert_eq!(s.balls[1].position.x, 400.0);

    let mut bad = tempfile::NamedTempFile::new().unwrap();
    bad.write_all(VALID.replace("radius = 30\n", "radius = -30\n").as_bytes())
        .unwrap();
    let e = load(bad.path()).unwrap_err();
    let path = bad.path().display().to_string();
    assert_eq!(e.line, Some(13));
    assert_eq!(
        e.to_string(),
        format!("{path}:13: ball[2].radius: must be positive, got -30")
    );
}

#[test]
fn load_reports_io_errors_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    let e = load(&missing).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (None, ""));
    assert!(e
        .to_string()
        .starts_with(&format!("{}: ", missing.display())));
    assert!(!e.to_string().contains('\n'));

    let binary = dir.path().join("binary.toml");
    std::fs::write(&binary, [0xff, 0xfe, b'\n', 0x80]).unwrap();
    let e = load(&binary).unwrap_err();
    assert_eq!(e.line, None);
    assert!(!e.to_string().contains('\n'));
}

#[test]
fn builtins_survive_a_round_trip_through_toml() {
    // Writing a built-in out as TOML and reading it back gives the same scenario.
    for (name, _) in builtin::list() {
        let s = builtin::build(name, &Params::default()).unwrap();
        let mut text = format!("[run]\nuntil = {:?}\n", s.until);
        for b in &s.balls {
            text += &format!(
                "[[ball]]\nposition = [{:?}, {:?}]\nvelocity = [{:?}, {:?}]\nradius = {:?}\nmass = {:?}\n",
                b.position.x, b.position.y, b.velocity.x, b.velocity.y, b.radius, b.mass
            );
            if let Some(c) = &b.colour {
                text += &format!("colour = {c:?}\n");
            }
            if let Some(l) = &b.label {
                text += &format!("label = {l:?}\n");
            }
        }
        for c in &s.cushions {
            text += &format!(
                "[[cushion]]\nfrom = [{:?}, {:?}]\nto = [{:?}, {:?}]\nelasticity = {:?}\n",
                c.from.x, c.from.y, c.to.x, c.to.y, c.elasticity
            );
        }
        for p in &s.pockets {
            text += &format!(
                "[[pocket]]\nfrom = [{:?}, {:?}]\nto = [{:?}, {:?}]\nelasticity = {:?}\n",
                p.from.x, p.from.y, p.to.x, p.to.y, p.corner_elasticity
            );
        }
        let back = parse(&text, name).unwrap();
        assert_eq!(back, s, "{name}");
    }
}

const SQUARE: &str = "[[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
[[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 400.0]\n\
[[cushion]]\nfrom = [400.0, 400.0]\nto = [400.0, 0.0]\n\
[[cushion]]\nfrom = [400.0, 0.0]\nto = [0.0, 0.0]\n";

fn ball_at(x: f64, y: f64) -> String {
    format!("[[ball]]\nposition = [{x:?}, {y:?}]\nvelocity = [500.0, 0.0]\nradius = 10.0\n")
}

/// Cushions wound the wrong way would let every ball through them: rejected at load.
#[test]
fn counter_clockwise_cushions_are_rejected() {
    assert!(parse(&(ball_at(100.0, 100.0) + SQUARE), SOURCE).is_ok());
    let reversed: String = SQUARE
        .replace("from", "FROM")
        .replace("to =", "from =")
        .replace("FROM", "to");
    let e = parse(&(ball_at(100.0, 100.0) + &reversed), SOURCE).unwrap_err();
    assert_eq!(e.field, "cushion[1]");
    assert!(e.message.contains("counter-clockwise"), "{e}");
}

/// A ball inside the box of a closed table but outside the region its cushions enclose.
#[test]
fn a_ball_outside_a_closed_triangle_is_rejected() {
    let triangle = "[[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
        [[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 0.0]\n\
        [[cushion]]\nfrom = [400.0, 0.0]\nto = [0.0, 0.0]\n";
    assert!(parse(&(ball_at(100.0, 100.0) + triangle), SOURCE).is_ok());
    let e = parse(&(ball_at(350.0, 350.0) + triangle), SOURCE).unwrap_err();
    assert_eq!(e.field, "ball[1].position");
    assert!(e.message.contains("outside the table"), "{e}");
}

/// Sector polygons are checked whatever engine will run, with the line of the polygon blamed.
#[test]
fn overlapping_sector_polygons_are_rejected_at_load() {
    let sectors = "[[sectors.polygon]]\npoints = [[0.0, 0.0], [0.0, 400.0], [300.0, 400.0], [300.0, 0.0]]\n\
        [[sectors.polygon]]\npoints = [[200.0, 0.0], [200.0, 400.0], [400.0, 400.0], [400.0, 0.0]]\n";
    let e = parse(&(ball_at(100.0, 100.0) + SQUARE + sectors), SOURCE).unwrap_err();
    assert_eq!(e.field, "sectors.polygon[1]");
    assert!(e.line.is_some(), "{e}");
}

/// One cushion or pocket wound the wrong way on a closed table is named; an open table (a
/// single wall, walls with a gap) keeps working.
#[test]
fn one_cushion_wound_the_wrong_way_is_named() {
    let ball = ball_at(100.0, 100.0);
    for k in 1..=4 {
        // swap from and to of the k-th cushion only
        let mut parts: Vec<String> = SQUARE.split("[[cushion]]\n").map(String::from).collect();
        parts[k] = parts[k]
            .replace("from", "FROM")
            .replace("to =", "from =")
            .replace("FROM", "to");
        let table = parts.join("[[cushion]]\n");
        let e = parse(&(ball.clone() + &table), SOURCE).unwrap_err();
        assert_eq!(e.field, format!("cushion[{k}]"), "{e}");
        assert!(e.message.contains("runs the wrong way"), "{e}");
        assert!(e.line.is_some(), "{e}");
    }
    let pocketed = SQUARE.replace(
        "[[cushion]]\nfrom = [400.0, 0.0]\nto = [0.0, 0.0]\n",
        "[[cushion]]\nfrom = [400.0, 0.0]\nto = [60.0, 0.0]\n[[pocket]]\nfrom = [0.0, 0.0]\nto = [60.0, 0.0]\n",
    );
    let e = parse(&(ball.clone() + &pocketed), SOURCE).unwrap_err();
    assert_eq!(e.field, "pocket[1]", "{e}");
    let open = "[[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
        [[cushion]]\nfrom = [400.0, 400.0]\nto = [400.0, 0.0]\n";
    assert!(parse(&(ball.clone() + open), SOURCE).is_ok());
    let corner = "[[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
        [[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 400.0]\n";
    assert!(parse(&(ball + corner), SOURCE).is_ok());
}

/// A ball far beyond the others once made the overlap check index outside its buckets.
#[test]
fn a_ball_astronomically_far_away_is_an_error_or_runs_never_a_panic() {
    let far = "[[ball]]\nposition = [100.0, 100.0]\nradius = 1.0\n\
        [[ball]]\nposition = [1e30, 0.0]\nradius = 1.0\n";
    assert!(
        parse(far, SOURCE).is_ok(),
        "an open table: nothing to be off"
    );
    let e = parse(&(far.to_string() + SQUARE), SOURCE).unwrap_err();
    assert_eq!(e.field, "ball[2].position", "{e}");
    assert!(e.message.contains("off the table"), "{e}");
    let below = far.replace("[1e30, 0.0]", "[-1e300, -1e300]");
    assert!(parse(&below, SOURCE).is_ok());
}

/// A scenario without balls is refused; a file without `[run]` runs to the default end time.
#[test]
fn a_scenario_needs_a_ball_and_defaults_its_end_time() {
    for text in ["", "[run]\nuntil = 1.0\n", SQUARE] {
        let e = parse(text, SOURCE).unwrap_err();
        assert_eq!(e.field, "ball", "{e}");
        assert!(e.message.contains("no balls"), "{e}");
    }
    let s = parse(&(ball_at(100.0, 100.0) + SQUARE), SOURCE).unwrap();
    assert_eq!(s.until, poolsim::scenario::toml::DEFAULT_UNTIL);
}

/// An endless file is refused once it passes the bound, not read until memory runs out.
#[cfg(unix)]
#[test]
fn an_endless_file_is_refused_at_the_bound() {
    let e = load(std::path::Path::new("/dev/zero")).unwrap_err();
    assert!(e.message.contains("over 1024 MiB"), "{e}");
    assert!(!e.to_string().contains('\n'));
}

/// A ball overlapping a pocket's corner and the end of a cushion, but level with neither's
/// face, was once let through: moving on, it ran into the cushion (`--check` said so).
#[test]
fn a_ball_over_a_cushion_end_or_a_corner_is_refused() {
    let table = "[[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
        [[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 400.0]\n\
        [[cushion]]\nfrom = [400.0, 400.0]\nto = [400.0, 0.0]\n\
        [[cushion]]\nfrom = [400.0, 0.0]\nto = [300.0, 0.0]\n\
        [[pocket]]\nfrom = [300.0, 0.0]\nto = [200.0, 0.0]\n\
        [[cushion]]\nfrom = [200.0, 0.0]\nto = [0.0, 0.0]\n";
    let ball = |x: f64, y: f64, r: f64| {
        format!("[[ball]]\nposition = [{x:?}, {y:?}]\nradius = {r:?}\nvelocity = [40.0, 0.0]\n")
    };
    let e = parse(
        &(ball(295.77746540736143, 20.0, 88.71270294991847) + table),
        SOURCE,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "fuzz.toml:2: ball[1].position: Ball-1 overlaps Cushion-4 at t = 0"
    );
    // a pocket's corner where no cushion ends: the mouth is open, the corner is not
    let mouth = "[[pocket]]\nfrom = [300.0, 0.0]\nto = [200.0, 0.0]\n\
        [[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 400.0]\n";
    let e = parse(&(ball(250.0, 8.0, 52.0) + mouth), SOURCE)
        .unwrap_err()
        .to_string();
    assert!(e.ends_with("Ball-1 overlaps Corner-1 at t = 0"), "{e}");
    assert!(parse(&(ball(250.0, 8.0, 40.0) + mouth), SOURCE).is_ok());
    // clear of both it runs
    assert!(parse(&(ball(250.0, 60.0, 20.0) + table), SOURCE).is_ok());
}
