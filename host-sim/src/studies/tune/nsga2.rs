//! NSGA-II (Deb, Pratap, Agarwal & Meyarivan 2002) on the unit cube, minimising every
//! objective (docs/tune.md#the-search).
//!
//! **Choice 441:** written here rather than taken from a crate. `moors` (0.2, MIT) brings
//! faer, ndarray and a second `rand` (0.9); `optirustic` (1.2, MIT) has moved to another
//! repository and brings chrono, env_logger, a C hypervolume library and a second `rand`;
//! `nsga2` is not on crates.io. The algorithm is small: the fast non-dominated sort, the
//! crowding distance, binary tournaments on (rank, crowding), simulated binary crossover
//! (η = [`ETA_CROSSOVER`]) and polynomial mutation (η = [`ETA_MUTATION`], rate 1/n), every
//! draw from the caller's seeded generator. Constraints are Deb's: a candidate with a smaller
//! violation dominates; among equal violations, Pareto dominance of the objectives.

use rand::RngExt;

/// The crossover's distribution index (SBX, Deb & Agrawal 1995).
pub const ETA_CROSSOVER: f64 = 15.0;
/// The mutation's distribution index.
pub const ETA_MUTATION: f64 = 20.0;
/// The probability a pair is crossed.
pub const CROSSOVER_RATE: f64 = 0.9;

/// A point's objectives (minimised) and its constraint violation (0: feasible).
#[derive(Clone, Debug, PartialEq)]
pub struct Scored {
    pub objectives: Vec<f64>,
    pub violation: f64,
}

/// `a` Pareto-dominates `b`: no objective worse, one better.
pub fn pareto_dominates(a: &[f64], b: &[f64]) -> bool {
    let mut better = false;
    for (x, y) in a.iter().zip(b) {
        if x > y {
            return false;
        }
        better |= x < y;
    }
    better
}

/// Deb's constrained domination: less violation wins; equal violation, Pareto dominance.
pub fn dominates(a: &Scored, b: &Scored) -> bool {
    if a.violation != b.violation {
        a.violation < b.violation
    } else {
        pareto_dominates(&a.objectives, &b.objectives)
    }
}

/// The fast non-dominated sort: the fronts, each a list of indices into `points`, the first
/// front the points no other dominates.
pub fn non_dominated_sort(points: &[Scored]) -> Vec<Vec<usize>> {
    let n = points.len();
    let mut dominated_by = vec![0usize; n];
    let mut dominates_list = vec![Vec::new(); n];
    for i in 0..n {
        for j in 0..n {
            if i != j && dominates(&points[i], &points[j]) {
                dominates_list[i].push(j);
            } else if i != j && dominates(&points[j], &points[i]) {
                dominated_by[i] += 1;
            }
        }
    }
    let mut fronts = Vec::new();
    let mut current: Vec<usize> = (0..n).filter(|&i| dominated_by[i] == 0).collect();
    while !current.is_empty() {
        let mut next = Vec::new();
        for &i in &current {
            for &j in &dominates_list[i] {
                dominated_by[j] -= 1;
                if dominated_by[j] == 0 {
                    next.push(j);
                }
            }
        }
        next.sort_unstable();
        fronts.push(current);
        current = next;
    }
    fronts
}

/// The crowding distance of each member of one front (`front` indexes `points`), in the
/// front's order: per objective, the members sorted, the two ends ∞, each inner one the gap
/// between its neighbours over the objective's range, summed. An objective of zero range, or
/// one that is not finite at an end, adds nothing to the inner members.
pub fn crowding_distance(points: &[Scored], front: &[usize]) -> Vec<f64> {
    let n = front.len();
    let mut d = vec![0.0; n];
    if n == 0 {
        return d;
    }
    let m = points[front[0]].objectives.len();
    for k in 0..m {
        let f = |i: usize| points[front[i]].objectives[k];
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| f(a).total_cmp(&f(b)).then(a.cmp(&b)));
        d[order[0]] = f64::INFINITY;
        d[order[n - 1]] = f64::INFINITY;
        let range = f(order[n - 1]) - f(order[0]);
        if !(range.is_finite() && range > 0.0) {
            continue;
        }
        for w in 1..n.saturating_sub(1) {
            d[order[w]] += (f(order[w + 1]) - f(order[w - 1])) / range;
        }
    }
    d
}

/// Each point's (rank, crowding distance).
pub fn rank_and_crowding(points: &[Scored]) -> Vec<(usize, f64)> {
    let mut out = vec![(0, 0.0); points.len()];
    for (rank, front) in non_dominated_sort(points).iter().enumerate() {
        for (&i, c) in front.iter().zip(crowding_distance(points, front)) {
            out[i] = (rank, c);
        }
    }
    out
}

/// Of `points`, the `keep` survivors: whole fronts in rank order, the last one cut by
/// descending crowding distance (ties by index). Indices into `points`, ascending.
pub fn survivors(points: &[Scored], keep: usize) -> Vec<usize> {
    let mut out = Vec::with_capacity(keep);
    for front in non_dominated_sort(points) {
        if out.len() + front.len() <= keep {
            out.extend_from_slice(&front);
            continue;
        }
        let c = crowding_distance(points, &front);
        let mut order: Vec<usize> = (0..front.len()).collect();
        order.sort_by(|&a, &b| c[b].total_cmp(&c[a]).then(front[a].cmp(&front[b])));
        out.extend(order.iter().take(keep - out.len()).map(|&k| front[k]));
        break;
    }
    out.sort_unstable();
    out
}

/// Binary tournament: the better (lower rank, then larger crowding) of two drawn members.
fn tournament(rc: &[(usize, f64)], rng: &mut impl rand::Rng) -> usize {
    let a = rng.random_range(0..rc.len());
    let b = rng.random_range(0..rc.len());
    let (ra, rb) = (rc[a], rc[b]);
    if ra.0 < rb.0 || (ra.0 == rb.0 && ra.1 > rb.1) {
        a
    } else {
        b
    }
}

/// Simulated binary crossover of one coordinate in [0, 1] (Deb & Agrawal's bounded form).
fn sbx(x1: f64, x2: f64, rng: &mut impl rand::Rng) -> (f64, f64) {
    if (x1 - x2).abs() < 1e-14 {
        return (x1, x2);
    }
    let (y1, y2) = if x1 < x2 { (x1, x2) } else { (x2, x1) };
    let u: f64 = rng.random();
    let child = |beta: f64| {
        let alpha = 2.0 - beta.powf(-(ETA_CROSSOVER + 1.0));
        if u <= 1.0 / alpha {
            (u * alpha).powf(1.0 / (ETA_CROSSOVER + 1.0))
        } else {
            (1.0 / (2.0 - u * alpha)).powf(1.0 / (ETA_CROSSOVER + 1.0))
        }
    };
    let q1 = child(1.0 + 2.0 * y1 / (y2 - y1));
    let c1 = 0.5 * ((y1 + y2) - q1 * (y2 - y1));
    let q2 = child(1.0 + 2.0 * (1.0 - y2) / (y2 - y1));
    let c2 = 0.5 * ((y1 + y2) + q2 * (y2 - y1));
    let (c1, c2) = (c1.clamp(0.0, 1.0), c2.clamp(0.0, 1.0));
    if rng.random::<bool>() {
        (c2, c1)
    } else {
        (c1, c2)
    }
}

/// Polynomial mutation of one coordinate in [0, 1].
fn mutate(x: f64, rng: &mut impl rand::Rng) -> f64 {
    let u: f64 = rng.random();
    let p = 1.0 / (ETA_MUTATION + 1.0);
    let delta = if u < 0.5 {
        let b = 2.0 * u + (1.0 - 2.0 * u) * (1.0 - x).powf(ETA_MUTATION + 1.0);
        b.powf(p) - 1.0
    } else {
        let b = 2.0 * (1.0 - u) + 2.0 * (u - 0.5) * x.powf(ETA_MUTATION + 1.0);
        1.0 - b.powf(p)
    };
    (x + delta).clamp(0.0, 1.0)
}

/// Two children of the parents picked by tournament from `parents` (their `rc`), by SBX
/// (each coordinate with probability ½) and polynomial mutation (rate 1/n).
pub fn offspring(
    parents: &[Vec<f64>],
    rc: &[(usize, f64)],
    rng: &mut impl rand::Rng,
) -> [Vec<f64>; 2] {
    let a = &parents[tournament(rc, rng)];
    let b = &parents[tournament(rc, rng)];
    let (mut c1, mut c2) = (a.clone(), b.clone());
    let n = a.len();
    if rng.random::<f64>() < CROSSOVER_RATE {
        for j in 0..n {
            if rng.random::<bool>() {
                (c1[j], c2[j]) = sbx(a[j], b[j], rng);
            }
        }
    }
    let rate = 1.0 / n.max(1) as f64;
    for c in [&mut c1, &mut c2] {
        for x in c.iter_mut() {
            if rng.random::<f64>() < rate {
                *x = mutate(*x, rng);
            }
        }
    }
    [c1, c2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sbx_and_mutation_stay_in_the_cube() {
        use rand::SeedableRng;
        let mut r = rand::rngs::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..2000 {
            let (x, y) = (r.random::<f64>(), r.random::<f64>());
            let (a, b) = sbx(x, y, &mut r);
            let m = mutate(x, &mut r);
            for v in [a, b, m] {
                assert!((0.0..=1.0).contains(&v), "{v}");
            }
        }
    }
}
