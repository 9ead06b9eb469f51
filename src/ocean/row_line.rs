//! A row of vertices evenly spaced on a line: what the projected grid's rows short of the far
//! line are (a camera whose image's right is horizontal), and what lets a kernel take a row's
//! phases from the line, in arithmetic progression, instead of from each vertex.
//!
//! The placement knows which rows it laid on a line and says so ([`RowLines`]); a kernel given
//! no such word checks the row itself ([`RowLine::of`]).

/// How far, relative to the row's largest coordinate (at least 1), a vertex may lie from its
/// row's line for the row to be taken as one: 4 units in the last place of an f32. A phase
/// from the line then differs from the vertex's own by about what an f32 sum a·x + b·y + c
/// rounds away.
const LINE_TOL: f64 = 1.0 / (1u64 << 21) as f64;

/// A row of points evenly spaced on a line: vertex j at (x0 + j·dx, y0 + j·dy), in f64.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RowLine {
    /// x of the row's first vertex.
    pub x0: f64,
    /// x step from one vertex to the next.
    pub dx: f64,
    /// y of the row's first vertex.
    pub y0: f64,
    /// y step from one vertex to the next.
    pub dy: f64,
}

/// For each row of a band, the line its vertices lie on, or None for a row that is not one
/// (the far line's arc, a rolled camera's rows); None for the whole band when nobody knows.
pub type RowLines<'a> = Option<&'a [Option<RowLine>]>;

impl RowLine {
    /// The line through the row's first and last vertices, taken on trust: for a row its
    /// placement laid on a line. None for a row of fewer than two vertices.
    #[inline(always)]
    pub fn through(x: &[f32], y: &[f32]) -> Option<RowLine> {
        let last = x.len().checked_sub(1).filter(|&l| l > 0)?;
        let (x0, y0) = (x[0] as f64, y[0] as f64);
        Some(RowLine {
            x0,
            dx: (x[last] as f64 - x0) / last as f64,
            y0,
            dy: (y[last] as f64 - y0) / last as f64,
        })
    }

    /// [`RowLine::through`] when every vertex lies within `LINE_TOL` of its place on the
    /// line (a NaN anywhere fails the check): for a row nobody vouches for.
    #[inline(always)]
    pub fn of(x: &[f32], y: &[f32]) -> Option<RowLine> {
        let line = Self::through(x, y)?;
        let last = x.len() - 1;
        let bound = |a: f64, b: f64| LINE_TOL * a.abs().max(b.abs()).max(1.0);
        let (tx, ty) = (
            bound(line.x0, x[last] as f64),
            bound(line.y0, y[last] as f64),
        );
        let mut on = true;
        for (j, (&x, &y)) in x.iter().zip(y).enumerate() {
            let j = j as i32 as f64;
            let (ex, ey) = (
                x as f64 - (line.x0 + j * line.dx),
                y as f64 - (line.y0 + j * line.dy),
            );
            on &= (ex.abs() <= tx) & (ey.abs() <= ty);
        }
        on.then_some(line)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_evenly_spaced_row_is_a_line_and_a_bent_or_broken_one_is_not() {
        let n = 100;
        let x: Vec<f32> = (0..n).map(|j| 3.0 + 0.5 * j as f32).collect();
        let y: Vec<f32> = (0..n).map(|j| -2.0 - 0.25 * j as f32).collect();
        let line = RowLine::of(&x, &y).expect("an evenly spaced row");
        assert_eq!(
            (line.x0, line.dx, line.y0, line.dy),
            (3.0, 0.5, -2.0, -0.25)
        );
        let moved = |k: usize, by: f32| {
            let mut x = x.clone();
            x[k] += by;
            RowLine::of(&x, &y)
        };
        // One vertex off by far more than rounding, anywhere in the row.
        assert_eq!(moved(37, 1e-3), None);
        assert_eq!(moved(1, -1e-3), None);
        // Off by less than the tolerance (a unit in the last place at 52.5).
        assert!(moved(99, 52.5f32.next_up() - 52.5).is_some());
        let mut nan = y.clone();
        nan[50] = f32::NAN;
        assert_eq!(RowLine::of(&x, &nan), None);
        let (ax, ay): (Vec<f32>, Vec<f32>) = (0..n)
            .map(|j| (j as f32 * 0.01).sin_cos())
            .map(|(s, c)| (50.0 * s, 50.0 * c))
            .unzip();
        assert_eq!(RowLine::of(&ax, &ay), None, "an arc");
        assert!(RowLine::through(&ax, &ay).is_some(), "taken on trust");
        assert_eq!(RowLine::of(&x[..1], &y[..1]), None, "one vertex");
        assert_eq!(RowLine::through(&x[..1], &y[..1]), None, "one vertex");
    }
}
