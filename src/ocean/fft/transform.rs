//! The inverse 2-D FFT of an N×N field in two passes that never transpose the whole field:
//! the row pass transforms a few rows at a time while they are in L1 and scatters them into
//! strips of [`STRIP`] columns, each strip contiguous; the column pass gathers a chunk of one
//! strip's columns (a small transpose inside the cache), transforms the columns as rows and
//! leaves them as rows of the output. Each pass streams the field through memory once, where a
//! whole-field transpose between two row passes streams it three times and, past the caches'
//! size, walks it at a stride of a row (results/fft-scaling-20261125T104608Z: 24 × the 512²
//! step at 2048² before this layout).
//!
//! rustfft does every length-N transform, planned once; its row and column transforms are the
//! same calls on the same values however the rows are grouped, so any split of the rows among
//! helpers gives the same bits.

use super::stream;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::ops::Range;
use std::sync::Arc;

/// Columns per strip: 8 complex f32 are one 64-byte cache line, so the row pass writes whole
/// lines and a strip of N rows (32 KiB at N = 512) transposes inside L1.
pub const STRIP: usize = 8;

/// One row's columns of one strip: a cache line, aligned so that the row pass writes whole
/// lines and never splits one across two.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub struct Line(pub [Complex<f32>; STRIP]);

/// The row pass's output for rows `b0..b0 + rows` of a field, strip by strip: strip s holds,
/// for each row, the row's columns s·STRIP.. (padded to STRIP) as one [`Line`], so a column
/// chunk is read from contiguous memory.
#[derive(Clone, Debug, Default)]
pub struct Strips {
    /// First row held.
    pub first: usize,
    /// Rows held.
    pub rows: usize,
    /// ceil(N / STRIP) strips of `rows` lines.
    pub lines: Vec<Line>,
    /// Whether the row pass writes the lines past the caches ([`stream::past_the_caches`]).
    pub streamed: bool,
}

impl Strips {
    /// Room for rows `rows` of an N-wide field.
    pub fn new(n: usize, rows: Range<usize>) -> Self {
        Strips {
            first: rows.start,
            rows: rows.len(),
            lines: vec![Line::default(); n.div_ceil(STRIP) * rows.len()],
            streamed: stream::past_the_caches(n),
        }
    }

    /// Whether row `b` is held here.
    fn holds(&self, b: usize) -> bool {
        (self.first..self.first + self.rows).contains(&b)
    }
}

/// An unnormalised inverse 2-D transform, `out[i][j] = Σ_a Σ_b in[b][a] e^{2πi(a·i + b·j)/N}`:
/// its input is laid out transposed (row b holds the coefficients of x-wavenumber index b), so
/// that the column pass's output rows are the output's rows.
#[derive(Clone)]
pub struct Inverse2d {
    n: usize,
    fft: Arc<dyn Fft<f32>>,
    scratch: Vec<Complex<f32>>,
}

impl std::fmt::Debug for Inverse2d {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Inverse2d").field("n", &self.n).finish()
    }
}

impl Inverse2d {
    /// Plans the length-`n` inverse transform once.
    pub fn new(n: usize) -> Self {
        let fft = FftPlanner::new().plan_fft_inverse(n);
        let scratch = vec![Complex::default(); fft.get_inplace_scratch_len()];
        Inverse2d { n, fft, scratch }
    }

    /// Transforms one whole field of N² values in place (layout: see [`Inverse2d`]).
    pub fn process(&mut self, field: &mut [Complex<f32>]) {
        let n = self.n;
        assert_eq!(field.len(), n * n, "an N×N field");
        let mut strips = Strips::new(n, 0..n);
        self.row_pass(field, 0, &mut strips);
        let every_row = 0..n;
        self.column_pass(&[&strips], std::slice::from_ref(&every_row), field);
    }

    /// The length-N transform of every row of `rows` in place: half of a 2-D transform.
    pub fn rows(&mut self, rows: &mut [Complex<f32>]) {
        self.fft.process_with_scratch(rows, &mut self.scratch);
    }

    /// Transforms `rows` (whole rows from row `first` on) in place and scatters them into
    /// `out`'s strips, which hold them.
    pub fn row_pass(&mut self, rows: &mut [Complex<f32>], first: usize, out: &mut Strips) {
        let n = self.n;
        self.rows(rows);
        for (r, row) in rows.chunks_exact(n).enumerate() {
            let b = first + r;
            debug_assert!(out.holds(b), "row {b} is not in these strips");
            let at = b - out.first;
            let whole = row.chunks_exact(STRIP);
            let rest = whole.remainder();
            for (s, columns) in whole.enumerate() {
                let line: &[Complex<f32>; STRIP] = columns.try_into().expect("a line");
                let to = &mut out.lines[s * out.rows + at];
                if out.streamed {
                    stream::line(&mut to.0, line);
                } else {
                    to.0 = *line;
                }
            }
            if !rest.is_empty() {
                out.lines[(n / STRIP) * out.rows + at].0[..rest.len()].copy_from_slice(rest);
            }
        }
        if out.streamed {
            stream::fence();
        }
    }

    /// The output rows `ranges` (in order, each row below N) into `out`, one after another:
    /// each row's column gathered from `parts`, which together hold every row of the row pass,
    /// then transformed.
    pub fn column_pass(
        &mut self,
        parts: &[&Strips],
        ranges: &[Range<usize>],
        out: &mut [Complex<f32>],
    ) {
        let n = self.n;
        let mut at = 0;
        for range in ranges {
            let mut i = range.start;
            while i < range.end {
                // The rest of the range within i's strip.
                let end = range.end.min((i / STRIP + 1) * STRIP);
                let chunk = &mut out[at * n..(at + end - i) * n];
                gather(parts, i..end, n, chunk);
                self.rows(chunk);
                at += end - i;
                i = end;
            }
        }
    }
}

/// Columns `columns` (within one strip) of every row the `parts` hold, as rows of `out`.
fn gather(parts: &[&Strips], columns: Range<usize>, n: usize, out: &mut [Complex<f32>]) {
    let s = columns.start / STRIP;
    let (w0, w1) = (columns.start % STRIP, columns.end - s * STRIP);
    for part in parts {
        let strip = &part.lines[s * part.rows..(s + 1) * part.rows];
        if (w0, w1) == (0, STRIP) {
            // A whole strip: eight rows at a time, an 8×8 block in registers, so that each
            // output row takes a whole line.
            let blocks = strip.chunks_exact(STRIP);
            let done = blocks.len() * STRIP;
            for (k, block) in blocks.enumerate() {
                let b = part.first + k * STRIP;
                for c in 0..STRIP {
                    let to: &mut [Complex<f32>; STRIP] = (&mut out[c * n + b..c * n + b + STRIP])
                        .try_into()
                        .expect("a line");
                    *to = std::array::from_fn(|r| block[r].0[c]);
                }
            }
            for (r, line) in strip.iter().enumerate().skip(done) {
                for (c, value) in line.0.iter().enumerate() {
                    out[c * n + part.first + r] = *value;
                }
            }
            continue;
        }
        for (r, line) in strip.iter().enumerate() {
            let b = part.first + r;
            for (c, value) in line.0[w0..w1].iter().enumerate() {
                out[c * n + b] = *value;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_coefficient_gives_one_plane_wave() {
        for n in [16, 30, 40] {
            let mut field = vec![Complex::default(); n * n];
            let (a, b) = (3, 5);
            field[b * n + a] = Complex::new(1.0, 0.0);
            Inverse2d::new(n).process(&mut field);
            for i in 0..n {
                for j in 0..n {
                    let angle = 2.0 * std::f64::consts::PI * (a * i + b * j) as f64 / n as f64;
                    let got = field[i * n + j];
                    assert!((got.re as f64 - angle.cos()).abs() < 1e-5, "({i}, {j})");
                    assert!((got.im as f64 - angle.sin()).abs() < 1e-5, "({i}, {j})");
                }
            }
        }
    }

    #[test]
    fn rows_and_columns_split_anyhow_give_the_same_bits() {
        let n = 40;
        let field: Vec<Complex<f32>> = (0..n * n)
            .map(|e| Complex::new((e as f32 * 0.37).sin(), (e as f32 * 0.11).cos()))
            .collect();
        let mut inverse = Inverse2d::new(n);
        let mut whole = field.clone();
        inverse.process(&mut whole);
        // Row passes in three parts, columns in odd ranges across strip edges.
        let parts: Vec<Strips> = [0..7, 7..29, 29..40]
            .into_iter()
            .map(|rows| {
                let mut strips = Strips::new(n, rows.clone());
                let mut mine = field[rows.start * n..rows.end * n].to_vec();
                inverse.row_pass(&mut mine, rows.start, &mut strips);
                strips
            })
            .collect();
        let parts: Vec<&Strips> = parts.iter().collect();
        let ranges = [39..40, 0..3, 3..21, 21..40, 0..1];
        let mut out = vec![Complex::default(); 42 * n];
        inverse.column_pass(&parts, &ranges, &mut out);
        assert!(out[..n] == whole[39 * n..]);
        assert!(out[n..41 * n] == whole[..]);
        assert!(out[41 * n..] == whole[..n]);
    }

    #[test]
    fn strips_streamed_past_the_caches_hold_the_same_bits() {
        // 40 is not a multiple of STRIP: the last strip's padded lines are written plainly.
        for n in [40, 64] {
            let field: Vec<Complex<f32>> = (0..n * n)
                .map(|e| Complex::new((e as f32 * 0.23).cos(), (e as f32 * 0.71).sin()))
                .collect();
            let mut inverse = Inverse2d::new(n);
            let pass = |inverse: &mut Inverse2d, streamed: bool| {
                let mut strips = Strips::new(n, 3..n);
                assert!(!strips.streamed, "a small field is not streamed by default");
                strips.streamed = streamed;
                inverse.row_pass(&mut field[3 * n..].to_vec(), 3, &mut strips);
                strips
            };
            let (cached, streamed) = (pass(&mut inverse, false), pass(&mut inverse, true));
            assert!(cached
                .lines
                .iter()
                .zip(&streamed.lines)
                .all(|(a, b)| a.0 == b.0));
            assert_eq!(cached.lines.len(), streamed.lines.len());
        }
        assert!(Strips::new(1024, 0..1).streamed);
    }
}
