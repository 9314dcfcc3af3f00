//! Triangle meshes of functional objects, for renderers that take meshes
//! (`quadray mesh`; the side-by-side with Mitsuba 3,
//! `scripts/mitsuba_side_by_side.py`).
//!
//! Surface nets (Gibson, "Constrained Elastic Surface Nets", 1998; the dual
//! of marching cubes): F' is sampled on a grid over the object's box padded
//! by a cell; every cell whose corners change sign holds one vertex, started
//! at the mean of its edges' linear crossings and then projected onto
//! F' = 0 by Newton steps along ∇F' (so vertices lie on the exact surface to
//! f64 rounding, not on a trilinear approximation of it); every grid edge
//! whose ends change sign joins the vertices of its four cells in a quad
//! (two triangles, wound so that their normal is the outward one, -∇F').
//! The clip box then cuts the triangles exactly (Sutherland–Hodgman), so the
//! mesh ends where the renderer's surface ends. Vertices carry the analytic
//! outward normal and the object's texture coordinates (duplicated along the
//! seam of the spherical and cylindrical mappings, where u wraps).
//!
//! What the mesh cannot keep: detail smaller than a cell (a perturbation
//! narrower than the grid spacing may vanish or join its neighbours), and
//! between vertices a flat triangle instead of the curved surface (the
//! chordal error falls as the square of the cell size).

use glam::{DAffine3, DVec2, DVec3};

use super::uv::{object_uv, UvMapping, UvSettings};
use super::{Aabb, FunctionalObject, GeometryError, Perturbation, Quadric};

/// An indexed triangle mesh with per-vertex normals and texture coordinates.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Unit outward normals at the vertices.
    pub normals: Vec<DVec3>,
    /// Texture coordinates at the vertices.
    pub uvs: Vec<DVec2>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// What a tessellation did, for the user and the tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshReport {
    /// Grid cells along each axis (the box padded by one cell each side).
    pub grid: [usize; 3],
    /// The grid spacing (object units).
    pub spacing: f64,
    /// The largest first-order distance |F'| / |∇F'| of a vertex from the
    /// surface after the Newton steps (object units).
    pub max_distance: f64,
    /// Vertices whose Newton steps did not converge near their cell (kept
    /// at the mean of their cell's edge crossings).
    pub unconverged: usize,
}

/// Grid points at most this many (memory: 4 bytes each).
pub const MAX_GRID_POINTS: usize = 300_000_000;

/// Why an object cannot be tessellated.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The object itself is not renderable.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// The grid would be too large.
    #[error("a grid of {cells} cells along the longest side needs {points} grid points, more than {MAX_GRID_POINTS}: use fewer cells")]
    TooFine {
        /// The cells asked for.
        cells: usize,
        /// The grid points they need.
        points: usize,
    },
}

/// F' restricted to the perturbations that can be non-zero in a region.
struct Local<'a> {
    base: &'a Quadric,
    perturbations: Vec<&'a Perturbation>,
}

impl Local<'_> {
    fn eval(&self, p: DVec3) -> f64 {
        self.base.eval(p) + self.perturbations.iter().map(|t| t.eval(p)).sum::<f64>()
    }

    fn gradient(&self, p: DVec3) -> DVec3 {
        self.perturbations.iter().fold(self.base.gradient(p), |g, t| g + t.gradient(p))
    }
}

/// The perturbations of `object` whose support meets `region`.
fn local<'a>(object: &'a FunctionalObject, region: &Aabb) -> Local<'a> {
    let perturbations = object
        .perturbations
        .iter()
        .filter(|t| match t.quadric.support_bounds() {
            None => true,
            Some(None) => false,
            Some(Some(b)) => b.overlaps(region),
        })
        .collect();
    Local { base: &object.base, perturbations }
}

/// The grid over an object's box: `n` cells per axis of side `h` from `origin`.
struct Grid {
    origin: DVec3,
    h: f64,
    n: [usize; 3],
}

impl Grid {
    fn point(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.h
    }
    fn point_index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * (self.n[1] + 1) + j) * (self.n[0] + 1) + i
    }
    fn cell_index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.n[1] + j) * self.n[0] + i
    }
    /// The slab of cells k (z from cell k to k + 1), widened by `pad` cells.
    fn slab(&self, k: usize, pad: f64) -> Aabb {
        let lo = self.point(0, 0, k) - DVec3::splat(pad * self.h);
        let hi = self.point(self.n[0], self.n[1], k + 1) + DVec3::splat(pad * self.h);
        Aabb::new(lo, hi)
    }
}

/// Tessellates `object` with about `cells` grid cells along its box's
/// longest side, in the object's frame, with texture coordinates from `uv`.
pub fn tessellate(object: &FunctionalObject, uv: &UvSettings, cells: usize) -> Result<(Mesh, MeshReport), MeshError> {
    let bounds = object.bounds()?;
    let size = bounds.size();
    let h = size.max_element() / cells.max(1) as f64;
    let n = [0, 1, 2].map(|a| ((size[a] / h).ceil() as usize).max(1) + 2);
    let extent = DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64) * h;
    let grid = Grid { origin: bounds.centre() - extent / 2.0, h, n };
    let points = (n[0] + 1) * (n[1] + 1) * (n[2] + 1);
    if points > MAX_GRID_POINTS {
        return Err(MeshError::TooFine { cells, points });
    }

    // F' at every grid point, a z-slab of points per task, each with the
    // perturbations that reach it.
    // f32 is enough for the signs and the first guess of each vertex (the
    // Newton steps then run in f64).
    let mut values = vec![0.0f32; points];
    let plane = (n[0] + 1) * (n[1] + 1);
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get()).min(n[2] + 1);
    let per_thread = (n[2] + 1).div_ceil(threads);
    std::thread::scope(|scope| {
        for (chunk, out) in values.chunks_mut(plane * per_thread).enumerate() {
            let grid = &grid;
            scope.spawn(move || {
                for (dk, slab) in out.chunks_mut(plane).enumerate() {
                    let k = chunk * per_thread + dk;
                    let f = local(object, &grid.slab(k.min(grid.n[2] - 1), 1.0));
                    for j in 0..=grid.n[1] {
                        for i in 0..=grid.n[0] {
                            slab[j * (grid.n[0] + 1) + i] = f.eval(grid.point(i, j, k)) as f32;
                        }
                    }
                }
            });
        }
    });
    let inside = |i: usize, j: usize, k: usize| values[grid.point_index(i, j, k)] >= 0.0;

    // One vertex per cell that the surface crosses.
    let mut mesh = Mesh::default();
    let mut report = MeshReport { grid: n, spacing: h, ..MeshReport::default() };
    let mut vertex_of = std::collections::HashMap::new();
    const CORNERS: [[usize; 3]; 8] =
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1], [1, 1, 1]];
    const EDGES: [[usize; 2]; 12] =
        [[0, 1], [2, 3], [4, 5], [6, 7], [0, 2], [1, 3], [4, 6], [5, 7], [0, 4], [1, 5], [2, 6], [3, 7]];
    for k in 0..n[2] {
        let f = local(object, &grid.slab(k, 2.0));
        for j in 0..n[1] {
            for i in 0..n[0] {
                let corner = CORNERS.map(|[a, b, c]| (i + a, j + b, k + c));
                let value = corner.map(|(a, b, c)| f64::from(values[grid.point_index(a, b, c)]));
                let signs = value.iter().filter(|v| **v >= 0.0).count();
                if signs == 0 || signs == 8 {
                    continue;
                }
                let (mut sum, mut count) = (DVec3::ZERO, 0.0);
                for [a, b] in EDGES {
                    if (value[a] >= 0.0) != (value[b] >= 0.0) {
                        let t = value[a] / (value[a] - value[b]);
                        let (pa, pb) = (
                            grid.point(corner[a].0, corner[a].1, corner[a].2),
                            grid.point(corner[b].0, corner[b].1, corner[b].2),
                        );
                        sum += pa + (pb - pa) * t;
                        count += 1.0;
                    }
                }
                let start = sum / count;
                let (p, converged) = project(&f, start, 2.0 * h);
                if !converged {
                    report.unconverged += 1;
                }
                let g = f.gradient(p);
                if g.length() > 0.0 {
                    report.max_distance = report.max_distance.max(f.eval(p).abs() / g.length());
                }
                vertex_of.insert(grid.cell_index(i, j, k), mesh.positions.len() as u32);
                mesh.positions.push(p);
                mesh.normals.push((-g).normalize_or_zero());
            }
        }
    }

    // A quad for every grid edge the surface crosses, between the vertices
    // of the four cells around it.
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                for axis in 0..3 {
                    let end = match axis {
                        0 if i < n[0] => (i + 1, j, k),
                        1 if j < n[1] => (i, j + 1, k),
                        2 if k < n[2] => (i, j, k + 1),
                        _ => continue,
                    };
                    if inside(i, j, k) == inside(end.0, end.1, end.2) {
                        continue;
                    }
                    // The two other axes: the four cells share this edge.
                    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                    let at = [i, j, k];
                    if at[u] == 0 || at[v] == 0 || at[u] > n[u] - 1 || at[v] > n[v] - 1 {
                        continue;
                    }
                    let cell = |du: usize, dv: usize| {
                        let mut c = at;
                        c[u] -= 1 - du;
                        c[v] -= 1 - dv;
                        vertex_of[&grid.cell_index(c[0], c[1], c[2])]
                    };
                    let quad = [cell(0, 0), cell(1, 0), cell(1, 1), cell(0, 1)];
                    for tri in [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]] {
                        mesh.triangles.push(outward(&mesh, tri));
                    }
                }
            }
        }
    }

    if let Some(clip) = object.clip {
        clip_to_box(&mut mesh, &clip, object);
    }
    mesh.drop_unused_vertices();
    mesh.uvs = mesh.positions.iter().map(|p| object_uv(uv, *p).0).collect();
    if let UvMapping::Spherical | UvMapping::Cylindrical = uv.mapping {
        split_seam(&mut mesh, uv.scale.x.abs());
    }
    Ok((mesh, report))
}

/// Newton steps from `start` onto F' = 0 along ∇F'; false (and `start`)
/// when they leave the ball of radius `reach` around it or do not settle.
fn project(f: &Local, start: DVec3, reach: f64) -> (DVec3, bool) {
    let mut p = start;
    for _ in 0..16 {
        let g = f.gradient(p);
        let g2 = g.length_squared();
        if g2 == 0.0 {
            return (start, false);
        }
        let step = g * (f.eval(p) / g2);
        p -= step;
        if !p.is_finite() || p.distance(start) > reach {
            return (start, false);
        }
        // Settled: the step is below f64's resolution at p (or a 1e-13 of
        // the cell's reach, whichever is larger).
        if step.length() <= (1e-13 * reach).max(4.0 * f64::EPSILON * p.abs().max_element()) {
            return (p, true);
        }
    }
    (start, false)
}

/// The triangle wound so that its geometric normal agrees with the mean of
/// its vertices' outward normals.
fn outward(mesh: &Mesh, [a, b, c]: [u32; 3]) -> [u32; 3] {
    let p = |i: u32| mesh.positions[i as usize];
    let geometric = (p(b) - p(a)).cross(p(c) - p(a));
    let normal = mesh.normals[a as usize] + mesh.normals[b as usize] + mesh.normals[c as usize];
    if geometric.dot(normal) >= 0.0 {
        [a, b, c]
    } else {
        [a, c, b]
    }
}

/// Cuts every triangle to the box (Sutherland–Hodgman on its six planes);
/// the new vertices get the analytic normal where they lie.
fn clip_to_box(mesh: &mut Mesh, clip: &Aabb, object: &FunctionalObject) {
    let triangles = std::mem::take(&mut mesh.triangles);
    // A cut point, computed from the edge's ends in one order, is one vertex
    // for both triangles on the edge (so the cut leaves no crack).
    let mut cuts: std::collections::HashMap<[u64; 3], u32> = std::collections::HashMap::new();
    for tri in triangles {
        let corners = tri.map(|i| mesh.positions[i as usize]);
        if corners.iter().all(|p| clip.contains(*p)) {
            mesh.triangles.push(tri);
            continue;
        }
        let mut polygon: Vec<DVec3> = corners.to_vec();
        for axis in 0..3 {
            for (bound, keep_below) in [(clip.max[axis], true), (clip.min[axis], false)] {
                let inside = |p: &DVec3| if keep_below { p[axis] <= bound } else { p[axis] >= bound };
                let mut out = Vec::new();
                for (idx, p) in polygon.iter().enumerate() {
                    let q = polygon[(idx + 1) % polygon.len()];
                    if inside(p) {
                        out.push(*p);
                    }
                    if inside(p) != inside(&q) {
                        // From the lexicographically smaller end, so that
                        // both triangles on the edge get the same point.
                        let (a, b) = if p.to_array() < q.to_array() { (*p, q) } else { (q, *p) };
                        let t = (bound - a[axis]) / (b[axis] - a[axis]);
                        let mut x = a + (b - a) * t;
                        x[axis] = bound;
                        out.push(x);
                    }
                }
                polygon = out;
                if polygon.is_empty() {
                    break;
                }
            }
        }
        if polygon.len() < 3 {
            continue;
        }
        // Corners of the original triangle keep their index; new points
        // become vertices.
        let mut index: Vec<u32> = polygon
            .iter()
            .map(|p| match corners.iter().position(|c| c == p) {
                Some(at) => tri[at],
                None => *cuts.entry(p.to_array().map(f64::to_bits)).or_insert_with(|| {
                    mesh.positions.push(*p);
                    mesh.normals.push(object.normal(*p));
                    (mesh.positions.len() - 1) as u32
                }),
            })
            .collect();
        // A corner on a plane gives the same point twice: one vertex.
        index.dedup();
        if index.len() > 1 && index[0] == index[index.len() - 1] {
            index.pop();
        }
        if index.len() < 3 {
            continue;
        }
        for w in 1..index.len() - 1 {
            mesh.triangles.push([index[0], index[w], index[w + 1]]);
        }
    }
}

/// Along the seam of a wrapping mapping (u jumps by `period`), the
/// triangles that straddle it get copies of their low-u vertices shifted by
/// one period, so that u runs continuously across each triangle. A vertex
/// on the mapping's axis (the poles, where u is undefined) gets, in each
/// triangle, a copy with the mean u of the triangle's other two.
fn split_seam(mesh: &mut Mesh, period: f64) {
    if period == 0.0 {
        return;
    }
    let scale = mesh.positions.iter().map(|p| p.length()).fold(0.0, f64::max);
    let on_axis = |p: DVec3| (p.x * p.x + p.z * p.z).sqrt() <= 1e-9 * scale;
    let mut shifted = std::collections::HashMap::new();
    for t in 0..mesh.triangles.len() {
        let tri = mesh.triangles[t];
        // A vertex on the axis has no u of its own (it gets one below).
        let off_axis: Vec<f64> =
            tri.iter().filter(|&&i| !on_axis(mesh.positions[i as usize])).map(|&i| mesh.uvs[i as usize].x).collect();
        let high = off_axis.iter().copied().fold(f64::MIN, f64::max);
        let low = off_axis.iter().copied().fold(f64::MAX, f64::min);
        if high - low > 0.5 * period {
            mesh.triangles[t] = tri.map(|i| {
                if high - mesh.uvs[i as usize].x <= 0.5 * period || on_axis(mesh.positions[i as usize]) {
                    return i;
                }
                *shifted.entry(i).or_insert_with(|| {
                    let at = i as usize;
                    mesh.positions.push(mesh.positions[at]);
                    mesh.normals.push(mesh.normals[at]);
                    mesh.uvs.push(mesh.uvs[at] + DVec2::new(period, 0.0));
                    (mesh.positions.len() - 1) as u32
                })
            });
        }
        let tri = mesh.triangles[t];
        if let Some(k) = (0..3).find(|&k| on_axis(mesh.positions[tri[k] as usize])) {
            let others = [tri[(k + 1) % 3], tri[(k + 2) % 3]];
            let u = 0.5 * (mesh.uvs[others[0] as usize].x + mesh.uvs[others[1] as usize].x);
            let at = tri[k] as usize;
            mesh.positions.push(mesh.positions[at]);
            mesh.normals.push(mesh.normals[at]);
            mesh.uvs.push(DVec2::new(u, mesh.uvs[at].y));
            mesh.triangles[t][k] = (mesh.positions.len() - 1) as u32;
        }
    }
}

impl Mesh {
    /// Removes the vertices no triangle uses (those the clip box cut away),
    /// renumbering the triangles.
    fn drop_unused_vertices(&mut self) {
        let mut new_index = vec![u32::MAX; self.positions.len()];
        let mut kept = 0u32;
        for t in &mut self.triangles {
            for i in t.iter_mut() {
                if new_index[*i as usize] == u32::MAX {
                    new_index[*i as usize] = kept;
                    kept += 1;
                }
                *i = new_index[*i as usize];
            }
        }
        let mut positions = vec![DVec3::ZERO; kept as usize];
        let mut normals = vec![DVec3::ZERO; kept as usize];
        for (old, &new) in new_index.iter().enumerate() {
            if new != u32::MAX {
                positions[new as usize] = self.positions[old];
                normals[new as usize] = self.normals[old];
            }
        }
        self.positions = positions;
        self.normals = normals;
    }

    /// The mesh in world space: positions by `transform`, normals by its
    /// inverse transpose.
    pub fn transformed(&self, transform: &DAffine3) -> Mesh {
        let normal_map = transform.matrix3.inverse().transpose();
        Mesh {
            positions: self.positions.iter().map(|p| transform.transform_point3(*p)).collect(),
            normals: self.normals.iter().map(|n| (normal_map * *n).normalize_or_zero()).collect(),
            uvs: self.uvs.clone(),
            triangles: self.triangles.clone(),
        }
    }

    /// The total area of the triangles.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| self.positions[i as usize]);
                0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
            })
            .sum()
    }

    /// The mesh as a binary little-endian PLY file: float x, y, z, nx, ny,
    /// nz, u, v per vertex; a list of int indices per face.
    pub fn to_ply(&self) -> Vec<u8> {
        let header = format!(
            "ply\nformat binary_little_endian 1.0\ncomment quadray mesh (surface nets of F' = 0)\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.positions.len(),
            self.triangles.len()
        );
        let mut out = header.into_bytes();
        for ((p, n), uv) in self.positions.iter().zip(&self.normals).zip(&self.uvs) {
            for x in [p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y] {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        for t in &self.triangles {
            out.push(3);
            for i in t {
                out.extend_from_slice(&(*i as i32).to_le_bytes());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(r: f64) -> FunctionalObject {
        FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(r)), perturbations: vec![], clip: None }
    }

    #[test]
    fn a_sphere_s_vertices_lie_on_it_and_its_area_converges() {
        let (mesh, report) = tessellate(&sphere(1.0), &UvSettings::default(), 64).unwrap();
        assert_eq!(report.unconverged, 0);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!((p.length() - 1.0).abs() < 1e-12, "{p}");
            assert!(n.dot(*p) > 0.999, "the normal points out");
        }
        for t in &mesh.triangles {
            let p = t.map(|i| mesh.positions[i as usize]);
            let geometric = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(geometric.dot(p[0]) > 0.0, "wound outward");
        }
        // Flat triangles under the sphere: the area falls short by the
        // chordal error, O(h²).
        let area = mesh.area();
        let exact = 4.0 * std::f64::consts::PI;
        assert!(area < exact && area > exact * 0.995, "area {area} against {exact}");
        let (finer, _) = tessellate(&sphere(1.0), &UvSettings::default(), 128).unwrap();
        assert!((exact - finer.area()) < 0.5 * (exact - area), "the error falls with the cell size");
    }

    #[test]
    fn a_closed_surface_is_watertight() {
        let (mesh, _) = tessellate(
            &sphere(0.7),
            &UvSettings { mapping: UvMapping::Planar { u_axis: DVec3::X, v_axis: DVec3::Y }, ..UvSettings::default() },
            40,
        )
        .unwrap();
        let mut edges = std::collections::HashMap::new();
        for t in &mesh.triangles {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&c| c == 2), "every edge between two triangles");
    }

    #[test]
    fn the_clip_box_cuts_exactly() {
        // The plane y = 0 clipped to a 3 x 2 rectangle: the mesh is that
        // rectangle, to rounding.
        let plane = FunctionalObject {
            base: Quadric { a: glam::DMat3::ZERO, b: DVec3::Y, c: 0.0 },
            perturbations: vec![],
            clip: Some(Aabb::new(DVec3::new(-1.0, -0.01, -0.5), DVec3::new(2.0, 0.01, 1.5))),
        };
        let (mesh, _) = tessellate(&plane, &UvSettings::default(), 32).unwrap();
        assert!((mesh.area() - 6.0).abs() < 1e-9, "area {}", mesh.area());
        let clip = plane.clip.unwrap();
        assert!(mesh.positions.iter().all(|p| clip.padded(1e-12).contains(*p) && p.y.abs() < 1e-12));
    }

    #[test]
    fn a_perturbation_s_bump_is_followed() {
        let bump = Perturbation {
            quadric: Quadric::ellipsoid(DVec3::new(0.0, 1.0, 0.0), DVec3::splat(0.4)),
            form_factor: 8.0,
        };
        let object = FunctionalObject {
            base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE),
            perturbations: vec![bump],
            clip: None,
        };
        let (mesh, report) = tessellate(&object, &UvSettings::default(), 96).unwrap();
        assert_eq!(report.unconverged, 0);
        assert!(report.max_distance < 1e-9, "{report:?}");
        for p in &mesh.positions {
            let g = object.gradient(*p);
            assert!(object.eval(*p).abs() / g.length() < 1e-9);
        }
        let top = mesh.positions.iter().map(|p| p.y).fold(f64::MIN, f64::max);
        assert!(top > 1.05, "the bump rises above the sphere: {top}");
    }

    #[test]
    fn a_clipped_surface_has_no_cracks() {
        // A sphere cut by the plane y = 0.3: every edge is shared by two
        // triangles but those of the cut, which lie on the plane.
        let mut object = sphere(1.0);
        object.clip = Some(Aabb::new(DVec3::splat(-2.0), DVec3::new(2.0, 0.3, 2.0)));
        // A planar mapping: no seam copies, so shared edges share indices.
        let planar =
            UvSettings { mapping: UvMapping::Planar { u_axis: DVec3::X, v_axis: DVec3::Z }, ..UvSettings::default() };
        let (mesh, _) = tessellate(&object, &planar, 40).unwrap();
        let mut edges = std::collections::HashMap::new();
        for t in &mesh.triangles {
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "a degenerate triangle {t:?}");
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut cut = 0;
        for ((a, b), count) in edges {
            if count == 1 {
                cut += 1;
                for v in [a, b] {
                    assert_eq!(mesh.positions[v as usize].y, 0.3, "an open edge off the cut");
                }
            } else {
                assert_eq!(count, 2);
            }
        }
        assert!(cut > 40, "the cut's edges: {cut}");
    }

    #[test]
    fn the_seam_of_a_spherical_mapping_is_split() {
        // 49 cells: vertices on the axis (the poles); 48: none.
        for cells in [48, 49] {
            seam_split_with(cells);
        }
    }

    fn seam_split_with(cells: usize) {
        let uv = UvSettings { mapping: UvMapping::Spherical, scale: DVec2::new(4.0, 2.0), offset: DVec2::ZERO };
        let (mesh, report) = tessellate(&sphere(1.0), &uv, cells).unwrap();
        // Within two cells of the axis (the mapping's singularity at the
        // poles, where u turns through a whole period around a point) a
        // triangle may span any u; elsewhere a fraction of a period.
        let near_pole = |p: DVec3| (p.x * p.x + p.z * p.z).sqrt() < 2.0 * report.spacing;
        let mut pole_area = 0.0;
        let mut seam_crossings = 0;
        for t in &mesh.triangles {
            let p = t.map(|i| mesh.positions[i as usize]);
            if p.iter().any(|p| near_pole(*p)) {
                pole_area += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                continue;
            }
            let us = t.map(|i| mesh.uvs[i as usize].x);
            let span = us.iter().copied().fold(f64::MIN, f64::max) - us.iter().copied().fold(f64::MAX, f64::min);
            assert!(span < 0.5, "u spans {span} of a period of 4 across one triangle");
            seam_crossings += usize::from(us.iter().any(|u| *u > 4.0));
        }
        assert!(seam_crossings > 10, "the seam's triangles were shifted by a period: {seam_crossings}");
        // A vertex on the axis takes, in each triangle, the mean u of the
        // other two.
        for t in &mesh.triangles {
            for k in 0..3 {
                let p = mesh.positions[t[k] as usize];
                if p.x.hypot(p.z) <= 1e-9 {
                    let others = [t[(k + 1) % 3], t[(k + 2) % 3]].map(|i| mesh.uvs[i as usize].x);
                    assert!((mesh.uvs[t[k] as usize].x - 0.5 * (others[0] + others[1])).abs() < 1e-12);
                }
            }
        }
        assert!(pole_area < 0.01 * mesh.area(), "the poles' triangles are {pole_area} of {}", mesh.area());
    }

    #[test]
    fn ply_has_the_header_and_the_sizes() {
        let (mesh, _) = tessellate(&sphere(1.0), &UvSettings::default(), 8).unwrap();
        let ply = mesh.to_ply();
        let text = String::from_utf8_lossy(&ply[..200]);
        assert!(text.starts_with("ply\nformat binary_little_endian 1.0\n"));
        let header_end = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        assert_eq!(ply.len() - header_end, mesh.positions.len() * 32 + mesh.triangles.len() * 13);
    }
}
