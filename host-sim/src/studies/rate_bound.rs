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

/// What the contract's sentence counts: false feasibles among independent draws of the
/// mission space (`sampled`) and among a search's candidates (`adversarial`), each of the
/// evaluations that counted (flown at a proposed scale).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Counts {
    pub sampled: u64,
    pub sampled_false_feasible: u64,
    pub adversarial: u64,
    pub adversarial_false_feasible: u64,
}

impl Counts {
    /// The one-sided 95 % Clopper–Pearson upper bound on the false-feasible rate over the
    /// sampled draws (NaN when none was sampled).
    pub fn upper_bound(&self) -> f64 {
        clopper_pearson_upper(self.sampled_false_feasible, self.sampled, 0.95)
    }

    /// "N false feasible in S sampled and A adversarial evaluations; 95 % upper bound on the
    /// false-feasible rate: x %": the contract's statistics in a sentence (**Choice 415**).
    /// The bound is over the sampled draws only (independent draws of the space); the
    /// adversarial evaluations are counted, not folded into the rate (a search's candidates are
    /// not independent draws), and their false feasibles are in N.
    pub fn sentence(&self) -> String {
        let total = self.sampled_false_feasible + self.adversarial_false_feasible;
        let split = if total > 0 {
            format!(
                " ({} sampled, {} adversarial)",
                self.sampled_false_feasible, self.adversarial_false_feasible
            )
        } else {
            String::new()
        };
        let bound = self.upper_bound();
        format!(
            "{total} false feasible in {} sampled and {} adversarial evaluations{split}; 95 % \
             upper bound on the false-feasible rate: {} (one-sided Clopper–Pearson over the \
             sampled draws{})",
            self.sampled,
            self.adversarial,
            if bound.is_nan() {
                "none (nothing sampled)".to_string()
            } else {
                format!("{:.2} %", 100.0 * bound)
            },
            if self.sampled_false_feasible == 0 && self.sampled > 0 {
                format!("; rule of three 3/S = {:.2} %", 300.0 / self.sampled as f64)
            } else {
                String::new()
            }
        )
    }
}
