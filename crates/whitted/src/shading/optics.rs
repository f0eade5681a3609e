//! Optics of smooth surfaces: mirror reflection, refraction by Snell's law
//! (with total internal reflection) and Schlick's approximation of the
//! Fresnel reflectance. Directions are unit vectors; normals face the side
//! the light arrives from.

use crate::math::Vec3;

/// The mirror direction of `incident` about the unit normal `n`.
pub fn reflect(incident: Vec3, n: Vec3) -> Vec3 {
    incident - 2.0 * incident.dot(n) * n
}

/// The refracted direction of the unit vector `incident` entering a medium
/// with relative index `eta = n_from / n_to` through the unit normal `n`
/// (facing against `incident`), or `None` on total internal reflection.
pub fn refract(incident: Vec3, n: Vec3, eta: f64) -> Option<Vec3> {
    let cos_i = -incident.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(eta * incident + (eta * cos_i - cos_t) * n)
}

/// Schlick's approximation of the Fresnel reflectance for light arriving at
/// `cos_i` from a medium of index `n_from` into one of index `n_to`, using the
/// transmitted angle when leaving the denser medium.
pub fn schlick_reflectance(cos_i: f64, n_from: f64, n_to: f64) -> f64 {
    let r0 = ((n_from - n_to) / (n_from + n_to)).powi(2);
    let cos = if n_from > n_to {
        let eta = n_from / n_to;
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
        if sin2_t > 1.0 {
            return 1.0;
        }
        (1.0 - sin2_t).sqrt()
    } else {
        cos_i
    };
    r0 + (1.0 - r0) * (1.0 - cos).powi(5)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-12
    }

    #[test]
    fn reflection_mirrors_about_the_normal() {
        let r = reflect(Vec3::new(1.0, -1.0, 0.0), Vec3::Y);
        assert!(close(r, Vec3::new(1.0, 1.0, 0.0)));
    }

    #[test]
    fn refraction_obeys_snells_law_at_known_angles() {
        for degrees in [0.0f64, 10.0, 30.0, 45.0, 60.0, 80.0] {
            let theta = degrees.to_radians();
            let incident = Vec3::new(theta.sin(), -theta.cos(), 0.0);
            let t = refract(incident, Vec3::Y, 1.0 / 1.5).unwrap();
            assert!((t.length() - 1.0).abs() < 1e-12);
            let sin_t = t.x;
            assert!((theta.sin() - 1.5 * sin_t).abs() < 1e-12, "{degrees}°");
            assert!(t.y < 0.0);
        }
    }

    #[test]
    fn total_internal_reflection_past_the_critical_angle() {
        let critical = (1.0f64 / 1.5).asin();
        let below = critical - 1e-6;
        let above = critical + 1e-6;
        let dir = |a: f64| Vec3::new(a.sin(), -a.cos(), 0.0);
        assert!(refract(dir(below), Vec3::Y, 1.5).is_some());
        assert!(refract(dir(above), Vec3::Y, 1.5).is_none());
        assert_eq!(schlick_reflectance(above.cos(), 1.5, 1.0), 1.0);
    }

    #[test]
    fn schlick_at_normal_incidence_is_r0() {
        let r = schlick_reflectance(1.0, 1.0, 1.5);
        assert!((r - 0.04).abs() < 1e-12);
        assert!((schlick_reflectance(0.0, 1.0, 1.5) - 1.0).abs() < 1e-12);
    }
}
