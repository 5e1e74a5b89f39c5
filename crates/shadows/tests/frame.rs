//! Stencil shadows in the shared frame against exact rays, pixel by pixel (tests/common/frame.rs):
//! a sphere over a ground quad seen from outside every volume; two lights accumulating, each
//! masked by its own stencil count, over an ambient term that stays in shadow — z-fail and
//! z-pass both equal the rays here. The eye inside a volume and the near plane cutting one, where
//! z-pass fails, are in `hard_cases.rs`.

mod common;

use common::frame::*;
use glam::{DVec3, Vec3};
use render::Camera;
use shadows::Light;

#[test]
fn seen_from_outside_every_volume_the_stencil_equals_rays() {
    let camera = Camera::look_at(
        Vec3::new(4.0, 5.0, 6.0),
        Vec3::new(-0.5, 0.0, -0.3),
        Vec3::Y,
        50.0,
        SIZE,
        SIZE,
    );
    check(
        "outside",
        camera,
        &[(sun(), std::f32::consts::PI)],
        0.0,
        true,
    );
}

#[test]
fn two_lights_accumulate_and_the_ambient_term_stays_in_shadow() {
    let camera = Camera::look_at(
        Vec3::new(0.5, 7.0, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        60.0,
        SIZE,
        SIZE,
    );
    let lights = [
        (sun(), 2.0),
        (Light::Point(DVec3::new(-1.5, 5.0, 0.5)), 30.0),
    ];
    check("two lights", camera, &lights, 0.05, true);
}
