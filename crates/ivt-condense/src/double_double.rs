//! Double-double arithmetic for the refinement's residuals
//! ([`super::dynamic`]): error-free products and sums (Dekker's TwoProduct
//! with Veltkamp's split; Ogita, Rump & Oishi, *Accurate sum and dot
//! product*, 2005, Dot2).

/// The rounding error `a·b − p` of `p = fl(a·b)`, exactly (Dekker's
/// TwoProduct with Veltkamp's split). Not `f64::mul_add`: without a target
/// FMA (the baseline x86-64 build) that is a library call, which made the
/// refinement's residual 40 % of the whole condensed curve (perf, N = 500).
#[inline(always)]
fn product_error(a: f64, b: f64, p: f64) -> f64 {
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    ((ah * bh - p) + ah * bl + al * bh) + al * bl
}

/// Veltkamp's split of `a` into 26-bit halves `hi + lo = a` (exact for
/// |a| < 2^996).
#[inline(always)]
fn split(a: f64) -> (f64, f64) {
    const FACTOR: f64 = 134_217_729.0; // 2^27 + 1
    let t = FACTOR * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

/// A double with its Veltkamp halves (split once, used in many products).
#[derive(Debug, Clone, Copy)]
pub(super) struct Split {
    v: f64,
    hi: f64,
    lo: f64,
}

impl Split {
    #[inline(always)]
    pub(super) fn of(v: f64) -> Self {
        let (hi, lo) = split(v);
        Self { v, hi, lo }
    }

    /// `a·b − fl(a·b)` exactly, `p = fl(a·b)`.
    #[inline(always)]
    fn product_error(self, b: Self, p: f64) -> f64 {
        ((self.hi * b.hi - p) + self.hi * b.lo + self.lo * b.hi) + self.lo * b.lo
    }
}

/// A double-double entry `hi + lo` of `D(w)` with `hi` split.
#[derive(Debug, Clone, Copy)]
pub(super) struct SplitDd {
    hi: Split,
    lo: f64,
}

impl From<Dd> for SplitDd {
    fn from(d: Dd) -> Self {
        Self {
            hi: Split::of(d.hi),
            lo: d.lo,
        }
    }
}

/// A double-double accumulator `hi + lo` (Dot2: error-free transformations).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Dd {
    hi: f64,
    lo: f64,
}

impl From<f64> for Dd {
    fn from(v: f64) -> Self {
        Self { hi: v, lo: 0.0 }
    }
}

impl Dd {
    /// `a·b` exactly (as `hi + lo`).
    pub(super) fn product(a: f64, b: f64) -> Self {
        let hi = a * b;
        Self {
            hi,
            lo: product_error(a, b, hi),
        }
    }

    /// `self + v` to double-double accuracy.
    pub(super) fn add(self, v: f64) -> Self {
        let s = self.hi + v;
        let bb = s - self.hi;
        let e = (self.hi - (s - bb)) + (v - bb);
        Self {
            hi: s,
            lo: self.lo + e,
        }
    }

    /// `self·v` to double-double accuracy.
    pub(super) fn scale(self, v: f64) -> Self {
        let mut p = Self::product(self.hi, v);
        p.lo += self.lo * v;
        p
    }

    /// `self += a·b` for a double-double `a` (both split already).
    #[inline(always)]
    pub(super) fn add_split_product(&mut self, a: &SplitDd, b: Split) {
        let p = a.hi.v * b.v;
        let ep = a.hi.product_error(b, p);
        self.add_exact(p, ep + a.lo * b.v);
    }

    /// `self −= a·b` for a double-double `a` (both split already).
    #[inline(always)]
    pub(super) fn sub_split_product(&mut self, a: &SplitDd, b: Split) {
        let p = a.hi.v * b.v;
        let ep = a.hi.product_error(b, p);
        self.add_exact(-p, -(ep + a.lo * b.v));
    }

    /// `self += p + e` with `p`'s sum error kept (`e` a small correction).
    #[inline(always)]
    fn add_exact(&mut self, p: f64, e: f64) {
        let s = self.hi + p;
        let bb = s - self.hi;
        let es = (self.hi - (s - bb)) + (p - bb);
        self.hi = s;
        self.lo += e + es;
    }

    pub(super) fn value(self) -> f64 {
        self.hi + self.lo
    }
}
