//! `host-sim tune` (docs/tune.md): NSGA-II's sort and crowding against brute force and closed
//! cases, the constraint filter against the law's conditions, and a study's determinism and
//! sharding on a tiny budget.

use host_sim::scenario::real_vehicle;
use host_sim::studies::tune::nsga2::{
    crowding_distance, dominates, non_dominated_sort, survivors, Scored,
};
use host_sim::studies::tune::{self, admissible, Candidate, Gains, Refusal, Scores, Spec};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

fn random_points(r: &mut ChaCha8Rng, n: usize, m: usize) -> Vec<Scored> {
    (0..n)
        .map(|_| Scored {
            // A coarse grid, so that ties and equal points occur.
            objectives: (0..m).map(|_| f64::from(r.random_range(0..6u8))).collect(),
            violation: if r.random::<f64>() < 0.2 {
                f64::from(r.random_range(1..3u8))
            } else {
                0.0
            },
        })
        .collect()
}

/// The rank of each point by definition: rank 0 if nothing dominates it, else one more than
/// the largest rank of those that dominate it (computed by repeated peeling, O(n³)).
fn brute_ranks(p: &[Scored]) -> Vec<usize> {
    let n = p.len();
    let mut rank = vec![usize::MAX; n];
    let mut left: Vec<usize> = (0..n).collect();
    let mut r = 0;
    while !left.is_empty() {
        let layer: Vec<usize> = left
            .iter()
            .copied()
            .filter(|&i| !left.iter().any(|&j| dominates(&p[j], &p[i])))
            .collect();
        for &i in &layer {
            rank[i] = r;
        }
        left.retain(|i| !layer.contains(i));
        r += 1;
    }
    rank
}

#[test]
fn non_dominated_sort_matches_brute_force_on_random_sets() {
    let mut r = ChaCha8Rng::seed_from_u64(7);
    for trial in 0..300 {
        let n = 1 + trial % 40;
        let m = 1 + trial % 4;
        let p = random_points(&mut r, n, m);
        let fronts = non_dominated_sort(&p);
        let mut rank = vec![usize::MAX; n];
        for (k, f) in fronts.iter().enumerate() {
            for &i in f {
                assert_eq!(rank[i], usize::MAX, "point {i} in two fronts");
                rank[i] = k;
            }
        }
        assert_eq!(rank, brute_ranks(&p), "trial {trial}: {p:?}");
    }
}

#[test]
fn survivors_keep_whole_better_fronts() {
    let mut r = ChaCha8Rng::seed_from_u64(11);
    for trial in 0..200 {
        let n = 2 + trial % 30;
        let p = random_points(&mut r, n, 3);
        let keep = 1 + trial % n;
        let kept = survivors(&p, keep);
        assert_eq!(kept.len(), keep);
        let rank = brute_ranks(&p);
        // No point left out has a better rank than one kept.
        let worst_kept = kept.iter().map(|&i| rank[i]).max().unwrap();
        for i in (0..n).filter(|i| !kept.contains(i)) {
            assert!(rank[i] >= worst_kept, "trial {trial}");
        }
    }
}

fn pts(xs: &[[f64; 2]]) -> Vec<Scored> {
    xs.iter()
        .map(|x| Scored {
            objectives: x.to_vec(),
            violation: 0.0,
        })
        .collect()
}

#[test]
fn crowding_distance_closed_cases() {
    // Four points of one front: ends infinite; (1, 3): (2 − 0)/4 + (4 − 2)/4 = 1;
    // (2, 2): (4 − 1)/4 + (3 − 0)/4 = 1.5.
    let p = pts(&[[0.0, 4.0], [1.0, 3.0], [2.0, 2.0], [4.0, 0.0]]);
    let d = crowding_distance(&p, &[0, 1, 2, 3]);
    assert_eq!(d[0], f64::INFINITY);
    assert_eq!(d[3], f64::INFINITY);
    assert!((d[1] - 1.0).abs() < 1e-12, "{d:?}");
    assert!((d[2] - 1.5).abs() < 1e-12, "{d:?}");
    // n evenly spaced points on x + y = 1: each inner one 2 · 2/(n − 1).
    let n = 9;
    let line: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let x = i as f64 / (n - 1) as f64;
            [x, 1.0 - x]
        })
        .collect();
    let p = pts(&line);
    let front: Vec<usize> = (0..n).rev().collect();
    let d = crowding_distance(&p, &front);
    for (k, &i) in front.iter().enumerate() {
        if i == 0 || i == n - 1 {
            assert_eq!(d[k], f64::INFINITY);
        } else {
            assert!((d[k] - 4.0 / (n - 1) as f64).abs() < 1e-12, "{d:?}");
        }
    }
    // Two points, or an objective of no range: ends infinite, nothing else added.
    let p = pts(&[[1.0, 5.0], [1.0, 6.0], [1.0, 7.0]]);
    let d = crowding_distance(&p, &[0, 1, 2]);
    assert_eq!(d[0], f64::INFINITY);
    assert_eq!(d[2], f64::INFINITY);
    assert!((d[1] - 1.0).abs() < 1e-12, "{d:?}");
}

#[test]
fn quantile_is_the_nearest_rank() {
    let xs: Vec<f64> = (1..=20).rev().map(f64::from).collect();
    assert_eq!(tune::quantile(&xs, 0.95), 19.0);
    assert_eq!(tune::quantile(&xs, 1.0), 20.0);
    assert_eq!(tune::quantile(&[3.0], 0.95), 3.0);
}

#[test]
fn the_constraint_filter_takes_the_laws_conditions() {
    let base = real_vehicle::real_scenarios().unwrap().swap_remove(0);
    let shipped = Gains::of(&base.config().controller);
    // The shipped (paper's) gains: K = 4, μ = 0.1, δ_max = 25 (Choice 497: the link carries no μ).
    let mu = 0.1f32 as f64;
    assert_eq!(shipped.0, [4.0, 4.0, 4.0, 4.0, 4.0, 4.0, mu, 25.0, 1.0]);
    // Eq 40 at δ_max with Q = I: √(μ δ_max / 2).
    let limit = tune::ball_at_delta_max(&base.config().controller);
    assert!((limit - (mu * 25.0 / 2.0).sqrt()).abs() < 1e-9);
    assert!(admissible(&base, &shipped, limit).is_ok());

    // Theorem 4's ball: μ = 0.4, δ_max = 25 → √5 > √1.25.
    let mut wide = shipped;
    wide.0[6] = 0.4;
    match admissible(&base, &wide, limit) {
        Err(Refusal::Ball { radius, .. }) => {
            assert!((radius - (0.4f32 as f64 * 12.5).sqrt()).abs() < 1e-6)
        }
        other => panic!("{other:?}"),
    }

    // The loop-rate rule, T (k₂ + p₂₂ δ_max/μ) < 2 at 100 Hz. Surge with k₁ = 4, k₂ = 0.5,
    // Q = I: AᵀP + PA = −I gives p₁₂ = 1/(2k₁) = 0.125 and p₂₂ = (1 + 2p₁₂)/(2k₂) = 1.25, so
    // δ_max/μ = 50/0.02 makes T·(…) = 0.01 · (0.5 + 3125) ≈ 31 ≥ 2.
    let mut fast = shipped;
    (fast.0[3], fast.0[6], fast.0[7]) = (0.5, 0.02, 50.0);
    match admissible(&base, &fast, f64::INFINITY) {
        Err(Refusal::Law(e)) => assert!(e.to_string().contains("loop period"), "{e}"),
        other => panic!("{other:?}"),
    }
    // The same with δ_max/μ = 5/0.5: 0.01 · (0.5 + 12.5) < 2, admitted (the ball √1.25 too).
    (fast.0[6], fast.0[7]) = (0.5, 5.0);
    assert!(admissible(&base, &fast, limit).is_ok());

    // Assumption 2 (β̂ ≤ β) does not depend on the searched settings, but the filter's path
    // is the one that refuses it: β = 0.01 is below the box's β̂, β = 0.9 above.
    let high_beta = base.with(|c| c.controller.beta = 0.9).unwrap();
    assert!(admissible(&high_beta, &shipped, limit).is_ok());
    let Err(e) = base.with(|c| c.controller.beta = 0.01) else {
        panic!("β = 0.01 accepted");
    };
    assert!(e.to_string().contains("Assumption 2"), "{e}");
}

/// A budget small enough for a test: one mission under both presets, 3 s, population 4, one
/// generation, two restarts.
fn tiny() -> Spec {
    Spec {
        seed: 5,
        missions: 1,
        duration: 3.0,
        margin: 0.8,
        population: 4,
        generations: 1,
        restarts: 2,
    }
}

/// Deb's constrained domination written out from the scores (not the library's `dominates`):
/// fewer missions refused or failed wins; as many, `a` is no worse on every p95 and better on
/// one.
fn beats(a: &Scores, b: &Scores) -> bool {
    let (va, vb) = (a.refused + a.failed, b.refused + b.failed);
    if va != vb {
        return va < vb;
    }
    let pairs = a.p95.iter().zip(&b.p95);
    pairs.clone().all(|(x, y)| x <= y) && pairs.clone().any(|(x, y)| x < y)
}

#[test]
fn a_study_is_deterministic_and_shards_merge_to_one_run() {
    let spec = tiny();
    let whole = tune::run_shard(&spec, 0, 1, &|| ()).unwrap();
    let one = tune::merge(std::slice::from_ref(&whole)).unwrap();
    let a = tune::run_shard(&spec, 0, 2, &|| ()).unwrap();
    let b = tune::run_shard(&spec, 1, 2, &|| ()).unwrap();
    let merged = tune::merge(&[b, a]).unwrap();
    assert!(!one.front.is_empty());
    assert_eq!(one.front, merged.front);
    assert_eq!(one.chosen, merged.chosen);
    assert_eq!(one.shipped, merged.shipped);
    assert_eq!(one.evaluations, merged.evaluations);
    assert_eq!(one.evaluations, 2 * spec.evaluations_per_restart());
    assert!(one.missing.is_empty());
    // The front against every candidate the study flew, by brute force: each member was
    // flown with the scores it reports, no flown candidate beats it, and every flown candidate
    // that nothing flown beats is on it.
    let flown: Vec<&Candidate> = whole.restarts.iter().flat_map(|r| &r.evaluated).collect();
    assert_eq!(flown.len(), one.evaluations);
    assert!(flown.iter().any(|c| c.x == one.shipped.x));
    for c in &one.front {
        assert!(flown.iter().any(|f| f.x == c.x && f.scores == c.scores));
        assert!(
            !flown.iter().any(|f| beats(&f.scores, &c.scores)),
            "{:?}",
            c.gains
        );
    }
    for f in &flown {
        let beaten = flown.iter().any(|g| beats(&g.scores, &f.scores));
        let on_front = one.front.iter().any(|c| c.x == f.x);
        assert_eq!(on_front, !beaten, "{:?}: {:?}", f.gains, f.scores);
    }
}
