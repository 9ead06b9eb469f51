//! Vertex normals from face normals: the paper's original linear triangle lookup and the
//! precomputed neighbour list that replaced it (sections 4.3 and 5.1). Analytic normals are
//! computed by the kernel itself, from the same phases as the heights.

use super::mesh::{Grid, Mesh};
use glam::Vec3;

crate::named! {
    /// How vertex normals are computed each frame.
    pub enum NormalMethod {
        /// The paper's original: for every vertex, a linear search of the triangle list (O(n²)).
        Lookup,
        /// A neighbour list built once; face normals recomputed and averaged every frame.
        Neighbors,
        /// The partial derivatives of the wave equation (section 3.5).
        Analytic,
    }
}

/// Triangle-vertex tests one `lookup` frame may take: about a second of one core.
pub const LOOKUP_MAX_WORK: u64 = 600_000_000;

/// Largest N for which `lookup` stays under [`LOOKUP_MAX_WORK`].
pub fn lookup_max_size() -> usize {
    (2..=super::mesh::MAX_SIZE)
        .take_while(|&n| lookup_work(n) <= LOOKUP_MAX_WORK)
        .last()
        .unwrap_or(2)
}

/// Vertex × triangle tests of one `lookup` frame on an N×N grid.
pub fn lookup_work(n: usize) -> u64 {
    let n = n as u64;
    n * n * 2 * (n - 1) * (n - 1)
}

/// Per-frame state for the face-normal methods: the triangle list, the face normals of the
/// current frame and, for `neighbors`, each vertex's triangles.
#[derive(Clone, Debug)]
pub struct FaceNormals {
    triangles: Vec<[u32; 3]>,
    faces: Vec<Vec3>,
    /// Compressed rows: vertex v's triangles are `neighbor_tris[offsets[v]..offsets[v + 1]]`.
    offsets: Vec<u32>,
    neighbor_tris: Vec<u32>,
}

impl FaceNormals {
    /// Builds the triangle list and, once, the neighbour list (triangles in ascending order, the
    /// order `lookup` finds them in, so both methods sum the same faces in the same order).
    pub fn new(grid: Grid) -> Self {
        let triangles = grid.triangles();
        let v = grid.vertices();
        let mut counts = vec![0u32; v + 1];
        for tri in &triangles {
            for &idx in tri {
                counts[idx as usize + 1] += 1;
            }
        }
        for k in 1..counts.len() {
            counts[k] += counts[k - 1];
        }
        let offsets = counts.clone();
        let mut fill = counts;
        let mut neighbor_tris = vec![0u32; triangles.len() * 3];
        for (t, tri) in triangles.iter().enumerate() {
            for &idx in tri {
                let slot = &mut fill[idx as usize];
                neighbor_tris[*slot as usize] = t as u32;
                *slot += 1;
            }
        }
        FaceNormals {
            faces: vec![Vec3::ZERO; triangles.len()],
            triangles,
            offsets,
            neighbor_tris,
        }
    }

    /// Recomputes every face normal (unnormalised cross product, so larger faces weigh more),
    /// then each vertex normal with `method` (`Lookup` or `Neighbors`).
    pub fn compute(&mut self, mesh: &mut Mesh, method: NormalMethod) {
        let pos = |v: u32| {
            let v = v as usize;
            Vec3::new(mesh.x[v], mesh.y[v], mesh.z[v])
        };
        for (face, tri) in self.faces.iter_mut().zip(&self.triangles) {
            let (a, b, c) = (pos(tri[0]), pos(tri[1]), pos(tri[2]));
            *face = (b - a).cross(c - a);
        }
        for v in 0..mesh.z.len() {
            let sum = match method {
                NormalMethod::Lookup => self.lookup_sum(v as u32),
                NormalMethod::Neighbors => {
                    let range = self.offsets[v] as usize..self.offsets[v + 1] as usize;
                    self.neighbor_tris[range]
                        .iter()
                        .fold(Vec3::ZERO, |acc, &t| acc + self.faces[t as usize])
                }
                NormalMethod::Analytic => unreachable!("analytic normals come from the kernel"),
            };
            let n = sum.normalize_or(Vec3::Z);
            mesh.nx[v] = n.x;
            mesh.ny[v] = n.y;
            mesh.nz[v] = n.z;
        }
    }

    /// The paper's `LookupTriIndex`: scan the whole triangle list for the ones holding `v`.
    fn lookup_sum(&self, v: u32) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri[0] == v || tri[1] == v || tri[2] == v {
                sum += self.faces[t];
            }
        }
        sum
    }
}
