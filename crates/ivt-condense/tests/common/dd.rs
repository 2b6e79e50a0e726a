//! Complex double-double arithmetic (≈ 32 digits) and a banded Gaussian
//! elimination in it: the extended-precision reference for the receptances
//! of the fine cantilever (an independent method: no LU of faer, no
//! refinement, twice the working precision).
#![allow(clippy::indexing_slicing)]
#![allow(dead_code)] // each test binary uses its own subset

use faer::sparse::SparseColMatRef;

/// A double-double `hi + lo`, |lo| ≤ ulp(hi)/2.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Dd {
    pub hi: f64,
    pub lo: f64,
}

fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

impl Dd {
    pub fn new(v: f64) -> Self {
        Self { hi: v, lo: 0.0 }
    }
    pub fn add(self, o: Self) -> Self {
        let (s, e) = two_sum(self.hi, o.hi);
        let (t, f) = two_sum(self.lo, o.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        Self { hi, lo }
    }
    pub fn neg(self) -> Self {
        Self {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
    pub fn sub(self, o: Self) -> Self {
        self.add(o.neg())
    }
    pub fn mul(self, o: Self) -> Self {
        let p = self.hi * o.hi;
        let e = self.hi.mul_add(o.hi, -p);
        let e = e + (self.hi * o.lo + self.lo * o.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Self { hi, lo }
    }
    pub fn div(self, o: Self) -> Self {
        let q1 = self.hi / o.hi;
        let r = self.sub(o.mul(Self::new(q1)));
        let q2 = r.hi / o.hi;
        let r = r.sub(o.mul(Self::new(q2)));
        let q3 = r.hi / o.hi;
        Self::new(q1).add(Self::new(q2)).add(Self::new(q3))
    }
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
}

/// A complex double-double.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Cdd {
    pub re: Dd,
    pub im: Dd,
}

impl Cdd {
    pub fn sub(self, o: Self) -> Self {
        Self {
            re: self.re.sub(o.re),
            im: self.im.sub(o.im),
        }
    }
    pub fn mul(self, o: Self) -> Self {
        Self {
            re: self.re.mul(o.re).sub(self.im.mul(o.im)),
            im: self.re.mul(o.im).add(self.im.mul(o.re)),
        }
    }
    pub fn div(self, o: Self) -> Self {
        let den = o.re.mul(o.re).add(o.im.mul(o.im));
        let num = self.mul(Self {
            re: o.re,
            im: o.im.neg(),
        });
        Self {
            re: num.re.div(den),
            im: num.im.div(den),
        }
    }
}

/// Entry `(i, j)` of a sparse matrix (0 if absent).
fn entry(a: SparseColMatRef<'_, usize, f64>, i: usize, j: usize) -> f64 {
    let rows = a.symbolic().row_idx_of_col_raw(j);
    rows.iter()
        .zip(a.val_of_col(j))
        .filter(|(r, _)| **r == i)
        .map(|(_, v)| *v)
        .sum()
}

/// Solves `(K − w²M + iwC) x = e_j` by Gaussian elimination without pivoting
/// on the band `|i − j| ≤ band`, all in complex double-double; `x` in double-double.
pub fn receptance_column(
    m: SparseColMatRef<'_, usize, f64>,
    c: SparseColMatRef<'_, usize, f64>,
    k: SparseColMatRef<'_, usize, f64>,
    w: f64,
    band: usize,
    j: usize,
) -> Vec<Cdd> {
    let entries = |i, col| [k, m, c].map(|a| Dd::new(entry(a, i, col)));
    band_solve(m.nrows(), entries, w, band, j)
}

/// [`receptance_column`] for `(K, M, C)` entries given in double-double by
/// `entries(i, j)`.
pub fn band_solve(
    n: usize,
    entries: impl Fn(usize, usize) -> [Dd; 3],
    w: f64,
    band: usize,
    j: usize,
) -> Vec<Cdd> {
    let width = 2 * band + 1;
    let w2 = Dd::new(w).mul(Dd::new(w));
    // a[i][band + (col − i)] for |col − i| ≤ band.
    let mut a = vec![Cdd::default(); n * width];
    for i in 0..n {
        for col in i.saturating_sub(band)..(i + band + 1).min(n) {
            let [kv, mv, cv] = entries(i, col);
            let re = kv.sub(w2.mul(mv));
            let im = Dd::new(w).mul(cv);
            a[i * width + band + col - i] = Cdd { re, im };
        }
    }
    let mut b = vec![Cdd::default(); n];
    b[j].re = Dd::new(1.0);
    for p in 0..n {
        let pivot = a[p * width + band];
        for i in p + 1..(p + band + 1).min(n) {
            let f = a[i * width + band + p - i].div(pivot);
            for col in p..(p + band + 1).min(n) {
                let v = a[p * width + band + col - p];
                let t = &mut a[i * width + band + col - i];
                *t = t.sub(f.mul(v));
            }
            b[i] = b[i].sub(f.mul(b[p]));
        }
    }
    let mut x = vec![Cdd::default(); n];
    for i in (0..n).rev() {
        let mut s = b[i];
        for col in i + 1..(i + band + 1).min(n) {
            s = s.sub(a[i * width + band + col - i].mul(x[col]));
        }
        x[i] = s.div(a[i * width + band]);
    }
    x
}

/// The cantilever's `(K, M, C)` entry `(i, j)` from the element formulas in
/// double-double (h = 1/N, C = 0.07 M + 2e-4 K with the decimal constants):
/// the model without the rounding of its stored matrices.
pub fn exact_cantilever_entry(n_elements: usize, i: usize, j: usize) -> [Dd; 3] {
    let d = |v: f64| Dd::new(v);
    let h = d(1.0).div(d(n_elements as f64));
    let inv_h = d(n_elements as f64);
    let h2 = h.mul(h);
    let mm = h.div(d(420.0));
    let ke = |a: usize, b: usize| -> Dd {
        let t = [
            [12.0, 6.0, -12.0, 6.0],
            [6.0, 4.0, -6.0, 2.0],
            [-12.0, -6.0, 12.0, -6.0],
            [6.0, 2.0, -6.0, 4.0],
        ];
        // Powers of 1/h: w–w 3, w–θ 2, θ–θ 1.
        let p = 3 - (a % 2) - (b % 2);
        let mut s = d(t[a][b]);
        for _ in 0..p {
            s = s.mul(inv_h);
        }
        s
    };
    let me = |a: usize, b: usize| -> Dd {
        let t = [
            [156.0, 22.0, 54.0, -13.0],
            [22.0, 4.0, 13.0, -3.0],
            [54.0, 13.0, 156.0, -22.0],
            [-13.0, -3.0, -22.0, 4.0],
        ];
        let p = (a % 2) + (b % 2);
        let hp = [d(1.0), h, h2][p];
        d(t[a][b]).mul(hp).mul(mm)
    };
    let alpha = d(7.0).div(d(100.0));
    let beta = d(2.0).div(d(10000.0));
    let (mut k, mut m) = (Dd::default(), Dd::default());
    for e in 0..n_elements {
        let dofs = ivt_condense::models::element_dofs(e);
        for a in 0..4 {
            for b in 0..4 {
                if dofs[a] == Some(i) && dofs[b] == Some(j) {
                    k = k.add(ke(a, b));
                    m = m.add(me(a, b));
                }
            }
        }
    }
    [k, m, alpha.mul(m).add(beta.mul(k))]
}
