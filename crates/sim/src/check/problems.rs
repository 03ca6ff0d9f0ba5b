//! The problems the scenario loader and [`crate::Scenario::check`] find in a definition,
//! worded once: both report the same words for the same value, a file with its
//! `file:line:column`, a scene built in code with its field path.

use std::collections::BTreeMap;

use ricochet_geom::{Number, Numbers};

use crate::def::{
    BodyDef, BodyKind, Controller, MAX_CONTROLLER_VALUE, MAX_MASS, MIN_MASS, WorldDef,
    controller_out_of_range,
};

/// The most bodies that destroying one body can create through its split chain (its
/// children, their children when destroyed, and so on). Asteroids' big → 2 medium → 4 small
/// is 6; a chain past this is almost surely a mistake, and it would multiply bodies past
/// what a frame can hold.
pub(crate) const MAX_SPLIT_BODIES: u64 = 65_536;

/// What is wrong with the templates' split chains.
pub(crate) enum SplitProblem {
    /// `path` (from the template back to itself) is a cycle.
    Cycle(Vec<String>),
    /// Destroying one body of the template creates this many bodies, down the chain.
    TooMany(u64),
}

/// Checks every template's split chain once (a depth-first search that visits each
/// template a single time, so a chain of 40 templates splitting in two costs 40 visits, not
/// 2^40): a template on a cycle (the first one found, starting from the templates in name
/// order), or the first template in name order whose chain creates more than
/// [`MAX_SPLIT_BODIES`] bodies, with the problem worded for `templates.{name}.split`.
pub(crate) fn split_problem(templates: &BTreeMap<String, BodyDef>) -> Option<(String, String)> {
    // Bodies created by destroying one body of each finished template (saturating).
    let mut created: BTreeMap<&str, u64> = BTreeMap::new();
    for start in templates.keys() {
        // Iterative DFS: (template, next child to visit); `path` is the grey stack.
        let mut path: Vec<(&str, usize)> = vec![(start.as_str(), 0)];
        while let Some(&mut (at, ref mut next)) = path.last_mut() {
            if created.contains_key(at) {
                path.pop();
                continue;
            }
            let children = templates.get(at).map_or(&[][..], |t| &t.split[..]);
            if let Some(child) = children.get(*next) {
                *next += 1;
                let c = child.template.as_str();
                if let Some(k) = path.iter().position(|(t, _)| *t == c) {
                    let mut cycle: Vec<String> =
                        path[k..].iter().map(|(t, _)| (*t).to_owned()).collect();
                    cycle.push(c.to_owned());
                    return Some((c.to_owned(), split_words(c, SplitProblem::Cycle(cycle))));
                }
                if !created.contains_key(c) {
                    path.push((c, 0));
                }
                continue;
            }
            let total = children.iter().fold(0u64, |sum, child| {
                let below = created.get(child.template.as_str()).copied().unwrap_or(0);
                sum.saturating_add(below.saturating_add(1))
            });
            created.insert(at, total);
            path.pop();
        }
        let total = created.get(start.as_str()).copied().unwrap_or(0);
        if total > MAX_SPLIT_BODIES {
            return Some((
                start.clone(),
                split_words(start, SplitProblem::TooMany(total)),
            ));
        }
    }
    None
}

fn split_words(name: &str, problem: SplitProblem) -> String {
    match problem {
        SplitProblem::Cycle(path) => format!(
            "{} splits into itself: a split chain must end",
            path.join(" -> ")
        ),
        SplitProblem::TooMany(n) => format!(
            "destroying one {name} creates {} bodies down its split chain; at most \
             {MAX_SPLIT_BODIES} are allowed",
            if n == u64::MAX {
                "more than 2^64".to_owned()
            } else {
                n.to_string()
            }
        ),
    }
}

/// `unknown {what} "{name}"; known: ...` (`none` when nothing is known).
pub(crate) fn unknown_problem<'a>(
    what: &str,
    name: &str,
    known: impl Iterator<Item = &'a String>,
) -> String {
    let known: Vec<&str> = known.map(String::as_str).collect();
    format!(
        "unknown {what} \"{name}\"; known: {}",
        if known.is_empty() {
            "none".to_owned()
        } else {
            known.join(", ")
        }
    )
}

/// What a script event naming `name` is told when no body, template or spawn has that name
/// (`known`: every such name, sorted).
pub(crate) fn no_such_name(name: &str, known: &[&str]) -> String {
    format!(
        "no body, template or spawn is named \"{name}\"; known: {}",
        known.join(", ")
    )
}

/// The problem with a dynamic body's mass, if any: not finite, not positive, or outside
/// [`MIN_MASS`] to [`MAX_MASS`].
pub(crate) fn mass_problem(mass: f64) -> Option<String> {
    if !mass.is_finite() {
        return Some(format!("must be a finite number, got {}", Number(mass)));
    }
    if mass <= 0.0 {
        return Some(format!("must be greater than 0, got {}", Number(mass)));
    }
    (!(MIN_MASS..=MAX_MASS).contains(&mass)).then(|| {
        format!(
            "{} is outside {MIN_MASS:e} to {MAX_MASS:e}, the masses Ricochet \
             accepts (a heavier body's kinetic energy overflows, a lighter one's \
             velocity after a push)",
            Number(mass)
        )
    })
}

/// The first of a controller's values that is past [`MAX_CONTROLLER_VALUE`], as
/// `(field, problem)` (the field is `controller.{name}`).
pub(crate) fn controller_problem(c: &Controller) -> Option<(String, String)> {
    let (f, v) = controller_out_of_range(c)?;
    let problem = if v.is_finite() {
        format!(
            "{} is beyond ±{MAX_CONTROLLER_VALUE:e}, the largest controller value Ricochet \
             accepts (a faster bullet only makes every frame's swept tests longer)",
            Number(v)
        )
    } else {
        format!("must be a finite number, got {}", Number(v))
    };
    Some((format!("controller.{f}"), problem))
}

/// The problem with a static `def` placed outside a wrapping world, if any: a static body
/// is never wrapped (it never moves), so one outside would be met only at its images one
/// world size away, not where the rule "contacts are those of the scene wrapped into the
/// world" puts it.
pub(crate) fn static_outside(world: &WorldDef, def: &BodyDef) -> Option<String> {
    let bounds = world.bounds?;
    let p = def.position;
    let inside = (0..2).all(|axis| bounds.min[axis] <= p[axis] && p[axis] <= bounds.max[axis]);
    (bounds.wrap && def.kind == BodyKind::Static && !inside).then(|| {
        format!(
            "{} is outside the wrap-around world {} to {}: a static body never moves, so \
             it is never wrapped; place it inside the world",
            Numbers([p.x, p.y]),
            Numbers([bounds.min.x, bounds.min.y]),
            Numbers([bounds.max.x, bounds.max.y])
        )
    })
}

/// The problem with `def` in a wrapping world it is too large for
/// ([`crate::WorldBounds::oversized`]), if any.
pub(crate) fn oversized(world: &WorldDef, def: &BodyDef) -> Option<String> {
    let bounds = world.bounds?;
    let reach = bounds.oversized(&def.shape)?;
    let size = bounds.size();
    Some(format!(
        "the shape reaches {} along x and {} along y from the body's position (at some \
         angle), more than half the {} x {} wrap-around world: a body in a wrapping world \
         must reach at most half its width and height, so that the wrap seam meets its \
         deepest image (make the shape smaller or the world larger)",
        Number(reach.x),
        Number(reach.y),
        Number(size.x),
        Number(size.y)
    ))
}

/// The problem with a position past the coordinates the geometry accepts, if any.
pub(crate) fn beyond_world(p: [f64; 2]) -> Option<String> {
    (p.iter().any(|x| x.abs() > ricochet_geom::MAX_COORDINATE)).then(|| {
        format!(
            "{} is beyond ±{:e}, the largest coordinate Ricochet accepts",
            Numbers(p),
            ricochet_geom::MAX_COORDINATE
        )
    })
}

/// The problem when more than one body of `bodies` has the name `name` that something
/// addresses (`purpose`: what must name one body), `None` otherwise. `sorted` holds every
/// body's `(name, index)`, sorted.
pub(crate) fn shared_name(sorted: &[(&str, usize)], name: &str, purpose: &str) -> Option<String> {
    let from = sorted.partition_point(|(n, _)| *n < name);
    let to = sorted.partition_point(|(n, _)| *n <= name);
    let same = &sorted[from..to];
    (same.len() > 1).then(|| {
        let list: Vec<String> = same.iter().map(|(_, i)| format!("bodies[{i}]")).collect();
        format!(
            "{} bodies are named \"{name}\" ({}): name {purpose} apart from the others",
            same.len(),
            list.join(", ")
        )
    })
}

/// Every body's `(name, index)`, sorted: what [`shared_name`] searches.
pub(crate) fn names_sorted(bodies: &[BodyDef]) -> Vec<(&str, usize)> {
    let mut v: Vec<(&str, usize)> = bodies
        .iter()
        .enumerate()
        .map(|(i, b)| (b.name.as_str(), i))
        .collect();
    v.sort_unstable();
    v
}
