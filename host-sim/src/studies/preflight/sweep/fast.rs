//! The fast engine's work at one point of a sweep (docs/real-vehicle.md#how-the-check-is-made,
//! **Choices 390–391, 450–451**): the same arithmetic as the reference engine's
//! [`Checker::check_point`](super::Checker), bit for bit, with what does not change
//! between the cases of a sample formed once per sample ([`Shared`]: the heading's and the
//! path pitch's sines and cosines, the reference rates at the time scale) and what does not
//! change along the path formed once per plant ([`RollConsts`]: the heeling and righting
//! moments, the static heel and its sines), so that a point's sines and cosines are only
//! those of its own roll and pitch offset; and the key by which a sweep recognises a sample
//! it has already judged ([`SampleKeys`]).

use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicU64, Ordering};

use controller_core::kinematics::{self, Attitude};
use nalgebra::{Vector3, Vector6};

use super::screen::Span;
use super::{CasePlants, Checker, PathSample, Point};
use crate::plant::{roll_moments, Plant, PlantState};
use crate::studies::preflight::attitude;
use crate::studies::preflight::bits::BitsMap;
use controller_core::config::ControllerConfig;

/// Index of roll, pitch and yaw in η, ν and τ.
const ROLL: usize = 3;
const PITCH: usize = 4;
const YAW: usize = 5;

/// The source of [`Checker`]s' serial numbers (0 is none's).
static SERIALS: AtomicU64 = AtomicU64::new(1);

/// A serial number no checker in this process had before (Choice 562).
pub(super) fn next_serial() -> u64 {
    SERIALS.fetch_add(1, Ordering::Relaxed)
}

/// A plant's roll constants: the heeling moment m_y, the righting coefficient k₄, ρ = |(m_y,
/// k₄)| and the static heel atan2(m_y, k₄) with its sine and cosine
/// ([`plant::static_heel`](crate::plant::static_heel), [`attitude::heel`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct RollConsts {
    k4: f64,
    rho: f64,
    phi0: f64,
    phi0_sin_cos: (f64, f64),
}

impl RollConsts {
    pub(super) fn of(plant: &Plant) -> Self {
        let (my, k4) = roll_moments(plant.params());
        let phi0 = my.atan2(k4);
        RollConsts {
            k4,
            rho: my.hypot(k4),
            phi0,
            phi0_sin_cos: phi0.sin_cos(),
        }
    }
}

/// What every case of one sample at one 1/k shares.
pub(super) struct Shared {
    /// ψ_d and θ_d (+ 0, as the reference engine forms them: the offset 0 added), and the sin,
    /// cos of each.
    psi_0: f64,
    psi: (f64, f64),
    theta: f64,
    theta_sin_cos: (f64, f64),
    /// cos θ_d, and whether |cos θ_d| > 0 (the static heel exists).
    cos_theta: f64,
    level_pitch: bool,
    /// η̇_d/k and η̈_d/k².
    eta_dot: Vector6<f64>,
    eta_ddot: Vector6<f64>,
    /// The states at the static heels met so far on this sample, by the heel's bits (Choice
    /// 451): the box's 2⁹ corners have at most 8 static heels (only Δm, Δy_G and Δz_G move
    /// it), so the state at each is formed once per sample, not once per corner.
    level: RefCell<Vec<(u64, PlantState, Vector6<f64>)>>,
    /// What the heels met so far on this sample give, by the heel's bits (Choice 528): the
    /// attitude and state at the heel and the law's nominal force there, which depend on the
    /// corner only through the heel. Corners that differ only in what the heel's roll row
    /// does not read meet the same heel bit for bit (ΔI_x, ΔI_y, ΔI_z multiply p, q and ṗ,
    /// exact zeros where the state at the static heel neither rolls nor pitches), and its
    /// state and nominal force are formed once per sample.
    heels: RefCell<BitsMap<u64, AtHeel>>,
}

/// The attitude and state at one heel on a sample, and the law's nominal force there
/// ([`Shared::at_heel`]).
#[derive(Clone, Copy)]
struct AtHeel {
    att: Attitude<f64>,
    state: PlantState,
    nu_dot: Vector6<f64>,
    modelled: Vector6<f64>,
}

impl Shared {
    pub(super) fn new(smp: &PathSample, inv_k: f64) -> Self {
        let theta = smp.eta[PITCH] + 0.0;
        Shared {
            psi_0: smp.eta[YAW] + 0.0,
            psi: (smp.eta[YAW] + 0.0).sin_cos(),
            theta,
            theta_sin_cos: theta.sin_cos(),
            cos_theta: theta.cos(),
            level_pitch: smp.eta[PITCH].cos().abs() > 0.0,
            eta_dot: smp.eta_dot * inv_k,
            eta_ddot: smp.eta_ddot * (inv_k * inv_k),
            level: RefCell::new(Vec::new()),
            heels: RefCell::new(BitsMap::default()),
        }
    }

    /// The attitude and state on the sample at roll `heel` (the sample's pitch and yaw, no
    /// roll acceleration) and the law's `nominal` force there without a current: formed once
    /// per distinct `heel` (its bits: the same inputs, the same state and force).
    fn at_heel(&self, smp: &PathSample, heel: f64, nominal: &Plant) -> AtHeel {
        let bits = heel.to_bits();
        if let Some(kept) = self.heels.borrow().get(&bits) {
            return *kept;
        }
        let att = self.attitude(heel.sin_cos(), self.theta_sin_cos);
        let (state, nu_dot) = self.state(smp, heel, (self.theta, self.psi_0), &att, 0.0);
        let modelled = nominal.required_force_at(&state, &att, &nu_dot, &Vector3::zeros());
        let out = AtHeel {
            att,
            state,
            nu_dot,
            modelled,
        };
        self.heels.borrow_mut().insert(bits, out);
        out
    }

    /// [`Shared::state`] at roll `level` (a static heel, sines and cosines `level_sc`), the
    /// sample's pitch and no roll acceleration: formed once per distinct `level` (its bits:
    /// the same inputs, the same state).
    fn level_state(
        &self,
        smp: &PathSample,
        level: f64,
        level_sc: (f64, f64),
    ) -> (PlantState, Vector6<f64>, Attitude<f64>) {
        let att = self.attitude(level_sc, self.theta_sin_cos);
        let bits = level.to_bits();
        let mut seen = self.level.borrow_mut();
        if let Some((_, state, nu_dot)) = seen.iter().find(|e| e.0 == bits) {
            return (*state, *nu_dot, att);
        }
        let (state, nu_dot) = self.state(smp, level, (self.theta, self.psi_0), &att, 0.0);
        seen.push((bits, state, nu_dot));
        (state, nu_dot, att)
    }

    fn attitude(&self, phi: (f64, f64), theta: (f64, f64)) -> Attitude<f64> {
        Attitude {
            sphi: phi.0,
            cphi: phi.1,
            stheta: theta.0,
            ctheta: theta.1,
            spsi: self.psi.0,
            cpsi: self.psi.1,
        }
    }

    /// The state on the sample with roll `phi`, pitch and yaw `(theta, psi)` (their sines and
    /// cosines in `att`) and roll acceleration `p_dot`: the reference engine's `state_at`.
    fn state(
        &self,
        smp: &PathSample,
        phi: f64,
        (theta, psi): (f64, f64),
        att: &Attitude<f64>,
        p_dot: f64,
    ) -> (PlantState, Vector6<f64>) {
        let mut eta = smp.eta;
        eta[ROLL] = phi;
        eta[PITCH] = theta;
        eta[YAW] = psi;
        let jinv = kinematics::jacobian_inv(att);
        let nu = jinv * self.eta_dot;
        let jjn = kinematics::jinv_jdot_nu(att, &nu).unwrap_or_else(|_| Vector6::zeros());
        let mut nu_dot = jinv * self.eta_ddot - jjn;
        nu_dot[ROLL] += p_dot;
        (PlantState { eta, nu }, nu_dot)
    }
}

/// One point (the reference engine's `check_point`): the heel, the pitch and yaw offsets, the
/// force at each extreme of the roll swing, each handed to `judge` with its time.
pub(super) fn check_point(
    checker: &Checker,
    at: &Point,
    shared: &Shared,
    roll: &RollConsts,
    judge: &mut dyn FnMut(f64, &Vector6<f32>),
) {
    let (smp, plant, current) = (at.smp, at.plant, at.current);
    let static_heel = roll.k4 > 0.0 && shared.level_pitch;
    let (level, level_sc) = match static_heel {
        true => (roll.phi0, roll.phi0_sin_cos),
        false => (0.0, 0.0f64.sin_cos()),
    };
    let (state, nu_dot, att) = shared.level_state(smp, level, level_sc);
    let heel = heel(plant, roll, shared, &state, &att, &nu_dot, current).unwrap_or(level);
    // The pitch error that holds the law's model mismatch in pitch, at the heel.
    let h = shared.at_heel(smp, heel, checker.nominal());
    let needed = plant.required_force_at(&h.state, &h.att, &h.nu_dot, current);
    let (d_theta, d_psi) = attitude::steady_errors(&needed, &h.modelled, &at.stiffness);
    let theta = smp.eta[PITCH] + d_theta;
    let theta_sc = theta.sin_cos();
    let psi = smp.eta[YAW] + d_psi;
    let psi_sc = psi.sin_cos();
    for (phi, p_dot) in at.swing.extremes(heel) {
        // At the heel itself (no swing) its sine and cosine are the heel's state's.
        let phi_sc = match phi.to_bits() == heel.to_bits() {
            true => (h.att.sphi, h.att.cphi),
            false => phi.sin_cos(),
        };
        let att = Attitude {
            spsi: psi_sc.0,
            cpsi: psi_sc.1,
            ..shared.attitude(phi_sc, theta_sc)
        };
        let (state, nu_dot) = shared.state(smp, phi, (theta, psi), &att, p_dot);
        let tau = plant
            .required_force_at(&state, &att, &nu_dot, current)
            .cast::<f32>();
        judge(at.t, &tau);
    }
}

/// [`attitude::heel`] at the static heel's state `state` (attitude `att`), with the plant's
/// roll constants.
fn heel(
    plant: &Plant,
    roll: &RollConsts,
    shared: &Shared,
    state: &PlantState,
    att: &Attitude<f64>,
    nu_dot: &Vector6<f64>,
    current: &Vector3<f64>,
) -> Option<f64> {
    let c_theta = shared.cos_theta;
    if roll.k4 <= 0.0 || c_theta.abs() < 1e-6 {
        return None;
    }
    // Here the static heel exists (k₄ > 0, cos θ ≠ 0): `state` is at it, as `attitude::heel`
    // puts it.
    // The roll row alone (Choice 564): the same bits as the whole force's.
    let dynamic = plant.required_roll_at(state, att, nu_dot, current);
    let s = (-dynamic / (c_theta * roll.rho)).clamp(-1.0, 1.0);
    Some(roll.phi0 + s.asin())
}

/// Whether a sweep at 1/k = `inv_k` under `currents` is yaw-free (**Choice 529**): at rest
/// (1/k = 0) every rate is η̇_d·0 and η̈_d·0, exact zeros, and so are ν, ν̇ but a swing's ṗ, J⁻¹J̇ν
/// and, without a current (every component ±0), the current in the body frame Rᵀv_c; the
/// yaw enters a point's force only through J⁻¹, J⁻¹J̇ν and R, each multiplied there by one
/// of those zeros, and the restoring force reads φ and θ alone. So the forces, the heel, the
/// offsets and the thrusts are the same bits (up to the sign of an exact zero, which no
/// comparison sees) at every yaw, and the sample's key leaves its yaw out: a lawn-mower's
/// turns and legs at rest are one sample per roll and pitch.
pub(super) fn yaw_free(inv_k: f64, currents: &[Vector3<f64>]) -> bool {
    inv_k == 0.0 && currents.iter().all(|c| c.iter().all(|&x| x == 0.0))
}

/// The inputs of a sample that its forces depend on (the reference's attitude, its rates at
/// the sweep's time scale — η̇_d/k and η̈_d/k², as [`Shared`] forms them — and the
/// mission-as-written case's plant and swing there), bit for bit: a sweep judges each key
/// once (Choice 391). Keyed at the time scale, not at k = 1 (Choice 450): at rest (1/k = 0)
/// every sample of one attitude is one key, so a straight leg with its speed changes, or a
/// whole lawn-mower line, is judged once.
#[derive(Default)]
pub(super) struct SampleKeys(BitsMap<Vec<u64>, usize>);

impl SampleKeys {
    /// Records the key of sample `smp` (index `j`) at 1/k = `inv_k` and prepared index `m` of
    /// `cases`; the index of the sample that had it first, if it was already there. With
    /// `yaw_free` (at rest without a current, [`yaw_free`]) the key leaves out the yaw.
    pub(super) fn insert(&mut self, key: Vec<u64>, j: usize) -> Option<usize> {
        match self.0.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => Some(*e.get()),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(j);
                None
            }
        }
    }

    /// The key of sample `smp` at 1/k = `inv_k` and prepared index `m` of `cases`: what
    /// [`SampleKeys::insert`] records. With `yaw_free` (at rest without a current,
    /// [`yaw_free`]) it leaves out the yaw.
    pub(super) fn key(
        smp: &PathSample,
        inv_k: f64,
        (cases, m): (&[CasePlants<'_>], usize),
        yaw_free: bool,
    ) -> Vec<u64> {
        // Room for the attitude and the rates (15 words), [`Kept`]'s 1/k, and the cases that
        // add to it: over the box none do, and room for its 2⁹ corners was 8 kB a key, kept
        // with it by [`Kept`] (Choice 562: 207 MB of `check`'s 344 MB on a 32-point route).
        let keyed = cases.iter().filter(|c| c.key(m).is_some()).count();
        let mut key: Vec<u64> = Vec::with_capacity(16 + 2 * keyed);
        let attitude = match yaw_free {
            true => &smp.eta.as_slice()[3..YAW],
            false => &smp.eta.as_slice()[3..],
        };
        key.extend(attitude.iter().map(|x| x.to_bits()));
        key.extend((smp.eta_dot * inv_k).iter().map(|x| x.to_bits()));
        key.extend((smp.eta_ddot * (inv_k * inv_k)).iter().map(|x| x.to_bits()));
        // A case constant along the path (every corner of the box) adds nothing.
        for (plant, amplitude) in cases.iter().filter_map(|c| c.key(m)) {
            key.push(plant as u64);
            key.push(amplitude.to_bits());
        }
        key
    }
}

/// The box's samples judged inside the margin by verdict-only sweeps, kept across checkers
/// (**Choice 537**): by the checker's context (what a point's verdict reads besides its
/// sample: the law's configuration, the corners' and the nominal plants' parameters, the
/// currents, the margin envelope, the path's K_d, the start and the first sample's pitch that
/// set the corners' swing) and, within it, by 1/k and the sample's key. `check` sweeps the box
/// at the scenario's scale, and the speed profile's check as flown sweeps it again on the
/// profile it proposes; a file that pins the profile `check` proposes (the shipped real
/// missions do) asks the same samples twice. The last [`KEPT_CONTEXTS`] contexts are kept
/// (the profile's per-part search is one between), and at most [`KEPT_SAMPLES`] samples.
#[derive(Default)]
pub(super) struct Kept(Vec<Context>);

/// One context of [`Kept`] and its samples judged inside the margin.
struct Context {
    config: ControllerConfig,
    context: Vec<u64>,
    inside: BitsMap<Vec<u64>, Span>,
    /// The serial of the last checker found to have this context (0: none yet): its later
    /// lookups skip comparing the context, tens of thousands of words over the box's 2⁹
    /// corners, that it cannot have changed (Choice 562).
    matched: Cell<u64>,
}

/// The contexts [`Kept`] holds, the latest used last.
const KEPT_CONTEXTS: usize = 4;
/// The most samples [`Kept`] holds over its contexts (a few hundred bytes each); past it, it
/// starts again.
const KEPT_SAMPLES: usize = 1 << 17;

thread_local! {
    static KEPT: RefCell<Kept> = RefCell::new(Kept::default());
}

impl Kept {
    /// Forgets every context this thread kept.
    pub(super) fn forget() {
        KEPT.with(|k| k.borrow_mut().0.clear());
    }

    /// The index of the context (`config`, `context`) of the checker numbered `serial`, if
    /// kept. A checker's configuration and context do not change after it is built, so a
    /// context matched once against its serial is its context at every later lookup.
    fn find(&self, config: &ControllerConfig, (context, serial): (&[u64], u64)) -> Option<usize> {
        if let Some(i) = self.0.iter().position(|c| c.matched.get() == serial) {
            return Some(i);
        }
        let i = self
            .0
            .iter()
            .position(|c| c.config == *config && c.context == context)?;
        self.0[i].matched.set(serial);
        Some(i)
    }

    /// The span of the sample keyed `key` at 1/k = `inv_k`, judged inside the margin in the
    /// context (`config`, `context`), if it was.
    pub(super) fn get(
        config: &ControllerConfig,
        context: (&[u64], u64),
        inv_k: f64,
        key: &mut Vec<u64>,
    ) -> Option<Span> {
        key.push(inv_k.to_bits());
        let span = KEPT.with(|k| {
            let k = k.borrow();
            k.find(config, context)
                .and_then(|i| k.0[i].inside.get(key.as_slice()).copied())
        });
        key.pop();
        span
    }

    /// Keeps the sample keyed `key` at 1/k = `inv_k` as judged inside the margin, with its
    /// span, in the context (`config`, `context`).
    pub(super) fn insert(
        config: &ControllerConfig,
        context: (&[u64], u64),
        inv_k: f64,
        mut key: Vec<u64>,
        span: Span,
    ) {
        key.push(inv_k.to_bits());
        KEPT.with(|k| {
            let mut k = k.borrow_mut();
            let total: usize = k.0.iter().map(|c| c.inside.len()).sum();
            if total >= KEPT_SAMPLES {
                k.0.clear();
            }
            let i = match k.find(config, context) {
                Some(i) => i,
                None => {
                    if k.0.len() >= KEPT_CONTEXTS {
                        k.0.remove(0);
                    }
                    k.0.push(Context {
                        config: *config,
                        context: context.0.to_vec(),
                        inside: BitsMap::default(),
                        matched: Cell::new(context.1),
                    });
                    k.0.len() - 1
                }
            };
            // The latest used last: the oldest is the one replaced.
            let mut c = k.0.remove(i);
            c.inside.insert(key, span);
            k.0.push(c);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Checker, Scope};
    use crate::plant::CurrentModel;
    use crate::scenario::{load_scenario, Scenario};
    use crate::studies::preflight::{Engine, DEFAULT_MARGIN};

    /// Every thruster's smallest and largest demand over the box's 2⁹ corners at rest on
    /// sample `j`, by the reference engine (no key, no screen: every corner from scratch).
    fn demands_at_rest(checker: &Checker, j: usize) -> Vec<(f64, f64)> {
        let sweep = checker
            .sweep_samples(Scope::WholeBox, 0.0, true, j..j + 1, 1)
            .expect("the sweep");
        sweep.peaks.iter().map(|p| (p.0, p.2)).collect()
    }

    /// Choice 529's premise on the reference's arithmetic: at rest without a current, the
    /// demands are the same at every yaw of the same roll and pitch (the shipped survey's
    /// legs and turns: 0°, 90°, 180° and the turns between); under a current they are not,
    /// so the key keeps the yaw there.
    #[test]
    fn at_rest_without_a_current_the_demands_do_not_depend_on_the_yaw() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/real/survey-200x100.toml");
        let survey = load_scenario(&path).expect("the survey");
        let still = Checker::new(&survey, DEFAULT_MARGIN, Engine::Exhaustive).expect("a checker");
        let roll_pitch = |j: usize| {
            let e = still.samples[j].eta;
            (e[3].to_bits(), e[4].to_bits())
        };
        // Samples of the same roll and pitch, their yaws all different.
        let mut yaws: Vec<u64> = Vec::new();
        let picked: Vec<usize> = (0..still.samples.len())
            .step_by(7)
            .filter(|&j| roll_pitch(j) == roll_pitch(0))
            .filter(|&j| {
                let yaw = still.samples[j].eta[5].to_bits();
                let new = !yaws.contains(&yaw);
                yaws.push(yaw);
                new
            })
            .take(40)
            .collect();
        assert!(picked.len() >= 20, "{} yaws", picked.len());
        let first = demands_at_rest(&still, picked[0]);
        for &j in &picked[1..] {
            assert_eq!(demands_at_rest(&still, j), first, "sample {j}");
        }
        // Under a current the body-frame current turns with the yaw.
        let mut cfg = survey.config().clone();
        cfg.current = CurrentModel::Constant([0.3, 0.0, 0.0]);
        let drifting = Scenario::new(cfg).expect("the survey under a current");
        let moving =
            Checker::new(&drifting, DEFAULT_MARGIN, Engine::Exhaustive).expect("a checker");
        let under = demands_at_rest(&moving, picked[0]);
        assert!(picked[1..]
            .iter()
            .any(|&j| demands_at_rest(&moving, j) != under));
    }

    /// Choice 563: a box sample's key holds 15 words (the attitude and the rates) and has
    /// room for [`Kept`](super::Kept)'s 1/k, not for two words per corner (8 kB a key, which
    /// `Kept` kept with it: 207 MB of `check` on a 32-point route); a case that varies along
    /// the path (the mission as written) adds its two words.
    #[test]
    fn a_box_samples_key_has_room_for_its_words_only() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/real/survey-200x100.toml");
        let survey = load_scenario(&path).expect("the survey");
        let checker = Checker::new(&survey, DEFAULT_MARGIN, Engine::Fast).expect("a checker");
        let times = checker.times(1.0);
        let cases = checker.cases(Scope::WholeBox, &times, &[]);
        assert_eq!(cases.len(), 512);
        let key = super::SampleKeys::key(&checker.samples[3], 1.0, (&cases, 3), false);
        assert_eq!(key.len(), 15);
        assert!(key.capacity() <= 16, "room for {} words", key.capacity());
    }

    /// Choice 564: the roll row alone is the whole force's roll row, bit for bit, at every
    /// corner of the box over random states, attitudes, accelerations and currents (zeros
    /// among them, for the signs of zero), with and without the damping and restoring terms.
    #[test]
    fn the_roll_row_alone_is_the_whole_forces_bit_for_bit() {
        use crate::plant::{Plant, PlantState, PlantTerms};
        use controller_core::kinematics::Attitude;
        use nalgebra::{Vector3, Vector6};
        use rand::{RngExt, SeedableRng};
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/real/survey-200x100.toml");
        let survey = load_scenario(&path).expect("the survey");
        let checker = Checker::new(&survey, DEFAULT_MARGIN, Engine::Fast).expect("a checker");
        let mut rng = rand::rngs::StdRng::seed_from_u64(564);
        let mut x = |scale: f64| match rng.random_range(0..8) {
            0 => 0.0,
            1 => -0.0,
            _ => scale * rng.random_range(-1.0..1.0),
        };
        let flags = [(true, true), (false, true), (true, false), (false, false)];
        for (c, corner) in checker.corners.iter().enumerate() {
            let (damping, restoring) = flags[c % 4];
            let terms = PlantTerms { damping, restoring };
            let plant = Plant::new(*corner.params(), terms).expect("a plant");
            for _ in 0..20 {
                let eta = Vector6::from_fn(|_, _| x(1.2));
                let state = PlantState {
                    eta,
                    nu: Vector6::from_fn(|_, _| x(1.5)),
                };
                let att = Attitude::from_eta(&eta);
                let nu_dot = Vector6::from_fn(|_, _| x(0.8));
                let current = Vector3::from_fn(|_, _| x(0.4));
                let whole = plant.required_force_at(&state, &att, &nu_dot, &current)[3];
                let roll = plant.required_roll_at(&state, &att, &nu_dot, &current);
                assert_eq!(
                    roll.to_bits(),
                    whole.to_bits(),
                    "corner {c}: {roll} {whole}"
                );
            }
        }
    }

    /// Choice 562: the bit hasher gives equal keys equal hashes and spreads nearby heels (one
    /// bit apart) over the table's low bits; a kept context is found by a checker's serial
    /// only after its context was matched, and another checker's serial does not find it.
    #[test]
    fn bit_keys_hash_apart_and_serials_find_only_their_context() {
        use std::hash::{BuildHasher, BuildHasherDefault};
        let build = BuildHasherDefault::<crate::studies::preflight::bits::BitsHasher>::default();
        let heel = 0.0123_f64.to_bits();
        let low: std::collections::HashSet<u64> =
            (0..64).map(|i| build.hash_one(heel + i) & 63).collect();
        assert!(low.len() > 32, "{} of 64 buckets", low.len());
        assert_eq!(build.hash_one(vec![1u64, 2]), build.hash_one(vec![1u64, 2]));
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/real/survey-200x100.toml");
        let survey = load_scenario(&path).expect("the survey");
        let a = Checker::new(&survey, DEFAULT_MARGIN, Engine::Fast).expect("a checker");
        let b = Checker::new(&survey, 0.5, Engine::Fast).expect("a checker");
        assert_ne!(a.serial, b.serial);
        let config = survey.controller().config();
        super::Kept::forget();
        let span = super::Span::EMPTY;
        super::Kept::insert(config, (&a.context, a.serial), 1.0, vec![7], span);
        let ask = |c: &Checker| super::Kept::get(config, (&c.context, c.serial), 1.0, &mut vec![7]);
        assert!(ask(&a).is_some());
        assert!(ask(&b).is_none());
        // A second checker of the same context matches it by comparison, then by serial.
        let a2 = Checker::new(&survey, DEFAULT_MARGIN, Engine::Fast).expect("a checker");
        assert!(ask(&a2).is_some() && ask(&a2).is_some());
        assert!(ask(&b).is_none());
        super::Kept::forget();
    }

    /// Choice 537's context: the same mission flown for another duration (the profile's
    /// check as flown of a file that pins it) is the same context, and so its kept samples
    /// are asked; a current, another margin, an untrimmed payload or another path are not.
    #[test]
    fn kept_samples_are_asked_only_in_the_same_context() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/real/survey-200x100.toml");
        let survey = load_scenario(&path).expect("the survey");
        let context = |s: &Scenario, margin: f64| {
            Checker::new(s, margin, Engine::Fast)
                .expect("a checker")
                .context
        };
        let with = |f: &dyn Fn(&mut crate::scenario::SimConfig)| {
            let mut cfg = survey.config().clone();
            f(&mut cfg);
            Scenario::new(cfg).expect("a scenario")
        };
        let base = context(&survey, DEFAULT_MARGIN);
        assert_eq!(
            context(&with(&|c| c.duration = 600.0), DEFAULT_MARGIN),
            base
        );
        assert_ne!(context(&survey, 0.7), base);
        let current = with(&|c| c.current = CurrentModel::Constant([0.2, 0.0, 0.0]));
        assert_ne!(context(&current, DEFAULT_MARGIN), base);
        assert_ne!(context(&with(&|c| c.trimmed = false), DEFAULT_MARGIN), base);
        let circle = load_scenario(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("scenarios/real/circular-10R.toml"),
        )
        .expect("the circle");
        assert_ne!(context(&circle, DEFAULT_MARGIN), base);
    }
}
