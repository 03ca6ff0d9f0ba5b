//! `Polygon::storage`, what a prefetch of a polygon asks for, is the polygon's own memory.

use ricochet_geom::{MAX_POLYGON_VERTICES, Polygon, Vec2};

/// `storage` is where `vertices` and `normals` read, the count included, for every vertex
/// count.
#[test]
fn a_polygons_storage_holds_its_vertices_and_normals() {
    for n in 3..=MAX_POLYGON_VERTICES {
        let points: Vec<Vec2> = (0..n)
            .map(|k| {
                let (s, c) = libm::sincos(std::f64::consts::TAU * k as f64 / n as f64);
                Vec2::new(c, s)
            })
            .collect();
        let p = Polygon::new(&points).unwrap();
        let (vertices, normals, count) = p.storage();
        assert_eq!(*count, n);
        assert_eq!(&vertices[..n], p.vertices());
        assert_eq!(&normals[..n], p.normals());
        assert!(std::ptr::eq(&vertices[0], &p.vertices()[0]));
        assert!(std::ptr::eq(&normals[0], &p.normals()[0]));
    }
}
