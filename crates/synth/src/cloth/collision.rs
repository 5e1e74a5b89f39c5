//! Collision of cloth vertices with the obstacle and the ground, with Coulomb friction.
//!
//! A penetrating vertex is projected to the surface (plus the collision margin). Friction
//! is positional (Macklin et al., "Unified Particle Physics for Real-Time Applications",
//! 2014, §6.1): tangential motion is removed up to `μ · depth`, the positional analogue of
//! `|f_t| ≤ μ |f_n|`, so a vertex sticks while the normal push is large against its slip
//! and slides (decelerated) otherwise.
//!
//! Deviation: the motion friction acts on is the *inertial* step of the substep (velocity
//! and gravity, `x̃ − x_prev`), not the full displacement. Removing constraint corrections
//! too (as Macklin et al. do) lets stiff bending press vertices into the obstacle, which
//! buys so much friction that one-iteration stretch corrections are undone every substep:
//! the default drape froze with edges stretched 18% on top of the sphere.

use super::params::{ClothParams, Obstacle};
use glam::{Vec3, Vec3A};

/// Below this distance from the sphere centre the push-out direction is undefined; +Y is
/// used instead.
const CENTRE_EPSILON: f32 = 1e-12;

/// The obstacle and ground in the obstacle-centred simulation frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Colliders {
    /// Sphere radius plus margin (the sphere is centred on the frame origin).
    sphere_radius: f32,
    /// Ground height plus margin, in the local frame.
    ground: Option<f32>,
    friction: f32,
}

impl Colliders {
    pub(crate) fn new(params: &ClothParams) -> Self {
        let margin = params.collision_margin;
        let anchor_y = f64::from(params.obstacle.anchor().y);
        let sphere_radius = match params.obstacle {
            Obstacle::Sphere { radius, .. } => radius + margin,
        };
        let ground = params
            .ground_height
            .map(|g| (f64::from(g) - anchor_y) as f32 + margin);
        Self {
            sphere_radius,
            ground,
            friction: params.friction,
        }
    }

    /// `p` moved to the nearest admissible point (no friction).
    #[inline]
    pub(crate) fn push_out(&self, p: Vec3A) -> Vec3A {
        let mut q = p;
        self.collide(&mut q, Vec3A::ZERO);
        q
    }

    /// [`Colliders::push_out`] for the initial placement.
    pub(crate) fn push_out_vec3(&self, p: Vec3) -> Vec3 {
        self.push_out(p.into()).into()
    }

    /// Resolves the collision of a vertex at `p` whose inertial step this substep was
    /// `inertial` (`v Δt` after gravity and damping).
    #[inline]
    pub(crate) fn collide(&self, p: &mut Vec3A, inertial: Vec3A) {
        let r = self.sphere_radius;
        let d2 = p.length_squared();
        if d2 < r * r {
            let d = d2.sqrt();
            let normal = if d > CENTRE_EPSILON { *p / d } else { Vec3A::Y };
            *p = normal * r;
            friction(p, inertial, normal, r - d, self.friction);
        }
        if let Some(ground) = self.ground.filter(|g| p.y < *g) {
            let depth = ground - p.y;
            p.y = ground;
            friction(p, inertial, Vec3A::Y, depth, self.friction);
            if p.length_squared() < r * r {
                self.out_of_wedge(p, ground);
            }
        }
    }

    /// A sphere standing on (or sunk into) the ground leaves no admissible point near the
    /// contact: the nearest admissible one is on the circle where the ground plane leaves
    /// the sphere. Moves `p` (on the ground plane, inside the sphere) there.
    #[cold]
    fn out_of_wedge(&self, p: &mut Vec3A, ground: f32) {
        let r = self.sphere_radius;
        let circle = (r * r - ground * ground).max(0.0).sqrt();
        let horizontal = Vec3A::new(p.x, 0.0, p.z);
        let direction = horizontal.try_normalize().unwrap_or(Vec3A::X);
        // Nudge outwards by a relative ulp so that the result tests as outside.
        *p = direction * (circle * (1.0 + f32::EPSILON)) + Vec3A::new(0.0, ground, 0.0);
    }
}

/// Removes the tangential part of the inertial step up to `mu · depth`.
#[inline]
fn friction(p: &mut Vec3A, inertial: Vec3A, normal: Vec3A, depth: f32, mu: f32) {
    let tangential = inertial - normal * inertial.dot(normal);
    let len = tangential.length();
    let limit = mu * depth;
    if len <= limit {
        *p -= tangential;
    } else {
        *p -= tangential * (limit / len);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn colliders(friction: f32) -> Colliders {
        let params = ClothParams {
            friction,
            collision_margin: 0.0,
            ..ClothParams::default()
        };
        Colliders::new(&params)
    }

    #[test]
    fn projects_to_surface_and_ground() {
        let c = colliders(0.0);
        let p = c.push_out(Vec3A::new(0.1, 0.2, -0.1));
        assert!((p.length() - 0.5).abs() < 1e-6, "{p}");
        // Default ground at world y = 0 is local y = −0.5.
        let q = c.push_out(Vec3A::new(2.0, -0.7, 0.0));
        assert_eq!(q, Vec3A::new(2.0, -0.5, 0.0));
        assert_eq!(c.push_out(Vec3A::ZERO), Vec3A::new(0.0, 0.5, 0.0));
    }

    #[test]
    fn wedge_between_sphere_and_ground_resolves_to_the_contact_circle() {
        // Default margin: the inflated sphere (r 0.508) pokes 0.016 below the inflated
        // ground (local y −0.492), so near the contact point no admissible point is above.
        let c = Colliders::new(&ClothParams::default());
        for start in [Vec3A::new(0.01, -0.5, 0.02), Vec3A::new(0.0, -0.6, 0.0)] {
            let p = c.push_out(start);
            assert!(
                p.length() >= 0.508 * (1.0 - 1e-6) && p.y >= -0.492 - 1e-6,
                "{p}"
            );
            let circle = (0.508f32 * 0.508 - 0.492 * 0.492).sqrt();
            assert!(
                (Vec3A::new(p.x, 0.0, p.z).length() - circle).abs() < 1e-5,
                "{p}"
            );
        }
    }

    #[test]
    fn friction_sticks_small_slip_and_slows_large_slip() {
        let c = colliders(0.5);
        // Moved 0.01 sideways while pressed 0.1 deep into the ground: static, slip removed.
        let prev = Vec3A::new(2.0, -0.5, 0.0);
        let mut p = Vec3A::new(2.01, -0.6, 0.0);
        let step = p - prev;
        c.collide(&mut p, step);
        assert!((p - prev).length() < 1e-6, "{p}");
        // Moved 1.0 while pressed 0.1 deep: kinetic, slip reduced by μ·depth = 0.05.
        let mut p = Vec3A::new(3.0, -0.6, 0.0);
        let step = p - prev;
        c.collide(&mut p, step);
        assert!((p.x - 2.95).abs() < 1e-5 && p.y == -0.5, "{p}");
        // A constraint correction (not part of the inertial step) is not held back.
        let mut p = Vec3A::new(2.3, -0.6, 0.0);
        c.collide(&mut p, Vec3A::new(0.0, -0.1, 0.0));
        assert_eq!(p, Vec3A::new(2.3, -0.5, 0.0));
    }
}
