//! Ricochet's layer matrix as Box2D collision filters.
//!
//! Box2D tests a pair when `(a.category & b.mask) != 0 && (b.category & a.mask) != 0`, in its
//! broad phase, before a contact exists. A shape of layer `l` gets category `1 << l` and a mask
//! with the bit of every layer whose response with `l` is not `ignore`: the matrix is
//! symmetric, so a pair passes exactly when Ricochet's response is not `ignore`, and layers
//! that ignore each other are never tested. Box2D's bits are 64 wide; a scene with more layers
//! would need a custom filter callback and is refused instead (the bench scenes have three at
//! most).

use boxdd::Filter;
use ricochet_sim::{LayerId, Layers, Response};

use crate::Box2dError;

/// How many layers Box2D's category bits can tell apart.
pub const BOX2D_LAYERS: usize = 64;

/// The Box2D filter of a shape on `layer`.
pub(crate) fn layer_filter(layers: &Layers, layer: LayerId) -> Result<Filter, Box2dError> {
    let count = layers.names().len();
    if count > BOX2D_LAYERS {
        return Err(Box2dError::Conversion(format!(
            "{count} layers: Box2D's collision filter has {BOX2D_LAYERS} category bits"
        )));
    }
    let mut mask = 0u64;
    for other in 0..count {
        let other = LayerId::try_from(other).unwrap_or(LayerId::MAX);
        if !matches!(
            layers.response(layer, other),
            // Box2D's filter can't say one-way: the pair is left out, as the referee does.
            Response::Ignore | Response::OneWay(_)
        ) {
            mask |= 1 << other;
        }
    }
    Ok(Filter {
        category_bits: 1 << layer,
        mask_bits: mask,
        group_index: 0,
    })
}
