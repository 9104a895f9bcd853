//! Exact sums of f64 terms: a long fixed-point accumulator that holds every finite double
//! without rounding (Kulisch & Miranker 1981, "Computer Arithmetic in Theory and
//! Practice", the exact dot-product register), rounded once to the nearest double when read.
//! A sum's value then does not depend on the order of its terms, so a reduction gives the
//! same bits for any thread count and any split of the terms across processes.

/// Bits per digit; digits are kept in i64 so that carries can wait.
const DIGIT: u32 = 32;
/// Digits covering 2^-1074 (the smallest subnormal) to past 2^1024 (the overflow), with
/// room for the carries of a sum that overflows.
const DIGITS: usize = 68;
/// Additions between carry propagations: each adds under 2^32 to a digit, so a digit that
/// starts below 2^32 stays far below i64's 2^63.
const CARRY_EVERY: u32 = 1 << 30;

/// An exact running sum of f64 terms; [`value`](Self::value) is the correctly rounded sum
/// (round to nearest, ties to even). A non-finite term makes the sum that term (infinities
/// of both signs or a NaN give NaN).
#[derive(Clone, Debug)]
pub struct ExactSum {
    /// Digit k weighs 2^(32 k - 1074); digits may leave [0, 2^32) until carried.
    digits: [i64; DIGITS],
    /// Additions since the last carry propagation.
    pending: u32,
    /// Sum of the non-finite terms (0 when there were none).
    special: f64,
}

impl Default for ExactSum {
    fn default() -> Self {
        ExactSum {
            digits: [0; DIGITS],
            pending: 0,
            special: 0.0,
        }
    }
}

impl ExactSum {
    /// The empty sum.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `x` exactly.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let bits = x.to_bits();
        let field = ((bits >> 52) & 0x7ff) as u32;
        if field == 0x7ff {
            self.special += x;
            return;
        }
        let fraction = bits & ((1 << 52) - 1);
        // x = m 2^(shift - 1074): subnormals have no hidden bit and the least exponent.
        let (m, shift) = if field == 0 {
            (fraction, 0)
        } else {
            (fraction | (1 << 52), field - 1)
        };
        if m == 0 {
            return;
        }
        let k = (shift / DIGIT) as usize;
        let v = (m as u128) << (shift % DIGIT);
        let parts = [
            (v as u32) as i64,
            ((v >> 32) as u32) as i64,
            (v >> 64) as i64,
        ];
        let negative = bits >> 63 == 1;
        for (d, part) in self.digits[k..k + 3].iter_mut().zip(parts) {
            if negative {
                *d -= part;
            } else {
                *d += part;
            }
        }
        self.pending += 1;
        if self.pending == CARRY_EVERY {
            self.carry();
        }
    }

    /// Adds every term of `other`.
    pub fn merge(&mut self, other: &ExactSum) {
        let mut other = other.clone();
        other.carry();
        self.carry();
        for (d, o) in self.digits.iter_mut().zip(other.digits) {
            *d += o;
        }
        self.pending = 2;
        self.special += other.special;
    }

    /// The sum of `terms`.
    pub fn of(terms: impl IntoIterator<Item = f64>) -> f64 {
        let mut s = ExactSum::new();
        terms.into_iter().for_each(|x| s.add(x));
        s.value()
    }

    /// The carried digits and the non-finite terms' sum, for adding sums held elsewhere
    /// digit by digit (integer addition, exact in any order).
    pub fn parts(&self) -> ([i64; DIGITS], f64) {
        let mut s = self.clone();
        s.carry();
        (s.digits, s.special)
    }

    /// The sum whose digits are `digits` (sums of [`parts`](Self::parts)' digits) and
    /// whose non-finite terms sum to `special`.
    pub fn from_parts(digits: &[i64], special: f64) -> Self {
        let mut s = ExactSum {
            special,
            ..Default::default()
        };
        s.digits.copy_from_slice(digits);
        s.carry();
        s
    }

    /// Propagates carries: every digit but the last into [0, 2^32), the last signed.
    fn carry(&mut self) {
        for k in 0..DIGITS - 1 {
            let c = self.digits[k] >> DIGIT;
            self.digits[k] -= c << DIGIT;
            self.digits[k + 1] += c;
        }
        self.pending = 0;
    }

    /// The sum rounded to the nearest double (ties to even); ±infinity past the largest.
    pub fn value(&self) -> f64 {
        if self.special != 0.0 {
            return self.special;
        }
        let mut s = self.clone();
        s.carry();
        let negative = s.digits[DIGITS - 1] < 0;
        if negative {
            s.digits.iter_mut().for_each(|d| *d = -*d);
            s.carry();
        }
        let magnitude = s.magnitude();
        if negative { -magnitude } else { magnitude }
    }

    /// The value of carried, non-negative digits, correctly rounded.
    fn magnitude(&self) -> f64 {
        let d = |k: usize| self.digits[k] as u128;
        let Some(top) = self.digits.iter().rposition(|&x| x != 0) else {
            return 0.0;
        };
        if top >= DIGITS - 2 {
            // At least 2^(32*66 - 1074) = 2^1038.
            return f64::INFINITY;
        }
        // The leading 65 to 96 bits, in units of 2^(lsb - 1074), and whether any lower
        // bit is set.
        let (high, lsb, sticky) = if top < 2 {
            ((d(1) << DIGIT) | d(0), 0, false)
        } else {
            let high = (d(top) << 64) | (d(top - 1) << 32) | d(top - 2);
            let sticky = self.digits[..top - 2].iter().any(|&x| x != 0);
            (high, DIGIT * (top as u32 - 2), sticky)
        };
        let msb = 127 - high.leading_zeros();
        if msb + lsb < 52 {
            // Below 2^-1022: a subnormal, exact (every term is a multiple of 2^-1074).
            return f64::from_bits(high as u64);
        }
        let mut shift = msb - 52;
        let mut mantissa = (high >> shift) as u64;
        if shift > 0 {
            let rest = high & ((1u128 << shift) - 1);
            let half = 1u128 << (shift - 1);
            if rest > half || (rest == half && (sticky || mantissa & 1 == 1)) {
                mantissa += 1;
                if mantissa == 1 << 53 {
                    mantissa >>= 1;
                    shift += 1;
                }
            }
        }
        // mantissa 2^(shift + lsb - 1074), mantissa in [2^52, 2^53): the biased exponent.
        let field = (shift + lsb + 1) as u64;
        if field >= 0x7ff {
            return f64::INFINITY;
        }
        f64::from_bits((field << 52) | (mantissa & ((1 << 52) - 1)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift) for the terms.
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    #[test]
    fn dyadic_sums_are_correctly_rounded() {
        // Terms n 2^e with |n| < 2^40 and e in [-30, 30]: their sum is exact in i128 (units
        // of 2^-30), and i128 -> f64 rounds to nearest, ties to even.
        let mut state = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..200 {
            let (mut exact, mut s) = (0i128, ExactSum::new());
            for _ in 0..50 {
                let n = (xorshift(&mut state) % (1 << 40)) as i64 - (1 << 39);
                let e = (xorshift(&mut state) % 61) as i32 - 30;
                exact += (n as i128) << (e + 30);
                s.add(n as f64 * 2f64.powi(e));
            }
            assert_eq!(s.value(), exact as f64 * 2f64.powi(-30));
        }
    }

    #[test]
    fn order_and_split_do_not_change_the_bits() {
        let mut state = 12345;
        let terms: Vec<f64> = (0..1000)
            .map(|_| {
                let u = xorshift(&mut state) as f64 / u64::MAX as f64 - 0.5;
                u * 10f64.powi((xorshift(&mut state) % 40) as i32 - 20)
            })
            .collect();
        let forward = ExactSum::of(terms.iter().copied());
        let backward = ExactSum::of(terms.iter().rev().copied());
        let (mut a, mut b) = (ExactSum::new(), ExactSum::new());
        for (k, &x) in terms.iter().enumerate() {
            if k % 3 == 0 { &mut a } else { &mut b }.add(x);
        }
        a.merge(&b);
        assert_eq!(forward.to_bits(), backward.to_bits());
        assert_eq!(forward.to_bits(), a.value().to_bits());
    }

    #[test]
    fn cancellation_keeps_the_small_terms() {
        assert_eq!(ExactSum::of([1e100, 1.0, -1e100]), 1.0);
        assert_eq!(ExactSum::of([f64::MAX, 1.0, -f64::MAX]), 1.0);
        // The doubles nearest 0.1, 0.2 and 0.3 are 3602879701896397, 7205759403792794 and
        // 10808639105689190 times 2^-55.
        assert_eq!(ExactSum::of([0.1, 0.2, -0.3]), 2f64.powi(-55));
        assert_eq!(ExactSum::of([]), 0.0);
        assert_eq!(ExactSum::of([-2.5]), -2.5);
    }

    #[test]
    fn extremes_round_and_overflow() {
        let tiny = f64::from_bits(1);
        assert_eq!(ExactSum::of([tiny, tiny, tiny]), f64::from_bits(3));
        assert_eq!(
            ExactSum::of([f64::MIN_POSITIVE, -tiny]),
            f64::MIN_POSITIVE - tiny
        );
        assert_eq!(ExactSum::of([f64::MAX, f64::MAX]), f64::INFINITY);
        assert_eq!(ExactSum::of([-f64::MAX, -f64::MAX]), f64::NEG_INFINITY);
        // 1 + 2^-53 is a tie: to even (1); one more 2^-100 breaks it upwards.
        assert_eq!(ExactSum::of([1.0, 2f64.powi(-53)]), 1.0);
        assert_eq!(
            ExactSum::of([1.0, 2f64.powi(-53), 2f64.powi(-100)]),
            1.0 + f64::EPSILON
        );
        assert!(ExactSum::of([1.0, f64::NAN]).is_nan());
        assert!(ExactSum::of([f64::INFINITY, f64::NEG_INFINITY]).is_nan());
        assert_eq!(ExactSum::of([f64::INFINITY, 1.0]), f64::INFINITY);
    }

    #[test]
    fn repeated_terms_sum_exactly() {
        let mut s = ExactSum::new();
        for _ in 0..(3u64 << 20) {
            s.add(f64::MAX / 4.0);
            s.add(-f64::MAX / 4.0);
            s.add(0.75);
        }
        assert_eq!(s.value(), 0.75 * (3u64 << 20) as f64);
    }
}
