//! Vectors, rotations and poses. All trigonometry goes through `libm`.

/// A 2D vector of `f64` (glam's `DVec2`).
pub type Vec2 = glam::DVec2;

/// A rotation stored as its cosine and sine, so that placing a shape costs no trigonometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rot {
    /// `cos(angle)`.
    pub c: f64,
    /// `sin(angle)`.
    pub s: f64,
}

impl Rot {
    /// No rotation.
    pub const IDENTITY: Rot = Rot { c: 1.0, s: 0.0 };

    /// The rotation by `angle` radians, counter-clockwise. Uses `libm`, so the bits are the same
    /// on every platform.
    #[must_use]
    pub fn from_angle(angle: f64) -> Rot {
        if angle == 0.0 {
            return Rot::IDENTITY;
        }
        let (s, c) = sincos(angle);
        Rot { c, s }
    }

    /// Rotates `v` by this rotation.
    #[must_use]
    #[inline]
    pub fn apply(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x - self.s * v.y, self.s * v.x + self.c * v.y)
    }

    /// Rotates `v` by the inverse of this rotation.
    #[must_use]
    #[inline]
    pub fn apply_inverse(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x + self.s * v.y, -self.s * v.x + self.c * v.y)
    }
}

/// Where a shape is: a position and an angle (radians, counter-clockwise).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Pose {
    /// World position of the body origin.
    pub position: Vec2,
    /// Body angle in radians, counter-clockwise.
    pub angle: f64,
}

impl Pose {
    /// A pose at `(x, y)` with no rotation.
    #[must_use]
    pub fn at(x: f64, y: f64) -> Pose {
        Pose {
            position: Vec2::new(x, y),
            angle: 0.0,
        }
    }

    /// A pose at `position` turned by `angle` radians.
    #[must_use]
    pub fn new(position: Vec2, angle: f64) -> Pose {
        Pose { position, angle }
    }
}

/// `a.x * b.y - a.y * b.x`: the z of the 3D cross product (glam calls it `perp_dot`).
#[inline]
#[must_use]
pub(crate) fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The vector turned a quarter turn clockwise: for a counter-clockwise polygon edge this is
/// the outward direction.
#[inline]
#[must_use]
pub(crate) fn right_perp(v: Vec2) -> Vec2 {
    Vec2::new(v.y, -v.x)
}

/// `(sin, cos)` through `libm`: the same bits on every platform.
#[cfg(not(feature = "gate-self-test-std-sin"))]
fn sincos(angle: f64) -> (f64, f64) {
    libm::sincos(angle)
}

/// The determinism gate's self-test only (`scripts/determinism-gate.sh --self-test`): the
/// platform's `sin_cos` for every rotated shape, which glibc and wasm32 round differently
/// for some angles, so the gate must fail. Never on in a real build.
#[cfg(feature = "gate-self-test-std-sin")]
#[expect(
    clippy::disallowed_methods,
    reason = "the gate's self-test puts platform trigonometry in on purpose"
)]
fn sincos(angle: f64) -> (f64, f64) {
    angle.sin_cos()
}
