//! How sure a count of zero failures makes us (docs/search.md#the-contracts-statistics): the
//! one-sided Clopper–Pearson upper bound on a failure rate from `k` failures in `n`
//! independent draws. **Choice 415:** one-sided (the rule of three, 3/n for k = 0 at 95 %, is
//! its large-n form), exact rather than the rule (it holds for small n too).

/// The p at which P(X ≤ `k`) = 1 − `confidence` for X ~ Binomial(`n`, p): the largest failure
/// rate that `k` failures in `n` draws do not exclude at `confidence` (one-sided). 1 when
/// `k` ≥ `n`; NaN for `n` = 0 or a confidence outside (0, 1).
pub fn clopper_pearson_upper(k: u64, n: u64, confidence: f64) -> f64 {
    if n == 0 || !(confidence > 0.0 && confidence < 1.0) {
        return f64::NAN;
    }
    if k >= n {
        return 1.0;
    }
    let alpha = 1.0 - confidence;
    if k == 0 {
        // (1 − p)ⁿ = α.
        return -f64::exp_m1(alpha.ln() / n as f64);
    }
    // P(X ≤ k) falls with p: bisect in (0, 1).
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if binomial_cdf(k, n, mid) > alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// P(X ≤ `k`) for X ~ Binomial(`n`, `p`), 0 < p < 1, summed in logarithms.
fn binomial_cdf(k: u64, n: u64, p: f64) -> f64 {
    let (lp, lq) = (p.ln(), (-p).ln_1p());
    let mut log_choose = 0.0; // ln C(n, 0)
    let mut sum = 0.0;
    for i in 0..=k {
        if i > 0 {
            log_choose += ((n - i + 1) as f64).ln() - (i as f64).ln();
        }
        sum += (log_choose + i as f64 * lp + (n - i) as f64 * lq).exp();
    }
    sum
}

/// "0 false feasible in N sampled and M adversarial evaluations, 95 % upper bound on the rate
/// …": the contract's statistics in a sentence. The bound is over the `sampled` draws only
/// (independent draws of the contract's distribution); the adversarial evaluations are
/// counted, not folded into the rate (a search's candidates are not independent draws).
pub fn contract_sentence(false_feasible: u64, sampled: u64, adversarial: u64) -> String {
    let bound = clopper_pearson_upper(false_feasible, sampled, 0.95);
    format!(
        "{false_feasible} false feasible in {sampled} sampled and {adversarial} adversarial \
         evaluations, 95 % upper bound on the rate over the sampled missions {:.2} % \
         (one-sided Clopper–Pearson{})",
        100.0 * bound,
        if false_feasible == 0 && sampled > 0 {
            format!("; rule of three 3/N = {:.2} %", 300.0 / sampled as f64)
        } else {
            String::new()
        }
    )
}
