//! Which worker runs which object under Time Warp: the table is cut into strips across its
//! longer side, each with about the same load, and every object goes to the strip where it
//! is. On a sectored table each sector and the balls that start in it share a worker, so only
//! messages across strip borders cross workers.

use super::Table;
use crate::geometry::Vec2;
use crate::model::sectored::Layout;
use crate::scenario::Scenario;

/// Strip borders along one axis.
struct Strips {
    along_x: bool,
    cuts: Vec<f64>,
}

impl Strips {
    /// `workers` strips over `table`, each with about the same weight of `points`.
    fn new(table: &Table, points: &[(Vec2, f64)], workers: usize) -> Strips {
        let size = table.hi - table.lo;
        let along_x = size.x >= size.y;
        let coord = |p: Vec2| if along_x { p.x } else { p.y };
        let mut sorted: Vec<(f64, f64)> = points.iter().map(|&(p, w)| (coord(p), w)).collect();
        sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
        let total: f64 = sorted.iter().map(|p| p.1).sum();
        let mut cuts = Vec::with_capacity(workers.saturating_sub(1));
        let mut acc = 0.0;
        for k in 0..sorted.len() {
            acc += sorted[k].1;
            let want = total * (cuts.len() + 1) as f64 / workers as f64;
            if cuts.len() + 1 < workers && acc >= want && k + 1 < sorted.len() {
                cuts.push(0.5 * (sorted[k].0 + sorted[k + 1].0));
            }
        }
        Strips { along_x, cuts }
    }

    /// The strip of point `p`.
    fn of(&self, p: Vec2) -> u32 {
        let c = if self.along_x { p.x } else { p.y };
        self.cuts.partition_point(|&cut| cut <= c) as u32
    }
}

/// Representative points of the fixed objects in id order: cushions and pockets by their
/// midpoints, corners where they are.
fn fixed_points(table: &Table) -> impl Iterator<Item = Vec2> + '_ {
    let mid = |a: Vec2, b: Vec2| 0.5 * (a + b);
    table
        .cushions
        .iter()
        .map(move |c| mid(c.0, c.1))
        .chain(table.pockets.iter().map(move |p| mid(p.0, p.1)))
        .chain(table.corners.iter().map(|c| c.0))
}

/// Workers of the plain objects (balls, then fixed objects) in strips of equal ball counts;
/// objects after them (the Projector) run on worker 0.
pub fn plain(s: &Scenario, workers: usize) -> Vec<u32> {
    let table = Table::new(s);
    let points: Vec<(Vec2, f64)> = s.balls.iter().map(|b| (b.position, 1.0)).collect();
    let strips = Strips::new(&table, &points, workers);
    let mut out: Vec<u32> = points.iter().map(|p| strips.of(p.0)).collect();
    out.extend(fixed_points(&table).map(|p| strips.of(p)));
    out
}

/// Workers of the sectored objects (balls, fixed objects, sectors): sectors in strips of equal
/// load (the balls that start in them, plus one), each ball with the sector holding its centre.
pub fn sectored(s: &Scenario, layout: &Layout, workers: usize) -> Vec<u32> {
    let table = Table::new(s);
    let home: Vec<u32> = s
        .balls
        .iter()
        .map(|b| layout.home(b.position).unwrap_or(0))
        .collect();
    let mut load = vec![1.0; layout.polys.len()];
    for &k in &home {
        load[k as usize] += 1.0;
    }
    let centroids: Vec<Vec2> = layout
        .polys
        .iter()
        .map(|p| {
            let (lo, hi) = p.bounds();
            0.5 * (lo + hi)
        })
        .collect();
    let points: Vec<(Vec2, f64)> = centroids.iter().copied().zip(load).collect();
    let strips = Strips::new(&table, &points, workers);
    let sector_worker: Vec<u32> = centroids.iter().map(|&c| strips.of(c)).collect();
    let mut out: Vec<u32> = home.iter().map(|&k| sector_worker[k as usize]).collect();
    out.extend(fixed_points(&table).map(|p| strips.of(p)));
    out.extend(sector_worker);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::builtin;

    #[test]
    fn strips_balance_the_balls() {
        let p = builtin::Params {
            balls: Some(64),
            ..Default::default()
        };
        let s = builtin::build("gas", &p).unwrap();
        for workers in 1..=4 {
            let w = plain(&s, workers);
            assert_eq!(w.len(), s.balls.len() + Table::new(&s).n_fixed() as usize);
            let mut counts = vec![0; workers];
            for &k in &w[..64] {
                counts[k as usize] += 1;
            }
            assert!(
                counts.iter().all(|&c| c >= 64 / workers - 8),
                "{workers}: {counts:?}"
            );
        }
    }

    #[test]
    fn a_sector_and_its_balls_share_a_worker() {
        let p = builtin::Params {
            balls: Some(64),
            ..Default::default()
        };
        let s = builtin::build("gas", &p).unwrap();
        let table = Table::new(&s);
        let layout = Layout::grid(&table, 4, 4);
        let w = sectored(&s, &layout, 2);
        let first_sector = 64 + table.n_fixed() as usize;
        assert_eq!(w.len(), first_sector + 16);
        for (i, b) in s.balls.iter().enumerate() {
            let k = layout.touching(b.position, 0.0)[0] as usize;
            assert_eq!(w[i], w[first_sector + k]);
        }
        let on_one = w[first_sector..].iter().filter(|&&x| x == 1).count();
        assert_eq!(on_one, 8, "two columns of sectors each");
    }
}
