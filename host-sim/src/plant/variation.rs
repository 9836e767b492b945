//! How the plant's parameters vary with time: the Table-3 profiles (docs/model.md#parameter-variation-table-3).

use controller_core::model::ParamVariation;

/// How the plant's parameters vary with time (Table 3, docs/model.md#parameter-variation-table-3). Δp is added to the
/// nominal parameters of the **plant only**; the controller keeps the nominal model.
#[derive(Clone, Debug, PartialEq)]
pub enum VariationProfile {
    /// No variation: the plant is the nominal model.
    None,
    /// Δp constant in time (the paper's figure-eight: Table 3's maximum).
    Constant(ParamVariation<f64>),
    /// Δp(t) = max · |sin(ω t)| (the paper's circle, ω = 0.1).
    AbsSin {
        max: ParamVariation<f64>,
        omega: f64,
    },
    /// Piecewise constant: `steps[i].1` holds until `steps[i].0` seconds; the last value holds
    /// after. The paper's lawn-mower: max until 25 s, then the 25–50 s row, then the last row.
    Staircase(Vec<(f64, ParamVariation<f64>)>),
}

impl VariationProfile {
    /// Δp at time t (s).
    pub fn at(&self, t: f64) -> ParamVariation<f64> {
        match self {
            VariationProfile::None => ParamVariation::default(),
            VariationProfile::Constant(d) => *d,
            VariationProfile::AbsSin { max, omega } => max.scaled((omega * t).sin().abs()),
            VariationProfile::Staircase(steps) => {
                for (until, d) in steps {
                    if t <= *until {
                        return *d;
                    }
                }
                steps.last().map(|s| s.1).unwrap_or_default()
            }
        }
    }
}
