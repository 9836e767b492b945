//! The saturation-aware allocator (`controller_core::allocation::Allocator`,
//! docs/thrusters.md#envelopes-at-the-supply-limit): a feasible demand gives exactly B₅⁻¹τ; the thrusts are always inside the envelope; a
//! higher-priority axis is met exactly whenever it is feasible on its own; the weighted
//! least-squares optimum and the lexicographic optimum are no worse than a brute-force search
//! over a fine grid of the box; the saturation bits and the unallocated part say what was given
//! up. Every expected value is computed here from B and the envelope, in f64.

use controller_core::allocation::{
    Allocated, AllocationError, Allocator, AxisPriority, PseudoInverse,
};
use controller_core::effectiveness::{ThrusterGeometry, THRUSTERS};
use controller_core::thruster::{default_maps, ThrustEnvelope, ThrustUnit};
use nalgebra::Vector6;
use proptest::prelude::*;

/// Rows of τ = [X Y Z K M N].
const X: usize = 0;
const Y: usize = 1;
const Z: usize = 2;
const M: usize = 4;
const N: usize = 5;

/// The blocks of the AUV-150: (thrusters, axes).
const BLOCKS: [([usize; 2], [usize; 2]); 2] = [([1, 2], [Z, M]), ([3, 4], [Y, N])];

fn envelope(unit: ThrustUnit) -> ThrustEnvelope {
    ThrustEnvelope::new(&default_maps(), unit, 24.0)
}

fn allocator(
    reversed: u8,
    unit: ThrustUnit,
    priority: &AxisPriority,
) -> (Allocator, PseudoInverse) {
    let a = PseudoInverse::new(&ThrusterGeometry::auv150(reversed)).expect("AUV-150 layout");
    let al = Allocator::new(&a, &envelope(unit), priority).expect("block geometry");
    (al, a)
}

/// B·T in f64, row `r`.
fn row(a: &PseudoInverse, r: usize, t: &[f32; THRUSTERS]) -> f64 {
    let b = a.matrix();
    (0..THRUSTERS).map(|c| b[(r, c)] as f64 * t[c] as f64).sum()
}

/// The range of axis `r` over the block's box (interval arithmetic in f64).
fn reach(a: &PseudoInverse, e: &ThrustEnvelope, thrusters: [usize; 2], r: usize) -> (f64, f64) {
    let b = a.matrix();
    let (mut lo, mut hi) = (0.0, 0.0);
    for t in thrusters {
        let g = b[(r, t)] as f64;
        let (x, y) = (g * e.min[t] as f64, g * e.max[t] as f64);
        lo += x.min(y);
        hi += x.max(y);
    }
    (lo, hi)
}

/// The same f32 bits, or both zeros of either sign.
fn same_bits(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0)
}

fn inside(e: &ThrustEnvelope, out: &Allocated) -> bool {
    e.contains(&out.thrusts)
}

fn wrench() -> impl Strategy<Value = [f32; 6]> {
    prop_oneof![
        proptest::array::uniform6(-1.0e3f32..1.0e3),
        proptest::array::uniform6(-1.0e5f32..1.0e5),
        proptest::array::uniform6(-50.0f32..50.0),
    ]
}

fn unit() -> impl Strategy<Value = ThrustUnit> {
    prop_oneof![Just(ThrustUnit::Kgf), Just(ThrustUnit::Newton)]
}

/// [`Allocator::allocate`] on a layout of the AUV-150's blocks with lexicographic rules: each
/// block's higher axis met exactly when feasible (else at the nearest end of its reach), the
/// lower then no worse than a brute-force grid on the segment that gives the higher.
fn lexicographic_optimum(
    al: &Allocator,
    a: &PseudoInverse,
    e: &ThrustEnvelope,
    tau: &[f32; 6],
) -> Result<(), TestCaseError> {
    let out = al.allocate(&Vector6::from(*tau));
    // (block, high axis, low axis)
    for (thrusters, high, low) in [(BLOCKS[0].0, M, Z), (BLOCKS[1].0, N, Y)] {
        let (lo, hi) = reach(a, e, thrusters, high);
        let want = (tau[high] as f64).clamp(lo, hi);
        let got = row(a, high, &out.thrusts);
        let tol = 1e-4 * (hi - lo);
        prop_assert!(
            (got - want).abs() <= tol,
            "axis {}: achieved {} but {} is reachable ({} … {})",
            high,
            got,
            want,
            lo,
            hi
        );
        // Brute force on the segment {g_high·T = want}: a fine grid of the first thruster,
        // the second from the segment's equation; the best lower-axis residual there.
        let b = a.matrix();
        let [p, q] = thrusters;
        let (gp, gq) = (b[(high, p)] as f64, b[(high, q)] as f64);
        let mut best = f64::INFINITY;
        for k in 0..=4000 {
            let tp = e.min[p] as f64 + (e.max[p] - e.min[p]) as f64 * k as f64 / 4000.0;
            let tq = (want - gp * tp) / gq;
            if tq < e.min[q] as f64 - 1e-9 || tq > e.max[q] as f64 + 1e-9 {
                continue;
            }
            let r = tau[low] as f64 - (b[(low, p)] as f64 * tp + b[(low, q)] as f64 * tq);
            best = best.min(r.abs());
        }
        let mine = (tau[low] as f64 - row(a, low, &out.thrusts)).abs();
        let step = (e.max[p] - e.min[p]) as f64 / 4000.0 * 4.0;
        prop_assert!(
            mine <= best + step + 1e-4 * (tau[low].abs() as f64).max(1.0),
            "axis {}: residual {} but the segment allows {}",
            low,
            mine,
            best
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// A demand the thrusters can give: exactly B₅⁻¹τ, nothing unallocated, no saturation.
    #[test]
    fn feasible_demand_gives_exactly_the_inverse(
        frac in proptest::array::uniform5(0.0f32..1.0),
        reversed in 0u8..32,
        unit in unit(),
    ) {
        let (al, a) = allocator(reversed, unit, &AxisPriority::default());
        let e = envelope(unit);
        // Thrusts strictly inside the box (1 % from each bound), and their wrench.
        let t: [f32; THRUSTERS] = std::array::from_fn(|i| {
            e.min[i] + (0.01 + 0.98 * frac[i]) * (e.max[i] - e.min[i])
        });
        let tau = a.wrench(&t);
        let out = al.allocate(&tau);
        prop_assert_eq!(out.thrusts, a.thrusts(&tau));
        prop_assert_eq!(out.saturated, 0);
        prop_assert_eq!(out.unallocated, [0.0; 6]);
    }

    /// Choice 522: the allocator forms B·T per block row (the voltage maps' achieved wrench);
    /// on every one of the 32 mountings it has the bits of the dense 6×5 product
    /// (`PseudoInverse::wrench`, nalgebra's), not merely its values. A zero may differ in its
    /// sign only.
    #[test]
    fn block_wrench_has_the_dense_products_bits(
        frac in proptest::array::uniform5(0.0f32..1.0),
        reversed in 0u8..32,
        unit in unit(),
    ) {
        let (al, a) = allocator(reversed, unit, &AxisPriority::default());
        let e = envelope(unit);
        let t: [f32; THRUSTERS] = std::array::from_fn(|i| e.min[i] + frac[i] * (e.max[i] - e.min[i]));
        let (fast, dense) = (al.wrench(&t), a.wrench(&t));
        for r in 0..6 {
            prop_assert!(same_bits(fast[r], dense[r]), "row {r}: {} vs {}", fast[r], dense[r]);
        }
    }

    /// Whatever the demand, every thrust is inside its envelope; saturation bits only on
    /// thrusters at a bound, and only when their block fell short.
    #[test]
    fn always_inside_the_envelope(tau in wrench(), reversed in 0u8..32, unit in unit()) {
        let (al, a) = allocator(reversed, unit, &AxisPriority::default());
        let e = envelope(unit);
        let out = al.allocate(&Vector6::from(tau));
        prop_assert!(inside(&e, &out), "{:?} outside {:?}", out.thrusts, e);
        let exact = a.thrusts(&Vector6::from(tau));
        let met = e.contains(&exact);
        prop_assert_eq!(met, out.saturated == 0);
        for i in 0..THRUSTERS {
            if out.saturated & (1 << i) != 0 {
                let w = e.max[i] - e.min[i];
                let gap = (out.thrusts[i] - e.min[i]).min(e.max[i] - out.thrusts[i]);
                prop_assert!(gap <= 1e-3 * w, "thruster {} flagged {} from a bound", i, gap);
            }
        }
        // τ_K is never allocated and never reported as unallocated.
        prop_assert_eq!(out.unallocated[3], 0.0);
        // Unallocated = τ − B·T on every axis (zero on the axes of met blocks).
        for r in [X, Y, Z, M, N] {
            let short = tau[r] as f64 - row(&a, r, &out.thrusts);
            let scale = tau[r].abs().max(1.0) as f64;
            let u = out.unallocated[r] as f64;
            prop_assert!(u == 0.0 && short.abs() <= 1e-4 * scale || (u - short).abs() <= 1e-4 * scale,
                "axis {}: unallocated {} vs τ − BT = {}", r, u, short);
        }
    }

    /// Lexicographic blocks (the default: pitch over depth, yaw over sway): the higher axis is
    /// met exactly when it is feasible on its own, and otherwise held at the nearest end of its
    /// reach; the lower axis is then no worse than the best grid point of the box that gives the
    /// same higher axis.
    #[test]
    fn higher_priority_axis_is_met_when_feasible(tau in wrench(), reversed in 0u8..32, unit in unit()) {
        let (al, a) = allocator(reversed, unit, &AxisPriority::default());
        lexicographic_optimum(&al, &a, &envelope(unit), &tau)?;
    }

    /// The same on a layout whose aft thrusters sit further aft than the fore ones are forward
    /// (2.2 m against 1.8 m): each block's larger gain on its higher axis (pitch, yaw) is its
    /// second thruster's, which the allocator takes first (Choice 493).
    #[test]
    fn higher_priority_axis_is_met_with_unequal_arms(tau in wrench(), reversed in 0u8..32, unit in unit()) {
        let mut g = ThrusterGeometry::auv150(reversed);
        g.position[2][0] = -2.2;
        g.position[4][0] = -2.2;
        let b = g.effectiveness().expect("a valid layout");
        prop_assert!(b[(M, 2)].abs() > b[(M, 1)].abs() && b[(N, 4)].abs() > b[(N, 3)].abs());
        let a = PseudoInverse::new(&g).expect("a block layout");
        let al = Allocator::new(&a, &envelope(unit), &AxisPriority::default()).expect("blocks");
        lexicographic_optimum(&al, &a, &envelope(unit), &tau)?;
    }

    /// Equal priority within each block: the weighted least-squares optimum over the box is no
    /// worse than the best of a 401 × 401 grid of the box.
    #[test]
    fn weighted_optimum_matches_brute_force(
        tau in wrench(),
        w in proptest::array::uniform6(0.05f32..20.0),
        reversed in 0u8..32,
        unit in unit(),
    ) {
        let priority = AxisPriority { rank: [1, 2, 2, 0, 2, 2], weight: w };
        let (al, a) = allocator(reversed, unit, &priority);
        let e = envelope(unit);
        let out = al.allocate(&Vector6::from(tau));
        prop_assert!(inside(&e, &out));
        let b = a.matrix();
        for (thrusters, axes) in BLOCKS {
            let cost = |t: [f64; 2]| -> f64 {
                axes.iter().map(|&r| {
                    let res = tau[r] as f64
                        - (b[(r, thrusters[0])] as f64 * t[0] + b[(r, thrusters[1])] as f64 * t[1]);
                    w[r] as f64 * res * res
                }).sum()
            };
            let [p, q] = thrusters;
            let mut best = f64::INFINITY;
            for i in 0..=400 {
                for j in 0..=400 {
                    let tp = e.min[p] as f64 + (e.max[p] - e.min[p]) as f64 * i as f64 / 400.0;
                    let tq = e.min[q] as f64 + (e.max[q] - e.min[q]) as f64 * j as f64 / 400.0;
                    best = best.min(cost([tp, tq]));
                }
            }
            let mine = cost([out.thrusts[p] as f64, out.thrusts[q] as f64]);
            prop_assert!(mine <= best * (1.0 + 1e-4) + 1e-3,
                "block {:?}: cost {} > grid's {}", axes, mine, best);
        }
    }
}

#[test]
fn main_thruster_clamps_surge_alone() {
    let (al, _) = allocator(0b11110, ThrustUnit::Kgf, &AxisPriority::default());
    let e = envelope(ThrustUnit::Kgf);
    let out = al.allocate(&Vector6::new(5000.0, 0.0, 0.0, 0.0, 0.0, 0.0));
    assert_eq!(out.thrusts, [e.max[0], 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(out.saturated, 1);
    assert!((out.unallocated[X] - (5000.0 - e.max[0])).abs() < 1e-3);
    let out = al.allocate(&Vector6::new(-5000.0, 0.0, 0.0, 0.0, 0.0, 0.0));
    assert_eq!(out.thrusts[0], e.min[0]);
}

#[test]
fn pitch_is_kept_and_depth_given_up() {
    // A nose-up moment the vertical pair can give (+255 N m, a 5 cm forward CG shift of the
    // full payload) with an upward force it cannot (2 kN): the moment is met, the force is
    // the most the pair can push up while keeping the moment.
    let (al, a) = allocator(0b11110, ThrustUnit::Kgf, &AxisPriority::default());
    let e = envelope(ThrustUnit::Kgf);
    let out = al.allocate(&Vector6::new(0.0, 0.0, -2000.0, 0.0, 255.0, 0.0));
    assert!((row(&a, M, &out.thrusts) - 255.0).abs() < 1e-2);
    // Up = positive thrust on both; the moment is 1.8 (T_f − T_a): T_f = T_max, T_a below it.
    assert_eq!(out.thrusts[1], e.max[1]);
    assert!((out.thrusts[2] as f64 - (e.max[2] as f64 - 255.0 / 1.8)).abs() < 1e-3);
    assert_eq!(out.saturated, 1 << 1);
    assert!(out.unallocated[M].abs() < 1e-2 && out.unallocated[Z] < -1000.0);
}

#[test]
fn non_finite_demand_switches_everything_off() {
    let (al, _) = allocator(0b11110, ThrustUnit::Kgf, &AxisPriority::default());
    for bad in [f32::NAN, f32::INFINITY] {
        let out = al.allocate(&Vector6::new(0.0, bad, 0.0, 0.0, 0.0, 0.0));
        assert_eq!(out.thrusts, [0.0; THRUSTERS]);
        assert_eq!(out.saturated, 0b11111);
        assert_eq!(out.unallocated, [0.0; 6]);
    }
}

#[test]
fn refuses_non_block_geometries_and_bad_weights() {
    // A main thruster tilted in the horizontal plane couples surge and sway: one block of three
    // thrusters.
    let mut g = ThrusterGeometry::default();
    g.direction[0] = [0.8, 0.6, 0.0];
    let a = PseudoInverse::new(&g).expect("invertible");
    let err = Allocator::new(&a, &envelope(ThrustUnit::Kgf), &AxisPriority::default())
        .expect_err("not block diagonal");
    assert_eq!(
        err,
        AllocationError::NotBlockDiagonal {
            thrusters: 3,
            axes: 3
        }
    );
    assert!(err.to_string().contains("block-diagonal"), "{err}");
    let a = PseudoInverse::new(&ThrusterGeometry::default()).expect("default");
    let mut p = AxisPriority::default();
    p.weight[M] = 0.0;
    assert_eq!(
        Allocator::new(&a, &envelope(ThrustUnit::Kgf), &p),
        Err(AllocationError::Weight {
            axis: M,
            weight: 0.0
        })
    );
    // K's weight is not used.
    p.weight = [1.0, 1.0, 1.0, f32::NAN, 1.0, 1.0];
    assert!(Allocator::new(&a, &envelope(ThrustUnit::Kgf), &p).is_ok());
    assert_eq!(
        AxisPriority::default().to_string(),
        "pitch > depth > yaw > sway > surge"
    );
}
