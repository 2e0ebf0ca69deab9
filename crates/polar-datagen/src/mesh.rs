//! Procedural meshes the renderer does not offer: bumpy blobs and extruded star polygons.
//! Both fit in the unit ball (bounding radius <= 1) so that a uniform scale sets their size.

use polar_render::TriangleMesh;
use polar_render::Vec3;
use std::f64::consts::PI;

/// A sphere with smooth radial bumps, r(n) = (1 + a g(n)) / (1 + a) with
/// g(n) = sin(f n_x + p_0) sin(f n_y + p_1) sin(f n_z + p_2), |g| <= 1.
/// Normals are the gradient of the implicit form |x| - r(x / |x|), by central differences.
pub fn blob(amplitude: f64, frequency: f64, phase: [f64; 3], segments: u32) -> TriangleMesh {
    let radius = |n: &Vec3| {
        let g = (0..3)
            .map(|i| (frequency * n[i] + phase[i]).sin())
            .product::<f64>();
        (1.0 + amplitude * g) / (1.0 + amplitude)
    };
    let implicit = |x: &Vec3| x.norm() - radius(&x.normalize());
    let mut mesh = polar_render::shapes::uv_sphere(segments);
    for (p, n) in mesh.positions.iter_mut().zip(mesh.normals.iter_mut()) {
        let dir = p.normalize();
        *p = dir * radius(&dir);
        // Step 1e-6: central differences of a smooth function, error O(h^2) ~ 1e-12.
        let h = 1e-6;
        let grad = Vec3::from_fn(|i, _| {
            let e = Vec3::ith(i, h);
            (implicit(&(*p + e)) - implicit(&(*p - e))) / (2.0 * h)
        });
        *n = grad.try_normalize(1e-12).unwrap_or(dir);
    }
    mesh
}

/// A star polygon with `sides` points (outer radius 1, inner radius `inner_ratio`; 1 gives a
/// regular 2n-gon) in the xy plane, extruded along z over `depth`, flat-shaded, then scaled
/// into the unit ball.
pub fn extrusion(sides: u32, inner_ratio: f64, depth: f64) -> TriangleMesh {
    let n = 2 * sides.max(3);
    let ring: Vec<Vec3> = (0..n)
        .map(|i| {
            let phi = 2.0 * PI * f64::from(i) / f64::from(n);
            let r = if i % 2 == 0 { 1.0 } else { inner_ratio };
            Vec3::new(r * phi.cos(), r * phi.sin(), 0.0)
        })
        .collect();
    let half = 0.5 * depth;
    let scale = 1.0 / (1.0 + half * half).sqrt();
    let mut mesh = TriangleMesh::default();
    let mut push = |verts: [Vec3; 3], normal: Vec3| {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(verts.map(|v| v * scale));
        mesh.normals.extend([normal; 3]);
        mesh.triangles.push([base, base + 1, base + 2]);
    };
    let up = Vec3::new(0.0, 0.0, half);
    for i in 0..n as usize {
        let (a, b) = (ring[i], ring[(i + 1) % n as usize]);
        push([up, a + up, b + up], Vec3::z());
        push([-up, b - up, a - up], -Vec3::z());
        let outward = Vec3::new(b.y - a.y, a.x - b.x, 0.0).normalize();
        push([a - up, b - up, b + up], outward);
        push([a - up, b + up, a + up], outward);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face(m: &TriangleMesh, t: &[u32; 3]) -> (Vec3, Vec3) {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        ((b - a).cross(&(c - a)), (a + b + c) / 3.0)
    }

    /// Signed volume by the divergence theorem: sum over faces of a . (b x c) / 6.
    fn volume(m: &TriangleMesh) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    fn check_star_shaped_and_outward(m: &TriangleMesh) {
        for t in &m.triangles {
            let (area_n, centroid) = face(m, t);
            if area_n.norm() < 1e-12 {
                continue; // pole triangles of the UV sphere are degenerate
            }
            assert!(area_n.dot(&centroid) > 0.0, "inward face {t:?}");
            for &i in t {
                let n = m.normals[i as usize];
                assert!((n.norm() - 1.0).abs() < 1e-9);
                assert!(
                    n.dot(&area_n) > 0.0,
                    "vertex normal disagrees with face {t:?}"
                );
            }
        }
        assert!(
            m.positions.iter().all(|p| p.norm() <= 1.0 + 1e-9),
            "leaves the unit ball"
        );
    }

    #[test]
    fn extrusion_is_outward_and_has_the_prism_volume() {
        let (sides, inner, depth) = (5, 0.5, 0.8);
        let m = extrusion(sides, inner, depth);
        check_star_shaped_and_outward(&m);
        // Star area = 2n triangles of 0.5 * 1 * inner * sin(pi / n) = n * inner * sin(pi / n).
        let area = f64::from(sides) * inner * (PI / f64::from(sides)).sin();
        let scale: f64 = 1.0 / (1.0 + 0.25 * depth * depth).sqrt();
        // Exact up to rounding: the mesh is the polyhedron itself.
        approx_eq(volume(&m), area * depth * scale.powi(3), 1e-12);
    }

    #[test]
    fn blob_is_outward_and_bounded_and_zero_amplitude_is_a_sphere() {
        let m = blob(0.2, 3.0, [0.1, 0.7, 2.0], 32);
        check_star_shaped_and_outward(&m);
        let s = blob(0.0, 3.0, [0.0; 3], 64);
        // A 64-segment UV sphere's volume is below 4/3 pi by the chord error, ~0.3 %.
        let v = volume(&s);
        assert!(
            v < 4.0 / 3.0 * PI && v > 0.99 * 4.0 / 3.0 * PI,
            "volume {v}"
        );
    }

    fn approx_eq(a: f64, b: f64, rel: f64) {
        assert!((a - b).abs() <= rel * b.abs(), "{a} vs {b}");
    }
}
