//! Procedural meshes (in canonical position, placed by a transform, as in
//! Mitsuba) and triangle-mesh loading from PLY and OBJ files.

use crate::Error;
use crate::math::Vec3;
use nalgebra::{Matrix4, Rotation3};
use std::f64::consts::{PI, TAU};
use std::path::Path;

/// An indexed triangle mesh in world space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals (empty: flat shading from the winding order).
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (empty: barycentric coordinates are used).
    pub uvs: Vec<[f64; 2]>,
    /// Counter-clockwise triangles (seen from the front), indices into the vertices.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Applies an affine transform (normals by the inverse transpose).
    pub fn transformed(mut self, m: &Matrix4<f64>) -> Self {
        let lin = m.fixed_view::<3, 3>(0, 0).into_owned();
        let normal_m = lin.try_inverse().map(|i| i.transpose()).unwrap_or(lin);
        let t = m.fixed_view::<3, 1>(0, 3).into_owned();
        self.positions.iter_mut().for_each(|p| *p = lin * *p + t);
        self.normals
            .iter_mut()
            .for_each(|n| *n = (normal_m * *n).normalize());
        if lin.determinant() < 0.0 {
            self.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        }
        self
    }
}

/// An affine transform `translate · rotate · scale` (rotation as Euler angles
/// in degrees applied about x, then y, then z).
pub fn transform(translate: [f64; 3], rotate_deg: [f64; 3], scale: [f64; 3]) -> Matrix4<f64> {
    let r = rotate_deg.map(f64::to_radians);
    let rot = Rotation3::from_axis_angle(&Vec3::z_axis(), r[2])
        * Rotation3::from_axis_angle(&Vec3::y_axis(), r[1])
        * Rotation3::from_axis_angle(&Vec3::x_axis(), r[0]);
    Matrix4::new_translation(&Vec3::from(translate))
        * rot.to_homogeneous()
        * Matrix4::new_nonuniform_scaling(&Vec3::from(scale))
}

/// The square `[-1, 1]²` in the plane `z = 0`, facing `+z` (Mitsuba's `rectangle`).
pub fn rectangle() -> TriangleMesh {
    let p = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    TriangleMesh {
        positions: p.iter().map(|[x, y]| Vec3::new(*x, *y, 0.0)).collect(),
        normals: vec![Vec3::z(); 4],
        uvs: p
            .iter()
            .map(|[x, y]| [0.5 * (x + 1.0), 0.5 * (y + 1.0)])
            .collect(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// The cube `[-1, 1]³` with outward-facing flat faces (Mitsuba's `cube`).
pub fn cube() -> TriangleMesh {
    let faces = [
        (Vec3::x_axis(), [0.0, 90.0, 0.0]),
        (-Vec3::x_axis(), [0.0, -90.0, 0.0]),
        (Vec3::y_axis(), [-90.0, 0.0, 0.0]),
        (-Vec3::y_axis(), [90.0, 0.0, 0.0]),
        (Vec3::z_axis(), [0.0, 0.0, 0.0]),
        (-Vec3::z_axis(), [0.0, 180.0, 0.0]),
    ];
    let meshes = faces
        .iter()
        .map(|(n, rot)| rectangle().transformed(&transform(n.into_inner().into(), *rot, [1.0; 3])));
    merge(meshes)
}

/// The unit disk in the plane `z = 0`, facing `+z`, as a fan of `segments` triangles.
pub fn disk(segments: u32) -> TriangleMesh {
    let mut positions = vec![Vec3::zeros()];
    positions.extend((0..segments).map(|i| {
        let phi = TAU * f64::from(i) / f64::from(segments);
        Vec3::new(phi.cos(), phi.sin(), 0.0)
    }));
    let triangles = (0..segments)
        .map(|i| [0, i + 1, (i + 1) % segments + 1])
        .collect();
    let uvs = positions
        .iter()
        .map(|p| [0.5 * (p.x + 1.0), 0.5 * (p.y + 1.0)])
        .collect();
    TriangleMesh {
        normals: vec![Vec3::z(); positions.len()],
        positions,
        uvs,
        triangles,
    }
}

/// Most `segments` a scene file may give a built-in shape: a 1024-segment sphere has 4 M
/// triangles (about 180 MB with its vertices), finer than any pixel of a 4K render needs,
/// while a larger count would let a few bytes of scene text exhaust memory (and `2 *
/// segments` overflow `u32`).
pub const MAX_SEGMENTS: u32 = 1024;

/// A smooth-shaded grid mesh over `(u, v) ∈ [0, 1]²` from a parametric surface
/// returning `(position, normal)`; `closed_u` joins the seam at `u = 1`.
fn parametric(nu: u32, nv: u32, f: impl Fn(f64, f64) -> (Vec3, Vec3)) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (f64::from(i) / f64::from(nu), f64::from(j) / f64::from(nv));
            let (p, n) = f(u, v);
            mesh.positions.push(p);
            mesh.normals.push(n);
            mesh.uvs.push([u, v]);
        }
    }
    let idx = |i: u32, j: u32| j * (nu + 1) + i;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            mesh.triangles.push([a, b, c]);
            mesh.triangles.push([a, c, d]);
        }
    }
    mesh
}

/// A torus around the z axis with tube radius `minor` (major radius 1), smooth normals.
pub fn torus(minor: f64, segments: u32) -> TriangleMesh {
    parametric(2 * segments, segments, |u, v| {
        let (phi, theta) = (TAU * u, TAU * v);
        let n = Vec3::new(
            theta.cos() * phi.cos(),
            theta.cos() * phi.sin(),
            theta.sin(),
        );
        let center = Vec3::new(phi.cos(), phi.sin(), 0.0);
        (center + minor * n, n)
    })
}

/// A unit sphere tessellated in latitude/longitude with smooth (exact) normals.
pub fn uv_sphere(segments: u32) -> TriangleMesh {
    parametric(2 * segments, segments, |u, v| {
        let (phi, theta) = (TAU * u, PI * v);
        let n = Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            -theta.cos(),
        );
        (n, n)
    })
}

/// A superquadric (superellipsoid) `|x|^(2/e2)+|y|^(2/e2))^(e2/e1) + |z|^(2/e1) = 1`
/// from its signed-power parametrisation (Barr 1981); smooth normals.
pub fn superquadric(e1: f64, e2: f64, segments: u32) -> TriangleMesh {
    let spow = |x: f64, e: f64| x.signum() * x.abs().powf(e);
    parametric(2 * segments, segments, |u, v| {
        let (phi, theta) = (TAU * u - PI, PI * v - 0.5 * PI);
        let (ct, st, cp, sp) = (theta.cos(), theta.sin(), phi.cos(), phi.sin());
        let p = Vec3::new(
            spow(ct, e1) * spow(cp, e2),
            spow(ct, e1) * spow(sp, e2),
            spow(st, e1),
        );
        let n = Vec3::new(
            spow(ct, 2.0 - e1) * spow(cp, 2.0 - e2),
            spow(ct, 2.0 - e1) * spow(sp, 2.0 - e2),
            spow(st, 2.0 - e1),
        );
        (p, n.try_normalize(1e-12).unwrap_or(p))
    })
}

/// Concatenates meshes.
pub fn merge(meshes: impl IntoIterator<Item = TriangleMesh>) -> TriangleMesh {
    let mut out = TriangleMesh::default();
    for m in meshes {
        let base = out.positions.len() as u32;
        out.triangles
            .extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
        out.positions.extend(m.positions);
        out.normals.extend(m.normals);
        out.uvs.extend(m.uvs);
    }
    out
}

/// Loads a triangle mesh from a `.ply` or `.obj` file (chosen by extension);
/// polygons are fan-triangulated.
pub fn load_mesh(path: &Path) -> Result<TriangleMesh, Error> {
    let fail = |reason: String| Error::Mesh {
        path: path.to_owned(),
        reason,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let mesh = match ext.as_deref() {
        Some("ply") => load_ply(path).map_err(fail)?,
        Some("obj") => load_obj(path).map_err(fail)?,
        _ => {
            return Err(fail(
                "unsupported mesh format (expected .ply or .obj)".into(),
            ));
        }
    };
    check_mesh(&mesh).map_err(fail)?;
    Ok(mesh)
}

/// Checks indices and that every coordinate is finite.
pub fn check_mesh(mesh: &TriangleMesh) -> Result<(), String> {
    let n = mesh.positions.len();
    if mesh.triangles.is_empty() {
        return Err("mesh has no triangles".into());
    }
    if let Some(t) = mesh
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(format!("triangle {t:?} indexes past the {n} vertices"));
    }
    if mesh
        .positions
        .iter()
        .chain(&mesh.normals)
        .any(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err("a vertex position or normal is not finite".into());
    }
    for (name, len) in [("normals", mesh.normals.len()), ("uvs", mesh.uvs.len())] {
        if len != 0 && len != n {
            return Err(format!("{len} {name} for {n} vertices"));
        }
    }
    Ok(())
}

fn fan(poly: &[u32]) -> impl Iterator<Item = [u32; 3]> + '_ {
    (1..poly.len().saturating_sub(1)).map(move |i| [poly[0], poly[i], poly[i + 1]])
}

fn load_ply(path: &Path) -> Result<TriangleMesh, String> {
    use ply_rs_bw::{parser::Parser, ply::DefaultElement, ply::Property};
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::BufReader::new(file))
        .map_err(|e| format!("PLY parse error: {e}"))?;
    let get =
        |v: &DefaultElement, k: &str| v.get(k).and_then(Property::to_f32_lossy).map(f64::from);
    let mut mesh = TriangleMesh::default();
    for v in ply.payload.get("vertex").ok_or("no `vertex` element")? {
        let p = [get(v, "x"), get(v, "y"), get(v, "z")];
        let [Some(x), Some(y), Some(z)] = p else {
            return Err("vertex without x, y, z".into());
        };
        mesh.positions.push(Vec3::new(x, y, z));
        if let (Some(nx), Some(ny), Some(nz)) = (get(v, "nx"), get(v, "ny"), get(v, "nz")) {
            mesh.normals.push(
                Vec3::new(nx, ny, nz)
                    .try_normalize(0.0)
                    .unwrap_or_else(Vec3::z),
            );
        }
        if let (Some(u), Some(w)) = (get(v, "u").or(get(v, "s")), get(v, "v").or(get(v, "t"))) {
            mesh.uvs.push([u, w]);
        }
    }
    for f in ply.payload.get("face").ok_or("no `face` element")? {
        let idx = f
            .get("vertex_indices")
            .or(f.get("vertex_index"))
            .and_then(Property::to_u32_list);
        mesh.triangles
            .extend(fan(&idx.ok_or("face without vertex_indices")?));
    }
    Ok(mesh)
}

fn load_obj(path: &Path) -> Result<TriangleMesh, String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _materials) =
        tobj::load_obj(path, &opts).map_err(|e| format!("OBJ load error: {e}"))?;
    let meshes = models.into_iter().map(|model| {
        let m = model.mesh;
        let v3 = |s: &[f32]| {
            s.chunks_exact(3)
                .map(|c| Vec3::new(c[0].into(), c[1].into(), c[2].into()))
                .collect()
        };
        TriangleMesh {
            positions: v3(&m.positions),
            normals: v3(&m.normals),
            uvs: m
                .texcoords
                .chunks_exact(2)
                .map(|c| [c[0].into(), c[1].into()])
                .collect(),
            triangles: m
                .indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        }
    });
    Ok(merge(meshes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_faces_point_outward() {
        let c = cube();
        for t in &c.triangles {
            let [a, b, d] = t.map(|i| c.positions[i as usize]);
            let n = (b - a).cross(&(d - a));
            let centroid = (a + b + d) / 3.0;
            assert!(n.dot(&centroid) > 0.0, "inward face {t:?}");
        }
        assert_eq!(c.triangles.len(), 12);
    }

    #[test]
    fn uv_sphere_winding_faces_outward() {
        let s = uv_sphere(8);
        let outward = s.triangles.iter().filter(|t| {
            let [a, b, d] = t.map(|i| s.positions[i as usize]);
            (b - a).cross(&(d - a)).dot(&(a + b + d)) > 0.0
        });
        // Triangles at the poles are degenerate (zero area); every other one faces outward.
        assert!(outward.count() >= s.triangles.len() - 2 * 16);
    }
}
