//! The spatial balance of STHB (Eq. 94, 97): DST-I on the interior grid
//! points and DCT-I on the closed grid, by rustdct or by direct partial sums.

use std::f64::consts::PI;
use std::sync::Arc;

use rustdct::{Dct1, Dst1};

/// Up to this many modes the spatial balance sums the few needed DST-I/DCT-I
/// terms directly (`O(N·N_s)` per time sample); rustdct's DST-I/DCT-I of these
/// odd lengths run a complex FFT of length `2 N_s`, which measured ~10× slower
/// for `N = 5`, `N_s = 64`. Both give the same numbers (tested).
pub(super) const DIRECT_MAX_MODES: usize = 12;

/// Spatial balance (Eq. 94, 97): DST-I on the interior points and DCT-I on the
/// closed grid, by rustdct or by direct partial sums over a sine table.
pub(super) struct Spatial {
    dst: Arc<dyn Dst1<f64>>,
    dct: Arc<dyn Dct1<f64>>,
    scratch: Vec<f64>,
    /// Rows `sin(π(m+1)(k+1)/N_s)`, `m < 2N`, `k < N_s − 1`.
    sin_t: Vec<f64>,
    /// Rows `cos(π m k/N_s)`, `m ≤ 2N`, `k ≤ N_s`.
    cos_t: Vec<f64>,
    tmp: Vec<f64>,
    direct: bool,
}

impl Spatial {
    pub(super) fn new(
        dst: Arc<dyn Dst1<f64>>,
        dct: Arc<dyn Dct1<f64>>,
        ns: usize,
        modes: usize,
        direct: bool,
    ) -> Self {
        let angle = |j: usize| PI * j as f64 / ns as f64;
        let mut sin_t = Vec::with_capacity(2 * modes * (ns - 1));
        for m in 0..2 * modes {
            sin_t.extend((0..ns - 1).map(|k| angle((m + 1) * (k + 1)).sin()));
        }
        let mut cos_t = Vec::with_capacity((2 * modes + 1) * (ns + 1));
        for m in 0..=2 * modes {
            cos_t.extend((0..=ns).map(|k| angle(m * k).cos()));
        }
        Self {
            scratch: vec![0.0; dst.get_scratch_len().max(dct.get_scratch_len())],
            dst,
            dct,
            sin_t,
            cos_t,
            tmp: vec![0.0; ns + 1],
            direct,
        }
    }

    /// DST-I of `buf` (length `N_s − 1`, `X_r = Σ_k x_k sin(π(k+1)(r+1)/N_s)`) when
    /// only the first `nin` inputs are nonzero and the first `nout` outputs are used
    /// (one of them at most `2N`).
    pub(super) fn sine(&mut self, buf: &mut [f64], nin: usize, nout: usize) {
        if !self.direct {
            self.dst.process_dst1_with_scratch(buf, &mut self.scratch);
            return;
        }
        Self::partial(&self.sin_t, &mut self.tmp, buf, nin, nout);
    }

    /// DCT-I of `buf` (length `N_s + 1`, half weight at both ends) with the
    /// first `nin` inputs nonzero and the first `nout` outputs used.
    pub(super) fn cosine(&mut self, buf: &mut [f64], nin: usize, nout: usize) {
        if !self.direct {
            self.dct.process_dct1_with_scratch(buf, &mut self.scratch);
            return;
        }
        if nin == buf.len() {
            if let Some(first) = buf.first_mut() {
                *first *= 0.5;
            }
            if let Some(last) = buf.last_mut() {
                *last *= 0.5;
            }
        }
        Self::partial(&self.cos_t, &mut self.tmp, buf, nin, nout);
    }

    /// `buf ← T buf` for the symmetric table `T` (rows of length `buf.len()`);
    /// NaN if `buf` is empty or longer than the scratch `tmp`.
    fn partial(table: &[f64], tmp: &mut [f64], buf: &mut [f64], nin: usize, nout: usize) {
        let len = buf.len();
        let Some(inputs) = tmp.get_mut(..len).filter(|_| len > 0) else {
            return buf.fill(f64::NAN);
        };
        let rows = table.chunks_exact(len);
        if nin < len {
            // Synthesis: few inputs, all outputs.
            let (inputs, _) = inputs.split_at_mut(nin);
            inputs.iter_mut().zip(buf.iter()).for_each(|(t, x)| *t = *x);
            buf.fill(0.0);
            for (x, row) in inputs.iter().zip(rows) {
                buf.iter_mut().zip(row).for_each(|(o, t)| *o += x * t);
            }
        } else {
            // Projection: all inputs, few outputs.
            inputs.copy_from_slice(buf);
            for (o, row) in buf.iter_mut().take(nout).zip(rows) {
                *o = row.iter().zip(inputs.iter()).map(|(t, x)| t * x).sum();
            }
        }
    }
}
