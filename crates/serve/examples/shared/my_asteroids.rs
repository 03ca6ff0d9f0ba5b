//! The level of `serve_game.rs`, built in code; shared with `tests/serve_game.rs`.

use ricochet_sim::{
    BodyDef, Controller, Doomed, Layers, Response, Scenario, Shape, Vec2, WorldBounds, WorldDef,
};

/// The game's level, built in code: a ship the player flies (layer 0), rocks (1) its bullets
/// (2) destroy, in a wrapping 100 × 100 world.
pub fn level() -> Result<Scenario, Box<dyn std::error::Error>> {
    let mut layers = Layers::new(vec!["ship".into(), "rock".into(), "bullet".into()]);
    layers.set(1, 2, Response::Destroy(Doomed::Both));
    layers.set_fast(2);
    let bullet = BodyDef {
        name: "bullet".into(),
        layer: 2,
        shape: Shape::circle(0.1)?,
        lifetime: Some(90),
        ..BodyDef::default()
    };
    let mut bodies = vec![BodyDef {
        name: "ship".into(),
        shape: Shape::circle(1.0)?,
        controller: Some(Controller::Ship {
            thrust: 20.0,
            turn_rate: 3.0,
            bullet: "bullet".into(),
            bullet_speed: 60.0,
            muzzle: 1.5,
        }),
        ..BodyDef::default()
    }];
    for (i, (x, y)) in [(20.0, 5.0), (-15.0, 25.0), (10.0, -30.0)]
        .into_iter()
        .enumerate()
    {
        bodies.push(BodyDef {
            name: format!("rock{i}"),
            layer: 1,
            shape: Shape::circle(3.0)?,
            position: Vec2::new(x, y),
            velocity: Vec2::new(-y / 10.0, x / 10.0),
            angular_velocity: 0.5,
            ..BodyDef::default()
        });
    }
    Ok(Scenario {
        name: "my-asteroids".into(),
        world: WorldDef {
            layers,
            bounds: Some(WorldBounds {
                min: Vec2::new(-50.0, -50.0),
                max: Vec2::new(50.0, 50.0),
                wrap: true,
            }),
            ..WorldDef::default()
        },
        templates: [("bullet".to_owned(), bullet)].into(),
        bodies,
        ..Scenario::default()
    })
}
