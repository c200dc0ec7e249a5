//! Configurations sampled during a run, as extended XYZ: one frame per sample time, which OVITO,
//! ASE and most particle tools read.
//!
//! Each frame is a count line (the balls on the table), a comment line of `key=value` pairs, and
//! one line per ball on the table:
//!
//! ```text
//! 2
//! Lattice="600.0 0.0 0.0 0.0 400.0 0.0 0.0 0.0 1.0" Origin="0.0 0.0 0.0" Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:I:1 Time=0.5 pbc="F F F"
//! X 300.0 300.0 0.0 0.0 0.0 0.0 20.0 1.0 1
//! X 300.0 150.0 0.0 0.0 100.0 0.0 20.0 1.0 2
//! ```
//!
//! The lattice is the table's bounding box (`Origin` its lower left corner; the walls are not
//! periodic, `pbc="F F F"`); positions and velocities are in the plane `z = 0`. In a periodic
//! box the lattice is the box, `pbc="T T F"`, positions lie in the box, and a last column
//! `image:I:3` gives the whole sides from each position to the ball's unwrapped one (as LAMMPS'
//! image flags: unwrapped = position + image × side), for its displacement. `species` is `X`
//! (ASE's placeholder element); `id` is the ball's number (`Ball-id`), so that a ball is followed
//! from frame to frame although balls in pockets are left out. Numbers are written as the
//! shortest decimals that read back to the same bits.

use crate::engine::{Frame, Table};
use crate::geometry::{PeriodicBox, Vec2};
use crate::scenario::{BallSpec, CushionSpec, Scenario};
use std::io::{self, Write};

/// The `Properties` of every frame, in column order.
pub const PROPERTIES: &str = "species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:I:1";

/// The `Properties` of a frame in a periodic box: [`PROPERTIES`] and the images.
pub const PERIODIC_PROPERTIES: &str =
    "species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:I:1:image:I:3";

/// Writes `frame` of a run on `table` as one extended XYZ frame.
pub fn write_frame(out: &mut impl Write, frame: &Frame, table: &Table) -> io::Result<()> {
    let on_table = frame.balls.iter().filter(|b| b.pocket.is_none()).count();
    let (lo, span) = (table.lo, table.hi - table.lo);
    let periodic = table.period.is_some();
    let (properties, pbc) = match periodic {
        true => (PERIODIC_PROPERTIES, "T T F"),
        false => (PROPERTIES, "F F F"),
    };
    writeln!(out, "{on_table}")?;
    writeln!(
        out,
        "Lattice=\"{:?} 0.0 0.0 0.0 {:?} 0.0 0.0 0.0 1.0\" Origin=\"{:?} {:?} 0.0\" \
         Properties={properties} Time={:?} pbc=\"{pbc}\"",
        span.x, span.y, lo.x, lo.y, frame.t
    )?;
    for (i, b) in frame.balls.iter().enumerate() {
        if b.pocket.is_some() {
            continue;
        }
        let (p, v) = (b.traj.at(frame.t), b.traj.velocity);
        write!(
            out,
            "X {:?} {:?} 0.0 {:?} {:?} 0.0 {:?} {:?} {}",
            p.x,
            p.y,
            v.x,
            v.y,
            b.radius,
            b.mass,
            i + 1
        )?;
        if periodic {
            let [ix, iy] = frame.images.get(i).copied().unwrap_or_default();
            write!(out, " {ix} {iy} 0")?;
        }
        writeln!(out)?;
    }
    Ok(())
}

/// One frame read back from extended XYZ written by [`write_frame`].
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Its time (`Time=`).
    pub t: f64,
    /// The lattice's lower left corner and its extent along x and y.
    pub origin: (f64, f64),
    /// The lattice's extent along x and y.
    pub size: (f64, f64),
    /// Whether the lattice is a periodic box (`pbc="T T F"`).
    pub periodic: bool,
    /// Each ball on the table: its number, position, velocity, radius and mass.
    pub balls: Vec<SampledBall>,
}

impl Sample {
    /// A scenario that starts from this sample: its balls at time 0 where they are in it, in
    /// its periodic box or a box of elastic cushions around its lattice, until `until`, named
    /// `name`. The balls are
    /// numbered afresh in the sample's order (a sample leaves out the balls in pockets).
    pub fn to_scenario(&self, name: &str, until: f64) -> Scenario {
        let (x0, y0) = self.origin;
        let (x1, y1) = (x0 + self.size.0, y0 + self.size.1);
        // clockwise from the left side, so the table lies on each cushion's right
        let corners = [(x0, y0), (x0, y1), (x1, y1), (x1, y0)].map(|(x, y)| Vec2::new(x, y));
        let mut s = Scenario {
            name: name.to_string(),
            until,
            balls: self
                .balls
                .iter()
                .map(|b| BallSpec {
                    position: Vec2::new(b.position.0, b.position.1),
                    velocity: Vec2::new(b.velocity.0, b.velocity.1),
                    radius: b.radius,
                    mass: b.mass,
                    fixed: None,
                    pocket: None,
                    colour: None,
                    label: None,
                })
                .collect(),
            cushions: (0..4)
                .map(|k| CushionSpec {
                    from: corners[k],
                    to: corners[(k + 1) % 4],
                    elasticity: 1.0,
                })
                .collect(),
            pockets: Vec::new(),
            sectors: None,
            periodic: None,
        };
        if self.periodic {
            s.cushions.clear();
            s.periodic = Some(PeriodicBox {
                lo: Vec2::new(x0, y0),
                size: Vec2::new(self.size.0, self.size.1),
            });
        }
        s
    }
}

/// Whether `text` looks like extended XYZ: a count line, then a comment line with `Properties=`.
pub fn is_xyz(text: &str) -> bool {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let count = lines
        .next()
        .is_some_and(|l| l.trim().parse::<usize>().is_ok());
    count && lines.next().is_some_and(|l| l.contains("Properties="))
}

/// One ball of a [`Sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledBall {
    /// Its number (`Ball-id`).
    pub id: u32,
    /// Its centre.
    pub position: (f64, f64),
    /// Its velocity.
    pub velocity: (f64, f64),
    /// Its radius.
    pub radius: f64,
    /// Its mass.
    pub mass: f64,
    /// In a periodic box, the whole sides from its position to its unwrapped one; zero else.
    pub image: (i64, i64),
}

/// Why extended XYZ text could not be read: the line (from 1) and what is wrong.
#[derive(Debug, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct XyzError {
    /// The line, counted from 1.
    pub line: usize,
    /// What is wrong with it.
    pub message: String,
}

/// Reads every frame of extended XYZ text in the columns of [`PROPERTIES`].
pub fn read(text: &str) -> Result<Vec<Sample>, XyzError> {
    let mut lines = text.lines().enumerate().map(|(k, l)| (k + 1, l));
    let mut out = Vec::new();
    while let Some((k, count)) = lines.next() {
        if count.trim().is_empty() {
            continue;
        }
        let bad = |line: usize, message: String| XyzError { line, message };
        let n: usize = count
            .trim()
            .parse()
            .map_err(|_| bad(k, format!("expected a ball count, found `{count}`")))?;
        let (k, comment) = lines
            .next()
            .ok_or_else(|| bad(k + 1, "the frame ends before its comment line".into()))?;
        let mut sample = comment_of(comment).map_err(|m| bad(k, m))?;
        let mut last = k;
        for _ in 0..n {
            let (k, line) = lines
                .next()
                .ok_or_else(|| bad(last + 1, format!("the frame ends before its {n} balls")))?;
            let columns = if sample.periodic { 13 } else { 10 };
            sample
                .balls
                .push(ball_of(line, columns).map_err(|m| bad(k, m))?);
            last = k;
        }
        out.push(sample);
    }
    Ok(out)
}

/// The time and lattice of a frame's comment line.
fn comment_of(line: &str) -> Result<Sample, String> {
    let value = |key: &str| -> Result<&str, String> {
        let at = line
            .find(&format!("{key}="))
            .ok_or_else(|| format!("no {key}= in the comment line"))?;
        let rest = &line[at + key.len() + 1..];
        Ok(match rest.strip_prefix('"') {
            Some(quoted) => &quoted[..quoted.find('"').unwrap_or(quoted.len())],
            None => rest.split_whitespace().next().unwrap_or(""),
        })
    };
    let properties = value("Properties")?;
    if properties != PROPERTIES && properties != PERIODIC_PROPERTIES {
        return Err(format!(
            "Properties must be {PROPERTIES} (or, in a periodic box, {PERIODIC_PROPERTIES})"
        ));
    }
    let periodic = properties == PERIODIC_PROPERTIES;
    let pbc = value("pbc").unwrap_or("F F F");
    if periodic != (pbc == "T T F") {
        return Err(format!(
            "pbc=\"{pbc}\" does not go with Properties={properties} (the image column is for \
             a box periodic along x and y, pbc=\"T T F\")"
        ));
    }
    let numbers = |key: &str| -> Result<Vec<f64>, String> {
        value(key)?
            .split_whitespace()
            .map(|x| {
                x.parse()
                    .map_err(|_| format!("{key}: `{x}` is not a number"))
            })
            .collect()
    };
    let (lattice, origin, t) = (numbers("Lattice")?, numbers("Origin")?, numbers("Time")?);
    if lattice.len() != 9 || origin.len() != 3 || t.len() != 1 {
        return Err("Lattice needs 9 numbers, Origin 3 and Time 1".into());
    }
    Ok(Sample {
        t: t[0],
        origin: (origin[0], origin[1]),
        size: (lattice[0], lattice[4]),
        periodic,
        balls: Vec::new(),
    })
}

/// One ball's line, of `columns` columns (13 with the images).
fn ball_of(line: &str, columns: usize) -> Result<SampledBall, String> {
    let fields: Vec<&str> = line.split_whitespace().collect();
    if fields.len() != columns {
        return Err(format!(
            "expected {columns} columns, found {}",
            fields.len()
        ));
    }
    let whole = |k: usize| -> Result<i64, String> {
        fields[k]
            .parse()
            .map_err(|_| format!("column {}: `{}` is not a whole number", k + 1, fields[k]))
    };
    let image = match columns {
        13 => (whole(10)?, whole(11)?),
        _ => (0, 0),
    };
    let x = |k: usize| -> Result<f64, String> {
        fields[k]
            .parse()
            .map_err(|_| format!("column {}: `{}` is not a number", k + 1, fields[k]))
    };
    let id = fields[9]
        .parse()
        .map_err(|_| format!("column 10: `{}` is not a ball number", fields[9]))?;
    Ok(SampledBall {
        id,
        position: (x(1)?, x(2)?),
        velocity: (x(4)?, x(5)?),
        radius: x(7)?,
        mass: x(8)?,
        image,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::BallState;
    use crate::scenario::builtin;

    #[test]
    fn frames_read_back_to_the_same_bits() {
        let s = builtin::build("plate1", &builtin::Params::default()).unwrap();
        let table = Table::new(&s);
        let mut balls = BallState::initial(&s, 0.0);
        balls[1].traj.velocity.y = 0.1 + 0.2; // not a short decimal
        let mut text = Vec::new();
        let first = Frame {
            t: 0.0,
            balls,
            images: Vec::new(),
        };
        write_frame(&mut text, &first, &table).unwrap();
        let mut later = first.clone();
        later.t = 1.25;
        later.balls[0].pocket = Some(0);
        write_frame(&mut text, &later, &table).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert!(
            text.starts_with("2\nLattice=\"600.0 0.0 0.0 0.0 400.0"),
            "{text}"
        );
        let back = read(&text).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!((back[0].t, back[1].t), (0.0, 1.25));
        assert_eq!((back[0].origin, back[0].size), ((0.0, 0.0), (600.0, 400.0)));
        for (got, want) in back[0].balls.iter().zip(&first.balls) {
            assert_eq!(got.position, (want.traj.position.x, want.traj.position.y));
            assert_eq!(got.velocity, (want.traj.velocity.x, want.traj.velocity.y));
            assert_eq!((got.radius, got.mass), (want.radius, want.mass));
        }
        // the pocketed ball is left out; the other keeps its number and moves on its line
        assert_eq!(back[1].balls.len(), 1);
        assert_eq!(back[1].balls[0].id, 2);
        let moved = first.balls[1].traj.at(1.25);
        assert_eq!(back[1].balls[0].position, (moved.x, moved.y));
    }

    #[test]
    fn bad_text_names_its_line() {
        let e = read("2\nLattice=\"1 0 0 0 1 0 0 0 1\"\n").unwrap_err();
        assert_eq!(e.line, 2);
        let good = format!(
            "1\nLattice=\"1 0 0 0 1 0 0 0 1\" Origin=\"0 0 0\" Properties={PROPERTIES} Time=0\n"
        );
        let e = read(&format!("{good}X 1 2 0 0 0 0 1 1\n")).unwrap_err();
        assert_eq!(
            (e.line, e.message.as_str()),
            (3, "expected 10 columns, found 9")
        );
        let e = read(&good).unwrap_err();
        assert_eq!(e.line, 3);
        let e = read(&format!(
            "{}X 1 2 0 0 0 0 1 1 7\n",
            good.replacen('1', "2", 1)
        ))
        .unwrap_err();
        assert_eq!(
            (e.line, e.message.as_str()),
            (4, "the frame ends before its 2 balls")
        );
        assert!(read("nonsense\n")
            .unwrap_err()
            .message
            .contains("ball count"));
        assert_eq!(
            read(&format!("{good}X 1 2 0 0 0 0 1 1 7\n")).unwrap()[0].balls[0].id,
            7
        );
    }

    #[test]
    fn a_periodic_sample_keeps_its_box_and_images() {
        let p = builtin::Params {
            balls: Some(30),
            boundary: Some(builtin::Boundary::Periodic),
            ..builtin::Params::default()
        };
        let s = builtin::build("disks", &p).unwrap();
        let table = Table::new(&s);
        let mut el = crate::engine::event_list::EventList::new(&s, Default::default());
        let out = el.run(5.0, &mut crate::engine::Ignore).unwrap();
        let frame = Frame {
            t: 5.0,
            balls: out.balls,
            images: el.images_at(5.0),
        };
        assert!(
            frame.images.iter().any(|&i| i != [0, 0]),
            "no ball crossed a side"
        );
        let mut text = Vec::new();
        write_frame(&mut text, &frame, &table).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert!(text.contains("pbc=\"T T F\""), "{text}");
        let back = read(&text).unwrap().remove(0);
        assert!(back.periodic);
        let unwrapped = el.unwrapped_at(5.0);
        let side = back.size;
        for (b, u) in back.balls.iter().zip(&unwrapped) {
            let x = b.position.0 + b.image.0 as f64 * side.0;
            let y = b.position.1 + b.image.1 as f64 * side.1;
            assert!((x - u.x).abs() < 1e-9 && (y - u.y).abs() < 1e-9);
        }
        let again = back.to_scenario("again", 1.0);
        assert_eq!(again.periodic, s.periodic);
        assert!(again.cushions.is_empty());
        again.validate().unwrap();
        // a periodic header without the images, or the images without a periodic box
        let bad = text.replace("pbc=\"T T F\"", "pbc=\"F F F\"");
        assert!(read(&bad).unwrap_err().message.contains("does not go with"));
    }
}
