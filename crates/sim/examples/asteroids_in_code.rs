//! A small Asteroids scene built in code, without a scenario file: a ship fires at a rock,
//! and the game reads the rock's destruction as a typed event.
//!
//! Run it with `cargo run -p ricochet-sim --example asteroids_in_code`.

use ricochet_sim::{
    Action, BodyDef, Controller, Doomed, GameEvent, Layers, Removal, Response, Shape, Simulation,
    Vec2, WorldBounds, WorldDef,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Layers 0, 1, 2: bullets destroy rocks (and themselves); everything else passes through.
    let mut layers = Layers::new(vec!["ship".into(), "rock".into(), "bullet".into()]);
    layers.set(1, 2, Response::Destroy(Doomed::Both));
    // Bullets move further than their size in a frame: their hits are swept.
    layers.set_fast(2);
    let mut sim = Simulation::from_def(WorldDef {
        layers,
        bounds: Some(WorldBounds {
            min: Vec2::new(-50.0, -50.0),
            max: Vec2::new(50.0, 50.0),
            wrap: true,
        }),
        ..WorldDef::default()
    })?;
    sim.add_template(
        "bullet",
        BodyDef {
            name: "bullet".into(),
            layer: 2,
            shape: Shape::circle(0.1)?,
            lifetime: Some(120),
            ..BodyDef::default()
        },
    );
    let ship = sim.spawn(&BodyDef {
        name: "ship".into(),
        layer: 0,
        shape: Shape::circle(1.0)?,
        controller: Some(Controller::Ship {
            thrust: 20.0,
            turn_rate: 3.0,
            bullet: "bullet".into(),
            bullet_speed: 60.0,
            muzzle: 1.5,
        }),
        ..BodyDef::default()
    });
    let rock = sim.spawn(&BodyDef {
        name: "rock".into(),
        layer: 1,
        shape: Shape::circle(2.0)?,
        position: Vec2::new(20.0, 0.0),
        ..BodyDef::default()
    });

    sim.step(); // frame 0: the initial state
    sim.apply(ship, Action::Fire)?; // heading +x (angle 0)
    for _ in 0..60 {
        let out = sim.step();
        for event in &out.events {
            match event {
                GameEvent::Fired { bullet, .. } => {
                    println!("frame {}: bullet {bullet} fired", out.frame);
                }
                GameEvent::Removed {
                    body,
                    cause: Removal::HitBy(by),
                    ..
                } if *body == rock => {
                    // The swept hit's contact: where the bullet first touched the rock.
                    let c = out.contacts.iter().find(|c| c.a == rock || c.b == rock);
                    let x = c.map_or(f64::NAN, |c| c.point.x);
                    println!(
                        "frame {}: rock {body} destroyed by {by}, hit at x = {x:.2}",
                        out.frame
                    );
                    assert!(!sim.contains(rock));
                    return Ok(());
                }
                _ => {}
            }
        }
    }
    Err("the bullet never hit the rock".into())
}
