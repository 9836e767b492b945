//! Derives every constant of the f32 math kernels (`controller_core::math::kernels`) from first
//! principles, so that none of them is copied from another library:
//!
//! * π to 350 bits by Machin's formula (π = 16 atan(1/5) − 4 atan(1/239)) in big fixed-point
//!   integers, and from it π/2, 2/π, the Cody–Waite splits of π/2, the 2/π bit table of the
//!   Payne–Hanek reduction, π/4 in 64-bit fixed point, and the atan2 base angles;
//! * the minimax polynomials (Remez exchange, in f64) of sin, cos and atan on their reduced
//!   ranges and the cube root's first guess, with the approximation error each achieves.
//!
//! `cargo run -p controller-core --example kernel_constants` prints them as Rust items; the
//! kernels hold that output. The tests of the kernels check the results against the host's f64
//! libm, which has its own constants, so a wrong digit here shows as an accuracy failure there.

use std::cmp::Ordering;

// ---------------------------------------------------------------------------------------------
// Big fixed point: value = Σ limb[i] · 2^(32 (LIMBS − 1 − i)) / 2^FRAC, limb 0 the integer part.

const LIMBS: usize = 12;
const FRAC: u32 = 32 * (LIMBS as u32 - 1);

#[derive(Clone, PartialEq, Eq)]
struct Fixed([u32; LIMBS]);

impl Fixed {
    fn int(n: u32) -> Fixed {
        let mut l = [0; LIMBS];
        l[0] = n;
        Fixed(l)
    }

    fn is_zero(&self) -> bool {
        self.0.iter().all(|&x| x == 0)
    }

    fn add(&self, o: &Fixed) -> Fixed {
        let mut out = [0; LIMBS];
        let mut carry = 0u64;
        for i in (0..LIMBS).rev() {
            let s = self.0[i] as u64 + o.0[i] as u64 + carry;
            out[i] = s as u32;
            carry = s >> 32;
        }
        Fixed(out)
    }

    /// self − o, for self ≥ o.
    fn sub(&self, o: &Fixed) -> Fixed {
        let mut out = [0; LIMBS];
        let mut borrow = 0i64;
        for i in (0..LIMBS).rev() {
            let mut d = self.0[i] as i64 - o.0[i] as i64 - borrow;
            borrow = 0;
            if d < 0 {
                d += 1 << 32;
                borrow = 1;
            }
            out[i] = d as u32;
        }
        Fixed(out)
    }

    fn mul_small(&self, m: u32) -> Fixed {
        let mut out = [0; LIMBS];
        let mut carry = 0u64;
        for i in (0..LIMBS).rev() {
            let p = self.0[i] as u64 * m as u64 + carry;
            out[i] = p as u32;
            carry = p >> 32;
        }
        Fixed(out)
    }

    fn div_small(&self, d: u32) -> Fixed {
        let mut out = [0; LIMBS];
        let mut rem = 0u64;
        for (o, &limb) in out.iter_mut().zip(&self.0) {
            let cur = (rem << 32) | limb as u64;
            *o = (cur / d as u64) as u32;
            rem = cur % d as u64;
        }
        Fixed(out)
    }

    fn half(&self) -> Fixed {
        self.div_small(2)
    }

    fn cmp(&self, o: &Fixed) -> Ordering {
        self.0.cmp(&o.0)
    }

    /// Bit `i` after the binary point (i ≥ 1).
    fn frac_bit(&self, i: u32) -> u32 {
        let pos = FRAC - i; // bit position counted from the least significant bit
        let limb = LIMBS - 1 - (pos / 32) as usize;
        (self.0[limb] >> (pos % 32)) & 1
    }

    /// Nearest f64 (for printing and for checks).
    fn to_f64(&self) -> f64 {
        self.0
            .iter()
            .enumerate()
            .map(|(i, &l)| l as f64 * 2f64.powi(-32 * i as i32))
            .sum()
    }
}

/// atan(1/n) = Σ (−1)^k / ((2k + 1) n^(2k+1)).
fn atan_inv(n: u32) -> Fixed {
    let mut power = Fixed::int(1).div_small(n);
    let mut sum = Fixed::int(0);
    let mut k = 0u32;
    while !power.is_zero() {
        let term = power.div_small(2 * k + 1);
        sum = if k.is_multiple_of(2) {
            sum.add(&term)
        } else {
            sum.sub(&term)
        };
        power = power.div_small(n).div_small(n);
        k += 1;
    }
    sum
}

fn pi() -> Fixed {
    atan_inv(5).mul_small(16).sub(&atan_inv(239).mul_small(4))
}

/// Binary digits of num/den (num < den), as a fixed-point fraction.
fn quotient(num: &Fixed, den: &Fixed) -> Fixed {
    let mut out = Fixed::int(0);
    let mut r = num.clone();
    for i in 1..=FRAC {
        r = r.add(&r);
        if r.cmp(den) != Ordering::Less {
            r = r.sub(den);
            let pos = FRAC - i;
            out.0[LIMBS - 1 - (pos / 32) as usize] |= 1 << (pos % 32);
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Splitting a big value into f32 parts.

/// A signed big value as (negative, magnitude).
#[derive(Clone)]
struct Signed(bool, Fixed);

impl Signed {
    fn sub(&self, o: &Signed) -> Signed {
        // self − o with signs: a − b = a + (−b).
        let (na, a) = (self.0, &self.1);
        let (nb, b) = (!o.0, &o.1);
        if na == nb {
            Signed(na, a.add(b))
        } else if a.cmp(b) != Ordering::Less {
            Signed(na, a.sub(b))
        } else {
            Signed(nb, b.sub(a))
        }
    }
}

/// The f32 nearest to `v` with at most `bits` significant bits, and that value exactly.
fn round_to_bits(v: &Signed, bits: u32) -> (f32, Signed) {
    let f = v.1.to_f64();
    let e = f.log2().floor() as i32; // 2^e ≤ |v| < 2^(e+1) (to f64 accuracy, enough here)
                                     // m = round(|v| · 2^(bits − 1 − e)), from the exact bits.
    let shift = bits as i32 - 1 - e; // value · 2^shift has `bits` integer bits
    let scaled = scale_pow2(&v.1, shift);
    let mut m = scaled.0[0] as u64;
    assert!(m >> (bits - 1) == 1, "exponent misjudged");
    if scaled.frac_bit(1) == 1 {
        m += 1;
    }
    let value = m as f64 * 2f64.powi(-shift);
    let x = if v.0 { -value } else { value } as f32;
    assert_eq!(
        x as f64,
        if v.0 { -value } else { value },
        "not exact in f32"
    );
    let exact = Signed(v.0, scale_pow2(&Fixed::int(m as u32), -shift));
    (x, exact)
}

/// v · 2^s, exactly (the bits that fall off the end are zero for the values used here).
fn scale_pow2(v: &Fixed, s: i32) -> Fixed {
    let mut out = v.clone();
    if s >= 0 {
        for _ in 0..s {
            out = out.add(&out);
        }
    } else {
        for _ in 0..(-s) {
            out = out.half();
        }
    }
    out
}

/// hi + lo with hi the nearest f32 and lo the nearest f32 to the rest.
fn hi_lo(v: &Signed) -> (f32, f32) {
    let (hi, exact) = round_to_bits(v, 24);
    let rest = v.sub(&exact);
    let lo = if rest.1.is_zero() {
        0.0
    } else {
        round_to_bits(&rest, 24).0
    };
    (hi, lo)
}

// ---------------------------------------------------------------------------------------------
// Remez exchange for a weighted polynomial minimax in f64.

/// Coefficients c₀…c_n of p(t) = Σ cⱼ tʲ minimising max |w(t) (p(t) − f(t))| on [a, b], and
/// that maximum.
fn remez(
    f: &dyn Fn(f64) -> f64,
    w: &dyn Fn(f64) -> f64,
    a: f64,
    b: f64,
    n: usize,
) -> (Vec<f64>, f64) {
    let m = n + 2;
    let mut nodes: Vec<f64> = (0..m)
        .map(|i| {
            let c = (std::f64::consts::PI * i as f64 / (m - 1) as f64).cos();
            a + (b - a) * (1.0 - c) / 2.0
        })
        .collect();
    let grid: Vec<f64> = (0..=40_000)
        .map(|i| a + (b - a) * i as f64 / 40_000.0)
        .collect();
    let mut coef = vec![0.0; n + 1];
    let mut worst = f64::INFINITY;
    for _ in 0..60 {
        // Σ cⱼ tᵢʲ + (−1)ⁱ E / w(tᵢ) = f(tᵢ).
        let mut mat = vec![vec![0.0; m + 1]; m];
        for (i, (&t, row)) in nodes.iter().zip(mat.iter_mut()).enumerate() {
            for (j, c) in row[..=n].iter_mut().enumerate() {
                *c = t.powi(j as i32);
            }
            row[n + 1] = if i % 2 == 0 { 1.0 } else { -1.0 } / w(t);
            row[m] = f(t);
        }
        let sol = solve(mat);
        coef = sol[..=n].to_vec();
        let err = |t: f64| w(t) * (poly(&coef, t) - f(t));
        // Alternating extrema of the error on the grid: the largest |e| of each run of one sign.
        let mut ext: Vec<(f64, f64)> = Vec::new();
        for &t in &grid {
            let e = err(t);
            if !e.is_finite() || e == 0.0 {
                continue;
            }
            match ext.last_mut() {
                Some(last) if last.1.signum() == e.signum() => {
                    if e.abs() > last.1.abs() {
                        *last = (t, e);
                    }
                }
                _ => ext.push((t, e)),
            }
        }
        while ext.len() > m {
            // Drop the smaller end.
            if ext[0].1.abs() < ext[ext.len() - 1].1.abs() {
                ext.remove(0);
            } else {
                ext.pop();
            }
        }
        worst = ext.iter().map(|e| e.1.abs()).fold(0.0, f64::max);
        let best = ext.iter().map(|e| e.1.abs()).fold(f64::INFINITY, f64::min);
        if ext.len() == m {
            nodes = ext.iter().map(|e| e.0).collect();
        }
        if worst - best < 1e-4 * worst {
            break;
        }
    }
    (coef, worst)
}

fn poly(c: &[f64], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &cj| acc * t + cj)
}

/// Gaussian elimination with partial pivoting on an augmented matrix.
fn solve(mut a: Vec<Vec<f64>>) -> Vec<f64> {
    let n = a.len();
    for col in 0..n {
        let p = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, p);
        let (top, below) = a.split_at_mut(col + 1);
        let pivot = &top[col];
        for row in below.iter_mut() {
            let k = row[col] / pivot[col];
            for (r, &p) in row[col..=n].iter_mut().zip(&pivot[col..=n]) {
                *r -= k * p;
            }
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|c| a[row][c] * x[c]).sum();
        x[row] = (a[row][n] - s) / a[row][row];
    }
    x
}

/// Taylor series Σ_{k≥0} s_k z^k with s_k given by `term(k)`, summed until negligible.
fn series(z: f64, term: impl Fn(u32) -> f64) -> f64 {
    let mut sum = 0.0;
    let mut zk = 1.0;
    for k in 0..60 {
        let t = term(k) * zk;
        sum += t;
        if t.abs() < 1e-30 {
            break;
        }
        zk *= z;
    }
    sum
}

fn factorial(n: u32) -> f64 {
    (1..=n).map(|i| i as f64).product()
}

fn f32_item(name: &str, x: f32, note: &str) {
    println!("/// {note}");
    println!(
        "const {name}: f32 = f32::from_bits({:#010x}); // {x:e}",
        x.to_bits()
    );
}

fn coef_items(prefix: &str, c: &[f64]) {
    for (j, &cj) in c.iter().enumerate() {
        let x = cj as f32;
        println!(
            "const {prefix}{j}: f32 = f32::from_bits({:#010x}); // {x:e}",
            x.to_bits()
        );
    }
}

fn main() {
    let pi = pi();
    let pio2 = pi.half();
    println!(
        "// π = {:.17} (check: {:.17})",
        pi.to_f64(),
        std::f64::consts::PI
    );
    assert!((pi.to_f64() - std::f64::consts::PI).abs() < 1e-15);
    cody_waite_items(&pio2);
    reduction_items(&pi, &pio2);
    atan2_base_items(&pi, &pio2);
    sin_cos_polynomials();
    atan_polynomials();
    cbrt_items();
}

/// Cody–Waite: π/2 = C1 + C2 + C3 + C4, C1..C3 with 14 significant bits (k·Cᵢ exact for
/// k < 2^10), C4 the rest rounded to 24 bits.
fn cody_waite_items(pio2: &Fixed) {
    println!("\n// Cody–Waite splits of π/2");
    let mut rest = Signed(false, pio2.clone());
    for (i, bits) in [(1, 14), (2, 14), (3, 14), (4, 24)] {
        let (x, exact) = round_to_bits(&rest, bits);
        f32_item(
            &format!("PIO2_{i}"),
            x,
            &format!("part {i} of π/2 ({bits} bits)"),
        );
        rest = rest.sub(&exact);
    }
    println!("// remainder after the four parts ≈ {:e}", rest.1.to_f64());
}

/// The Payne–Hanek table (2/π bits 1..=224, seven words), π/4 in 0.64 fixed point and π/2 in
/// Q1.31, each rounded.
fn reduction_items(pi: &Fixed, pio2: &Fixed) {
    let two_over_pi = quotient(&Fixed::int(2), pi);
    println!("\n/// 2/π, bits 1…224 after the binary point, most significant first.");
    print!("const TWO_OVER_PI: [u32; 7] = [");
    for w in 0..7 {
        let mut word = 0u32;
        for b in 0..32 {
            word = (word << 1) | two_over_pi.frac_bit(w * 32 + b + 1);
        }
        print!("{word:#010x}, ");
    }
    println!("];");

    // π/4 in 0.64 fixed point (rounded).
    let pio4 = pio2.half();
    let mut fix = 0u64;
    for b in 1..=64 {
        fix = (fix << 1) | pio4.frac_bit(b) as u64;
    }
    if pio4.frac_bit(65) == 1 {
        fix += 1;
    }
    println!("\n/// π/4 · 2^64, rounded.\nconst PIO4_FIX: u64 = {fix:#018x};");

    // π/2 · 2^-30 as a 0.32 fixed-point multiplier of a 2^-32-turn phase: 2π · 2^-32 = π/2 · 2^-30.
    // As Q1.31: round(π/2 · 2^31) (used with the turn remainder).
    let mut q = 0u64;
    for b in 1..=31 {
        q = (q << 1) | pio2.frac_bit(b) as u64;
    }
    q |= (pio2.0[0] as u64) << 31;
    if pio2.frac_bit(32) == 1 {
        q += 1;
    }
    println!("/// π/2 · 2^31, rounded.\nconst PIO2_Q31: u32 = {q:#010x};");
}

/// atan2 base angles: atan(1/2), π/4, π/2 ∓ those, π − those, and π/2, π, as hi + lo.
fn atan2_base_items(pi: &Fixed, pio2: &Fixed) {
    println!("\n// atan2 base angles (hi, lo)");
    let atan_half = atan_inv(2);
    let pio4 = Signed(false, pio2.half());
    let a5 = Signed(false, atan_half);
    let zero = Signed(false, Fixed::int(0));
    let p2 = Signed(false, pio2.clone());
    let pi_s = Signed(false, pi.clone());
    let bases = [
        ("ATAN_HALF", a5.clone()),
        ("PIO4", pio4.clone()),
        ("PIO2_MINUS_ATAN_HALF", p2.sub(&a5)),
        ("PIO2_MINUS_PIO4", p2.sub(&pio4)),
        ("PIO2", p2.clone()),
        ("PI_MINUS_ATAN_HALF", pi_s.sub(&a5)),
        ("PI_MINUS_PIO4", pi_s.sub(&pio4)),
        ("PIO2_PLUS_ATAN_HALF", p2.sub(&zero.sub(&a5))),
        ("PIO2_PLUS_PIO4", p2.sub(&zero.sub(&pio4))),
        ("PI", pi_s.clone()),
    ];
    for (name, v) in &bases {
        let (hi, lo) = hi_lo(v);
        println!(
            "const {name}: (f32, f32) = (f32::from_bits({:#010x}), f32::from_bits({:#010x})); // {hi:e} + {lo:e}",
            hi.to_bits(),
            lo.to_bits()
        );
    }
}

/// Minimax polynomials of sin and cos. The reduced argument of sin/cos is within π/4 up to a
/// few ulps.
fn sin_cos_polynomials() {
    let rmax: f64 = std::f64::consts::FRAC_PI_4 * (1.0 + 1e-6);
    let zmax = rmax * rmax;
    println!("\n// sin r = r + r³ S(r²), relative error, |r| ≤ {rmax}");
    // f(z) = (sin x − x)/x³ = Σ (−1)^(k+1) z^k / (2k+3)!
    let sin_f = |z: f64| {
        series(z, |k| {
            (if k % 2 == 0 { -1.0 } else { 1.0 }) / factorial(2 * k + 3)
        })
    };
    let sin_w = |z: f64| {
        let x = z.sqrt();
        if z == 0.0 {
            0.0
        } else {
            x * x * x / x.sin()
        }
    };
    for n in [2, 3] {
        let (c, e) = remez(&sin_f, &sin_w, zmax * 1e-6, zmax, n);
        println!(
            "// degree {n} in r²: max relative error {e:.3e} ({:.3} ulp-fractions of 2^-24)",
            e / 2f64.powi(-24)
        );
        coef_items(&format!("S{n}_"), &c);
    }

    println!("\n// cos r = 1 − r²/2 + r⁴ C(r²), error relative to cos r");
    // g(z) = (cos x − 1 + z/2)/z² = Σ (−1)^k z^k / (2k+4)!
    let cos_f = |z: f64| {
        series(z, |k| {
            (if k % 2 == 0 { 1.0 } else { -1.0 }) / factorial(2 * k + 4)
        })
    };
    let cos_w = |z: f64| z * z / z.sqrt().cos();
    for n in [2, 3] {
        let (c, e) = remez(&cos_f, &cos_w, zmax * 1e-6, zmax, n);
        println!(
            "// degree {n} in r²: max relative error {e:.3e} ({:.3} of 2^-24)",
            e / 2f64.powi(-24)
        );
        coef_items(&format!("C{n}_"), &c);
    }
}

/// atan u = u − u³ A(u²) on |u| ≤ 7/16 (the widest of the atan2 kernel's intervals).
fn atan_polynomials() {
    let umax: f64 = 7.0 / 16.0 * (1.0 + 1e-6);
    println!("\n// atan u = u − u³ A(u²), relative error, |u| ≤ {umax}");
    // h(z) = (u − atan u)/u³ = Σ (−1)^k z^k / (2k + 3)
    let atan_f = |z: f64| {
        series(z, |k| {
            (if k % 2 == 0 { 1.0 } else { -1.0 }) / (2 * k + 3) as f64
        })
    };
    let atan_w = |z: f64| {
        let u = z.sqrt();
        if z == 0.0 {
            0.0
        } else {
            u * u * u / u.atan()
        }
    };
    for n in [3, 4, 5] {
        let (c, e) = remez(&atan_f, &atan_w, umax * umax * 1e-6, umax * umax, n);
        println!(
            "// degree {n} in u²: max relative error {e:.3e} ({:.3} of 2^-24)",
            e / 2f64.powi(-24)
        );
        coef_items(&format!("A{n}_"), &c);
    }
}

/// The cube root's first guess on [1, 2] (relative error), and ∛2, ∛4.
fn cbrt_items() {
    println!("\n// ∛m ≈ G(m) on [1, 2], relative error");
    for n in [2, 3] {
        let (c, e) = remez(&|m: f64| m.cbrt(), &|m: f64| 1.0 / m.cbrt(), 1.0, 2.0, n);
        println!(
            "// degree {n}: max relative error {e:.3e} (2^{:.1})",
            e.log2()
        );
        coef_items(&format!("G{n}_"), &c);
    }
    for (name, v) in [("CBRT_2", 2f64.cbrt()), ("CBRT_4", 4f64.cbrt())] {
        f32_item(name, v as f32, "∛2ʲ, rounded");
    }
}
