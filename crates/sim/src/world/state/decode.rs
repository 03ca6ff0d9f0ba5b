//! Reading a snapshot's bodies back: what [`World::encode`] wrote, decoded against the
//! baseline and checked (every baseline body accounted for, ids in order and live, layers
//! in range, every carrier alive) before anything is put in a world (`restore.rs`).

use super::*;
use crate::def::{MAX_CONTROLLER_VALUE, MAX_MASS, MIN_MASS, controller_out_of_range};
use crate::snapshot::codec::Reader;

fn bad(what: &str) -> SnapshotError {
    SnapshotError::malformed(what)
}

impl World {
    /// Reads what [`World::encode`] wrote against `base` (with `game_data`), checked against
    /// it: every baseline body accounted for, ids in order and live, layers below `layers`.
    pub(crate) fn decode(
        r: &mut Reader,
        base: &World,
        layers: usize,
    ) -> Result<Bodies, SnapshotError> {
        let mut b = Bodies::default();
        let m = base.len();
        let mut j = 0usize;
        loop {
            let tag = r.u8()?;
            match tag {
                KEEP | DROP => {
                    let n = usize::try_from(r.var()?).unwrap_or(usize::MAX);
                    if n == 0 || n > m - j {
                        return Err(bad("a run of bodies past the baseline's"));
                    }
                    if tag == KEEP {
                        for k in j..j + n {
                            b.entries.push(Entry {
                                base: k as u32,
                                mask: 0,
                                at: 0,
                            });
                            b.entities.push(base.entity[k]);
                        }
                    }
                    j += n;
                }
                WHOLE => {
                    let w = read_whole(r, layers)?;
                    if base.entity.get(j) == Some(&w.entity) {
                        j += 1;
                        b.redefined = true;
                    }
                    b.entities.push(w.entity);
                    b.entries.push(Entry {
                        base: u32::MAX,
                        mask: 0,
                        at: b.wholes.len() as u32,
                    });
                    b.wholes.push(w);
                }
                END => break,
                t if t & CHANGED != 0 => {
                    let mask = t & !CHANGED;
                    if j >= m {
                        return Err(bad("a changed body past the baseline's"));
                    }
                    if mask & group::ROW != 0 && base.row[j] == NO_ROW {
                        return Err(bad("moving state for scenery"));
                    }
                    let d = read_groups(r, mask, &mut b.motions)?;
                    b.entities.push(base.entity[j]);
                    b.entries.push(Entry {
                        base: j as u32,
                        mask,
                        at: b.deltas.len() as u32,
                    });
                    b.deltas.push(d);
                    j += 1;
                }
                _ => return Err(bad("a body's tag")),
            }
        }
        if j != m {
            return Err(bad("baseline bodies neither kept nor dropped"));
        }
        if b.entities.windows(2).any(|p| p[0].index >= p[1].index) {
            return Err(bad("bodies out of id order"));
        }
        let n = r.u32()? as usize;
        let changed = r.len(5)?;
        let mut g = base.ids.generations().to_vec();
        // Every slot past the baseline's is listed: a damaged count reserves nothing more.
        if n > g.len() + changed {
            return Err(bad("more id slots than generations"));
        }
        g.resize(n, 0);
        let mut k = 0usize;
        for c in 0..changed {
            let gap = usize::try_from(r.var()?).unwrap_or(usize::MAX);
            k = k.saturating_add(gap);
            if (c > 0 && gap == 0) || k >= n {
                return Err(bad("a generation's slot"));
            }
            g[k] = r.u32()?;
        }
        if b.entities
            .iter()
            .any(|e| g.get(e.index as usize) != Some(&e.generation))
        {
            return Err(bad("a body's generation is not its slot's"));
        }
        b.generations = g;
        // Every carrier a live body.
        for (k, e) in b.entries.iter().enumerate() {
            let carrier = match (e.base, e.mask & group::MOTION != 0) {
                (u32::MAX, _) => b.wholes[e.at as usize]
                    .row
                    .as_ref()
                    .and_then(|w| w.motion.carrier),
                (_, true) => b.motion(&b.deltas[e.at as usize]).carrier,
                (j, false) => base.carrier(j as usize),
            };
            if carrier.is_some_and(|c| b.entities.binary_search(&c).is_err()) {
                return Err(bad(&format!("body {k}'s carrier is not a live body")));
            }
        }
        check_values(&b)?;
        Ok(b)
    }
}

/// What the loader would refuse in a restored body (issue #34: a snapshot whose
/// `bullet_speed` was flipped from 30 to 5.5e20, its checksum recomputed, restored and made
/// each step take a second): every number finite, a mass within [`MIN_MASS`] to
/// [`MAX_MASS`], a controller's values within [`MAX_CONTROLLER_VALUE`], inputs within
/// -1 to 1. Positions and velocities are only required to be finite: a run may carry a
/// body past the loader's ±1e15 (an unbounded world, a velocity of 1e146), and its
/// snapshot must restore. The world settings (`dt`, gravity, bounds) are not in a snapshot:
/// its scene hash must match the simulation's.
fn check_values(b: &Bodies) -> Result<(), SnapshotError> {
    let finite = |what: &str, ok: bool| if ok { Ok(()) } else { Err(bad(what)) };
    let motion = |m: &Motion| -> Result<(), SnapshotError> {
        finite("a body's force is not finite", m.force.is_finite())?;
        let input = |x: f64| (-1.0..=1.0).contains(&x);
        finite(
            "a body's input is not within -1 to 1",
            input(m.inputs.turn) && input(m.inputs.run),
        )?;
        if let Some((f, v)) = m.controller.as_ref().and_then(controller_out_of_range) {
            return Err(bad(&format!(
                "controller.{f} = {} is beyond ±{MAX_CONTROLLER_VALUE:e}, the loader's limit",
                ricochet_geom::Number(v)
            )));
        }
        Ok(())
    };
    for d in &b.deltas {
        finite("a body's position is not finite", d.position.is_finite())?;
        finite("a body's angle is not finite", d.angle.is_finite())?;
        finite("a body's velocity is not finite", d.velocity.is_finite())?;
        finite(
            "a body's angular velocity is not finite",
            d.spin.is_finite(),
        )?;
    }
    for m in &b.motions {
        motion(m)?;
    }
    for w in &b.wholes {
        finite("a body's position is not finite", w.position.is_finite())?;
        finite("a body's angle is not finite", w.angle.is_finite())?;
        let Some(row) = &w.row else { continue };
        if !(MIN_MASS..=MAX_MASS).contains(&row.mass) {
            return Err(bad(&format!(
                "mass = {} is outside {MIN_MASS:e} to {MAX_MASS:e}, the loader's limits",
                ricochet_geom::Number(row.mass)
            )));
        }
        finite("a body's velocity is not finite", row.velocity.is_finite())?;
        finite(
            "a body's angular velocity is not finite",
            row.spin.is_finite(),
        )?;
        finite(
            "a body's gravity scale is not finite",
            row.gravity_scale.is_finite(),
        )?;
        finite(
            "a split's offset or velocity is not finite",
            row.split
                .iter()
                .all(|s| s.offset.is_finite() && s.velocity.is_finite()),
        )?;
        motion(&row.motion)?;
    }
    Ok(())
}

fn read_lifetime(r: &mut Reader) -> Result<Option<u32>, SnapshotError> {
    Ok(if r.bool()? { Some(r.u32()?) } else { None })
}

fn read_motion(r: &mut Reader) -> Result<Motion, SnapshotError> {
    Ok(Motion {
        force: r.vec2()?,
        controller: r.controller()?,
        inputs: r.inputs()?,
        grounded: r.bool()?,
        on_static: r.bool()?,
        carrier: r.opt_entity()?,
        still: r.bool()?,
        frozen: r.bool()?,
        asleep: r.bool()?,
        rest_frames: r.u32()?,
        user_data: r.u128()?,
    })
}

fn read_groups(
    r: &mut Reader,
    mask: u8,
    motions: &mut Vec<Motion>,
) -> Result<Delta, SnapshotError> {
    let mut d = Delta::default();
    if mask & group::POSITION != 0 {
        d.position = r.vec2()?;
    }
    if mask & group::ANGLE != 0 {
        d.angle = r.f64()?;
    }
    if mask & group::VELOCITY != 0 {
        d.velocity = r.vec2()?;
    }
    if mask & group::SPIN != 0 {
        d.spin = r.f64()?;
    }
    if mask & group::LIFETIME != 0 {
        d.lifetime = read_lifetime(r)?;
    }
    if mask & group::MOTION != 0 {
        d.motion = motions.len() as u32;
        motions.push(read_motion(r)?);
    }
    Ok(d)
}

fn read_whole(r: &mut Reader, layers: usize) -> Result<Whole, SnapshotError> {
    let entity = r.entity()?;
    let layer = r.u8()?;
    if usize::from(layer) >= layers {
        return Err(bad("a body's layer"));
    }
    let kind = match r.u8()? {
        0 => BodyKind::Dynamic,
        1 => BodyKind::Static,
        2 => BodyKind::Kinematic,
        _ => return Err(bad("a body's kind")),
    };
    let mut w = Whole {
        entity,
        layer,
        kind,
        position: r.vec2()?,
        angle: r.f64()?,
        shape: r.shape()?,
        name: r.str()?,
        row: None,
    };
    if !r.bool()? {
        let def = BodyDef {
            kind,
            ..BodyDef::default()
        };
        if !World::makes_scenery(&def) {
            return Err(bad("scenery that is not static"));
        }
        return Ok(w);
    }
    w.row = Some(WholeRow {
        mass: r.f64()?,
        velocity: r.vec2()?,
        spin: r.f64()?,
        gravity_scale: r.f64()?,
        lifetime: read_lifetime(r)?,
        split: r.splits()?,
        motion: read_motion(r)?,
        turned: r.bool()?,
    });
    Ok(w)
}
