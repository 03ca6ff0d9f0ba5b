//! Rapier's pipelines as the referee and the bench both set them up: one layer filter (the
//! layer matrix as rapier's pair filter, for any number of layers) and one reading of a
//! penetrating pair.

use rapier2d_f64::prelude::{
    ActiveHooks, Collider, ColliderBuilder, ContactPair, Group, InteractionGroups,
    InteractionTestMode, PairContacts, PairFilterContext, PhysicsHooks, SolverFlags,
};
use ricochet_sim::{LayerId, Layers, Response};

/// How many layers rapier's collision groups can tell apart (`Group` is 32 bits).
pub const RAPIER_GROUPS: usize = 32;

/// Ricochet's layer matrix as rapier's pair filter: a pair is tested exactly when its layers'
/// response is not `ignore`.
///
/// With at most [`RAPIER_GROUPS`] layers, every collider gets collision groups (membership =
/// its layer's bit, filter = every layer it does not ignore), which rapier's broad phase
/// applies for free. With more, group bits cannot name every layer: colliders get no groups
/// and ask for the contact-pair hook instead, and this filter, passed to the pipeline as its
/// [`PhysicsHooks`], looks the pair's layers up in the matrix. Either way every collider's
/// `user_data` carries its layer (high 64 bits) and the caller's index (low 64 bits).
#[derive(Clone, Copy, Debug)]
pub struct LayerFilter<'a> {
    layers: &'a Layers,
}

impl<'a> LayerFilter<'a> {
    /// The filter of a layer matrix.
    #[must_use]
    pub fn new(layers: &'a Layers) -> LayerFilter<'a> {
        LayerFilter { layers }
    }

    /// Whether this matrix fits rapier's collision groups (else the hook filters).
    #[must_use]
    pub fn uses_groups(&self) -> bool {
        self.layers.names().len() <= RAPIER_GROUPS
    }

    /// `builder` for a collider of a body of `layer`, numbered `index` by the caller: its
    /// `user_data`, and its groups or its request for the filter hook.
    pub fn collider(
        &self,
        builder: ColliderBuilder,
        layer: LayerId,
        index: usize,
    ) -> ColliderBuilder {
        let builder = builder.user_data((u128::from(layer) << 64) | index as u128);
        if !self.uses_groups() {
            return builder.active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS);
        }
        let mut filter = 0u32;
        for other in 0..self.layers.names().len() {
            let other = LayerId::try_from(other).unwrap_or(LayerId::MAX);
            if !matches!(
                self.layers.response(layer, other),
                // One-way platforms are the referee's blind spot: left out (docs/validation.md).
                Response::Ignore | Response::OneWay(_)
            ) {
                filter |= 1 << other;
            }
        }
        builder.collision_groups(InteractionGroups::new(
            Group::from_bits_retain(1 << layer),
            Group::from_bits_retain(filter),
            InteractionTestMode::And,
        ))
    }
}

/// The caller's index of a collider built by [`LayerFilter::collider`].
#[must_use]
pub fn index(collider: &Collider) -> usize {
    (collider.user_data & u128::from(u64::MAX)) as usize
}

/// The layer of a collider built by [`LayerFilter::collider`].
fn layer(collider: &Collider) -> Option<LayerId> {
    LayerId::try_from(collider.user_data >> 64).ok()
}

impl PhysicsHooks for LayerFilter<'_> {
    fn filter_contact_pair(&self, ctx: &PairFilterContext) -> Option<SolverFlags> {
        let layer = |h| ctx.colliders.get(h).and_then(layer);
        let (a, b) = (layer(ctx.collider1)?, layer(ctx.collider2)?);
        (!matches!(
            self.layers.response(a, b),
            Response::Ignore | Response::OneWay(_)
        ))
        .then_some(SolverFlags::default())
    }
}

/// A pair's smallest contact-point distance when it is negative (the pair penetrates):
/// minus its depth. `None` for a pair that only touches or whose points are all apart.
#[must_use]
pub fn penetration(pair: &ContactPair) -> Option<f64> {
    let PairContacts::Rigid(rigid) = &pair.contacts else {
        return None;
    };
    let dist = rigid
        .manifolds
        .iter()
        .flat_map(|m| m.points.iter())
        .map(|p| p.dist)
        .fold(f64::INFINITY, f64::min);
    (dist < 0.0).then_some(dist)
}
