//! `neighbors` normals on the regular grid as a row-wise stencil.
//!
//! Each vertex's adjacent faces are a fixed pattern: of cell row i−1 the second triangle of
//! cell j−1 and both triangles of cell j, of cell row i both triangles of cell j−1 and the
//! first of cell j. So one row of face normals is computed once, reused by the two vertex rows
//! it touches, and summed with shifted contiguous loads instead of a gathered list. Faces and
//! sums use the same operations in the same order as `FaceNormals` (glam's cross product,
//! ascending triangle order, no fused multiply-add), so results match it to rounding.

use super::norm;
use super::simd::Isa;
use crate::ocean::mesh::Mesh;

/// Face normals of one row of cells, stored at column j + 1 for cell j so that index 0 and n
/// are zero padding for the missing cells at the left and right edges. Both triangles of a
/// cell share the z component dx·dy.
#[derive(Clone, Debug, Default)]
struct FaceRow {
    t1x: Vec<f32>,
    t1y: Vec<f32>,
    t2x: Vec<f32>,
    t2y: Vec<f32>,
    fz: Vec<f32>,
}

impl FaceRow {
    fn zeros(n: usize) -> FaceRow {
        let z = vec![0.0; n + 1];
        FaceRow {
            t1x: z.clone(),
            t1y: z.clone(),
            t2x: z.clone(),
            t2y: z.clone(),
            fz: z,
        }
    }

    fn clear(&mut self) {
        for v in [
            &mut self.t1x,
            &mut self.t1y,
            &mut self.t2x,
            &mut self.t2y,
            &mut self.fz,
        ] {
            v.fill(0.0);
        }
    }
}

/// The `neighbors` normal method for the fast kernel: same sums as `FaceNormals`, computed as a
/// stencil over two rolling rows of face normals.
#[derive(Clone, Debug)]
pub struct StencilNormals {
    isa: Isa,
    n: usize,
    prev: FaceRow,
    cur: FaceRow,
    /// x[j + 1] − x[j] of the mesh (exactly what the reference's b − a gives).
    dx: Vec<f32>,
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
            prev: FaceRow::default(),
            cur: FaceRow::default(),
            dx: Vec::new(),
        }
    }

    /// Recomputes every vertex normal of `mesh` from its current heights.
    pub fn compute(&mut self, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        if self.n != n {
            self.n = n;
            self.prev = FaceRow::zeros(n);
            self.cur = FaceRow::zeros(n);
        }
        self.dx.clear();
        self.dx.extend(mesh.x[..n].windows(2).map(|w| w[1] - w[0]));
        match self.isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `with_isa` checked the CPU supports `isa`.
            Isa::Avx512 => unsafe { compute_avx512(self, mesh) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Isa::Avx2 => unsafe { compute_avx2(self, mesh) },
            _ => compute_body::<false>(self, mesh),
        }
    }
}

impl Default for StencilNormals {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2")]
fn compute_avx512(s: &mut StencilNormals, mesh: &mut Mesh) {
    compute_body::<true>(s, mesh)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn compute_avx2(s: &mut StencilNormals, mesh: &mut Mesh) {
    compute_body::<false>(s, mesh)
}

/// `W` selects the AVX-512 normalisation (only instantiated inside `compute_avx512`).
#[inline(always)]
fn compute_body<const W: bool>(s: &mut StencilNormals, mesh: &mut Mesh) {
    let n = s.n;
    s.prev.clear();
    for i in 0..n {
        if i + 1 < n {
            let dy = mesh.y[(i + 1) * n] - mesh.y[i * n];
            let z0 = &mesh.z[i * n..(i + 1) * n];
            let z1 = &mesh.z[(i + 1) * n..(i + 2) * n];
            face_row(&mut s.cur, &s.dx, dy, z0, z1);
        } else {
            s.cur.clear();
        }
        let r = i * n..(i + 1) * n;
        let (nx, ny, nz) = (
            &mut mesh.nx[r.clone()],
            &mut mesh.ny[r.clone()],
            &mut mesh.nz[r],
        );
        vertex_row(&s.prev, &s.cur, nx, ny, nz);
        std::mem::swap(&mut s.prev, &mut s.cur);
        #[cfg(target_arch = "x86_64")]
        if W {
            // SAFETY: W is only set in `compute_avx512`, which runs on AVX-512 CPUs.
            unsafe { norm::sums_avx512(nx, ny, nz) };
            continue;
        }
        norm::sums(nx, ny, nz);
    }
}

/// Face normals of the cells between vertex rows z0 (y) and z1 (y + dy); triangle 1 is [a,b,c],
/// triangle 2 is [b,d,c] with a = z0[j], b = z0[j+1], c = z1[j], d = z1[j+1].
#[inline(always)]
fn face_row(f: &mut FaceRow, dx: &[f32], dy: f32, z0: &[f32], z1: &[f32]) {
    let m = dx.len();
    let (a, b, c, d) = (&z0[..m], &z0[1..m + 1], &z1[..m], &z1[1..m + 1]);
    let (t1x, t1y) = (&mut f.t1x[1..m + 1], &mut f.t1y[1..m + 1]);
    let (t2x, t2y, fz) = (
        &mut f.t2x[1..m + 1],
        &mut f.t2y[1..m + 1],
        &mut f.fz[1..m + 1],
    );
    for j in 0..m {
        let (ab, ac, bc, bd) = (b[j] - a[j], c[j] - a[j], c[j] - b[j], d[j] - b[j]);
        t1x[j] = -(dy * ab);
        t1y[j] = -(ac * dx[j]);
        t2x[j] = dy * bc - dy * bd;
        t2y[j] = bd * -dx[j];
        fz[j] = dx[j] * dy;
    }
}

/// Sums the six faces around each vertex of a row, in ascending triangle order.
#[inline(always)]
fn vertex_row(p: &FaceRow, c: &FaceRow, nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
    let n = nx.len();
    let (ny, nz) = (&mut ny[..n], &mut nz[..n]);
    let (p1x, p1y, p2x, p2y, pz) = (&p.t1x, &p.t1y, &p.t2x, &p.t2y, &p.fz);
    let (c1x, c1y, c2x, c2y, cz) = (&c.t1x, &c.t1y, &c.t2x, &c.t2y, &c.fz);
    let (p1x, p1y, p2x, p2y, pz) = (
        &p1x[..n + 1],
        &p1y[..n + 1],
        &p2x[..n + 1],
        &p2y[..n + 1],
        &pz[..n + 1],
    );
    let (c1x, c1y, c2x, c2y, cz) = (
        &c1x[..n + 1],
        &c1y[..n + 1],
        &c2x[..n + 1],
        &c2y[..n + 1],
        &cz[..n + 1],
    );
    for j in 0..n {
        let sx = p2x[j] + p1x[j + 1] + p2x[j + 1] + c1x[j] + c2x[j] + c1x[j + 1];
        let sy = p2y[j] + p1y[j + 1] + p2y[j + 1] + c1y[j] + c2y[j] + c1y[j + 1];
        nx[j] = sx;
        ny[j] = sy;
        nz[j] = pz[j] + pz[j + 1] + pz[j + 1] + cz[j] + cz[j] + cz[j + 1];
    }
}
