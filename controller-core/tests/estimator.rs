//! The state estimator (docs/law.md#the-state-estimator) against independent facts: the
//! steady-state gain against the Riccati recursion iterated in f64 and against brute-force
//! optimality, white noise's variance against the closed-form factor, a constant acceleration
//! against the closed-form lag, prediction over the solution's age exact under the model, f32
//! against an f64 reference, and non-finite input never taken or passed on.
// Tests change one field of the defaults at a time; that reads best as an assignment.
#![allow(clippy::field_reassign_with_default)]

use controller_core::estimator::{
    steady_state_gain, Estimate, EstimatorConfig, EstimatorGains, EstimatorKind, DISTURBANCE_TIME,
    HORIZON, MAX_AGE,
};
use controller_core::{
    ConfigError, Controller, ControllerConfig, Solution, Status, Table1Case, Trajectory,
};
use proptest::prelude::*;

type M2 = [[f64; 2]; 2];

fn mul(a: &M2, b: &M2) -> M2 {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}
fn tr(a: &M2) -> M2 {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}
fn add(a: &M2, b: &M2) -> M2 {
    [
        [a[0][0] + b[0][0], a[0][1] + b[0][1]],
        [a[1][0] + b[1][0], a[1][1] + b[1][1]],
    ]
}
fn sub(a: &M2, b: &M2) -> M2 {
    [
        [a[0][0] - b[0][0], a[0][1] - b[0][1]],
        [a[1][0] - b[1][0], a[1][1] - b[1][1]],
    ]
}
fn inv(a: &M2) -> M2 {
    let d = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    [[a[1][1] / d, -a[0][1] / d], [-a[1][0] / d, a[0][0] / d]]
}
const I2: M2 = [[1.0, 0.0], [0.0, 1.0]];

/// F, Q and R of one axis in f64.
fn model(t: f64, sp: f64, sv: f64, sa: f64) -> (M2, M2, M2) {
    let f = [[1.0, t], [0.0, 1.0]];
    let g = [0.5 * t * t, t];
    let q = [
        [sa * sa * g[0] * g[0], sa * sa * g[0] * g[1]],
        [sa * sa * g[1] * g[0], sa * sa * g[1] * g[1]],
    ];
    let r = [[sp * sp, 0.0], [0.0, sv * sv]];
    (f, q, r)
}

/// The Kalman gain after `n` steps of the covariance recursion from P = R, in f64:
/// K = P⁻(P⁻ + R)⁻¹, P⁺ = (I − K)P⁻, P⁻ ← F P⁺ Fᵀ + Q.
fn riccati_gain(t: f64, sp: f64, sv: f64, sa: f64, n: usize) -> M2 {
    let (f, q, r) = model(t, sp, sv, sa);
    let mut p = r;
    let mut k = I2;
    for _ in 0..n {
        k = mul(&p, &inv(&add(&p, &r)));
        let post = mul(&sub(&I2, &k), &p);
        p = add(&mul(&mul(&f, &post), &tr(&f)), &q);
    }
    k
}

/// The steady-state covariance of a fixed-gain filter's estimation error, S = A S Aᵀ + N, by
/// the exact solution of its three linear equations (S symmetric).
fn lyapunov(a: &M2, n: &M2) -> M2 {
    // Unknowns s = [s11, s12, s22]; (A S Aᵀ)_ij = Σ a_ik s_kl a_jl.
    let idx = |k: usize, l: usize| match (k, l) {
        (0, 0) => 0,
        (1, 1) => 2,
        _ => 1,
    };
    let rows = [(0usize, 0usize), (0, 1), (1, 1)];
    let mut m = [[0.0f64; 4]; 3];
    for (r, &(i, j)) in rows.iter().enumerate() {
        m[r][r] += 1.0;
        for k in 0..2 {
            for l in 0..2 {
                m[r][idx(k, l)] -= a[i][k] * a[j][l];
            }
        }
        m[r][3] = n[i][j];
    }
    // Gaussian elimination with partial pivoting.
    for c in 0..3 {
        let p = (c..3)
            .max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))
            .unwrap();
        m.swap(c, p);
        let pivot = m[c];
        for (r, row) in m.iter_mut().enumerate() {
            if r != c {
                let f = row[c] / pivot[c];
                for (x, p) in row.iter_mut().zip(pivot.iter()).skip(c) {
                    *x -= f * p;
                }
            }
        }
    }
    let s = [m[0][3] / m[0][0], m[1][3] / m[1][1], m[2][3] / m[2][2]];
    [[s[0], s[1]], [s[1], s[2]]]
}

/// The posterior error covariance of the fixed gain `k` on the truth of `model` (process
/// noise Q, measurement noise R): e⁺ = (I − K)(F e + w) − K n.
fn posterior_covariance(k: &M2, t: f64, sp: f64, sv: f64, sa: f64) -> M2 {
    let (f, q, r) = model(t, sp, sv, sa);
    let ik = sub(&I2, k);
    let a = mul(&ik, &f);
    let n = add(&mul(&mul(&ik, &q), &tr(&ik)), &mul(&mul(k, &r), &tr(k)));
    lyapunov(&a, &n)
}

/// Settings of one axis: (σₚ, σᵥ, σₐ).
const AXES: [(f64, f64, f64); 5] = [
    (0.005, 0.002, 0.02),
    (0.001, 0.0005, 0.004),
    (0.005, 0.002, 1.0),
    (0.05, 0.001, 0.01),
    (0.002, 0.05, 0.5),
];

#[test]
fn the_steady_state_gain_is_the_limit_of_the_riccati_recursion() {
    for rate in [10.0, 100.0, 400.0] {
        let t = 1.0 / rate;
        for &(sp, sv, sa) in &AXES {
            let got = steady_state_gain(t as f32, sp as f32, sv as f32, sa as f32).unwrap();
            let want = riccati_gain(t, sp, sv, sa, 200_000);
            for i in 0..2 {
                for j in 0..2 {
                    let g = f64::from(got.k[(i, j)]);
                    let w = want[i][j];
                    let scale = w.abs().max(1e-6 * (want[0][0].abs() + want[1][1].abs()));
                    assert!(
                        (g - w).abs() <= 2e-3 * scale,
                        "rate {rate}, σ ({sp}, {sv}, {sa}): K[{i}][{j}] = {g}, Riccati {w}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_steady_state_gain_has_the_least_error_variance_of_any_fixed_gain() {
    let t = 0.01;
    for &(sp, sv, sa) in &AXES {
        let g = steady_state_gain(t as f32, sp as f32, sv as f32, sa as f32).unwrap();
        let k: M2 = [
            [g.k[(0, 0)].into(), g.k[(0, 1)].into()],
            [g.k[(1, 0)].into(), g.k[(1, 1)].into()],
        ];
        // Each error's variance in its own unit, weighted to be comparable.
        let cost = |k: &M2| {
            let s = posterior_covariance(k, t, sp, sv, sa);
            s[0][0] / (sp * sp) + s[1][1] / (sv * sv)
        };
        let best = cost(&k);
        for i in 0..2 {
            for j in 0..2 {
                for step in [-0.05, 0.05] {
                    let mut other = k;
                    other[i][j] += step * (k[i][j].abs() + 1e-3);
                    let c = cost(&other);
                    assert!(
                        c > best,
                        "σ ({sp}, {sv}, {sa}): K[{i}][{j}] moved by {step} gives {c} ≤ {best}"
                    );
                }
            }
        }
    }
}

/// The two-state filter's gains (no disturbance state: the closed forms below are of it).
fn gains(sp: f32, sv: f32, sa: f32) -> EstimatorGains {
    gains_with(sp, sv, sa, 0.0)
}

/// The gains with the disturbance state of time scale `tau_d` (0: none, Choice 510).
fn gains_with(sp: f32, sv: f32, sa: f32, tau_d: f32) -> EstimatorGains {
    let config = EstimatorConfig {
        kind: EstimatorKind::Kalman,
        position_sigma: [sp; 6],
        velocity_sigma: [sv; 6],
        accel_sigma: [sa; 6],
        disturbance_time: tau_d,
    };
    EstimatorGains::new(&config, 100).unwrap()
}

/// A deterministic standard normal sequence (xorshift64* and Box–Muller).
struct Normal(u64);
impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn next(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// The estimate's position and velocity error variance on a vehicle at rest at `offset` (m),
/// told the solution with white noise σₚ, σᵥ every period; the f32 estimator, or (`f64`) the
/// same recursion in f64.
fn filtered_variance(
    g: &EstimatorGains,
    sp: f64,
    sv: f64,
    offset: f64,
    f64_reference: bool,
) -> (f64, f64) {
    let mut noise = Normal(0x9e37_79b9_7f4a_7c15);
    let mut memory = Estimate::new();
    let k: M2 = [
        [g.axes[0].k[(0, 0)].into(), g.axes[0].k[(0, 1)].into()],
        [g.axes[0].k[(1, 0)].into(), g.axes[0].k[(1, 1)].into()],
    ];
    let t = f64::from(g.period);
    let (mut p64, mut v64) = (offset, 0.0);
    let (n, warm) = (400_000u64, 5_000u64);
    let (mut sum_p, mut sum_v) = (0.0, 0.0);
    for tick in 0..n {
        let zp = offset + sp * noise.next();
        let zv = sv * noise.next();
        let (p, v) = if f64_reference {
            if tick == 0 {
                (p64, v64) = (zp, zv);
            } else {
                let (pp, vp) = (p64 + v64 * t, v64);
                let (dz, dv) = (zp - pp, zv - vp);
                p64 = pp + k[0][0] * dz + k[0][1] * dv;
                v64 = vp + k[1][0] * dz + k[1][1] * dv;
            }
            (p64, v64)
        } else {
            let eta = [zp as f32, 0.0, 0.0, 0.0, 0.0, 0.0];
            let eta_dot = [zv as f32, 0.0, 0.0, 0.0, 0.0, 0.0];
            let (e, ed) = memory.step(g, tick, tick, &eta, &eta_dot).unwrap();
            memory.applied(g, tick, &[0.0; 6]);
            (f64::from(e[0]), f64::from(ed[0]))
        };
        if tick >= warm {
            sum_p += (p - offset) * (p - offset);
            sum_v += v * v;
        }
    }
    let m = (n - warm) as f64;
    (sum_p / m, sum_v / m)
}

#[test]
fn white_noise_variance_is_reduced_by_the_closed_form_factor() {
    let (sp, sv, sa) = (0.005, 0.002, 0.02);
    let g = gains(sp as f32, sv as f32, sa as f32);
    let k: M2 = [
        [g.axes[0].k[(0, 0)].into(), g.axes[0].k[(0, 1)].into()],
        [g.axes[0].k[(1, 0)].into(), g.axes[0].k[(1, 1)].into()],
    ];
    // A vehicle at rest: the estimate is (I − K)F x + K z with no process noise, so its
    // covariance solves S = A S Aᵀ + K R Kᵀ, A = (I − K)F.
    let s = posterior_covariance(&k, 0.01, sp, sv, 0.0);
    let (var_p, var_v) = filtered_variance(&g, sp, sv, 0.0, false);
    let (fp, fv) = (s[0][0] / (sp * sp), s[1][1] / (sv * sv));
    assert!(
        fp < 0.2 && fv < 0.5,
        "the filter must reduce noise: {fp}, {fv}"
    );
    for (what, got, want) in [("position", var_p, s[0][0]), ("velocity", var_v, s[1][1])] {
        assert!(
            (got / want - 1.0).abs() < 0.1,
            "{what}: variance {got}, closed form {want}"
        );
    }
}

/// Where f32 costs accuracy: far from the origin a correction is smaller than half an ulp of
/// the position (0.98 mm at 10 km, the largest position the controller accepts). Kept as an
/// offset from the last solution (Choice 342) it is not lost: at 10 km the f32 estimator's
/// filtered noise is the f64 reference's plus at most the rounding of the estimate itself to
/// the position's ulp (uniform, ulp²/12), which no f32 position avoids.
#[test]
fn f32_filters_as_f64_near_the_origin_and_at_ten_kilometres() {
    let (sp, sv, sa) = (0.005, 0.002, 0.02);
    let g = gains(sp as f32, sv as f32, sa as f32);
    let (ref_p, ref_v) = filtered_variance(&g, sp, sv, 10.0, true);
    let (near_p, near_v) = filtered_variance(&g, sp, sv, 10.0, false);
    assert!((near_p / ref_p - 1.0).abs() < 0.05, "{near_p} vs {ref_p}");
    assert!((near_v / ref_v - 1.0).abs() < 0.05, "{near_v} vs {ref_v}");
    let (far_p, _) = filtered_variance(&g, sp, sv, 10_000.0, false);
    let (far_ref_p, _) = filtered_variance(&g, sp, sv, 10_000.0, true);
    assert!((far_ref_p / ref_p - 1.0).abs() < 0.05);
    println!(
        "filtered position σ: f64 {:.3} mm, f32 at 10 m {:.3} mm, f32 at 10 km {:.3} mm",
        ref_p.sqrt() * 1e3,
        near_p.sqrt() * 1e3,
        far_p.sqrt() * 1e3
    );
    // At most the f64 variance plus the rounding of the estimate to the ulp (uniform,
    // ulp²/12); a state kept whole would lose the corrections (σ ≈ 5.9 mm, above the raw
    // solution's 5 mm).
    let ulp = f64::from(10_000f32.next_up() - 10_000f32);
    assert!(
        far_p < far_ref_p + ulp * ulp / 12.0 && far_p > 0.9 * far_ref_p,
        "{far_p} vs {far_ref_p}"
    );
}

#[test]
fn a_constant_acceleration_the_model_does_not_know_is_tracked_with_the_closed_form_lag() {
    let (sp, sv, sa) = (0.005, 0.002, 0.02);
    let g = gains(sp as f32, sv as f32, sa as f32);
    let k: M2 = [
        [g.axes[0].k[(0, 0)].into(), g.axes[0].k[(0, 1)].into()],
        [g.axes[0].k[(1, 0)].into(), g.axes[0].k[(1, 1)].into()],
    ];
    let t = 0.01;
    let a0 = 0.1;
    // e = x − x̂ obeys e⁺ = (I − K)(F e + g a₀): e = (I − (I − K)F)⁻¹ (I − K) g a₀.
    let (f, _, _) = model(t, sp, sv, sa);
    let ik = sub(&I2, &k);
    let m = inv(&sub(&I2, &mul(&ik, &f)));
    let gv = [0.5 * t * t * a0, t * a0];
    let ikg = [
        ik[0][0] * gv[0] + ik[0][1] * gv[1],
        ik[1][0] * gv[0] + ik[1][1] * gv[1],
    ];
    let want = [
        m[0][0] * ikg[0] + m[0][1] * ikg[1],
        m[1][0] * ikg[0] + m[1][1] * ikg[1],
    ];
    let mut memory = Estimate::new();
    let mut last = (0.0, 0.0);
    for tick in 0..1500u64 {
        let time = tick as f64 * t;
        let (p, v) = (0.5 * a0 * time * time, a0 * time);
        let (e, ed) = memory
            .step(
                &g,
                tick,
                tick,
                &[p as f32, 0., 0., 0., 0., 0.],
                &[v as f32, 0., 0., 0., 0., 0.],
            )
            .unwrap();
        memory.applied(&g, tick, &[0.0; 6]);
        last = (p - f64::from(e[0]), v - f64::from(ed[0]));
    }
    assert!(want[0] > 1e-4, "a lag worth measuring: {want:?}");
    assert!(
        (last.0 / want[0] - 1.0).abs() < 0.02,
        "{last:?} vs {want:?}"
    );
    assert!(
        (last.1 / want[1] - 1.0).abs() < 0.02,
        "{last:?} vs {want:?}"
    );
}

type M3 = [[f64; 3]; 3];

fn mul3(a: &M3, b: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn tr3(a: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| a[j][i]))
}

/// The disturbance filter's gain (3×2) after `n` steps of its covariance recursion in f64
/// from P = diag(σₚ², σᵥ², 1): K = P⁻Cᵀ(C P⁻ Cᵀ + R)⁻¹, P⁺ = (I − K C)P⁻, P⁻ ← F P⁺ Fᵀ + Q
/// (C = [I₂ 0]; F, g, Q of docs/law.md#the-state-estimator, Choice 510).
fn riccati_gain_with_disturbance(sp: f64, sv: f64, sa: f64, tau_d: f64, n: usize) -> [[f64; 2]; 3] {
    let t = 0.01;
    let f: M3 = [[1.0, t, 0.5 * t * t], [0.0, 1.0, t], [0.0, 0.0, 1.0]];
    let g = [0.5 * t * t, t, 0.0];
    let mut q: M3 = core::array::from_fn(|i| core::array::from_fn(|j| sa * sa * g[i] * g[j]));
    q[2][2] = sa * sa * 2.0 * t / tau_d;
    let r = [[sp * sp, 0.0], [0.0, sv * sv]];
    let mut p: M3 = [[sp * sp, 0.0, 0.0], [0.0, sv * sv, 0.0], [0.0, 0.0, 1.0]];
    let mut k = [[0.0; 2]; 3];
    for _ in 0..n {
        let s = inv(&add(&[[p[0][0], p[0][1]], [p[1][0], p[1][1]]], &r));
        k = core::array::from_fn(|i| {
            core::array::from_fn(|j| p[i][0] * s[0][j] + p[i][1] * s[1][j])
        });
        let ikc: M3 = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                f64::from(u8::from(i == j)) - if j < 2 { k[i][j] } else { 0.0 }
            })
        });
        let post = mul3(&ikc, &p);
        let fp = mul3(&mul3(&f, &post), &tr3(&f));
        p = core::array::from_fn(|i| core::array::from_fn(|j| fp[i][j] + q[i][j]));
    }
    k
}

#[test]
fn the_disturbance_gain_is_the_limit_of_its_riccati_recursion() {
    for &(sp, sv, sa) in &AXES {
        for tau_d in [10.0, 60.0] {
            let got = gains_with(sp as f32, sv as f32, sa as f32, tau_d as f32).axes[0];
            let want = riccati_gain_with_disturbance(sp, sv, sa, tau_d, 200_000);
            for (i, row) in want.iter().enumerate() {
                for (j, &w) in row.iter().enumerate() {
                    let g = f64::from(if i < 2 { got.k[(i, j)] } else { got.kd[j] });
                    assert!(
                        (g - w).abs() <= 2e-3 * w.abs() + 1e-9,
                        "σ ({sp}, {sv}, {sa}), τ_d {tau_d}: K[{i}][{j}] {g} vs {w}"
                    );
                }
            }
        }
    }
}

/// A steady current is a constant acceleration a₀ the nominal model does not know (its drag
/// on the relative velocity: the vehicle's velocity through the water is offset by the current
/// by a constant). Flown on exact solutions `age` periods old, the two-state filter's
/// prediction keeps a constant error (the closed-form lag of the test above, plus a₀·age²/2
/// over the age); the disturbance state takes a₀ and the prediction's error goes to zero.
#[test]
fn a_steady_current_leaves_no_prediction_error_with_the_disturbance_state() {
    let (sp, sv, sa) = (0.01f32, 0.005, 0.01);
    let (t, a0, age) = (0.01f64, 0.05f64, 5u64);
    let fly = |g: &EstimatorGains| {
        let mut memory = Estimate::new();
        let mut last = (0.0, 0.0);
        for tick in age..12_000u64 {
            let truth = |k: u64| {
                let time = k as f64 * t;
                (0.5 * a0 * time * time, a0 * time)
            };
            let (p, v) = truth(tick - age);
            let (e, ed) = memory
                .step(
                    g,
                    tick,
                    tick - age,
                    &[p as f32, 0., 0., 0., 0., 0.],
                    &[v as f32, 0., 0., 0., 0., 0.],
                )
                .unwrap();
            memory.applied(g, tick, &[0.0; 6]);
            let (p, v) = truth(tick);
            last = (p - f64::from(e[0]), v - f64::from(ed[0]));
        }
        (last, memory.disturbance()[0])
    };
    let (before, _) = fly(&gains(sp, sv, sa));
    let (after, d) = fly(&gains_with(sp, sv, sa, 60.0));
    // Before: at least the prediction's share over the age, a₀·(age·T)²/2.
    let over_age = 0.5 * a0 * (age as f64 * t).powi(2);
    assert!(before.0 > over_age, "two-state: {before:?}");
    assert!(before.1 > a0 * age as f64 * t, "two-state: {before:?}");
    // After: the f32 rounding of positions up to 360 m (ulp 31 µm), not a lag.
    assert!(after.0.abs() < 1e-4, "with the disturbance: {after:?}");
    assert!(after.1.abs() < 1e-4, "with the disturbance: {after:?}");
    assert!(((f64::from(d) - a0) / a0).abs() < 0.01, "d {d} vs a₀ {a0}");
}

/// The motion the model describes: piecewise-constant accelerations a_t, integrated exactly in
/// f64. A solution `age` periods old, exact, and the applied accelerations recorded: the
/// estimate at the current period is the motion's state there.
#[test]
fn prediction_over_the_solution_age_is_exact_under_the_model() {
    let g = gains(0.005, 0.002, 0.02);
    let t = 0.01f64;
    for age in 0..=MAX_AGE {
        let mut noise = Normal(17 + age);
        let n = 400u64;
        let mut p = vec![[0.0f64; 6]];
        let mut v = vec![[0.1f64, -0.2, 0.05, 0.0, 0.01, 0.2]];
        let mut a = Vec::new();
        for _ in 0..n {
            let at: [f64; 6] = core::array::from_fn(|_| 0.2 * noise.next());
            let (pl, vl) = (*p.last().unwrap(), *v.last().unwrap());
            p.push(core::array::from_fn(|i| {
                pl[i] + vl[i] * t + 0.5 * at[i] * t * t
            }));
            v.push(core::array::from_fn(|i| vl[i] + at[i] * t));
            a.push(at);
        }
        let mut memory = Estimate::new();
        // The accelerations applied before the first solution arrives.
        for tick in 0..age {
            memory.applied(&g, tick, &a[tick as usize].map(|x| x as f32));
        }
        let mut worst = 0.0f64;
        for tick in age..n {
            let s = (tick - age) as usize;
            let eta = p[s].map(|x| x as f32);
            let eta_dot = v[s].map(|x| x as f32);
            let (e, ed) = memory.step(&g, tick, tick - age, &eta, &eta_dot).unwrap();
            let k = tick as usize;
            if tick >= age + HORIZON as u64 {
                for i in 0..6 {
                    worst = worst
                        .max((f64::from(e[i]) - p[k][i]).abs())
                        .max((f64::from(ed[i]) - v[k][i]).abs());
                }
            }
            memory.applied(&g, tick, &a[k].map(|x| x as f32));
        }
        // Every period starts the sums afresh: f32 rounding of positions below 1 m.
        assert!(worst < 2e-6, "age {age}: worst error {worst}");
    }
}

#[test]
fn a_solution_too_old_repeated_or_from_the_future_is_refused_and_the_state_held() {
    let g = gains(0.005, 0.002, 0.02);
    let mut memory = Estimate::new();
    let z = [1.0f32, 2.0, 3.0, 0.0, 0.1, 0.2];
    let zd = [0.5f32, 0.0, 0.0, 0.0, 0.0, 0.0];
    memory.step(&g, 100, 100, &z, &zd).unwrap();
    memory.applied(&g, 100, &[0.0; 6]);
    let held = memory.at_stamp();
    let jump = [9.0f32; 6];
    for (ticks, stamp) in [
        (101, 100),
        (101, 102),
        (200, 100),
        (101, 101 - HORIZON as u64 - 1),
        (101, 101 - HORIZON as u64),
    ] {
        let mut m = memory;
        m.step(&g, ticks, stamp, &jump, &jump).unwrap();
        assert_eq!(m.at_stamp(), held, "ticks {ticks}, stamp {stamp}");
    }
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut m = memory;
        let mut eta = z;
        eta[2] = bad;
        let (e, ed) = m.step(&g, 101, 101, &eta, &zd).unwrap();
        assert_eq!(m.at_stamp(), held);
        assert!(e.iter().chain(ed.iter()).all(|x| x.is_finite()));
        // Held and predicted one period: x + v T.
        assert!((e[0] - (1.0 + 0.5 * 0.01)).abs() < 1e-6);
    }
}

/// Choice 527: a finite solution whose correction is not finite (the innovation overflows f32)
/// is not kept: the state, its stamp and its disturbance are those held before, and the
/// estimate is the held state predicted, bit for bit what a refused solution gives (on both
/// filters; the correction is made in place and the held state put back, Choice 566).
#[test]
fn a_correction_that_is_not_finite_leaves_the_held_state_predicted() {
    for (g, with_disturbance) in [
        (gains(0.005, 0.002, 0.02), false),
        (gains_with(0.005, 0.002, 0.02, DISTURBANCE_TIME), true),
    ] {
        let mut memory = Estimate::new();
        let z = [3.0e38f32, 2.0, 3.0, 0.0, 0.1, 0.2];
        let zd = [0.5f32, 0.0, 0.0, 0.0, 0.0, 0.1];
        memory.step(&g, 100, 100, &z, &zd).unwrap();
        memory.applied(&g, 100, &[0.1; 6]);
        memory.step(&g, 101, 101, &z, &zd).unwrap();
        memory.applied(&g, 101, &[0.2; 6]);
        let held = (memory.at_stamp(), memory.disturbance(), memory.stamp());
        assert_eq!(
            held.1 != [0.0; 6],
            with_disturbance,
            "the disturbance state moved: its hold is tested"
        );
        // −3·10³⁸ − 3·10³⁸ overflows: the innovation, the posterior and the gain's terms are
        // infinite.
        let mut overflow = z;
        overflow[0] = -3.0e38;
        let mut refused = z;
        refused[0] = f32::NAN;
        let mut taken = memory;
        let mut reference = memory;
        let estimate = taken.step(&g, 103, 102, &overflow, &zd).unwrap();
        let expected = reference.step(&g, 103, 102, &refused, &zd).unwrap();
        assert_eq!((taken.at_stamp(), taken.disturbance(), taken.stamp()), held);
        assert_eq!(taken, reference);
        let bits = |(e, ed): ([f32; 6], [f32; 6])| {
            e.iter().chain(&ed).map(|x| x.to_bits()).collect::<Vec<_>>()
        };
        assert_eq!(bits(estimate), bits(expected));
        assert!(estimate.0.iter().chain(&estimate.1).all(|x| x.is_finite()));
        // And a finite correction at the same stamp is kept.
        let mut m = memory;
        m.step(&g, 103, 102, &z, &zd).unwrap();
        assert_eq!(m.stamp(), 102);
    }
}

/// Choice 492: periods the board did not run (here 101–109) are zero accelerations, and the
/// record after them moves the state's stamp to the first of them, predicted under the model
/// with the last period's acceleration (x + vT + aT²/2, v + aT), instead of filling the ring's
/// sums period by period; a solution stamped before that first period is then refused, one
/// stamped after it is taken, and the estimate at the new period is the closed-form prediction.
#[test]
fn periods_not_run_move_the_stamp_to_the_first_of_them() {
    let g = gains(0.005, 0.002, 0.02);
    let t = g.period;
    let z = [1.0f32, 2.0, 3.0, 0.0, 0.1, 0.2];
    let zd = [0.5f32, -0.2, 0.0, 0.0, 0.0, 0.01];
    let a = [0.4f32, 0.2, -0.1, 0.0, 0.03, 0.0];
    let mut memory = Estimate::new();
    memory.step(&g, 100, 100, &z, &zd).unwrap();
    memory.applied(&g, 100, &a);
    memory.applied(&g, 110, &[0.0; 6]);
    assert_eq!(memory.stamp(), 101);
    let (x, v) = memory.at_stamp();
    for i in 0..6 {
        let (xe, ve) = (z[i] + zd[i] * t + 0.5 * a[i] * t * t, zd[i] + a[i] * t);
        assert!(
            (x[i] - xe).abs() < 1e-6 && (v[i] - ve).abs() < 1e-6,
            "axis {i}: {x:?} {v:?}"
        );
    }
    // Refused: stamped 101, not newer than the state's; the estimate is the state predicted
    // nine periods on (zero accelerations since).
    let mut m = memory;
    let (e, ed) = m.step(&g, 110, 101, &[9.0; 6], &[9.0; 6]).unwrap();
    assert_eq!(m.at_stamp(), (x, v));
    for i in 0..6 {
        assert!((e[i] - (x[i] + v[i] * 9.0 * t)).abs() < 1e-6 && (ed[i] - v[i]).abs() < 1e-6);
    }
    // Taken: stamped in the missed periods.
    let mut m = memory;
    m.step(&g, 110, 105, &z, &zd).unwrap();
    assert_eq!(m.stamp(), 105);
}

/// A period recorded twice (lock-step: the board ran it once without a fresh frame, then on
/// the frame) is as if recorded once with its last acceleration: the next solution is taken
/// (not refused as older than the state) and the memory is the same, bit for bit.
#[test]
fn a_period_recorded_again_replaces_its_own_acceleration_and_keeps_the_stamp() {
    let g = gains(0.005, 0.002, 0.02);
    let z = |k: u64| [1.0 + 0.005 * k as f32, 2.0, 3.0, 0.0, 0.1, 0.2];
    let zd = [0.5f32, 0.0, 0.0, 0.0, 0.0, 0.0];
    let a = [0.3f32, -0.1, 0.0, 0.0, 0.0, 0.02];
    let mut once = Estimate::new();
    once.step(&g, 100, 100, &z(100), &zd).unwrap();
    once.applied(&g, 100, &a);
    let mut twice = once;
    // The repeat: tick 100's solution predicted to 101, its thrust recorded for 101.
    twice.step(&g, 101, 100, &z(100), &zd).unwrap();
    twice.applied(&g, 101, &[5.0; 6]);
    for m in [&mut once, &mut twice] {
        m.step(&g, 101, 101, &z(101), &zd).unwrap();
        m.applied(&g, 101, &a);
        assert_eq!(m.stamp(), 101, "tick 101's solution taken");
    }
    assert_eq!(twice, once);
    let next_once = once.step(&g, 102, 102, &z(102), &zd);
    assert_eq!(twice.step(&g, 102, 102, &z(102), &zd), next_once);
    assert_eq!(twice.stamp(), 102, "tick 102's solution taken");
}

/// A position fix jumps the solution by 1 m (docs/board.md#the-state-estimator-on-the-board):
/// no gate refuses it; it enters through the gain at once (the estimate moves by K·[d, 0]) and
/// the error then decays as the closed-form recursion e⁺ = (I − K)F e, with K the gain of the
/// Riccati recursion iterated in f64.
#[test]
fn a_position_fix_that_jumps_the_solution_enters_through_the_gain_and_converges() {
    let (t, sp, sv, sa) = (0.01f64, 0.005, 0.002, 0.02);
    let g = gains(sp as f32, sv as f32, sa as f32);
    let k = riccati_gain(t, sp, sv, sa, 200_000);
    let mut memory = Estimate::new();
    let zero = [0.0f32; 6];
    for tick in 0..300 {
        memory.step(&g, tick, tick, &zero, &zero).unwrap();
        memory.applied(&g, tick, &zero);
    }
    let d = 1.0f64;
    let fix = [d as f32, 0.0, 0.0, 0.0, 0.0, 0.0];
    // The error against the vehicle at x = d: before the fix's correction [−d, 0].
    let mut e = [-d, 0.0];
    let step = |e: [f64; 2], first: bool| {
        let prior = if first { e } else { [e[0] + t * e[1], e[1]] };
        let ik = sub(&I2, &k);
        [
            ik[0][0] * prior[0] + ik[0][1] * prior[1],
            ik[1][0] * prior[0] + ik[1][1] * prior[1],
        ]
    };
    for n in 0..400u64 {
        let tick = 300 + n;
        let (x, v) = memory.step(&g, tick, tick, &fix, &zero).unwrap();
        memory.applied(&g, tick, &zero);
        e = step(e, n == 0);
        if n == 0 {
            // At once: K₀₀·d of the jump, and the velocity K₁₀·d.
            assert!(
                (f64::from(x[0]) - k[0][0] * d).abs() < 2e-3 * k[0][0] * d,
                "{}",
                x[0]
            );
            assert!((f64::from(v[0]) - k[1][0] * d).abs() < 2e-3 * k[1][0].abs() * d + 1e-6);
        }
        assert!(
            (f64::from(x[0]) - (d + e[0])).abs() < 2e-3 * d,
            "period {n}: x̂ {} against the closed form {}",
            x[0],
            d + e[0]
        );
        // The other axes never see it.
        assert_eq!(&x[1..], &[0.0; 5]);
    }
    // With the defaults' σ the model is trusted: 4 s after the fix a fifth of it remains
    // (the closed form's 0.20 m of 1 m; docs/board.md#the-state-estimator-on-the-board).
    assert!(e[0].abs() < 0.25 * d, "4 s after the fix: {}", e[0]);
}

fn estimating() -> Controller {
    let mut c = ControllerConfig::default();
    c.estimator.kind = EstimatorKind::Kalman;
    Controller::new(c).unwrap()
}

#[test]
fn with_the_estimator_off_the_solution_is_flown_as_update_flies_it() {
    let c = Controller::new(ControllerConfig::default()).unwrap();
    let tr = Trajectory::table1(Table1Case::Circular10R);
    let mut memory = Estimate::new();
    for k in 0..50u64 {
        let d = tr.sample(k, 100);
        let mut eta: [f32; 6] = d.eta.into();
        eta[0] += 0.01 * (k as f32).sin();
        let nu = [0.5, 0.01, 0.0, 0.0, 0.0, 0.1];
        let s = Solution { stamp: k, eta, nu };
        assert_eq!(
            c.update_from_solution(&mut memory, k, &s, &tr),
            c.update(k, &eta, &nu, &tr)
        );
    }
    assert_eq!(memory, Estimate::new());
}

#[test]
fn a_noise_setting_not_finite_and_positive_is_refused_by_name() {
    for (name, value) in [
        ("estimator_position_sigma", 0.0f32),
        ("estimator_velocity_sigma", -1.0),
        ("estimator_accel_sigma", f32::NAN),
    ] {
        let mut c = ControllerConfig::default();
        c.estimator.kind = EstimatorKind::Kalman;
        let sigma = match name {
            "estimator_position_sigma" => &mut c.estimator.position_sigma,
            "estimator_velocity_sigma" => &mut c.estimator.velocity_sigma,
            _ => &mut c.estimator.accel_sigma,
        };
        sigma[4] = value;
        let e = Controller::new(c).unwrap_err();
        assert!(
            matches!(e, ConfigError::EstimatorSigma { axis: 4, .. }),
            "{e:?}"
        );
        let field = e.field().unwrap();
        assert_eq!((field.name, field.index), (name, Some(4)));
        // Off, the settings are not used and not checked.
        c.estimator.kind = EstimatorKind::Off;
        assert!(Controller::new(c).is_ok());
    }
}

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        prop::num::f32::ANY,
        -1e3f32..1e3,
        -10f32..10.0,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::MAX),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]
    /// Any sequence of solutions — NaN, ±∞, huge, stamps anywhere — never panics, never leaves a
    /// non-finite value in the memory or the output, and a non-finite solution is never taken.
    #[test]
    fn no_solution_makes_the_estimate_or_the_output_non_finite(
        frames in prop::collection::vec(
            (0u64..40, 0u64..40, prop::array::uniform6(any_f32()), prop::array::uniform6(any_f32())),
            1..12,
        ),
    ) {
        let c = estimating();
        let tr = Trajectory::table1(Table1Case::Circular10R);
        let mut memory = Estimate::new();
        let mut ticks = 0u64;
        for (dt, age, eta, nu) in frames {
            ticks += dt;
            let before = memory.at_stamp();
            let s = Solution { stamp: ticks.saturating_sub(age), eta, nu };
            let out = c.update_from_solution(&mut memory, ticks, &s, &tr);
            prop_assert!(out.voltage.iter().chain(out.tau.iter()).all(|x| x.is_finite()));
            let (p, v) = memory.at_stamp();
            prop_assert!(p.iter().chain(v.iter()).all(|x| x.is_finite()));
            if !eta.iter().chain(nu.iter()).all(|x| x.is_finite()) {
                prop_assert_ne!(out.status, Status::Ok);
                // The stamp may move past a period whose entry was replaced, never to the
                // refused solution's values.
                prop_assert!(memory.at_stamp() == before || memory.stamp() != s.stamp || s.stamp == 0);
            }
        }
    }
}

/// The filter of docs/law.md#the-state-estimator as it was before Choice 430, written again
/// over any float: the prediction sums every held period's acceleration with its weight
/// (Δη = Σ aₜ T² (to − t − ½), Δη̇ = Σ aₜ T), the stamp moved on when its period's entry is
/// replaced (and, as Choice 430's filter does, a past period recorded again other than the latest
/// dropped, and, as Choice 492's does, after periods not run the stamp moved to the first of
/// them). In f64 it is the reference; in f32 it is that weighted-sum filter, which differs from
/// the code Choice 430 replaced in that drop and that move only.
#[derive(Clone, Copy)]
struct Weighted<T> {
    anchor: [T; 6],
    offset: [T; 6],
    velocity: [T; 6],
    stamp: u64,
    valid: bool,
    accel: [[T; 6]; HORIZON],
    tick: [u64; HORIZON],
    /// The latest period recorded (`u64::MAX`: none).
    last: u64,
}

impl<T: nalgebra::RealField + Copy> Weighted<T> {
    fn new() -> Self {
        Weighted {
            anchor: [T::zero(); 6],
            offset: [T::zero(); 6],
            velocity: [T::zero(); 6],
            stamp: 0,
            valid: false,
            accel: [[T::zero(); 6]; HORIZON],
            tick: [u64::MAX; HORIZON],
            last: u64::MAX,
        }
    }

    fn predicted(&self, period: T, from: u64, to: u64) -> ([T; 6], [T; 6]) {
        let dt = nalgebra::convert::<f64, T>(to.saturating_sub(from) as f64) * period;
        let (mut p, mut v) = (self.offset, self.velocity);
        for i in 0..6 {
            let (mut dp, mut dv) = (T::zero(), T::zero());
            for j in 0..HORIZON {
                let t = self.tick[j];
                if t >= from && t < to {
                    let lead = nalgebra::convert::<f64, T>((to - t) as f64 - 0.5);
                    dp += period * period * lead * self.accel[j][i];
                    dv += period * self.accel[j][i];
                }
            }
            p[i] += v[i] * dt + dp;
            v[i] += dv;
        }
        (p, v)
    }

    fn step(
        &mut self,
        g: &EstimatorGains,
        ticks: u64,
        stamp: u64,
        eta: &[T; 6],
        eta_dot: &[T; 6],
    ) -> ([T; 6], [T; 6]) {
        let period = nalgebra::convert::<f64, T>(f64::from(g.period));
        // Choice 554: a stamp the period's record keeps.
        let oldest = (ticks + 1).saturating_sub(HORIZON as u64);
        let kept_from = if self.last != u64::MAX && ticks > self.last + 1 {
            (self.last + 1).max(oldest)
        } else {
            oldest
        };
        if stamp <= ticks && stamp >= kept_from {
            if !self.valid {
                (self.anchor, self.offset, self.velocity) = (*eta, [T::zero(); 6], *eta_dot);
                (self.stamp, self.valid) = (stamp, true);
            } else if stamp > self.stamp {
                let (o, v) = self.predicted(period, self.stamp, stamp);
                for i in 0..6 {
                    let k = |r, c| nalgebra::convert::<f64, T>(f64::from(g.axes[i].k[(r, c)]));
                    let mut dz = (eta[i] - self.anchor[i]) - o[i];
                    if i == 5 {
                        let tau = T::two_pi();
                        dz -= tau * ((dz + T::pi()) / tau).floor();
                    }
                    let dv = eta_dot[i] - v[i];
                    self.offset[i] = (k(0, 0) - T::one()) * dz + k(0, 1) * dv;
                    self.velocity[i] = v[i] + k(1, 0) * dz + k(1, 1) * dv;
                }
                (self.anchor, self.stamp) = (*eta, stamp);
            }
        }
        let (o, v) = self.predicted(period, self.stamp, ticks);
        (core::array::from_fn(|i| self.anchor[i] + o[i]), v)
    }

    fn applied(&mut self, g: &EstimatorGains, ticks: u64, a: &[T; 6]) {
        if self.last != u64::MAX && ticks > self.last + 1 && self.valid && self.stamp <= self.last {
            // Choice 492: periods not run; the stamp moves to the first of them.
            let period = nalgebra::convert::<f64, T>(f64::from(g.period));
            let first = self.last + 1;
            (self.offset, self.velocity) = self.predicted(period, self.stamp, first);
            self.stamp = first;
        }
        if self.last == u64::MAX || ticks > self.last {
            self.last = ticks;
        }
        let j = (ticks % HORIZON as u64) as usize;
        let old = self.tick[j];
        if self.valid && old != u64::MAX && old != ticks && old == self.stamp {
            let period = nalgebra::convert::<f64, T>(f64::from(g.period));
            (self.offset, self.velocity) = self.predicted(period, self.stamp, self.stamp + 1);
            self.stamp += 1;
        }
        (self.accel[j], self.tick[j]) = (*a, ticks);
    }
}

/// The largest differences of the f32 estimator, over `periods` periods of a vehicle
/// accelerating in every axis at `origin` (m), told a noisy solution 0–3 periods late (some
/// periods twice, some not at all), from the f64 reference and from the f32 implementation
/// before Choice 430: (position, velocity) in each case, scaled as |Δ| / max(1, |x|).
fn flight_differences(periods: u64, origin: f32) -> ([f64; 2], [f64; 2]) {
    let g = gains(0.005, 0.002, 0.02);
    let mut noise = Normal(0x5eed);
    let (mut new, mut old) = (Estimate::new(), Weighted::<f32>::new());
    let mut reference = Weighted::<f64>::new();
    let (mut to_f64, mut to_old) = ([0.0f64; 2], [0.0f64; 2]);
    let t = 0.01f64;
    let (mut p, mut v) = ([f64::from(origin); 6], [0.3f64, -0.2, 0.05, 0.0, 0.01, 0.1]);
    p[3..].fill(0.0);
    for tick in 0..periods {
        let phase = tick as f64 * t;
        let a: [f64; 6] = core::array::from_fn(|i| {
            0.05 * (0.2 * phase + i as f64).sin() * if i >= 3 { 0.1 } else { 1.0 }
        });
        let lag = (tick / 7) % 4;
        if tick % 11 != 5 {
            let eta = p.map(|x| (x + 0.005 * noise.next()) as f32);
            let eta_dot = v.map(|x| (x + 0.002 * noise.next()) as f32);
            let stamp = tick.saturating_sub(lag);
            let (e, ed) = new.step(&g, tick, stamp, &eta, &eta_dot).unwrap();
            let (eo, edo) = old.step(&g, tick, stamp, &eta, &eta_dot);
            let (er, edr) = reference.step(
                &g,
                tick,
                stamp,
                &eta.map(f64::from),
                &eta_dot.map(f64::from),
            );
            for i in 0..6 {
                let scaled = |x: f32, y: f64| (f64::from(x) - y).abs() / y.abs().max(1.0);
                to_f64[0] = to_f64[0].max(scaled(e[i], er[i]));
                to_f64[1] = to_f64[1].max(scaled(ed[i], edr[i]));
                to_old[0] = to_old[0].max(scaled(e[i], f64::from(eo[i])));
                to_old[1] = to_old[1].max(scaled(ed[i], f64::from(edo[i])));
            }
        }
        let af = a.map(|x| x as f32);
        if tick % 13 != 4 {
            new.applied(&g, tick, &af);
            old.applied(&g, tick, &af);
            reference.applied(&g, tick, &af.map(f64::from));
        }
        for i in 0..6 {
            p[i] += v[i] * t + 0.5 * a[i] * t * t;
            v[i] += a[i] * t;
        }
    }
    (to_f64, to_old)
}

/// Choice 430: the running sums give the prediction the weighted sums gave, to f32 rounding,
/// over a flight with late, repeated and missing solutions and periods, near the origin and
/// at 10 km; and they do not drift: after a day of periods (8.64 M at 100 Hz) the estimate is
/// as close to the f64 reference as in the first hour.
#[test]
fn running_sums_predict_as_the_weighted_sums_did_to_f32_rounding() {
    for origin in [1.0f32, 10_000.0] {
        let (to_f64, to_old) = flight_differences(50_000, origin);
        println!("origin {origin} m: against f64 {to_f64:?}, against the weighted f32 {to_old:?}");
        // A few ulps of the state (|x| ≥ 1 scaled to 1: 2⁻²³ ≈ 1.2e-7 an ulp).
        assert!(to_f64[0] < 8.0 * f64::from(f32::EPSILON), "{to_f64:?}");
        assert!(to_f64[1] < 8.0 * f64::from(f32::EPSILON), "{to_f64:?}");
        assert!(to_old[0] < 8.0 * f64::from(f32::EPSILON), "{to_old:?}");
        assert!(to_old[1] < 8.0 * f64::from(f32::EPSILON), "{to_old:?}");
    }
}

/// A day of periods: the running sums' error against the f64 reference stays that of the
/// first hour (opt-in: ~11 s under `--profile host`; `cargo test --profile host -p
/// controller-core --test estimator -- --ignored a_day`).
#[test]
#[ignore = "a day of 100 Hz periods, ~11 s; run with --ignored"]
fn a_day_of_periods_does_not_drift() {
    let (hour, _) = flight_differences(360_000, 10.0);
    let (day, _) = flight_differences(8_640_000, 10.0);
    println!("against f64: first hour {hour:?}, a day {day:?}");
    assert!(
        day[0] <= 2.0 * hour[0] && day[1] <= 2.0 * hour[1],
        "{hour:?} → {day:?}"
    );
}

/// Choice 554: a solution is taken only at a stamp the period's record keeps, so that the
/// state it corrects is never predicted a third time in that period: at most [`MAX_AGE`] =
/// [`HORIZON`] − 1 periods old, and after periods not run not before the first of them. Before,
/// a solution [`HORIZON`] periods old, or stamped at the last period recorded before a gap, was
/// taken and the record moved the state's stamp again at once.
#[test]
fn a_solution_is_taken_only_at_a_stamp_the_periods_record_keeps() {
    let g = gains(0.005, 0.002, 0.02);
    let z = [1.0f32, 2.0, 3.0, 0.0, 0.1, 0.2];
    let zd = [0.5f32, 0.0, 0.0, 0.0, 0.0, 0.0];
    let jump = [1.5f32, 2.0, 3.0, 0.0, 0.1, 0.2];
    let mut memory = Estimate::new();
    memory.step(&g, 100, 100, &z, &zd).unwrap();
    memory.applied(&g, 100, &[0.0; 6]);
    for tick in 101..=120 {
        memory.step(&g, tick, 100, &z, &zd).unwrap();
        memory.applied(&g, tick, &[0.0; 6]);
    }
    // Every period run, no solution yet: MAX_AGE old is taken, HORIZON old is not.
    let mut first = Estimate::new();
    for tick in 100..=120 {
        first.applied(&g, tick, &[0.0; 6]);
    }
    let mut taken = first;
    taken.step(&g, 121, 121 - MAX_AGE, &jump, &zd).unwrap();
    assert_eq!(taken.stamp(), 121 - MAX_AGE);
    let mut refused = first;
    assert!(refused
        .step(&g, 121, 121 - HORIZON as u64, &jump, &zd)
        .is_none());
    // Periods 121..=124 not run: a stamp at or before the last recorded (120) is refused, the
    // first missed period's is taken.
    let mut refused = memory;
    refused.step(&g, 125, 120, &jump, &zd).unwrap();
    assert_eq!(refused.at_stamp(), memory.at_stamp());
    let mut taken = memory;
    taken.step(&g, 125, 121, &jump, &zd).unwrap();
    assert_eq!(taken.stamp(), 121);
    // Taken, its stamp survives the period's record: not moved (nor predicted) again.
    let before = taken;
    taken.applied(&g, 125, &[0.0; 6]);
    assert_eq!(taken.at_stamp(), before.at_stamp());
    assert_eq!(taken.stamp(), 121);
}

/// One scripted flight of the estimator from period `t0`: a solution every period, most
/// 1–3 periods late, one refused (15 periods not run, then a solution stamped before them),
/// a period recorded twice, a jump of the solution; each period's estimate, stamp and state.
type Flown = Vec<(Option<([f32; 6], [f32; 6])>, u64, ([f32; 6], [f32; 6]))>;
fn scripted_flight(g: &EstimatorGains, t0: u64) -> Flown {
    let mut m = Estimate::new();
    let mut flown = Vec::new();
    let mut k = 0u64;
    for n in 0..120u64 {
        // Periods 60–74 are not run.
        k = if n == 60 { k + 16 } else { k + 1 };
        let late = if n == 60 { 18 } else { n % 4 };
        let stamp = (t0 + k).saturating_sub(late);
        let s = stamp.saturating_sub(t0) as f32;
        let jump = if n >= 90 { 1.0 } else { 0.0 };
        let z = [0.02 * s + jump, -0.01 * s, 3.0, 0.0, 0.1, 0.001 * s];
        let zd = [2.0f32, -1.0, 0.0, 0.0, 0.0, 0.1];
        let e = m.step(g, t0 + k, stamp, &z, &zd);
        let a = [0.1 * (n % 7) as f32, -0.05, 0.02, 0.0, 0.01, 0.0];
        if n % 11 == 0 {
            m.applied(g, t0 + k, &[9.0; 6]);
        }
        m.applied(g, t0 + k, &a);
        flown.push((e, m.stamp() - t0, m.at_stamp()));
    }
    flown
}

/// Choice 499: the estimator counts periods in u32 from an anchor that moves on by whole rings
/// 2³¹ periods past it; a mission that starts anywhere (at 0, across 2³¹ and 2³² periods, near
/// the end of u64) flies the same bits as one that starts at 0 (the filter depends only on
/// differences of periods), and time that goes back past the anchor starts a new mission.
#[test]
fn the_estimator_flies_the_same_bits_wherever_its_periods_start() {
    let g = gains_with(0.005, 0.002, 0.02, 60.0);
    let reference = scripted_flight(&g, 0);
    assert!(reference.iter().all(|f| f.0.is_some()));
    for t0 in [
        1u64 << 20,
        (1 << 31) - 50,
        (1 << 32) - 37,
        (1 << 32) + 5,
        (1 << 40) - 1,
        u64::MAX - 300,
    ] {
        assert_eq!(scripted_flight(&g, t0), reference, "start {t0}");
    }
    // Time goes back past a moved anchor: forgotten, the next solution starts anew.
    let z = [1.0f32; 6];
    let mut m = Estimate::new();
    let t = (1u64 << 33) + 7;
    m.step(&g, t, t, &z, &z).unwrap();
    m.applied(&g, t, &z);
    let mut fresh = Estimate::new();
    for mem in [&mut m, &mut fresh] {
        assert_eq!(mem.step(&g, 1000, 1000, &z, &z), Some((z, z)));
        assert_eq!(mem.stamp(), 1000);
    }
}

/// Choice 499: a solution not renewed for 2³⁰ periods or more (124 days at 100 Hz) when the
/// anchor moves on is forgotten, as in a new mission: the next solution is taken as the state;
/// one renewed is carried across the move (the same estimate as from an anchor at 0).
#[test]
fn a_solution_older_than_the_anchors_move_is_forgotten() {
    let g = gains(0.005, 0.002, 0.02);
    let (z, zd) = (
        [1.0f32, 2.0, 3.0, 0.0, 0.1, 0.2],
        [0.5f32, 0.0, 0.0, 0.0, 0.0, 0.0],
    );
    let mut m = Estimate::new();
    m.step(&g, 10, 10, &z, &zd).unwrap();
    m.applied(&g, 10, &[0.0; 6]);
    // Held and predicted up to 2³¹ − 1 periods on (no solution since).
    let t = (1u64 << 31) - 1;
    assert!(m.step(&g, t, 0, &z, &zd).is_some());
    assert_eq!(m.stamp(), 10);
    // Past 2³¹: the anchor moves on and the state more than 2³⁰ old is forgotten.
    let t = 1u64 << 31;
    assert_eq!(m.step(&g, t, 0, &z, &zd), None);
    assert_eq!(m.step(&g, t, t, &z, &zd), Some((z, zd)));
}
