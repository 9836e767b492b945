//! The ultimate bound of the boundary-layer law (Theorem 4, Eq 40): the radius of the ball the
//! tracking error enters and stays in. One formula, used by the flight log's law inside
//! (`output::log::inside`) and by the tuning study's constraint (`studies::tune`).

use controller_core::law::RobustLaw;

/// Eq 40's radius X = √(μδ / (2 λ_min(Q))) for the configuration `config` at δ = `delta`: 0
/// for the discontinuous law (Theorem 3), `None` without Δu (no theorem applies).
pub fn ball_radius(config: &controller_core::ControllerConfig, delta: f64) -> Option<f64> {
    match (config.robust, config.law) {
        (false, _) => None,
        (true, RobustLaw::Discontinuous) => Some(0.0),
        (true, RobustLaw::BoundaryLayer) => {
            let lambda_min = f64::from(config.q[0].min(config.q[1]));
            Some((f64::from(config.mu) * delta / (2.0 * lambda_min)).sqrt())
        }
    }
}
