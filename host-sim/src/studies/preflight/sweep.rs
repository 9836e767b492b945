//! The preflight's work: the path sampled once, the plants of every case (the mission as
//! written, or every corner of the parameter box), and one sweep of every sample at a time
//! scale — the attitude the vehicle holds there ([`super::attitude`]), the force it needs,
//! the board's allocator on the margin envelope.

mod fast;
mod screen;

use controller_core::effectiveness::{THRUSTERS, THRUSTER_NAMES};
use controller_core::kinematics::{self, Attitude};
use controller_core::model::VehicleParams;
use controller_core::thruster::ThrustEnvelope;
use controller_core::uncertainty::ParamBox;
use controller_core::{allocation::AxisPriority, axes::NAMES as AXIS_NAMES};
use controller_core::{Mission, Trajectory};
use nalgebra::{Vector3, Vector6};

use super::attitude::{self, Stiffness, Swing};
use super::bits::BitsMap;
use super::lag::Margin;
use super::period;
use super::{
    poll, time_scale, CheckError, Engine, Scope, Violation, GAUSS_MARKOV_SIGMAS, SAMPLE_RATE_HZ,
};
use crate::plant::{self, CurrentModel, Plant, PlantState, PlantTerms};
use crate::scenario::{InitialAttitude, Scenario};
use fast::{Kept, RollConsts, SampleKeys, Shared};
use screen::{Screen, Span};

/// An unallocated part above this (relative to 1 + |τ|) means the axis was given up; below it
/// is the f32 rounding of an axis met on its bound.
const GIVEN_UP: f32 = 1.0e-4;
/// Index of roll, pitch and yaw in η.
const ROLL: usize = 3;
const PITCH: usize = 4;
const YAW: usize = 5;

/// The reference at one sample of the path, at k = 1.
pub(super) struct PathSample {
    /// Path time (s, at k = 1).
    pub s: f64,
    pub eta: Vector6<f64>,
    pub eta_dot: Vector6<f64>,
    pub eta_ddot: Vector6<f64>,
}

/// Per thruster: the smallest demand (N) and when (s), the largest and when.
pub(super) type Peaks = [(f64, f64, f64, f64); THRUSTERS];

/// One sweep over the samples at one 1/k.
pub(super) struct Sweep {
    pub first: Option<Violation>,
    pub peaks: Peaks,
    /// Where the first violation was: the next probe of a bisection tries it first.
    at: Option<PointId>,
    /// The span of the sample being judged, when the box's screen records it (Choice 530).
    span: Option<Span>,
}

/// One point of a sweep: a regular sample (`peak` false) or a corner's extreme, the case and
/// the current.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct PointId {
    peak: bool,
    sample: usize,
    case: usize,
    current: usize,
}

/// The regular times and the corners' extremes' (with their index) in time order.
type Merged = Vec<(f64, Option<usize>)>;

/// The cases of a sweep at one 1/k: the sample times, the plants the mission as written meets
/// there, and each case's plant and swing per sample.
struct Prepared<'p> {
    times: Vec<f64>,
    cases: Vec<CasePlants<'p>>,
}

/// The plant of a case at each sample, and its roll swing there.
pub(super) struct CasePlants<'p> {
    /// Index into `plants` per sample (one entry: the same plant throughout).
    at: Vec<usize>,
    plants: Vec<&'p Plant>,
    /// Each plant's roll constants (the fast engine's, Choice 390).
    roll: Vec<RollConsts>,
    /// The swing's amplitude per sample (one entry: the same throughout), and its ω.
    amplitude: Vec<f64>,
    omega: f64,
}

impl CasePlants<'_> {
    fn index(&self, j: usize) -> usize {
        self.at[j.min(self.at.len() - 1)]
    }
    fn plant(&self, j: usize) -> &Plant {
        self.plants[self.index(j)]
    }
    /// The plant's index and the swing's amplitude at sample `j`; `None` when both are the
    /// same throughout.
    pub(super) fn key(&self, j: usize) -> Option<(usize, f64)> {
        (self.at.len() > 1 || self.amplitude.len() > 1)
            .then(|| (self.index(j), self.swing(j).amplitude))
    }
    fn swing(&self, j: usize) -> Swing {
        Swing {
            amplitude: self.amplitude[j.min(self.amplitude.len() - 1)],
            omega: self.omega,
        }
    }
}

/// Everything the check needs, built once per scenario.
pub(super) struct Checker<'a> {
    scenario: &'a Scenario,
    samples: Vec<PathSample>,
    /// A waypoint path's corners at their closed-form extremes (Choice 314): every blend's
    /// middle (its largest heading rate) and the two points of its largest heading
    /// acceleration, in time order, whatever the blend's length against the sample period.
    corners_peaks: Vec<PathSample>,
    /// K_d of the path at k = 1.
    accel_bound: f64,
    /// Every corner of the controller's parameter box (trimmed if the scenario is).
    corners: Vec<Plant>,
    /// The law's nominal model, as a plant: what its feedforward gives.
    nominal: Plant,
    currents: Vec<Vector3<f64>>,
    /// The margin envelope and its allocator at each time scale (Choices 372, 548, 558).
    margins: super::lag::Margins<'a>,
    engine: Engine,
    /// Per scope, where the last infeasible probe failed (Choice 392).
    hint: [std::cell::Cell<Option<PointId>>; 2],
    /// The box's thrust span per sample at the 1/k it was judged at (Choice 530).
    screen: std::cell::RefCell<Screen>,
    /// A long abs-sin mission's torus (Choice 538): the plant at each payload level, and the
    /// largest roll swing its payload drives.
    torus: Option<(Vec<Plant>, f64)>,
    /// What a box point's verdict reads besides its sample and the law's configuration, by
    /// its bits: the key of the samples [`Kept`] across checkers (Choice 537).
    context: Vec<u64>,
    /// This checker's number, unique in the process: [`Kept`] knows a context it has matched
    /// against this checker's by it, without comparing the context again (Choice 562).
    serial: u64,
}

/// [`super::forget_kept`].
pub(super) fn forget_kept() {
    Kept::forget();
}

/// The currents the check takes (see the module docs of [`super`]).
fn currents(model: &CurrentModel) -> Vec<Vector3<f64>> {
    match model {
        CurrentModel::None => vec![Vector3::zeros()],
        CurrentModel::Constant(v) => vec![Vector3::from(*v)],
        CurrentModel::GaussMarkov { mean, sigma, .. } => {
            let mut out: Vec<Vector3<f64>> = Vec::new();
            for corner in 0..8u32 {
                let mut v = Vector3::from(*mean);
                for axis in 0..3 {
                    let sign = if corner & (1 << axis) != 0 { 1.0 } else { -1.0 };
                    v[axis] += sign * GAUSS_MARKOV_SIGMAS * sigma[axis];
                }
                if !out.contains(&v) {
                    out.push(v);
                }
            }
            out
        }
    }
}

/// The state of the vehicle on the reference sample `smp` at 1/k = `inv_k`, with roll `phi`
/// and the steady errors `offset` (pitch, yaw): η, ν = J⁻¹(η) η̇_d, ν̇ = J⁻¹(η̈_d − J̇ν) plus
/// the roll acceleration `p_dot` of a swing.
fn state_at(
    smp: &PathSample,
    inv_k: f64,
    phi: f64,
    offset: (f64, f64),
    p_dot: f64,
) -> (PlantState, Vector6<f64>) {
    let mut eta = smp.eta;
    eta[ROLL] = phi;
    eta[PITCH] += offset.0;
    eta[YAW] += offset.1;
    let att = Attitude::from_eta(&eta);
    let jinv = kinematics::jacobian_inv(&att);
    let nu = jinv * (smp.eta_dot * inv_k);
    let jjn = kinematics::jinv_jdot_nu(&att, &nu).unwrap_or_else(|_| Vector6::zeros());
    let mut nu_dot = jinv * (smp.eta_ddot * (inv_k * inv_k)) - jjn;
    nu_dot[ROLL] += p_dot;
    (PlantState { eta, nu }, nu_dot)
}

/// A parameter set's bits, equal exactly when the sets are `==` (−0 taken as +0; no field is
/// NaN in a plant that builds).
fn params_key(p: &VehicleParams<f64>) -> Vec<u64> {
    let fields = [p.mass, p.buoyancy, p.z_b_roll, p.z_b_pitch, p.gravity]
        .into_iter()
        .chain(p.r_g)
        .chain(p.inertia)
        .chain(p.added_mass)
        .chain(p.damping)
        .chain(p.r_b_xy);
    fields.map(|x| (x + 0.0).to_bits()).collect()
}

/// The path at k = 1 sampled at [`SAMPLE_RATE_HZ`] over its first `checked` seconds.
fn path_samples(path: &Trajectory, checked: f64) -> Result<Vec<PathSample>, CheckError> {
    let n = (checked * f64::from(SAMPLE_RATE_HZ)).ceil().max(1.0) as u64;
    (0..=n)
        .map(|j| {
            if j % 4096 == 0 {
                poll()?;
            }
            let d = path.sample(j, SAMPLE_RATE_HZ);
            Ok(PathSample {
                s: j as f64 / f64::from(SAMPLE_RATE_HZ),
                eta: d.eta.cast::<f64>(),
                eta_dot: d.eta_dot.cast::<f64>(),
                eta_ddot: d.eta_ddot.cast::<f64>(),
            })
        })
        .collect()
}

/// A long abs-sin mission's torus (Choice 538, [`period`]'s module docs): the plant at each
/// payload level (trimmed if the scenario is; the first is level 0, the payload at t = 0), and
/// the largest amplitude of the roll swing the payload drives over the whole mission
/// ([`period::swing_bound`]; the start's swing with it). `None` when the swing has no bound.
fn torus(
    scenario: &Scenario,
    path: &Trajectory,
    levels: &[controller_core::model::ParamVariation<f64>],
    payload_period: f64,
) -> Result<Option<(Vec<Plant>, f64)>, CheckError> {
    let cfg = scenario.config();
    let params = |v: &controller_core::model::ParamVariation<f64>| {
        let p = VehicleParams::auv150().with_variation(v);
        match cfg.trimmed {
            true => plant::trimmed(&p),
            false => p,
        }
    };
    let plants = levels
        .iter()
        .map(|v| {
            Plant::new(params(v), PlantTerms::default())
                .map_err(|e| CheckError::Invalid(format!("a payload level: {e}")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let pitch = path_samples(path, 0.0)?
        .first()
        .map_or(0.0, |s| s.eta[PITCH]);
    let omega = plants
        .first()
        .map_or(0.0, |p| attitude::roll_frequency(p, pitch));
    let start = match cfg.initial_attitude() {
        InitialAttitude::Level => Some(0.0),
        InitialAttitude::Trim => None,
    };
    let heel = |t: f64| plant::static_heel(&cfg.plant_params_at(t), pitch).unwrap_or(0.0);
    Ok(period::swing_bound(omega, start, &heel, payload_period).map(|a| (plants, a)))
}

/// The plant at every corner of the parameter box `bx` (trimmed to neutral buoyancy when the
/// scenario's payload is).
fn corner_plants(bx: ParamBox<f64>, trimmed: bool) -> Result<Vec<Plant>, CheckError> {
    let nominal = VehicleParams::auv150();
    (0..ParamBox::<f64>::CORNERS)
        .map(|c| {
            let mut p = nominal.with_variation(&bx.corner(c));
            if trimmed {
                p = plant::trimmed(&p);
            }
            Plant::new(p, PlantTerms::default())
                .map_err(|e| CheckError::Invalid(format!("parameter box corner {c}: {e}")))
        })
        .collect()
}

impl<'a> Checker<'a> {
    pub(super) fn new(
        scenario: &'a Scenario,
        margin: f64,
        engine: Engine,
    ) -> Result<Self, CheckError> {
        let invalid = CheckError::Invalid;
        let cfg = scenario.config();
        let controller = scenario.controller();
        // The path at k = 1, sampled over the part the scenario flies.
        let path = Trajectory::new(Mission {
            time_scale: 1.0,
            ..cfg.mission()
        })
        .map_err(|e| invalid(format!("the mission at time scale 1: {e}")))?;
        let span = cfg.duration / time_scale(cfg.time_scale);
        // A periodic mission: its first period (Choice 393), a long one's after its
        // staircase's last step or at its payload's levels (Choice 538), by the fast engine.
        let mut reduction = match engine {
            Engine::Fast => period::reduction(cfg),
            Engine::Exhaustive => None,
        };
        let torus = match reduction.as_ref().and_then(|r| r.levels.as_ref()) {
            Some((levels, payload_period)) => torus(scenario, &path, levels, *payload_period)?,
            None => None,
        };
        // A torus whose swing has no bound (resonance) is swept as written.
        if torus.is_none() && reduction.as_ref().is_some_and(|r| r.levels.is_some()) {
            reduction = None;
        }
        let checked = reduction.as_ref().map_or(span, |r| span.min(r.checked()));
        let samples = path_samples(&path, checked)?;
        let corners_peaks = blend_peaks(&path, span);
        let (n_samples, n_peaks) = (samples.len(), corners_peaks.len());
        let corners = corner_plants(controller.config().uncertainty.cast(f64::from), cfg.trimmed)?;
        let law_model = controller.params().cast(f64::from);
        let nominal = Plant::new(law_model, PlantTerms::default())
            .map_err(|e| invalid(format!("the law's nominal model: {e}")))?;
        let currents = currents(&cfg.current);
        // The navigation's noise force (Choice 372) is kept on each side, the lag's overshoot
        // (Choices 509, 557) on the side it takes.
        let kept = super::navigation::share(scenario, None).thrust;
        let margins = super::lag::Margins::new(
            scenario,
            margin,
            super::navigation::keep(controller.envelope().scaled(margin as f32), &kept),
        )?;
        let mut checker = Checker {
            context: Vec::new(),
            serial: fast::next_serial(),
            scenario,
            samples,
            corners_peaks,
            accel_bound: f64::from(path.accel_bound()),
            corners,
            nominal,
            currents,
            margins,
            engine,
            hint: Default::default(),
            screen: std::cell::RefCell::new(Screen::new(n_samples, n_peaks)),
            torus,
        };
        checker.context = checker.context();
        Ok(checker)
    }

    /// [`Checker::context`]: the corners' and the nominal plants' parameters, the currents,
    /// the margin envelope, the path's K_d, and the first sample's pitch and the start, which
    /// set the corners' roll swing (Choice 537).
    fn context(&self) -> Vec<u64> {
        let mut out: Vec<u64> = self
            .corners
            .iter()
            .chain(std::iter::once(&self.nominal))
            .flat_map(|p| params_key(p.params()))
            .collect();
        let currents = self
            .currents
            .iter()
            .flat_map(|c| c.iter().map(|x| x.to_bits()));
        out.extend(currents);
        out.push(u64::MAX);
        out.extend(self.margins.context());
        let pitch = self.samples[0].eta[PITCH];
        out.extend([self.accel_bound.to_bits(), pitch.to_bits()]);
        out.push(self.start().map_or(u64::MAX, f64::to_bits));
        out
    }

    /// The real time of each sample at 1/k = `inv_k` (at rest: at the scenario's scale).
    fn times(&self, inv_k: f64) -> Vec<f64> {
        let k = self.scale(inv_k);
        self.samples.iter().map(|s| s.s * k).collect()
    }

    /// The swing left by the start: none from trim, the static heel's from level.
    fn start(&self) -> Option<f64> {
        match self.scenario.config().initial_attitude() {
            InitialAttitude::Level => Some(0.0),
            InitialAttitude::Trim => None,
        }
    }

    /// The static heel of `plant` on sample `smp` (0 without a righting moment).
    fn static_heel(plant: &Plant, smp: &PathSample) -> f64 {
        plant::static_heel(plant.params(), smp.eta[PITCH]).unwrap_or(0.0)
    }

    /// The cases of `scope` at the sample times `times`: the mission as written (its own
    /// payload profile, a plant per distinct parameter set, the swing its start and payload
    /// jumps leave), or every corner of the box (constant payload, the start's swing).
    fn cases<'p>(&'p self, scope: Scope, times: &[f64], owned: &'p [Plant]) -> Vec<CasePlants<'p>> {
        let start = self.start();
        match scope {
            Scope::WholeBox => self
                .corners
                .iter()
                .map(|p| {
                    let heel = Self::static_heel(p, &self.samples[0]);
                    CasePlants {
                        at: vec![0],
                        plants: vec![p],
                        roll: vec![RollConsts::of(p)],
                        amplitude: vec![start.map_or(0.0, |s| (heel - s).abs())],
                        omega: attitude::roll_frequency(p, self.samples[0].eta[PITCH]),
                    }
                })
                .collect(),
            Scope::AsWritten if self.torus.is_some() => {
                let (plants, amplitude) = self
                    .torus
                    .as_ref()
                    .map_or((&[][..], 0.0), |t| (&t.0[..], t.1));
                let omega = plants.first().map_or(0.0, |p| {
                    attitude::roll_frequency(p, self.samples[0].eta[PITCH])
                });
                (0..plants.len())
                    .map(|i| CasePlants {
                        at: vec![i],
                        plants: plants.iter().collect(),
                        roll: plants.iter().map(RollConsts::of).collect(),
                        amplitude: vec![amplitude],
                        omega,
                    })
                    .collect()
            }
            Scope::AsWritten => {
                let cfg = self.scenario.config();
                // Each sample's plant by its parameters' bits, as `profile_plants` found them
                // (the first of equal ones): a search through `owned` per sample was quadratic
                // in a long varying mission's length (~10⁶ plants a day).
                let index: BitsMap<Vec<u64>, usize> = owned
                    .iter()
                    .enumerate()
                    .rev()
                    .map(|(i, q)| (params_key(q.params()), i))
                    .collect();
                let at: Vec<usize> = times
                    .iter()
                    .map(|&t| {
                        let key = params_key(&cfg.plant_params_at(t));
                        index.get(&key).copied().unwrap_or(0)
                    })
                    .collect();
                let heel = |t: f64| {
                    let params = cfg.plant_params_at(t);
                    plant::static_heel(&params, self.samples[0].eta[PITCH]).unwrap_or(0.0)
                };
                let omega = attitude::roll_frequency(&owned[at[0]], self.samples[0].eta[PITCH]);
                let amplitude = attitude::swing_amplitudes(times, omega, start, &heel);
                vec![CasePlants {
                    at,
                    plants: owned.iter().collect(),
                    roll: owned.iter().map(RollConsts::of).collect(),
                    amplitude,
                    omega,
                }]
            }
        }
    }

    /// The plants the mission as written meets at the sample times `times`, one per distinct
    /// parameter set, in the order first met. Distinct sets are found by their bits (a hash
    /// set), not by comparing each with every one before: a payload that varies all along a
    /// day-long mission meets ~10⁶ of them, and the pairwise search was quadratic (and did not
    /// look at a stop request).
    fn profile_plants(&self, times: &[f64]) -> Result<Vec<Plant>, CheckError> {
        let cfg = self.scenario.config();
        let mut seen = std::collections::HashSet::new();
        let mut out: Vec<Plant> = Vec::new();
        for (i, &t) in times.iter().enumerate() {
            if i % 4096 == 0 {
                poll()?;
            }
            let p = cfg.plant_params_at(t);
            if seen.insert(params_key(&p)) {
                out.push(Plant::new(p, PlantTerms::default()).map_err(|e| {
                    CheckError::Invalid(format!("the payload at t = {t:.2} s: {e}"))
                })?);
            }
        }
        Ok(out)
    }

    /// Every sample of every case of `scope` at 1/k = `inv_k`, then the corners' extremes
    /// (Choice 314); stops at the first violation unless `full` (which also collects the
    /// peaks), and at a stop request.
    pub(super) fn sweep(&self, scope: Scope, inv_k: f64, full: bool) -> Result<Sweep, CheckError> {
        let mut out = self.sweep_samples(scope, inv_k, full, 0..self.samples.len(), 1)?;
        if out.first.is_some() && !full {
            return Ok(out);
        }
        self.sweep_peaks(scope, inv_k, full, &mut out)?;
        Ok(out)
    }

    /// The corners' extremes of [`Checker::sweep`], after its regular samples (`out`).
    fn sweep_peaks(
        &self,
        scope: Scope,
        inv_k: f64,
        full: bool,
        out: &mut Sweep,
    ) -> Result<(), CheckError> {
        if self.corners_peaks.is_empty() {
            return Ok(());
        }
        let (merged, owned) = self.merged(scope, inv_k)?;
        let prepared = self.prepare_at(scope, merged.iter().map(|m| m.0).collect(), &owned);
        // The cases over the regular times and the extremes' merged in order, so that the
        // payload and the roll swing at an extreme are those of its time.
        let points = merged
            .iter()
            .enumerate()
            .filter_map(|(m, &(_, peak))| peak.map(|j| (m, j)));
        self.sweep_points(scope, &prepared, points, true, inv_k, full, out)
    }

    /// The regular times at 1/k = `inv_k` and the extremes' merged in time order (each with
    /// its index into the extremes), and the plants the mission as written meets at them.
    fn merged(&self, scope: Scope, inv_k: f64) -> Result<(Merged, Vec<Plant>), CheckError> {
        let k = self.scale(inv_k);
        let mut merged: Merged = self
            .times(inv_k)
            .into_iter()
            .map(|t| (t, None))
            .chain(
                self.corners_peaks
                    .iter()
                    .enumerate()
                    .map(|(j, s)| (s.s * k, Some(j))),
            )
            .collect();
        merged.sort_by(|a, b| a.0.total_cmp(&b.0));
        let owned = self.owned(scope, merged.iter().map(|m| m.0))?;
        Ok((merged, owned))
    }

    /// The plants of `scope` at `times`: the mission's own (as written), none for the box.
    fn owned(
        &self,
        scope: Scope,
        times: impl Iterator<Item = f64>,
    ) -> Result<Vec<Plant>, CheckError> {
        match scope {
            // A torus's plants are its levels', built once (Choice 538).
            Scope::AsWritten if self.torus.is_some() => Ok(Vec::new()),
            Scope::AsWritten => self.profile_plants(&times.collect::<Vec<_>>()),
            Scope::WholeBox => Ok(Vec::new()),
        }
    }

    fn prepare_at<'p>(&'p self, scope: Scope, times: Vec<f64>, owned: &'p [Plant]) -> Prepared<'p> {
        let cases = self.cases(scope, &times, owned);
        Prepared { times, cases }
    }

    /// Records the box's span at every sample at 1/k = `inv_k` (a full sweep, its verdict
    /// unused), so that a bisection's later probes between `inv_k` and a feasible 1/k are
    /// interpolated, not swept (Choice 531). Nothing for the mission as written or the
    /// reference engine.
    pub(super) fn prime(&self, scope: Scope, inv_k: f64) -> Result<(), CheckError> {
        if self.engine == Engine::Fast && scope == Scope::WholeBox {
            self.sweep(scope, inv_k, true)?;
        }
        Ok(())
    }

    /// Whether every point of `scope` fits at 1/k = `inv_k` ([`Checker::sweep`]'s verdict
    /// only). The fast engine tries first the point where the last infeasible probe of this
    /// scope failed (Choice 392): a bisection's infeasible probes then stop at once.
    pub(super) fn feasible(&self, scope: Scope, inv_k: f64) -> Result<bool, CheckError> {
        let slot = &self.hint[scope as usize];
        if let (Engine::Fast, Some(id)) = (self.engine, slot.get()) {
            if self.violates(scope, inv_k, id)? {
                return Ok(false);
            }
        }
        let out = self.sweep(scope, inv_k, false)?;
        if self.engine == Engine::Fast && out.at.is_some() {
            slot.set(out.at);
        }
        Ok(out.first.is_none())
    }

    /// Whether the point `id` violates the margin envelope at 1/k = `inv_k`.
    fn violates(&self, scope: Scope, inv_k: f64, id: PointId) -> Result<bool, CheckError> {
        let mut out = Sweep::new();
        if id.peak {
            let (merged, owned) = self.merged(scope, inv_k)?;
            let m = merged.iter().position(|x| x.1 == Some(id.sample));
            let prepared = self.prepare_at(scope, merged.iter().map(|m| m.0).collect(), &owned);
            if let Some(m) = m {
                let ctx = self.at_sample(self.sample(true, id.sample), inv_k)?;
                self.check_one(&prepared, m, id, &ctx, false, &mut out);
            }
        } else {
            let owned = self.owned(scope, self.times(inv_k).into_iter())?;
            let prepared = self.prepare_at(scope, self.times(inv_k), &owned);
            let ctx = self.at_sample(self.sample(false, id.sample), inv_k)?;
            self.check_one(&prepared, id.sample, id, &ctx, false, &mut out);
        }
        Ok(out.first.is_some())
    }

    /// The time scale of 1/k = `inv_k` (at rest: the scenario's).
    fn scale(&self, inv_k: f64) -> f64 {
        match inv_k > 0.0 {
            true => 1.0 / inv_k,
            false => time_scale(self.scenario.config().time_scale),
        }
    }

    /// The samples (at k = 1: path time, s) the check takes, in order.
    pub(super) fn sample_times(&self) -> impl Iterator<Item = f64> + '_ {
        self.samples.iter().map(|s| s.s)
    }

    /// [`Checker::sweep`] of every `stride`-th sample of `range` only (the speed profile's
    /// per-part search, docs/missions.md#the-speed-profile).
    pub(super) fn sweep_samples(
        &self,
        scope: Scope,
        inv_k: f64,
        full: bool,
        range: std::ops::Range<usize>,
        stride: usize,
    ) -> Result<Sweep, CheckError> {
        let times = self.times(inv_k);
        let owned = self.owned(scope, times.iter().copied())?;
        let prepared = self.prepare_at(scope, times, &owned);
        let mut out = Sweep::new();
        let points = range.step_by(stride.max(1)).map(|j| (j, j));
        self.sweep_points(scope, &prepared, points, false, inv_k, full, &mut out)?;
        Ok(out)
    }

    /// Every case and current at each point `(m, j)` of `points` (m: index into the prepared
    /// times, j: into the regular samples or, if `peak`, the corners' extremes), in order;
    /// stops at the first violation unless `full`. The fast engine skips a point whose
    /// inputs equal, bit for bit, a point already judged in this sweep (Choice 391): it
    /// would give the same forces, so neither the first violation nor a peak can change.
    /// Over the box, a verdict-only sweep skips a sample its screen clears and records the
    /// span of each it judges in full (Choice 530), and asks first whether it was judged
    /// inside the margin before in this context (Choice 537).
    #[allow(clippy::too_many_arguments)]
    fn sweep_points(
        &self,
        scope: Scope,
        prepared: &Prepared,
        points: impl Iterator<Item = (usize, usize)>,
        peak: bool,
        inv_k: f64,
        full: bool,
        out: &mut Sweep,
    ) -> Result<(), CheckError> {
        let mut seen = SampleKeys::default();
        // Over the box the fast engine records every sample's span, and skips those its
        // screen clears when the sweep gives a verdict only.
        let recording = self.engine == Engine::Fast && scope == Scope::WholeBox;
        let (screening, margin) = (recording && !full, self.margins.at(inv_k)?);
        for (m, j) in points {
            // One sample is every case (up to 2⁹ corners): tens of microseconds.
            poll()?;
            let smp = self.sample(peak, j);
            let mut key = Vec::new();
            if self.engine == Engine::Fast {
                let yaw_free = fast::yaw_free(inv_k, &self.currents);
                key = SampleKeys::key(smp, inv_k, (&prepared.cases, m), yaw_free);
                if let Some(first) = seen.insert(key.clone(), j) {
                    // The same inputs: the same span as the sample that had them first.
                    if recording {
                        let mut screen = self.screen.borrow_mut();
                        if let Some(span) = screen.recorded(peak, first, inv_k) {
                            screen.record(peak, j, inv_k, span);
                        }
                    }
                    continue;
                }
            }
            if screening
                && self
                    .screen
                    .borrow()
                    .clears(peak, j, inv_k, &margin.envelope)
            {
                continue;
            }
            let config = self.scenario.controller().config();
            if screening {
                if let Some(span) = Kept::get(config, self.kept(), inv_k, &mut key) {
                    self.screen.borrow_mut().record(peak, j, inv_k, span);
                    continue;
                }
            }
            if recording {
                out.span = Some(Span::EMPTY);
            }
            let ctx = self.at_sample(smp, inv_k)?;
            for case in 0..prepared.cases.len() {
                for current in 0..self.currents.len() {
                    let id = PointId {
                        peak,
                        sample: j,
                        case,
                        current,
                    };
                    self.check_one(prepared, m, id, &ctx, full, out);
                    if out.first.is_some() && out.at.is_none() {
                        out.at = Some(id);
                    }
                    if out.first.is_some() && !full {
                        out.span = None;
                        return Ok(());
                    }
                }
            }
            if let Some(span) = out.span.take() {
                self.screen.borrow_mut().record(peak, j, inv_k, span);
                if screening {
                    Kept::insert(config, self.kept(), inv_k, key, span);
                }
            }
        }
        Ok(())
    }

    /// This checker's context and serial, as [`Kept`] asks for them (Choice 562).
    fn kept(&self) -> (&[u64], u64) {
        (&self.context, self.serial)
    }

    fn sample(&self, peak: bool, j: usize) -> &PathSample {
        match peak {
            true => &self.corners_peaks[j],
            false => &self.samples[j],
        }
    }

    /// What every case at sample `smp` shares at 1/k = `inv_k`.
    fn at_sample(&self, smp: &PathSample, inv_k: f64) -> Result<AtSample, CheckError> {
        Ok(AtSample {
            inv_k,
            stiffness: self.stiffness(smp, inv_k),
            shared: match self.engine {
                Engine::Fast => Some(Shared::new(smp, inv_k)),
                Engine::Exhaustive => None,
            },
            margin: self.margins.at(inv_k)?,
        })
    }

    /// The point `id` at prepared index `m`, by the checker's engine.
    fn check_one(
        &self,
        prepared: &Prepared,
        m: usize,
        id: PointId,
        ctx: &AtSample,
        full: bool,
        out: &mut Sweep,
    ) {
        let smp = self.sample(id.peak, id.sample);
        let case = &prepared.cases[id.case];
        let at = Point {
            smp,
            t: prepared.times[m],
            inv_k: ctx.inv_k,
            plant: case.plant(m),
            swing: case.swing(m),
            current: &self.currents[id.current],
            stiffness: ctx.stiffness,
        };
        match &ctx.shared {
            None => self.check_point(&at, &ctx.margin, full, out),
            Some(shared) => {
                let roll = &case.roll[case.index(m)];
                fast::check_point(self, &at, shared, roll, &mut |t, tau| {
                    self.judge(&ctx.margin, t, tau, full, out)
                });
            }
        }
    }

    /// The law's pitch and yaw stiffness on the reference at sample `smp` ([`attitude::stiffness`]).
    fn stiffness(&self, smp: &PathSample, inv_k: f64) -> Stiffness {
        let (state, _) = state_at(smp, inv_k, smp.eta[ROLL], (0.0, 0.0), 0.0);
        let att = Attitude::from_eta(&state.eta);
        let jjn = kinematics::jinv_jdot_nu(&att, &state.nu).unwrap_or_else(|_| Vector6::zeros());
        attitude::stiffness(
            self.scenario.controller(),
            &state.nu,
            &jjn,
            att.ctheta,
            self.accel_bound * inv_k * inv_k,
        )
    }

    /// One point: the attitude the vehicle holds there, the force it needs at each extreme of
    /// its roll swing, each through the margin allocator.
    pub(super) fn nominal(&self) -> &Plant {
        &self.nominal
    }

    fn check_point(&self, at: &Point, margin: &Margin, full: bool, out: &mut Sweep) {
        let (smp, inv_k, plant, current) = (at.smp, at.inv_k, at.plant, at.current);
        let level = Self::static_heel(plant, smp);
        let (state, nu_dot) = state_at(smp, inv_k, level, (0.0, 0.0), 0.0);
        let heel = attitude::heel(plant, &state, &nu_dot, current).unwrap_or(level);
        // The pitch and yaw errors that hold the law's model mismatch, at the heel.
        let (state, nu_dot) = state_at(smp, inv_k, heel, (0.0, 0.0), 0.0);
        let needed = plant.required_force(&state, &nu_dot, current);
        let modelled = self
            .nominal
            .required_force(&state, &nu_dot, &Vector3::zeros());
        let offset = attitude::steady_errors(&needed, &modelled, &at.stiffness);
        for (phi, p_dot) in at.swing.extremes(heel) {
            let (state, nu_dot) = state_at(smp, inv_k, phi, offset, p_dot);
            let tau = plant.required_force(&state, &nu_dot, current).cast::<f32>();
            self.judge(margin, at.t, &tau, full, out);
        }
    }

    /// The body force `tau` at time `t` through the allocator: the peaks (if `full`) and the
    /// first violation of the margin envelope.
    fn judge(&self, margin: &Margin, t: f64, tau: &Vector6<f32>, full: bool, out: &mut Sweep) {
        let allocation = self.scenario.controller().allocation();
        // The pseudo-inverse's thrusts once for the span and the peaks (Choice 578).
        let thrusts = (out.span.is_some() || full).then(|| allocation.thrusts(tau));
        if let (Some(span), Some(thrusts)) = (out.span.as_mut(), &thrusts) {
            span.add(thrusts);
        }
        if let (true, Some(thrusts)) = (full, &thrusts) {
            for (i, p) in out.peaks.iter_mut().enumerate() {
                let x = f64::from(thrusts[i]);
                if x < p.0 {
                    *p = (x, t, p.2, p.3);
                }
                if x > p.2 {
                    *p = (p.0, p.1, x, t);
                }
            }
        }
        if out.first.is_none() {
            let a = margin.allocator.allocate(tau);
            let lost = |r: usize| a.unallocated[r].abs() > GIVEN_UP * (1.0 + tau[r].abs());
            if (0..6).any(lost) {
                let priority = &self.scenario.controller().config().priority;
                out.first = Some(self.violation(&margin.envelope, t, tau, priority, &lost));
            }
        }
    }

    fn violation(
        &self,
        env: &ThrustEnvelope,
        t: f64,
        tau: &Vector6<f32>,
        priority: &AxisPriority,
        lost: &dyn Fn(usize) -> bool,
    ) -> Violation {
        let demand = self.scenario.controller().allocation().thrusts(tau);
        let excess = |i: usize| {
            let (lo, hi) = (env.min[i], env.max[i]);
            (demand[i] - hi).max(lo - demand[i]) / (hi - lo)
        };
        let worst = (0..THRUSTERS)
            .max_by(|&a, &b| excess(a).total_cmp(&excess(b)))
            .unwrap_or(0);
        let mut axes: Vec<usize> = (0..6).filter(|&r| lost(r)).collect();
        axes.sort_by_key(|&r| priority.rank[r]);
        Violation {
            t,
            thruster: THRUSTER_NAMES[worst].to_string(),
            demand: f64::from(demand[worst]),
            limit: [f64::from(env.min[worst]), f64::from(env.max[worst])],
            given_up: axes.iter().map(|&r| AXIS_NAMES[r].to_string()).collect(),
        }
    }
}

/// Sample rate (Hz) of the corners' extremes: their times to a microsecond.
const PEAK_RATE_HZ: u32 = 1 << 20;

/// A waypoint path's corners at their closed-form extremes, at k = 1, up to path time `span`
/// (Choice 314): per blend, its middle and the two points of its largest heading
/// acceleration ([`Route::heading_accel_peaks`](controller_core::trajectory::Route::heading_accel_peaks)),
/// each sampled from the trajectory itself at its time on the path (the time law's inverse).
/// Empty for the other kinds.
fn blend_peaks(path: &Trajectory, span: f64) -> Vec<PathSample> {
    let controller_core::TrajectoryKind::Waypoints { speed, .. } = path.kind() else {
        return Vec::new();
    };
    let (route, law) = (path.route(), path.time_law());
    let mut out = Vec::new();
    for i in 0..route.segment_count() {
        if route.segment_part(i) % 2 == 0 {
            continue;
        }
        let [up, down] = route.heading_accel_peaks(i);
        let mut locals = [0.5 * route.segment_length(i), up, down];
        locals.sort_by(f32::total_cmp);
        for local in locals {
            let sigma = route.segment_start(i) + local;
            let t = match law.is_set() {
                true => f64::from(law.time_at(route, sigma)),
                false => f64::from(sigma) / f64::from(speed),
            };
            if t > span {
                continue;
            }
            let ticks = (t * f64::from(PEAK_RATE_HZ)).round() as u64;
            let d = path.sample(ticks, PEAK_RATE_HZ);
            out.push(PathSample {
                s: ticks as f64 / f64::from(PEAK_RATE_HZ),
                eta: d.eta.cast::<f64>(),
                eta_dot: d.eta_dot.cast::<f64>(),
                eta_ddot: d.eta_ddot.cast::<f64>(),
            });
        }
    }
    out
}

/// One point of a sweep: a sample, the case's plant and swing there, a current, and the law's
/// pitch and yaw stiffness there.
pub(super) struct Point<'s> {
    pub smp: &'s PathSample,
    pub t: f64,
    pub inv_k: f64,
    pub plant: &'s Plant,
    pub swing: Swing,
    pub current: &'s Vector3<f64>,
    pub stiffness: Stiffness,
}

/// What every case of one sample shares: 1/k, the law's stiffness there, and the fast
/// engine's [`Shared`].
struct AtSample {
    inv_k: f64,
    /// The margin envelope at this 1/k (Choice 558).
    margin: std::rc::Rc<Margin>,
    stiffness: Stiffness,
    shared: Option<Shared>,
}

impl Sweep {
    fn new() -> Self {
        Sweep {
            first: None,
            peaks: [(f64::INFINITY, 0.0, f64::NEG_INFINITY, 0.0); THRUSTERS],
            at: None,
            span: None,
        }
    }
}
