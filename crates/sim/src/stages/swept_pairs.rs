//! `detect`'s swept pairs (a layer in `fast_layers`, or `sweep = true` on a `[[collide]]`
//! entry; `report` and `destroy` only): each pair's first touch by time of impact over the
//! frame's straight motion (through the wrap seam, or along a path longer than the world:
//! `far_path.rs`), then each moving body's hits in time order, responded to by `detect`'s
//! `respond` until one destroys it.

use ricochet_geom::{Contact, Pose, Sweep, time_of_impact};

use crate::entity::Entity;
use crate::output::Phase;
use crate::stages::StageCtx;
use crate::stages::detect::respond;
use crate::stages::far_path;
use crate::stages::push::Statics;
use crate::stages::wrap::Seam;

/// Swept pairs: each pair's first touch along the frame's motion, then, per moving body,
/// its hits in time order, stopping at the first hit that destroys it. So a bullet hits the
/// first rock on its path and no other, however fast it goes.
pub(super) fn run_swept(
    ctx: &mut StageCtx,
    push_statics: &mut Statics,
    doomed: &mut Vec<(Entity, Entity)>,
    swept: &[(usize, usize)],
    seam: &Seam,
    woken: &mut Vec<usize>,
) {
    let layers = &ctx.def.layers;
    struct Hit {
        mover: Entity,
        toi: f64,
        pair: (usize, usize),
        contact: Contact,
        poses: (Pose, Pose),
    }
    let mut hits = Vec::new();
    let wrap = ctx.def.bounds.filter(|b| b.wrap);
    let mut offsets = Vec::new();
    let mut budget = far_path::CastBudget::new();
    for &(i, j) in swept {
        ctx.out.stats.narrow_tests += 1;
        let w = &ctx.world;
        // Straight from the frame's start to its end, at the end angles.
        let sweep = |k: usize| Sweep {
            start: w.start_position(k),
            end: w.position[k],
            angle: w.angle[k],
        };
        let mut first = time_of_impact(w.shape(i), &sweep(i), w.shape(j), &sweep(j));
        // Along a path longer than the world, the images it meets in time order
        // (`far_path.rs`); otherwise through the seam: `b`'s images next to `a`, the
        // earliest (the first on a tie).
        let far = wrap.is_some_and(|b| {
            far_path::earliest(
                &b,
                (w.shape(i), &sweep(i)),
                (w.shape(j), &sweep(j)),
                &mut first,
                &mut budget,
                &mut ctx.out.stats.narrow_tests,
            )
        });
        offsets.clear();
        if !far {
            offsets.extend(seam.offsets(i, j));
        }
        for &offset in &offsets {
            ctx.out.stats.narrow_tests += 1;
            let image = Sweep {
                start: w.start_position(j) + offset,
                end: w.position[j] + offset,
                angle: w.angle[j],
            };
            let hit = time_of_impact(w.shape(i), &sweep(i), w.shape(j), &image);
            if let Some(h) = hit
                && first.as_ref().is_none_or(|f| h.t < f.t)
            {
                first = Some(h);
            }
        }
        if let Some(impact) = first {
            // The mover is the body that went further: a bullet against a drifting rock.
            let travel = |k: usize| (w.position[k] - w.start_position(k)).length();
            let mover = if travel(j) > travel(i) {
                w.entity[j]
            } else {
                w.entity[i]
            };
            hits.push(Hit {
                mover,
                toi: impact.t,
                pair: (i, j),
                contact: impact.contact,
                poses: (impact.pose_a, impact.pose_b),
            });
        }
    }
    // Per mover, earliest first; ties by the pair's ids (dense order is id order).
    hits.sort_by(|a, b| {
        a.mover
            .cmp(&b.mover)
            .then(a.toi.total_cmp(&b.toi))
            .then(a.pair.cmp(&b.pair))
    });
    let mut spent: Vec<Entity> = Vec::new();
    for hit in hits {
        if spent.contains(&hit.mover) {
            continue;
        }
        let w = &ctx.world;
        let response = layers.response(w.layer[hit.pair.0], w.layer[hit.pair.1]);
        woken.extend(
            [hit.pair.0, hit.pair.1]
                .into_iter()
                .filter(|&k| w.asleep(k)),
        );
        let before = doomed.len();
        respond(
            ctx,
            (doomed, push_statics),
            hit.pair,
            response,
            Phase::Swept,
            hit.contact,
            hit.poses,
        );
        if doomed[before..].iter().any(|(e, _)| *e == hit.mover) {
            spent.push(hit.mover);
        }
    }
}
