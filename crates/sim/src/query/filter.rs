//! [`QueryFilter`]: which bodies a scene query sees.

use crate::def::LayerId;
use crate::entity::Entity;

/// Which bodies a query sees: layers (all by default) and one entity left out (Box2D's
/// `b2QueryFilter`, rapier's `QueryFilter::exclude_rigid_body`).
#[derive(Clone, Debug, PartialEq)]
pub struct QueryFilter {
    /// Bit `l` set: layer `l` is seen (256 bits: a [`LayerId`] is a `u8`).
    mask: [u64; 4],
    /// The body left out, if any.
    exclude: Option<Entity>,
}

impl Default for QueryFilter {
    fn default() -> Self {
        QueryFilter {
            mask: [u64::MAX; 4],
            exclude: None,
        }
    }
}

impl QueryFilter {
    /// Every body of every layer (the default).
    #[must_use]
    pub fn all() -> Self {
        QueryFilter::default()
    }

    /// Only the bodies of these layers (none for an empty slice).
    #[must_use]
    pub fn layers(layers: &[LayerId]) -> Self {
        let mut mask = [0; 4];
        for &l in layers {
            mask[usize::from(l >> 6)] |= 1 << (l & 63);
        }
        QueryFilter {
            mask,
            exclude: None,
        }
    }

    /// The same filter, leaving `e` out too (a shooter's own body); replaces an earlier
    /// exclusion.
    #[must_use]
    pub fn exclude(self, e: Entity) -> Self {
        QueryFilter {
            exclude: Some(e),
            ..self
        }
    }

    /// Whether a body `e` of `layer` is seen.
    #[must_use]
    pub fn accepts(&self, layer: LayerId, e: Entity) -> bool {
        self.accepts_layer(layer) && self.exclude != Some(e)
    }

    /// Whether bodies of `layer` are seen (before the exclusion).
    #[must_use]
    pub(crate) fn accepts_layer(&self, layer: LayerId) -> bool {
        self.mask[usize::from(layer >> 6)] & (1 << (layer & 63)) != 0
    }
}
