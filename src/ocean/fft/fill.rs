//! The mesh rows from the transforms' output rows: displaced positions, heights, the fold value
//! J and its direction, and the analytic normal. Two sources of the derivatives:
//!
//! - `reference`: the spectral ones, from four transforms;
//! - `fast`: slopes and the Jacobian's diagonal from central differences of the displaced
//!   surface (two transforms: heights and displacements, whose transform also carries
//!   ∂Dx/∂y, the Jacobian's off-diagonal, for free), as real-time oceans do.
//!
//! Each row is done a chunk of [`CHUNK`] columns at a time, in two passes over L1: the source's
//! derivatives into scratch, then the vertex values from them, both written branch-free over
//! the chunk so that they vectorise; the same IEEE operations run on every instruction set (no
//! fused multiply-add is formed), so helpers agree bit for bit whichever set each runs, and
//! any width of chunk gives the same bits.

use crate::isa;
use crate::ocean::mesh::MeshRows;
use rustfft::num_complex::Complex;
use std::ops::Range;

/// Where a band's derivatives come from: the column pass's output rows of each transform.
#[derive(Clone, Copy, Debug)]
pub enum Source<'a> {
    /// The four transforms' rows of the band: (h, ∂Dx/∂y·scale), (Dx, Dy), (∂h/∂x, ∂h/∂y),
    /// (∂Dx/∂x, ∂Dy/∂y).
    Spectral([&'a [Complex<f32>]; 4]),
    /// The first two transforms' rows of the band with the row above it first and the row
    /// below it last (wrapped around the patch).
    Differences([&'a [Complex<f32>]; 2]),
}

/// What the fill needs of the run: the grid and the surface's parameters.
#[derive(Clone, Copy, Debug)]
pub struct Fill {
    /// Vertices per side.
    pub n: usize,
    /// L ÷ N in metres.
    pub spacing: f32,
    /// λ, the choppiness.
    pub lambda: f32,
    /// 1 ÷ the packing scale of ∂Dx/∂y (a power of two, so exact).
    pub unscale: f32,
    /// Whether to write the analytic normal (otherwise face normals follow).
    pub analytic: bool,
    /// Columns of a row filled together ([`CHUNK`]; any other width gives the same bits).
    pub chunk: usize,
}

/// Columns of a row filled together: their derivatives (10 KiB) and a chunk of each mesh
/// array stay in L1 from the derivatives' loop to the outputs' loops, whatever the patch's
/// size. Whole rows of 2048² took more than twice as long a vertex as those of 512², whose
/// row was this long (results/bench-fft-scaling-20261129T164404Z).
pub const CHUNK: usize = 512;

/// Some columns of a row's derivatives: the Jacobian [[a, b], [b, d]] of
/// (x, y) ↦ (x + λDx, y + λDy) and the height's slopes.
struct Derivatives {
    a: Vec<f32>,
    b: Vec<f32>,
    d: Vec<f32>,
    sx: Vec<f32>,
    sy: Vec<f32>,
}

/// The first columns of [`Derivatives`], as the outputs' loops read them.
#[derive(Clone, Copy)]
struct DerivativeCols<'a> {
    a: &'a [f32],
    b: &'a [f32],
    d: &'a [f32],
    sx: &'a [f32],
    sy: &'a [f32],
}

impl Derivatives {
    /// The first `m` columns.
    #[inline(always)]
    fn first(&self, m: usize) -> DerivativeCols<'_> {
        DerivativeCols {
            a: &self.a[..m],
            b: &self.b[..m],
            d: &self.d[..m],
            sx: &self.sx[..m],
            sy: &self.sy[..m],
        }
    }
}

/// [`Fill::fill`]'s rows as a loop for [`isa::run_widest`].
struct FillRows<'a, 's, 'm> {
    fill: &'a Fill,
    source: Source<'s>,
    rows: &'a mut MeshRows<'m>,
    these: Range<usize>,
}

impl isa::Loop for FillRows<'_, '_, '_> {
    type Output = ();

    #[inline(always)]
    fn run(self) {
        self.fill.fill_rows(self.source, self.rows, self.these)
    }
}

impl Fill {
    /// Fills rows `these` of the band `rows` (indices within the band) from `source`, which
    /// starts at the first of them.
    pub fn fill(&self, source: Source<'_>, rows: &mut MeshRows<'_>, these: Range<usize>) {
        isa::run_widest(FillRows {
            fill: self,
            source,
            rows,
            these,
        })
    }

    #[inline(always)]
    fn fill_rows(&self, source: Source<'_>, rows: &mut MeshRows<'_>, these: Range<usize>) {
        let n = self.n;
        let w = self.chunk.min(n);
        let mut der = Derivatives {
            a: vec![0.0; w],
            b: vec![0.0; w],
            d: vec![0.0; w],
            sx: vec![0.0; w],
            sy: vec![0.0; w],
        };
        for (q, r) in these.enumerate() {
            let i = rows.first_row + r;
            for c in (0..n).step_by(w) {
                let cols = c..(c + w).min(n);
                let m = cols.len();
                let (hd, disp) = match source {
                    Source::Spectral([hd, disp, slope, dd]) => {
                        let u = q * n + c..q * n + c + m;
                        let (hd, disp) = (&hd[u.clone()], &disp[u.clone()]);
                        self.spectral(hd, &slope[u.clone()], &dd[u], &mut der);
                        (hd, disp)
                    }
                    Source::Differences([hd, disp]) => {
                        // Row q is row q + 1 of the source.
                        let hds = [0, 1, 2].map(|k| &hd[(q + k) * n..(q + k + 1) * n]);
                        let disps = [0, 1, 2].map(|k| &disp[(q + k) * n..(q + k + 1) * n]);
                        self.differences(hds, disps, cols.clone(), &mut der);
                        (&hds[1][cols.clone()], &disps[1][cols])
                    }
                };
                let [x, y, z, nx, ny, nz, fold, fold_dx, fold_dy] =
                    rows.outputs(r * n + c..r * n + c + m);
                self.positions(i, c, hd, disp, [x, y, z]);
                let der = der.first(m);
                folds(der, fold, fold_dx, fold_dy);
                if self.analytic {
                    normals(der, nx, ny, nz);
                }
            }
        }
    }

    /// The displaced positions and heights of row i from column `j0` on.
    #[inline(always)]
    fn positions(
        &self,
        i: usize,
        j0: usize,
        hd: &[Complex<f32>],
        disp: &[Complex<f32>],
        [x, y, z]: [&mut [f32]; 3],
    ) {
        let (s, lambda) = (self.spacing, self.lambda);
        let rest_y = i as f32 * s;
        for (j, ((x, y), (z, (hd, disp)))) in x
            .iter_mut()
            .zip(y.iter_mut())
            .zip(z.iter_mut().zip(hd.iter().zip(disp)))
            .enumerate()
        {
            // Through i32, which vectorises on every instruction set where usize's conversion
            // is a scalar instruction a vertex; the same value for any column below 2^24.
            *x = (j0 + j) as i32 as f32 * s + lambda * disp.re;
            *y = rest_y + lambda * disp.im;
            *z = hd.re;
        }
    }

    /// The spectral derivatives of some columns of a row, into `der`'s first entries.
    #[inline(always)]
    fn spectral(
        &self,
        hd: &[Complex<f32>],
        slope: &[Complex<f32>],
        dd: &[Complex<f32>],
        der: &mut Derivatives,
    ) {
        let (lambda, unscale) = (self.lambda, self.unscale);
        for j in 0..hd.len() {
            der.a[j] = 1.0 + lambda * dd[j].re;
            der.d[j] = 1.0 + lambda * dd[j].im;
            der.b[j] = lambda * hd[j].im * unscale;
            der.sx[j] = slope[j].re;
            der.sy[j] = slope[j].im;
        }
    }

    /// The derivatives of columns `cols` of one row, into `der`'s first entries, from central
    /// differences over two spacings: the rows above and below it and its own neighbours
    /// (wrapped: the patch tiles).
    #[inline(always)]
    fn differences(
        &self,
        hd: [&[Complex<f32>]; 3],
        disp: [&[Complex<f32>]; 3],
        cols: Range<usize>,
        der: &mut Derivatives,
    ) {
        let n = self.n;
        let (lambda, unscale) = (self.lambda, self.unscale);
        let inv = 1.0 / (2.0 * self.spacing);
        let [up, mid, down] = hd;
        let [dup, dmid, ddown] = disp;
        let c = cols.start;
        for j in cols.clone() {
            der.sy[j - c] = (down[j].re - up[j].re) * inv;
            der.d[j - c] = 1.0 + lambda * ((ddown[j].im - dup[j].im) * inv);
            der.b[j - c] = lambda * mid[j].im * unscale;
        }
        // The first and last vertices' neighbours wrap around the row.
        for (j, before, after) in [(0, n - 1, 1), (n - 1, n - 2, 0)] {
            if cols.contains(&j) {
                der.sx[j - c] = (mid[after].re - mid[before].re) * inv;
                der.a[j - c] = 1.0 + lambda * ((dmid[after].re - dmid[before].re) * inv);
            }
        }
        for j in cols.start.max(1)..cols.end.min(n - 1) {
            der.sx[j - c] = (mid[j + 1].re - mid[j - 1].re) * inv;
            der.a[j - c] = 1.0 + lambda * ((dmid[j + 1].re - dmid[j - 1].re) * inv);
        }
    }
}

/// J and the direction in which the surface compresses, at some columns of a row.
#[inline(always)]
fn folds(der: DerivativeCols<'_>, fold: &mut [f32], fold_dx: &mut [f32], fold_dy: &mut [f32]) {
    for j in 0..fold.len() {
        let (a, b, d) = (der.a[j], der.b[j], der.d[j]);
        fold[j] = a * d - b * b;
        let (x, y) = compressing_direction(a, b, d);
        fold_dx[j] = x;
        fold_dy[j] = y;
    }
}

/// The analytic normals at some columns of a row: the cross product of the displaced surface's
/// tangents (a, b, ∂h/∂x) and (b, d, ∂h/∂y), normalised; straight up where it has no length.
#[inline(always)]
fn normals(der: DerivativeCols<'_>, nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
    for j in 0..nx.len() {
        let (a, b, d, sx, sy) = (der.a[j], der.b[j], der.d[j], der.sx[j], der.sy[j]);
        let cx = b * sy - d * sx;
        let cy = sx * b - sy * a;
        let cz = a * d - b * b;
        let rcp = 1.0 / (cx * cx + cy * cy + cz * cz).sqrt();
        let ok = rcp.is_finite() && rcp > 0.0;
        nx[j] = if ok { cx * rcp } else { 0.0 };
        ny[j] = if ok { cy * rcp } else { 0.0 };
        nz[j] = if ok { cz * rcp } else { 1.0 };
    }
}

/// The unit eigenvector of the smaller eigenvalue of the symmetric [[a, b], [b, d]], the
/// direction in which the surface compresses; (0, 1) where every direction is one.
#[inline(always)]
pub fn compressing_direction(a: f32, b: f32, d: f32) -> (f32, f32) {
    let half = 0.5 * (a - d);
    let r = (half * half + b * b).sqrt();
    // Of the two rows of M − μI, μ = (a + d)/2 − r, the one with the larger diagonal entry
    // (h + r or r − h) gives the eigenvector without cancellation.
    let up = half >= 0.0;
    let x = if up { -b } else { r - half };
    let y = if up { half + r } else { -b };
    let len = (x * x + y * y).sqrt();
    let ok = len > 0.0;
    (
        if ok { x / len } else { 0.0 },
        if ok { y / len } else { 1.0 },
    )
}
