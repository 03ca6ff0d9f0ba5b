//! Scene queries (issue #22) against hand-computed geometry: each ray/primitive pairing,
//! solid bodies, ordering, filters, wrap images, bad input, and an index that must follow
//! the world (query, step, move, query).

use ricochet_sim::prelude::*;

const EPS: f64 = 1e-12;

fn layers() -> Layers {
    Layers::new(vec!["a".into(), "b".into()])
}

fn sim() -> Simulation {
    Simulation::from_def(WorldDef {
        layers: layers(),
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap()
}

fn wrap_sim() -> Simulation {
    Simulation::from_def(WorldDef {
        layers: layers(),
        gravity: Vec2::ZERO,
        bounds: Some(WorldBounds {
            min: Vec2::ZERO,
            max: Vec2::new(100.0, 100.0),
            wrap: true,
        }),
        ..WorldDef::default()
    })
    .unwrap()
}

fn body(sim: &mut Simulation, shape: Shape, x: f64, y: f64) -> Entity {
    body_on(sim, 0, BodyKind::Static, shape, Vec2::new(x, y), 0.0)
}

fn body_on(
    sim: &mut Simulation,
    layer: LayerId,
    kind: BodyKind,
    shape: Shape,
    position: Vec2,
    angle: f64,
) -> Entity {
    sim.spawn(&BodyDef {
        layer,
        kind,
        shape,
        position,
        angle,
        ..BodyDef::default()
    })
}

fn close(a: Vec2, b: Vec2) -> bool {
    (a - b).length() <= EPS * (1.0 + b.length())
}

#[track_caller]
fn hit(sim: &Simulation, o: Vec2, d: Vec2, max: f64) -> RayHit {
    sim.cast_ray(o, d, max, &QueryFilter::all()).expect("a hit")
}

#[track_caller]
fn expect(h: RayHit, e: Entity, distance: f64, point: Vec2, normal: Vec2) {
    assert_eq!(h.entity, e, "{h:?}");
    assert!(
        (h.distance - distance).abs() <= EPS * (1.0 + distance),
        "{h:?} vs {distance}"
    );
    assert!(close(h.point, point), "{h:?} vs {point:?}");
    assert!(close(h.normal, normal), "{h:?} vs {normal:?}");
}

#[test]
fn ray_circle() {
    let mut s = sim();
    let c = body(&mut s, Shape::circle(1.0).unwrap(), 5.0, 0.0);
    // A non-unit direction is normalised: the face at x = 4.
    expect(
        hit(&s, Vec2::ZERO, Vec2::new(2.0, 0.0), 10.0),
        c,
        4.0,
        Vec2::new(4.0, 0.0),
        Vec2::new(-1.0, 0.0),
    );
    // Off centre by 0.6: enters at x = 5 - 0.8.
    let h = hit(&s, Vec2::new(0.0, 0.6), Vec2::X, 10.0);
    expect(h, c, 4.2, Vec2::new(4.2, 0.6), Vec2::new(-0.8, 0.6));
    // Just short of the face, and a miss above it.
    assert!(
        s.cast_ray(Vec2::ZERO, Vec2::X, 3.999, &QueryFilter::all())
            .is_none()
    );
    assert!(
        s.cast_ray(Vec2::new(0.0, 1.001), Vec2::X, 10.0, &QueryFilter::all())
            .is_none()
    );
    // Heading away.
    assert!(
        s.cast_ray(Vec2::ZERO, -Vec2::X, 100.0, &QueryFilter::all())
            .is_none()
    );
}

#[test]
fn ray_aabb_obb() {
    let mut s = sim();
    let b = body(&mut s, Shape::aabb(Vec2::new(1.0, 2.0)).unwrap(), 0.0, 10.0);
    expect(
        hit(&s, Vec2::ZERO, Vec2::Y, 20.0),
        b,
        8.0,
        Vec2::new(0.0, 8.0),
        Vec2::new(0.0, -1.0),
    );
    // From the right, diagonally: x = 1 face at t with 5 - t/√2 = 1.
    let d = Vec2::new(-1.0, 1.0);
    let t = 4.0 * 2f64.sqrt();
    expect(
        hit(&s, Vec2::new(5.0, 5.0), d, 20.0),
        b,
        t,
        Vec2::new(1.0, 9.0),
        Vec2::X,
    );
    // An OBB turned 45°: a unit square whose left corner is at x = 10 - √2; along y = 0.5
    // it meets the upper-left face x - y = 10 - √2.
    let mut s = sim();
    let o = body_on(
        &mut s,
        0,
        BodyKind::Static,
        Shape::obb(Vec2::ONE).unwrap(),
        Vec2::new(10.0, 0.0),
        std::f64::consts::FRAC_PI_4,
    );
    let x = 10.0 - 2f64.sqrt() + 0.5;
    let n = Vec2::new(-1.0, 1.0) / 2f64.sqrt();
    expect(
        hit(&s, Vec2::new(0.0, 0.5), Vec2::X, 20.0),
        o,
        x,
        Vec2::new(x, 0.5),
        n,
    );
}

#[test]
fn ray_capsule_polygon_compound() {
    let mut s = sim();
    let c = body(
        &mut s,
        Shape::capsule(Vec2::new(0.0, -1.0), Vec2::new(0.0, 1.0), 0.5).unwrap(),
        5.0,
        0.0,
    );
    // The side: x = 4.5.
    expect(
        hit(&s, Vec2::ZERO, Vec2::X, 10.0),
        c,
        4.5,
        Vec2::new(4.5, 0.0),
        -Vec2::X,
    );
    // The upper cap (centre (5, 1)) at y = 1.25: x = 5 - √(0.25 - 0.0625).
    let x = 5.0 - 0.1875f64.sqrt();
    let n = Vec2::new(x - 5.0, 0.25) / 0.5;
    expect(
        hit(&s, Vec2::new(0.0, 1.25), Vec2::X, 10.0),
        c,
        x,
        Vec2::new(x, 1.25),
        n,
    );

    let mut s = sim();
    // A triangle (0,0), (2,0), (0,2) placed at (10, 0): its hypotenuse x + y = 12.
    let tri = Shape::polygon(&[Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::new(0.0, 2.0)]).unwrap();
    let p = body(&mut s, tri, 10.0, 0.0);
    let h = hit(&s, Vec2::new(20.0, 1.0), -Vec2::X, 20.0);
    expect(
        h,
        p,
        9.0,
        Vec2::new(11.0, 1.0),
        Vec2::new(1.0, 1.0) / 2f64.sqrt(),
    );
    // From the left, its vertical side x = 10.
    expect(
        hit(&s, Vec2::new(0.0, 1.0), Vec2::X, 20.0),
        p,
        10.0,
        Vec2::new(10.0, 1.0),
        -Vec2::X,
    );

    let mut s = sim();
    // A compound of two discs at x = +-3 (radius 1), at (0, 10): the ray from below at
    // x = 3 hits the right one at y = 9.
    let parts = vec![
        Primitive::circle(Vec2::new(-3.0, 0.0), 1.0).unwrap(),
        Primitive::circle(Vec2::new(3.0, 0.0), 1.0).unwrap(),
    ];
    let k = body(&mut s, Shape::compound(parts).unwrap(), 0.0, 10.0);
    expect(
        hit(&s, Vec2::new(3.0, 0.0), Vec2::Y, 20.0),
        k,
        9.0,
        Vec2::new(3.0, 9.0),
        -Vec2::Y,
    );
    // Between the parts: a miss.
    assert!(
        s.cast_ray(Vec2::ZERO, Vec2::Y, 20.0, &QueryFilter::all())
            .is_none()
    );
    // From the left, the left part first (x = -4), though the right is also on the line.
    let h = hit(&s, Vec2::new(-10.0, 10.0), Vec2::X, 20.0);
    expect(h, k, 6.0, Vec2::new(-4.0, 10.0), -Vec2::X);
}

#[test]
fn ray_from_inside_is_solid() {
    let mut s = sim();
    let b = body(&mut s, Shape::aabb(Vec2::ONE).unwrap(), 0.0, 0.0);
    let h = hit(&s, Vec2::new(0.5, 0.0), Vec2::X, 10.0);
    assert_eq!(
        h,
        RayHit {
            entity: b,
            point: Vec2::new(0.5, 0.0),
            normal: Vec2::ZERO,
            distance: 0.0
        }
    );
    // On the boundary is not inside: heading in, it hits the face at 0 with its normal.
    let h = hit(&s, Vec2::new(1.0, 0.0), -Vec2::X, 10.0);
    assert_eq!((h.distance, h.normal), (0.0, Vec2::X));
    assert!(
        s.overlap_point(Vec2::new(1.0, 0.0), &QueryFilter::all())
            .is_empty()
    );
    assert_eq!(
        s.overlap_point(Vec2::new(0.999, 0.0), &QueryFilter::all()),
        [b]
    );
}

#[test]
fn ray_all_order_and_filters() {
    let mut s = sim();
    let far = body(&mut s, Shape::circle(1.0).unwrap(), 20.0, 0.0);
    let a = body(&mut s, Shape::circle(1.0).unwrap(), 10.0, 0.0);
    // The same distance as `a`, another layer, a higher id.
    let b = body_on(
        &mut s,
        1,
        BodyKind::Dynamic,
        Shape::aabb(Vec2::ONE).unwrap(),
        Vec2::new(10.0, 0.0),
        0.0,
    );
    let all = s.cast_ray_all(Vec2::ZERO, Vec2::X, 100.0, &QueryFilter::all());
    let got: Vec<(Entity, f64)> = all.iter().map(|h| (h.entity, h.distance)).collect();
    assert_eq!(got, [(a, 9.0), (b, 9.0), (far, 19.0)]);
    // The first hit on a tie: the lowest id.
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).entity, a);
    let only_b = QueryFilter::layers(&[1]);
    assert_eq!(
        s.cast_ray(Vec2::ZERO, Vec2::X, 100.0, &only_b)
            .unwrap()
            .entity,
        b
    );
    let not_a = QueryFilter::all().exclude(a);
    assert_eq!(
        s.cast_ray(Vec2::ZERO, Vec2::X, 100.0, &not_a)
            .unwrap()
            .entity,
        b
    );
    let layer0_not_a = QueryFilter::layers(&[0]).exclude(a);
    assert_eq!(
        s.cast_ray(Vec2::ZERO, Vec2::X, 100.0, &layer0_not_a)
            .unwrap()
            .entity,
        far
    );
    assert!(
        s.cast_ray(Vec2::ZERO, Vec2::X, 100.0, &QueryFilter::layers(&[]))
            .is_none()
    );
    assert_eq!(
        s.overlap_point(Vec2::new(10.0, 0.5), &QueryFilter::all()),
        [a, b]
    );
    assert_eq!(s.overlap_point(Vec2::new(10.0, 0.5), &only_b), [b]);
    assert!(QueryFilter::all().accepts(200, a) && !QueryFilter::layers(&[1]).accepts(0, a));
    assert_eq!(QueryFilter::all(), QueryFilter::default());
}

#[test]
fn overlaps_are_exact_and_touching_does_not_count() {
    let mut s = sim();
    let c = body(&mut s, Shape::circle(1.0).unwrap(), 0.0, 0.0);
    let b = body(&mut s, Shape::aabb(Vec2::ONE).unwrap(), 5.0, 0.0);
    let all = QueryFilter::all();
    // The box's corner region near the disc's bounds corner, outside the disc: bounds meet,
    // the shapes do not (0.8² + 0.8² > 1).
    let corner = Bounds {
        min: Vec2::new(0.8, 0.8),
        max: Vec2::new(2.0, 2.0),
    };
    assert!(s.overlap_aabb(corner, &all).is_empty());
    let inside = Bounds {
        min: Vec2::new(0.6, 0.6),
        max: Vec2::new(2.0, 2.0),
    };
    assert_eq!(s.overlap_aabb(inside, &all), [c]);
    // Touching the box's left face (x = 4) only.
    let touch = Bounds {
        min: Vec2::new(3.0, -1.0),
        max: Vec2::new(4.0, 1.0),
    };
    assert!(s.overlap_aabb(touch, &all).is_empty());
    let both = Bounds {
        min: Vec2::new(0.5, -0.5),
        max: Vec2::new(4.5, 0.5),
    };
    assert_eq!(s.overlap_aabb(both, &all), [c, b]);
    // A capsule lying across both.
    let cap = Shape::capsule(Vec2::new(-2.0, 0.0), Vec2::new(2.0, 0.0), 0.25).unwrap();
    assert_eq!(
        s.overlap_shape(&cap, Pose::new(Vec2::new(2.5, 0.0), 0.0), &all),
        [c, b]
    );
    // Turned upright it reaches neither (x = 2.5 is 1.5 from each).
    let upright = Pose::new(Vec2::new(2.5, 0.0), std::f64::consts::FRAC_PI_2);
    assert!(s.overlap_shape(&cap, upright, &all).is_empty());
}

#[test]
fn cast_shape_time_of_impact() {
    let mut s = sim();
    let b = body(&mut s, Shape::aabb(Vec2::ONE).unwrap(), 6.0, 0.0);
    let disc = Shape::circle(1.0).unwrap();
    let all = QueryFilter::all();
    // The disc's right side reaches the face x = 5 after 4 of 10.
    let h = s
        .cast_shape(
            &disc,
            Pose::new(Vec2::ZERO, 0.0),
            Vec2::new(10.0, 0.0),
            &all,
        )
        .unwrap();
    assert_eq!(h.entity, b);
    assert!((h.fraction - 0.4).abs() < 1e-8, "{h:?}");
    assert!(
        close(h.normal, Vec2::X) && (h.point - Vec2::new(5.0, 0.0)).length() < 1e-8,
        "{h:?}"
    );
    // Too short, or already overlapping (fraction 0).
    assert!(
        s.cast_shape(&disc, Pose::new(Vec2::ZERO, 0.0), Vec2::new(3.9, 0.0), &all)
            .is_none()
    );
    let h = s
        .cast_shape(&disc, Pose::new(Vec2::new(4.5, 0.0), 0.0), Vec2::ZERO, &all)
        .unwrap();
    assert_eq!((h.entity, h.fraction), (b, 0.0));
    assert!(
        s.cast_shape(
            &disc,
            Pose::new(Vec2::ZERO, 0.0),
            Vec2::new(10.0, 0.0),
            &all.clone().exclude(b)
        )
        .is_none()
    );
}

#[test]
fn bad_input_is_nothing() {
    let mut s = sim();
    body(&mut s, Shape::circle(1.0).unwrap(), 0.0, 0.0);
    let all = QueryFilter::all();
    let nan = Vec2::new(f64::NAN, 0.0);
    let inf = Vec2::new(f64::INFINITY, 0.0);
    for (o, d, m) in [
        (Vec2::new(-5.0, 0.0), Vec2::ZERO, 10.0),
        (Vec2::new(-5.0, 0.0), nan, 10.0),
        (Vec2::new(-5.0, 0.0), inf, 10.0),
        (nan, Vec2::X, 10.0),
        (Vec2::new(-5.0, 0.0), Vec2::X, -1.0),
        (Vec2::new(-5.0, 0.0), Vec2::X, f64::NAN),
    ] {
        assert!(s.cast_ray(o, d, m, &all).is_none(), "{o:?} {d:?} {m}");
        assert!(s.cast_ray_all(o, d, m, &all).is_empty());
    }
    // A tiny direction still normalises.
    assert_eq!(
        hit(&s, Vec2::new(-5.0, 0.0), Vec2::new(1e-300, 0.0), 10.0).distance,
        4.0
    );
    // An infinite max distance is fine.
    assert_eq!(
        hit(&s, Vec2::new(-5.0, 0.0), Vec2::X, f64::INFINITY).distance,
        4.0
    );
    assert!(s.overlap_point(nan, &all).is_empty());
    let inverted = Bounds {
        min: Vec2::ONE,
        max: -Vec2::ONE,
    };
    assert!(s.overlap_aabb(inverted, &all).is_empty());
    assert!(
        s.overlap_aabb(
            Bounds {
                min: nan,
                max: Vec2::ONE
            },
            &all
        )
        .is_empty()
    );
    let disc = Shape::circle(1.0).unwrap();
    assert!(s.overlap_shape(&disc, Pose::new(nan, 0.0), &all).is_empty());
    assert!(
        s.overlap_shape(&disc, Pose::new(Vec2::ZERO, f64::NAN), &all)
            .is_empty()
    );
    assert!(
        s.cast_shape(&disc, Pose::new(Vec2::new(-5.0, 0.0), 0.0), inf, &all)
            .is_none()
    );
}

#[test]
fn wrap_rays_go_on_from_the_opposite_edge() {
    let mut s = wrap_sim();
    let c = body(&mut s, Shape::circle(1.0).unwrap(), 5.0, 50.0);
    let all = QueryFilter::all();
    // From x = 90 to the edge (10), on from x = 0 to the disc's face at 4: 14 in all.
    let h = hit(&s, Vec2::new(90.0, 50.0), Vec2::X, 20.0);
    expect(h, c, 14.0, Vec2::new(4.0, 50.0), -Vec2::X);
    assert!(
        s.cast_ray(Vec2::new(90.0, 50.0), Vec2::X, 13.9, &all)
            .is_none()
    );
    // Leftwards from x = 10 it passes the disc first (face x = 6 at 4).
    assert_eq!(hit(&s, Vec2::new(10.0, 50.0), -Vec2::X, 20.0).distance, 4.0);
    // Up through the top edge: from (5, 90), the disc's bottom at y = 49 after 10 + 49.
    expect(
        hit(&s, Vec2::new(5.0, 90.0), Vec2::Y, 100.0),
        c,
        59.0,
        Vec2::new(5.0, 49.0),
        -Vec2::Y,
    );
    // Around the whole world: it sees the disc on the first turn only, once.
    let all_hits = s.cast_ray_all(Vec2::new(90.0, 50.0), Vec2::X, 250.0, &all);
    assert_eq!(all_hits.len(), 1);
    assert_eq!(all_hits[0].distance, 14.0);
}

#[test]
fn wrap_images_of_a_body_across_an_edge() {
    let mut s = wrap_sim();
    // A disc straddling the right edge (x = 99.5, radius 1): its image reaches x = 0.5.
    let c = body_on(
        &mut s,
        0,
        BodyKind::Dynamic,
        Shape::circle(1.0).unwrap(),
        Vec2::new(99.5, 50.0),
        0.0,
    );
    let all = QueryFilter::all();
    assert_eq!(s.overlap_point(Vec2::new(0.2, 50.0), &all), [c]);
    assert_eq!(s.overlap_point(Vec2::new(99.2, 50.0), &all), [c]);
    assert!(s.overlap_point(Vec2::new(0.6, 50.0), &all).is_empty());
    let b = Bounds {
        min: Vec2::new(0.3, 49.0),
        max: Vec2::new(2.0, 51.0),
    };
    assert_eq!(s.overlap_aabb(b, &all), [c]);
    let disc = Shape::circle(0.25).unwrap();
    assert_eq!(
        s.overlap_shape(&disc, Pose::new(Vec2::new(0.6, 50.0), 0.0), &all),
        [c]
    );
    // A ray from the left side heading left meets the image's face at x = 0.5.
    let h = hit(&s, Vec2::new(10.0, 50.0), -Vec2::X, 20.0);
    expect(h, c, 9.5, Vec2::new(0.5, 50.0), Vec2::X);
    // A query point outside the world is wrapped in: (100.2, 50) is (0.2, 50).
    assert_eq!(s.overlap_point(Vec2::new(100.2, 50.0), &all), [c]);
    // A shape cast through the edge: a disc of radius 0.25 from (95, 10) up... no: from
    // (3, 50) leftwards it meets the image (face x = 0.5) when its left side gets there.
    let h = s
        .cast_shape(
            &disc,
            Pose::new(Vec2::new(3.0, 50.0), 0.0),
            Vec2::new(-10.0, 0.0),
            &all,
        )
        .unwrap();
    assert_eq!(h.entity, c);
    assert!((h.fraction - 0.225).abs() < 1e-8, "{h:?}");
    assert!(close(h.normal, -Vec2::X), "{h:?}");
}

#[test]
fn the_index_follows_the_world() {
    let mut s = sim();
    let all = QueryFilter::all();
    let m = body_on(
        &mut s,
        0,
        BodyKind::Kinematic,
        Shape::circle(1.0).unwrap(),
        Vec2::new(10.0, 0.0),
        0.0,
    );
    s.set_velocity(m, Vec2::new(60.0, 0.0)).unwrap();
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).distance, 9.0);
    s.step(); // frame 0: nothing moves
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).distance, 9.0);
    s.step(); // one unit to the right
    let x = s.position(m).unwrap().x;
    assert!((x - 11.0).abs() < 1e-12);
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).distance, x - 1.0);
    assert_eq!(s.overlap_point(Vec2::new(x + 0.5, 0.0), &all), [m]);
    // Moved, turned, reshaped, despawned: each seen at once.
    s.set_position(m, Vec2::new(30.0, 0.0)).unwrap();
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).distance, 29.0);
    s.set_shape(m, Shape::circle(2.0).unwrap()).unwrap();
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).distance, 28.0);
    s.set_shape(m, Shape::aabb(Vec2::new(2.0, 0.5)).unwrap())
        .unwrap();
    s.set_angle(m, std::f64::consts::FRAC_PI_2).unwrap(); // an AABB ignores the turn
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).distance, 28.0);
    // A static body spawned after a query, then moved.
    let w = body(&mut s, Shape::aabb(Vec2::ONE).unwrap(), 5.0, 0.0);
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).entity, w);
    s.set_position(w, Vec2::new(50.0, 0.0)).unwrap();
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).entity, m);
    s.despawn(m).unwrap();
    assert_eq!(hit(&s, Vec2::ZERO, Vec2::X, 100.0).distance, 49.0);
    let before = s.clone();
    s.despawn(w).unwrap();
    assert!(s.cast_ray(Vec2::ZERO, Vec2::X, 100.0, &all).is_none());
    // A clone made before keeps its own answers.
    assert_eq!(
        before
            .cast_ray(Vec2::ZERO, Vec2::X, 100.0, &all)
            .unwrap()
            .entity,
        w
    );
}

#[test]
fn far_from_the_origin_the_answers_hold() {
    let far = Vec2::new(1e6, -1e6);
    let mut s = sim();
    let c = body(&mut s, Shape::circle(1.0).unwrap(), far.x + 5.0, far.y);
    let h = hit(&s, far + Vec2::new(0.0, 0.6), Vec2::X, 10.0);
    assert_eq!(h.entity, c);
    // The distance is as good as at the origin, to the ulps of the coordinates.
    assert!((h.distance - 4.2).abs() < 1e-9, "{h:?}");
    assert!((h.normal - Vec2::new(-0.8, 0.6)).length() < 1e-9, "{h:?}");
}
