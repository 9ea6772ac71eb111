//! Whether a mesh bounds a solid the right way round: a translucent body takes its inside and
//! outside from the triangles' winding, so its mesh must be closed, consistently wound
//! ([`Mesh::open_edges`]) and wound outward ([`Mesh::signed_volume`] > 0). A closed mesh wound
//! inside-out passes the first check but not the second: rendered, its normals point inward, so
//! light "enters" where it leaves and the stone comes out too bright.

use super::Mesh;
use glam::Vec3;

impl Mesh {
    /// Directed edges without their reverse: 0 for a closed mesh whose triangles are wound
    /// consistently (each edge shared by exactly two triangles that traverse it in opposite
    /// directions). Vertices are matched by their exact coordinates, as an OBJ file's shared
    /// vertices are. A translucent body needs 0: its inside and outside come from the winding.
    pub fn open_edges(&self) -> usize {
        use std::collections::HashMap;
        let key = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let mut count: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
        for t in &self.tris {
            for k in 0..3 {
                let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
                *count.entry((a, b)).or_insert(0) += 1;
            }
        }
        count
            .iter()
            .filter(|&(&(a, b), &n)| n != 1 || count.get(&(b, a)) != Some(&1))
            .count()
    }

    /// The volume the triangles enclose, in object units³, signed by their winding: positive
    /// when they are wound counter-clockwise seen from outside (normals outward), negative for
    /// the same mesh inside-out. By the divergence theorem the volume is `Σ a·(b × c) / 6` over
    /// the triangles `(a, b, c)` (the signed volumes of the tetrahedra they make with the
    /// origin); summed in `f64` about the bounds' centre so that a stone far from the origin
    /// keeps its precision. Meaningful for a closed mesh ([`Mesh::open_edges`] = 0).
    pub fn signed_volume(&self) -> f64 {
        let (lo, hi) = self.bounds();
        let c = (lo + hi).as_dvec3() * 0.5;
        self.tris
            .iter()
            .map(|t| {
                let [a, b, c3] = t.map(|v| v.as_dvec3() - c);
                a.dot(b.cross(c3))
            })
            .sum::<f64>()
            / 6.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit tetrahedron's four faces, wound outward.
    fn tetrahedron() -> Vec<[Vec3; 3]> {
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        faces.iter().map(|f| f.map(|i| v[i])).collect()
    }

    /// A tetrahedron wound outward is closed; one flipped or missing face is reported.
    #[test]
    fn open_edges_finds_holes_and_flips() {
        let tris = tetrahedron();
        let closed = Mesh::from_triangles(tris.clone(), None).unwrap();
        assert_eq!(closed.open_edges(), 0);
        let mut flipped = tris.clone();
        flipped[3].swap(1, 2);
        assert_eq!(Mesh::from_triangles(flipped, None).unwrap().open_edges(), 3);
        let holed = Mesh::from_triangles(tris[..3].to_vec(), None).unwrap();
        assert_eq!(holed.open_edges(), 3);
    }

    /// The tetrahedron encloses 1/6 wound outward and −1/6 inside out, wherever it stands.
    #[test]
    fn signed_volume_follows_the_winding() {
        for offset in [Vec3::ZERO, Vec3::new(1e4, -3e4, 2e4)] {
            let tris: Vec<[Vec3; 3]> = tetrahedron()
                .iter()
                .map(|t| t.map(|v| v + offset))
                .collect();
            let out = Mesh::from_triangles(tris.clone(), None).unwrap();
            assert!((out.signed_volume() - 1.0 / 6.0).abs() < 1e-9, "{offset}");
            let inside_out: Vec<[Vec3; 3]> = tris.iter().map(|&[a, b, c]| [a, c, b]).collect();
            let m = Mesh::from_triangles(inside_out, None).unwrap();
            assert_eq!(m.open_edges(), 0, "still closed and consistent");
            assert!((m.signed_volume() + 1.0 / 6.0).abs() < 1e-9, "{offset}");
        }
    }
}
