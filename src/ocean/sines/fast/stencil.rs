//! `neighbors` normals on the regular grid as a row-wise stencil, fused into one loop.
//!
//! Each vertex's adjacent faces are a fixed pattern: of cell row i−1 the second triangle of
//! cell j−1 and both triangles of cell j, of cell row i both triangles of cell j−1 and the
//! first of cell j. `FaceNormals` sums them in that (ascending triangle) order, so the first
//! three terms come from the cell row above and the last three from the cell row below.
//!
//! One loop over vector blocks of a vertex row computes the face normals of the cells below it
//! (from the two height rows), takes the cells one to the left from the previous block's
//! registers, adds the row's three terms to the three the row above left, normalises, and
//! stores the normals. It also leaves, for the next row, that row's first three terms: so of
//! the cell row between two vertex rows only two rolling rows of partial sums (x and y) ever
//! reach memory, and they stay in L1. The z terms depend on the spacing alone and are summed
//! once per distinct pair of row spacings.
//!
//! Faces and sums use the same operations in the same order as `FaceNormals` (glam's cross
//! product without fused multiply-add), so results match it to rounding.

use super::simd::{dispatch, ForIsa, Isa};
use super::vector::Vector;
use crate::ocean::mesh::{field, Field, Mesh};

/// The `neighbors` normal method for the fast kernel: same sums as `FaceNormals`, computed as a
/// stencil in one pass per vertex row.
#[derive(Clone, Debug)]
pub struct StencilNormals {
    isa: Isa,
    n: usize,
    /// For each vertex of the current row, x and y of its first three face terms (cell row
    /// above); 0 for the first row.
    above: [Field; 2],
    /// The same for the next row, written while the current row is summed.
    below: [Field; 2],
    /// −(x[c + 1] − x[c]) of each cell column c; 0 from the missing cell n − 1 on.
    ndx: Field,
    /// Each vertex's summed z terms for the row spacings in `zsum_for`.
    zsum: Field,
    /// Their squares, for the normalisation.
    zsum2: Field,
    /// Bits of the spacings (above, below) `zsum` was summed for.
    zsum_for: Option<(u32, u32)>,
}

impl StencilNormals {
    /// Stencil normals using the widest instruction set this CPU has.
    pub fn new() -> Self {
        Self::with_isa(Isa::detect())
    }

    /// Stencil normals forced to `isa`, which must be one of `Isa::available()`.
    pub fn with_isa(isa: Isa) -> Self {
        assert!(Isa::available().contains(&isa), "{isa:?} not supported");
        StencilNormals {
            isa,
            n: 0,
            above: [field(0, 0.0), field(0, 0.0)],
            below: [field(0, 0.0), field(0, 0.0)],
            ndx: field(0, 0.0),
            zsum: field(0, 0.0),
            zsum2: field(0, 0.0),
            zsum_for: None,
        }
    }

    /// Recomputes every vertex normal of `mesh` from its current heights.
    pub fn compute(&mut self, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        // Whole vectors of every width from any block start below n.
        let len = n.next_multiple_of(16);
        if self.n != n {
            self.n = n;
            // Scratch rows on cache lines as the mesh's are: the stencil streams them beside it.
            for v in self.above.iter_mut().chain(&mut self.below) {
                *v = field(len, 0.0);
            }
            self.zsum = field(len, 0.0);
            self.zsum2 = field(len, 0.0);
            self.ndx = field(len, 0.0);
        }
        let widths = mesh.x[..n].windows(2).map(|w| -(w[1] - w[0]));
        for (d, w) in self
            .ndx
            .iter_mut()
            .zip(widths.chain(std::iter::repeat(0.0)))
        {
            *d = w;
        }
        self.zsum_for = None;
        dispatch(self.isa, Compute { s: self, mesh });
    }

    /// Sums each vertex's six face z terms (cell width × row spacing) for spacings `above`
    /// and `below` (0 where that cell row is missing), unless they were summed last.
    fn sum_z(&mut self, above: f32, below: f32) {
        let key = (above.to_bits(), below.to_bits());
        if self.zsum_for == Some(key) {
            return;
        }
        self.zsum_for = Some(key);
        let left = std::iter::once(0.0).chain(self.ndx.iter().map(|d| -d));
        let right = self.ndx.iter().map(|d| -d);
        let sums = self.zsum.iter_mut().zip(self.zsum2.iter_mut());
        for ((z, z2), (l, r)) in sums.zip(left.zip(right)) {
            let (pl, pr, cl, cr) = (l * above, r * above, l * below, r * below);
            *z = pl + pr + pr + cl + cl + cr;
            *z2 = *z * *z;
        }
    }
}

impl Default for StencilNormals {
    fn default() -> Self {
        Self::new()
    }
}

/// `StencilNormals::compute` through `dispatch`.
struct Compute<'a> {
    s: &'a mut StencilNormals,
    mesh: &'a mut Mesh,
}

impl ForIsa for Compute<'_> {
    type Output = ();

    #[inline(always)]
    fn run<const F: bool, const K: usize, V: Vector>(self) {
        let Compute { s, mesh } = self;
        let n = s.n;
        let Mesh {
            y, z, nx, ny, nz, ..
        } = mesh;
        for v in &mut s.above {
            v.fill(0.0);
        }
        let spacing = |i: usize| y[(i + 1) * n] - y[i * n];
        for i in 0..n {
            let cells = i + 1 < n;
            let dy = if cells { spacing(i) } else { 0.0 };
            s.sum_z(if i > 0 { spacing(i - 1) } else { 0.0 }, dy);
            let (r, next) = (i * n..(i + 1) * n, (i + 1) * n..(i + 2).min(n + 1) * n);
            let [ax, ay] = &s.above;
            let [bx, by] = &mut s.below;
            let row = Row {
                z0: &z[r.clone()],
                z1: if cells { &z[next] } else { &z[r.clone()] },
                dy,
                ndx: &s.ndx,
                zsum: &s.zsum,
                zsum2: &s.zsum2,
                above: [ax, ay],
                below: [bx, by],
                out: [&mut nx[r.clone()], &mut ny[r.clone()], &mut nz[r]],
            };
            if cells {
                row_normals::<V, true>(row);
            } else {
                row_normals::<V, false>(row);
            }
            std::mem::swap(&mut s.above, &mut s.below);
        }
    }
}

/// One vertex row's inputs and outputs.
struct Row<'a> {
    /// Heights of the row.
    z0: &'a [f32],
    /// Heights of the next row (the row itself when there is none).
    z1: &'a [f32],
    /// Spacing to the next row.
    dy: f32,
    /// See `StencilNormals::ndx`.
    ndx: &'a [f32],
    /// See `StencilNormals::zsum`.
    zsum: &'a [f32],
    /// See `StencilNormals::zsum2`.
    zsum2: &'a [f32],
    /// See `StencilNormals::above`.
    above: [&'a [f32]; 2],
    /// See `StencilNormals::below`.
    below: [&'a mut [f32]; 2],
    /// The row's normals: x, y, z.
    out: [&'a mut [f32]; 3],
}

impl Row<'_> {
    /// `V` at `s[j..]`: unchecked in whole blocks, which `row_normals` keeps inside every array,
    /// so that the loop carries one index instead of a bounds check per access.
    #[inline(always)]
    fn get<V: Vector, const WHOLE: bool>(s: &[f32], j: usize) -> V {
        if WHOLE {
            debug_assert!(j + V::LANES <= s.len());
            // SAFETY: see above.
            unsafe { V::read(s.as_ptr().add(j)) }
        } else {
            V::load(&s[j..])
        }
    }

    /// Writes `v` to `s[j..]`, at most to the end of `s`; unchecked in whole blocks, as `get`.
    #[inline(always)]
    fn put<V: Vector, const WHOLE: bool>(v: V, s: &mut [f32], j: usize) {
        if WHOLE {
            debug_assert!(j + V::LANES <= s.len());
            // SAFETY: see `get`.
            unsafe { v.write(s.as_mut_ptr().add(j)) }
        } else {
            let end = (j + V::LANES).min(s.len());
            v.store_prefix(&mut s[j..end]);
        }
    }
}

/// Normals of one vertex row, `V::LANES` vertices a block; `CELLS` when there is a cell row
/// below it (every row but the last).
#[inline(always)]
fn row_normals<V: Vector, const CELLS: bool>(mut r: Row) {
    let (n, l) = (r.z0.len(), V::LANES);
    // What makes whole blocks' unchecked accesses safe: they end before n − 1 (heights are
    // read one past a block), and the scratch arrays are as long as the padded rows.
    assert!(r.z1.len() == n && r.out.iter().all(|o| o.len() == n));
    let scratch = [
        r.ndx,
        r.zsum,
        r.zsum2,
        r.above[0],
        r.above[1],
        &*r.below[0],
        &*r.below[1],
    ];
    assert!(scratch.iter().all(|s| s.len() >= n.next_multiple_of(l)));
    let mut left = [V::splat(0.0); 4];
    // Blocks whose faces need no height past the row's end, two at a time: one block's chain
    // from heights to stored normals is about 60 cycles of latency, more than the FP scheduler
    // can overlap with the next block's on its own. The rest go through padded buffers, kept
    // apart so that the whole blocks' registers do not spill around them.
    let whole = (n - 1) / l * l;
    let pairs = whole / (2 * l) * (2 * l);
    for j in (0..pairs).step_by(2 * l) {
        blocks::<V, CELLS, true, 2>(&mut r, j, &mut left);
    }
    for j in (pairs..whole).step_by(l) {
        blocks::<V, CELLS, true, 1>(&mut r, j, &mut left);
    }
    for j in (whole..n).step_by(l) {
        blocks::<V, CELLS, false, 1>(&mut r, j, &mut left);
    }
}

/// The normals of `U` consecutive blocks of vertices from j, their steps interleaved; `left`
/// holds the faces of the block before and receives the last block's. `WHOLE` when the blocks
/// end before the row's last vertex.
#[inline(always)]
fn blocks<V: Vector, const CELLS: bool, const WHOLE: bool, const U: usize>(
    r: &mut Row,
    j: usize,
    left: &mut [V; 4],
) {
    // Plain loops, no closures: a closure is compiled without the caller's target features,
    // and if it is not inlined every intrinsic in it becomes a call.
    let l = V::LANES;
    let zero = V::splat(0.0);
    let mut here = [[zero; 4]; U];
    if CELLS {
        for (u, faces_u) in here.iter_mut().enumerate() {
            *faces_u = faces::<V, WHOLE>(r, j + u * l);
        }
    }
    let mut shifted = [[zero; 4]; U];
    for u in 0..U {
        let before = if u == 0 { *left } else { here[u - 1] };
        for k in 0..4 {
            shifted[u][k] = here[u][k].shift_in(before[k]);
        }
    }
    *left = here[U - 1];
    let mut sums = [[zero; 4]; U];
    for u in 0..U {
        let ([l1x, l1y, l2x, l2y], [t1x, t1y, t2x, t2y]) = (shifted[u], here[u]);
        let j = j + u * l;
        let sx = Row::get::<V, WHOLE>(r.above[0], j) + l1x + l2x + t1x;
        let sy = Row::get::<V, WHOLE>(r.above[1], j) + l1y + l2y + t1y;
        if CELLS {
            Row::put::<V, WHOLE>(l2x + t1x + t2x, r.below[0], j);
            Row::put::<V, WHOLE>(l2y + t1y + t2y, r.below[1], j);
        }
        let get = Row::get::<V, WHOLE>;
        let (sz, zz) = (get(r.zsum, j), get(r.zsum2, j));
        sums[u] = [sx, sy, sz, zz];
    }
    let mut units = [[zero; 3]; U];
    for (unit, &[x, y, z, zz]) in units.iter_mut().zip(&sums) {
        *unit = V::unit(x, y, z, zz);
    }
    for (u, normal) in units.into_iter().enumerate() {
        for (c, out) in normal.into_iter().zip(&mut r.out) {
            Row::put::<V, WHOLE>(c, out, j + u * l);
        }
    }
}

/// x and y of both triangles' face normals (t1x, t1y, t2x, t2y) of cells j.. between height
/// rows z0 and z1: triangle 1 is [a,b,c], triangle 2 is [b,d,c] with a = z0[j], b = z0[j+1],
/// c = z1[j], d = z1[j+1]. Past the row's end (only when not `WHOLE`) the heights repeat the
/// last one, which with the zero cell width there makes every term of the missing cells 0.
#[inline(always)]
fn faces<V: Vector, const WHOLE: bool>(r: &Row, j: usize) -> [V; 4] {
    let n = r.z0.len();
    let (a, b, c, d) = if WHOLE {
        let get = Row::get::<V, WHOLE>;
        (
            get(r.z0, j),
            get(r.z0, j + 1),
            get(r.z1, j),
            get(r.z1, j + 1),
        )
    } else {
        let (p0, p1) = (r.z0[n - 1], r.z1[n - 1]);
        let (z0, z1) = (&r.z0[j..], &r.z1[j..]);
        let (a, b) = (V::load_padded(z0, p0), V::load_padded(&z0[1..], p0));
        (a, b, V::load_padded(z1, p1), V::load_padded(&z1[1..], p1))
    };
    let ndx = Row::get::<V, WHOLE>(r.ndx, j);
    let (dy, ndy) = (V::splat(r.dy), V::splat(-r.dy));
    let (ab, ac, bc, bd) = (b - a, c - a, c - b, d - b);
    // −(dy·ab) and −(ac·dx) of the cross product, with the sign moved onto a factor (exact).
    [ab * ndy, ac * ndx, dy * bc - dy * bd, bd * ndx]
}
