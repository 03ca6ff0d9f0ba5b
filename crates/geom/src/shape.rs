//! The shapes a body can carry, in local coordinates, validated on construction.

use crate::math::{Vec2, cross};
use crate::number::Number;

/// The most vertices a polygon may have (Box2D's limit too). Fixed so that a polygon is `Copy`
/// and the narrow phase never allocates.
pub const MAX_POLYGON_VERTICES: usize = 8;

/// The most parts a compound may have. Two compounds that touch test their part pairs near
/// each other (culled by bounds, see `contact`), but a compound of 20,000 parts made a
/// 2.2 MB scenario take 36 s for 10 frames: this keeps every body's cost bounded. A larger
/// outline is several bodies, or a tile map.
pub const MAX_COMPOUND_PARTS: usize = 1024;

/// Why a shape description was rejected. `field` is the path of the offending value, relative
/// to the shape (for example `vertices[2]` or `parts[1].radius`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct ShapeError {
    /// Path of the offending field inside the shape description.
    pub field: String,
    /// What is wrong and what was expected.
    pub problem: String,
}

impl ShapeError {
    pub(crate) fn new(field: impl Into<String>, problem: impl Into<String>) -> ShapeError {
        ShapeError {
            field: field.into(),
            problem: problem.into(),
        }
    }

    /// The same error with `prefix.` in front of its field path.
    #[must_use]
    pub fn within(mut self, prefix: &str) -> ShapeError {
        self.field = if self.field.is_empty() {
            prefix.to_owned()
        } else {
            format!("{prefix}.{}", self.field)
        };
        self
    }
}

/// The largest coordinate or size the geometry accepts, in magnitude. The narrow phase
/// squares lengths, so results stay exact far beyond it (overflow starts near 1e150), and
/// `f64` still resolves 0.125 at 1e15: the bound keeps every answer finite.
pub const MAX_COORDINATE: f64 = 1e15;

/// The smallest size (radius, half extent) the geometry accepts. Squares of lengths stay
/// normal numbers far below it (underflow starts near 1e-150).
pub const MIN_SIZE: f64 = 1e-12;

fn finite(field: &str, v: f64) -> Result<f64, ShapeError> {
    if !v.is_finite() {
        return Err(ShapeError::new(
            field,
            format!("must be a finite number, got {}", Number(v)),
        ));
    }
    if v.abs() > MAX_COORDINATE {
        return Err(ShapeError::new(
            field,
            format!(
                "{} is beyond ±{MAX_COORDINATE:e}, the largest coordinate Ricochet accepts",
                Number(v)
            ),
        ));
    }
    Ok(v)
}

fn finite_vec(field: &str, v: Vec2) -> Result<Vec2, ShapeError> {
    finite(&format!("{field}[0]"), v.x)?;
    finite(&format!("{field}[1]"), v.y)?;
    Ok(v)
}

fn positive(field: &str, v: f64) -> Result<f64, ShapeError> {
    finite(field, v)?;
    if v <= 0.0 {
        return Err(ShapeError::new(
            field,
            format!("must be greater than 0, got {}", Number(v)),
        ));
    }
    if v < MIN_SIZE {
        return Err(ShapeError::new(
            field,
            format!(
                "{} is below {MIN_SIZE:e}, the smallest size Ricochet accepts",
                Number(v)
            ),
        ));
    }
    Ok(v)
}

/// A disc of `radius` around `center`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Local offset of the centre from the body origin.
    pub center: Vec2,
    /// Radius, `> 0`.
    pub radius: f64,
}

/// An axis-aligned box: it ignores the body's rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Local offset of the centre (turned by the body's angle; the box itself is not).
    pub center: Vec2,
    /// Half width and half height, both `> 0`.
    pub half_extents: Vec2,
}

/// An oriented box: turned by the body's angle plus its own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obb {
    /// Local offset of the centre from the body origin.
    pub center: Vec2,
    /// Half width and half height, both `> 0`.
    pub half_extents: Vec2,
    /// The box's own angle relative to the body, radians counter-clockwise.
    pub angle: f64,
}

/// A segment `a`–`b` swept by `radius`. A zero-length segment is a circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// First end of the core segment, local coordinates.
    pub a: Vec2,
    /// Second end of the core segment, local coordinates.
    pub b: Vec2,
    /// Radius, `> 0`.
    pub radius: f64,
}

/// The most points a terrain chain may have: one segment per compound part
/// ([`MAX_COMPOUND_PARTS`]), so a chain's cost is bounded like a compound's. A longer line is
/// several chains that name each other's end points as ghosts ([`Shape::chain`]).
pub const MAX_CHAIN_POINTS: usize = MAX_COMPOUND_PARTS + 1;

/// One segment `a`–`b` of a terrain chain, of zero thickness, with its neighbours' far
/// points (`prev` before `a`, `next` after `b`; Box2D's "ghost vertices"). A contact at a
/// joint takes a normal the neighbouring segment would also allow, so a body sliding along
/// the chain never catches on a joint (see `collide/segment.rs`). Two-sided: a body is
/// pushed out to the side of the segment its centre is on. Built only by [`Shape::chain`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// First end, local coordinates.
    pub a: Vec2,
    /// Second end, local coordinates.
    pub b: Vec2,
    /// The previous segment's first end, if the chain goes on before `a`.
    pub prev: Option<Vec2>,
    /// The next segment's second end, if the chain goes on after `b`.
    pub next: Option<Vec2>,
}

/// A convex, counter-clockwise polygon of 3 to [`MAX_POLYGON_VERTICES`] vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polygon {
    vertices: [Vec2; MAX_POLYGON_VERTICES],
    /// Outward unit normal of each edge `i`–`i + 1`, computed once here rather than per query.
    normals: [Vec2; MAX_POLYGON_VERTICES],
    count: usize,
}

impl Polygon {
    /// Validates `vertices` (local coordinates, already including any centre offset): 3 to
    /// [`MAX_POLYGON_VERTICES`] finite points, counter-clockwise, strictly convex, no repeated
    /// vertex.
    pub fn new(vertices: &[Vec2]) -> Result<Polygon, ShapeError> {
        let n = vertices.len();
        if !(3..=MAX_POLYGON_VERTICES).contains(&n) {
            return Err(ShapeError::new(
                "vertices",
                format!("a polygon needs 3 to {MAX_POLYGON_VERTICES} vertices, got {n}"),
            ));
        }
        for (i, v) in vertices.iter().enumerate() {
            finite_vec(&format!("vertices[{i}]"), *v)?;
        }
        let mut twice_area = 0.0;
        for i in 0..n {
            twice_area += cross(vertices[i], vertices[(i + 1) % n]);
        }
        if twice_area <= 0.0 {
            return Err(ShapeError::new(
                "vertices",
                format!(
                    "polygon is clockwise or flat (signed area {}); list the vertices counter-clockwise",
                    Number(twice_area / 2.0)
                ),
            ));
        }
        for i in 0..n {
            let p = vertices[i];
            let q = vertices[(i + 1) % n];
            let r = vertices[(i + 2) % n];
            if p == q {
                return Err(ShapeError::new(
                    format!("vertices[{}]", (i + 1) % n),
                    "repeats the previous vertex",
                ));
            }
            if cross(q - p, r - q) <= 0.0 {
                return Err(ShapeError::new(
                    format!("vertices[{}]", (i + 1) % n),
                    "polygon is not convex here (the boundary turns clockwise or goes straight); \
                     a polygon must be convex and counter-clockwise",
                ));
            }
        }
        let mut out = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        out[..n].copy_from_slice(vertices);
        let mut normals = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        for i in 0..n {
            let e = vertices[(i + 1) % n] - vertices[i];
            normals[i] = Vec2::new(e.y, -e.x).normalize();
        }
        Ok(Polygon {
            vertices: out,
            normals,
            count: n,
        })
    }

    /// The outward unit edge normals, local coordinates: `normals()[i]` belongs to the edge
    /// from vertex `i` to vertex `i + 1`.
    #[must_use]
    pub fn normals(&self) -> &[Vec2] {
        &self.normals[..self.count]
    }

    /// The vertices, counter-clockwise, in local coordinates.
    #[must_use]
    pub fn vertices(&self) -> &[Vec2] {
        &self.vertices[..self.count]
    }

    /// Where the polygon is held: its whole fixed arrays of vertices and normals (past the
    /// count too) and its count, reached without reading any of them. For a prefetch,
    /// which asks for memory before it is read: [`Polygon::vertices`] reads the count.
    #[must_use]
    pub fn storage(
        &self,
    ) -> (
        &[Vec2; MAX_POLYGON_VERTICES],
        &[Vec2; MAX_POLYGON_VERTICES],
        &usize,
    ) {
        (&self.vertices, &self.normals, &self.count)
    }
}

/// One convex piece: every shape kind except a compound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    /// A disc.
    Circle(Circle),
    /// An axis-aligned box.
    Aabb(Aabb),
    /// An oriented box.
    Obb(Obb),
    /// A swept segment.
    Capsule(Capsule),
    /// A convex polygon.
    Polygon(Polygon),
    /// A segment of a terrain chain.
    Segment(Segment),
}

/// The error for a compound of `n` parts, more than [`MAX_COMPOUND_PARTS`].
pub(crate) fn too_many_parts(n: usize) -> ShapeError {
    ShapeError::new(
        "parts",
        format!(
            "a compound has at most {MAX_COMPOUND_PARTS} parts, this one has {n}; split it \
             into several bodies"
        ),
    )
}

/// Several primitives carried by one body, each with its own local offset: the "list of
/// geometries" that lets one body follow a concave outline.
#[derive(Clone, Debug, PartialEq)]
pub struct Compound {
    parts: Vec<Primitive>,
}

impl Compound {
    /// A compound of at least one part and at most [`MAX_COMPOUND_PARTS`].
    pub fn new(parts: Vec<Primitive>) -> Result<Compound, ShapeError> {
        if parts.is_empty() {
            return Err(ShapeError::new(
                "parts",
                "a compound needs at least one part",
            ));
        }
        if parts.len() > MAX_COMPOUND_PARTS {
            return Err(too_many_parts(parts.len()));
        }
        Ok(Compound { parts })
    }

    /// The parts, in the order given.
    #[must_use]
    pub fn parts(&self) -> &[Primitive] {
        &self.parts
    }
}

/// A collision shape in local coordinates.
#[derive(Clone, Debug, PartialEq)]
#[expect(
    clippy::large_enum_variant,
    reason = "a body's shape is usually one primitive, kept inline; compounds hold a Vec"
)]
pub enum Shape {
    /// One convex primitive.
    Primitive(Primitive),
    /// A list of primitives.
    Compound(Compound),
}

/// The kind of a primitive, used to name pairings (`circle-obb`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ShapeKind {
    /// [`Circle`].
    Circle,
    /// [`Aabb`].
    Aabb,
    /// [`Obb`].
    Obb,
    /// [`Capsule`].
    Capsule,
    /// [`Polygon`].
    Polygon,
    /// [`Segment`] (of a chain).
    Segment,
}

impl ShapeKind {
    /// The name used in scenario and case files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Circle => "circle",
            ShapeKind::Aabb => "aabb",
            ShapeKind::Obb => "obb",
            ShapeKind::Capsule => "capsule",
            ShapeKind::Polygon => "polygon",
            ShapeKind::Segment => "segment",
        }
    }
}

impl Primitive {
    /// Which kind of primitive this is.
    #[must_use]
    pub fn kind(&self) -> ShapeKind {
        match self {
            Primitive::Circle(_) => ShapeKind::Circle,
            Primitive::Aabb(_) => ShapeKind::Aabb,
            Primitive::Obb(_) => ShapeKind::Obb,
            Primitive::Capsule(_) => ShapeKind::Capsule,
            Primitive::Polygon(_) => ShapeKind::Polygon,
            Primitive::Segment(_) => ShapeKind::Segment,
        }
    }

    /// A validated circle.
    pub fn circle(center: Vec2, radius: f64) -> Result<Primitive, ShapeError> {
        Ok(Primitive::Circle(Circle {
            center: finite_vec("center", center)?,
            radius: positive("radius", radius)?,
        }))
    }

    /// A validated axis-aligned box.
    pub fn aabb(center: Vec2, half_extents: Vec2) -> Result<Primitive, ShapeError> {
        Ok(Primitive::Aabb(Aabb {
            center: finite_vec("center", center)?,
            half_extents: Vec2::new(
                positive("half_extents[0]", half_extents.x)?,
                positive("half_extents[1]", half_extents.y)?,
            ),
        }))
    }

    /// A validated oriented box.
    pub fn obb(center: Vec2, half_extents: Vec2, angle: f64) -> Result<Primitive, ShapeError> {
        Ok(Primitive::Obb(Obb {
            center: finite_vec("center", center)?,
            half_extents: Vec2::new(
                positive("half_extents[0]", half_extents.x)?,
                positive("half_extents[1]", half_extents.y)?,
            ),
            angle: finite("angle", angle)?,
        }))
    }

    /// A validated capsule; `a` and `b` already include any centre offset.
    pub fn capsule(a: Vec2, b: Vec2, radius: f64) -> Result<Primitive, ShapeError> {
        Ok(Primitive::Capsule(Capsule {
            a: finite_vec("a", a)?,
            b: finite_vec("b", b)?,
            radius: positive("radius", radius)?,
        }))
    }

    /// A validated polygon; see [`Polygon::new`].
    pub fn polygon(vertices: &[Vec2]) -> Result<Primitive, ShapeError> {
        Ok(Primitive::Polygon(Polygon::new(vertices)?))
    }

    /// Whether turning the body changes this primitive: false only for a circle or an AABB
    /// centred on the body origin, which lets the narrow phase skip the trigonometry.
    #[must_use]
    pub fn turns_with_body(&self) -> bool {
        match self {
            Primitive::Circle(c) => c.center != Vec2::ZERO,
            Primitive::Aabb(b) => b.center != Vec2::ZERO,
            _ => true,
        }
    }

    /// Half the diagonal of the local bounding box: the "size" the shared cases use to scale
    /// tolerances.
    #[must_use]
    pub fn size(&self) -> f64 {
        let b = crate::place(self, &crate::Pose::default(), Vec2::ZERO);
        b.bounds().half_extents().length()
    }
}

impl Shape {
    /// A circle of `radius` at the body origin.
    pub fn circle(radius: f64) -> Result<Shape, ShapeError> {
        Primitive::circle(Vec2::ZERO, radius).map(Shape::Primitive)
    }

    /// An axis-aligned box centred on the body origin.
    pub fn aabb(half_extents: Vec2) -> Result<Shape, ShapeError> {
        Primitive::aabb(Vec2::ZERO, half_extents).map(Shape::Primitive)
    }

    /// An oriented box centred on the body origin.
    pub fn obb(half_extents: Vec2) -> Result<Shape, ShapeError> {
        Primitive::obb(Vec2::ZERO, half_extents, 0.0).map(Shape::Primitive)
    }

    /// A capsule around the segment `a`–`b`.
    pub fn capsule(a: Vec2, b: Vec2, radius: f64) -> Result<Shape, ShapeError> {
        Primitive::capsule(a, b, radius).map(Shape::Primitive)
    }

    /// A convex counter-clockwise polygon.
    pub fn polygon(vertices: &[Vec2]) -> Result<Shape, ShapeError> {
        Primitive::polygon(vertices).map(Shape::Primitive)
    }

    /// A compound of primitives.
    pub fn compound(parts: Vec<Primitive>) -> Result<Shape, ShapeError> {
        Compound::new(parts).map(Shape::Compound)
    }

    /// A terrain chain through `points` (2 to [`MAX_CHAIN_POINTS`], finite, no segment of
    /// zero length): a compound of [`Segment`]s, each knowing its neighbours. `prev` and
    /// `next` are ghost points: where the terrain goes on beyond the first and last point
    /// (another chain's), so the end joints are smooth too; `None` is an open end.
    pub fn chain(
        points: &[Vec2],
        prev: Option<Vec2>,
        next: Option<Vec2>,
    ) -> Result<Shape, ShapeError> {
        let n = points.len();
        if !(2..=MAX_CHAIN_POINTS).contains(&n) {
            return Err(ShapeError::new(
                "points",
                format!(
                    "a chain needs 2 to {MAX_CHAIN_POINTS} points, got {n}; split a longer \
                     line into several chains"
                ),
            ));
        }
        for (i, p) in points.iter().enumerate() {
            finite_vec(&format!("points[{i}]"), *p)?;
            if i > 0 && points[i - 1] == *p {
                return Err(ShapeError::new(
                    format!("points[{i}]"),
                    "repeats the previous point: a chain's segments must have a length",
                ));
            }
        }
        if let Some(g) = prev {
            finite_vec("prev", g)?;
            if g == points[0] {
                return Err(ShapeError::new("prev", "is the chain's first point"));
            }
        }
        if let Some(g) = next {
            finite_vec("next", g)?;
            if g == points[n - 1] {
                return Err(ShapeError::new("next", "is the chain's last point"));
            }
        }
        // A closed loop (last point on the first, at least a triangle) is smooth at its
        // closing joint too: each end's ghost is the point across the joint.
        let closed = n >= 4 && points[0] == points[n - 1];
        let prev = prev.or(if closed { Some(points[n - 2]) } else { None });
        let next = next.or(if closed { Some(points[1]) } else { None });
        let parts = (0..n - 1)
            .map(|i| {
                Primitive::Segment(Segment {
                    a: points[i],
                    b: points[i + 1],
                    prev: if i == 0 { prev } else { Some(points[i - 1]) },
                    next: points
                        .get(i + 2)
                        .copied()
                        .or(if i + 2 == n { next } else { None }),
                })
            })
            .collect();
        Shape::compound(parts)
    }

    /// Whether this shape is a terrain chain (a compound of segments).
    #[must_use]
    pub fn is_chain(&self) -> bool {
        matches!(self, Shape::Compound(c) if c.parts().iter().all(|p| matches!(p, Primitive::Segment(_))))
    }

    /// The rotation a body at `angle` applies to this shape, skipping the trigonometry when
    /// no part turns with the body.
    #[must_use]
    pub fn rotation(&self, angle: f64) -> crate::Rot {
        if self.primitives().iter().any(Primitive::turns_with_body) {
            crate::Rot::from_angle(angle)
        } else {
            crate::Rot::IDENTITY
        }
    }

    /// Whether this is a single axis-aligned box (what per-axis separation resolves).
    #[must_use]
    pub fn is_single_aabb(&self) -> bool {
        matches!(self, Shape::Primitive(Primitive::Aabb(_)))
    }

    /// The primitives of this shape: one for a primitive, all parts for a compound.
    #[must_use]
    pub fn primitives(&self) -> &[Primitive] {
        match self {
            Shape::Primitive(p) => std::slice::from_ref(p),
            Shape::Compound(c) => c.parts(),
        }
    }

    /// A lower bound on the shape's width in every direction (at any angle): the diameter of
    /// a circle or a capsule, the smaller side of a box, the smallest extent of a polygon
    /// across its edge normals (exact for a convex polygon); for a compound, its narrowest
    /// part. A body moving less than half of it in a frame, from outside an obstacle, cannot
    /// get past the obstacle's middle.
    #[must_use]
    pub fn min_width(&self) -> f64 {
        self.primitives()
            .iter()
            .map(|p| match p {
                Primitive::Circle(c) => 2.0 * c.radius,
                Primitive::Capsule(c) => 2.0 * c.radius,
                // Zero thickness: anything moving may cross it in one frame, so it is swept.
                Primitive::Segment(_) => 0.0,
                Primitive::Aabb(b) => 2.0 * b.half_extents.min_element(),
                Primitive::Obb(b) => 2.0 * b.half_extents.min_element(),
                Primitive::Polygon(g) => g
                    .normals()
                    .iter()
                    .map(|n| {
                        let (lo, hi) = g
                            .vertices()
                            .iter()
                            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                                (lo.min(v.dot(*n)), hi.max(v.dot(*n)))
                            });
                        hi - lo
                    })
                    .fold(f64::INFINITY, f64::min),
            })
            .fold(f64::INFINITY, f64::min)
    }
}
