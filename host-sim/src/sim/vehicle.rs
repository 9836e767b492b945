//! The simulated vehicle between two control periods: the plant of Eq (1) with its parameter
//! profile (trimmed if the scenario says so) and the ocean current, stepped by RK4.
//!
//! One plant for the run, whose M is formed again only when the parameters change, and a
//! profile that does not vary in time is not evaluated again (**Choice 80**,
//! [`Plant::set_params`]).

use nalgebra::Vector6;

use crate::plant::VariationProfile;
use crate::plant::{OceanCurrent, Plant, PlantError, PlantState, PlantTerms};
use crate::scenario::{Scenario, SimConfig};

/// The plant of one run, its current and its state.
pub struct Vehicle<'a> {
    config: &'a SimConfig,
    /// The profile does not vary in time: the plant's parameters are set once.
    params_fixed: bool,
    plant: Option<Plant>,
    current: OceanCurrent,
    /// η, ν now.
    pub state: PlantState,
}

impl<'a> Vehicle<'a> {
    /// The vehicle of `scenario` at its start ([`Scenario::initial_state`]).
    pub fn new(scenario: &'a Scenario) -> Self {
        let config = scenario.config();
        Vehicle {
            config,
            params_fixed: matches!(
                config.variation,
                VariationProfile::None | VariationProfile::Constant(_)
            ),
            plant: None,
            current: OceanCurrent::new(&config.current),
            state: scenario.initial_state(),
        }
    }

    /// One plant step of `h` (the scenario's integrator) from time `t` with the body force `tau` held, then the current's.
    pub fn step(&mut self, t: f64, tau: &Vector6<f64>, h: f64) -> Result<(), PlantError> {
        let params_at = |t: f64| self.config.plant_params_at(t);
        let plant = match &mut self.plant {
            Some(p) if self.params_fixed => &*p,
            Some(p) => {
                p.set_params(params_at(t))?;
                &*p
            }
            None => &*self
                .plant
                .insert(Plant::new(params_at(t), PlantTerms::default())?),
        };
        self.state = plant.step(
            self.config.plant_integrator,
            &self.state,
            tau,
            self.current.velocity(),
            h,
        )?;
        self.current.step(h);
        Ok(())
    }

    /// How many times the plant formed and factorised M ([`Plant::factorisations`]).
    pub fn factorisations(&self) -> u64 {
        self.plant.as_ref().map_or(0, Plant::factorisations)
    }
}
