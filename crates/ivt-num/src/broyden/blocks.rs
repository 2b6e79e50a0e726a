//! A square matrix that is block diagonal after a symmetric permutation: each
//! block couples one set of unknowns among themselves only. The inverse of the
//! linear harmonic-balance Jacobian Eq. 60 is one (one `2·n_dof` block per
//! harmonic, coupling the `a_k`, `b_k` of every DOF), and it is the Broyden
//! solver's usual `H₀`: products with it cost O(Σ size²) = O(m·n_dof) instead of
//! the O(m²) of the dense matrix.

/// Blocks over index sets of `0..m`; unknowns in no block have zero rows and
/// columns. Built by [`Self::clear`] then [`Self::push_block`] per block.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BlockDiagonal {
    m: usize,
    /// The index sets, concatenated.
    index: Vec<usize>,
    /// The blocks, row-major, concatenated.
    values: Vec<f64>,
    /// Block `b` has the indices `index[starts[b]..starts[b + 1]]`.
    starts: Vec<usize>,
}

impl BlockDiagonal {
    /// Empties the matrix and sets its size to `m×m`.
    pub fn clear(&mut self, m: usize) {
        self.m = m;
        self.index.clear();
        self.values.clear();
        self.starts.clear();
        self.starts.push(0);
    }

    /// Size `m` of the `m×m` matrix.
    pub fn len(&self) -> usize {
        self.m
    }

    /// True for a `0×0` matrix.
    pub fn is_empty(&self) -> bool {
        self.m == 0
    }

    /// Appends the block on the unknowns `index` (each `< m`, none in an earlier
    /// block) with the row-major `values` (`index.len()²`). Returns `false`, and
    /// leaves the matrix unchanged, when the sizes disagree or an index is out
    /// of range.
    pub fn push_block(&mut self, index: &[usize], values: &[f64]) -> bool {
        let size = index.len();
        if values.len() != size * size || index.iter().any(|&i| i >= self.m) {
            return false;
        }
        self.index.extend_from_slice(index);
        self.values.extend_from_slice(values);
        self.starts.push(self.index.len());
        true
    }

    /// The blocks as (index set, row-major values).
    fn blocks(&self) -> impl Iterator<Item = (&[usize], &[f64])> {
        let mut values = self.values.as_slice();
        self.starts.windows(2).filter_map(move |w| {
            let &[s, e] = w else {
                return None;
            };
            let idx = self.index.get(s..e)?;
            let (block, rest) = values.split_at_checked(idx.len() * idx.len())?;
            values = rest;
            Some((idx, block))
        })
    }

    /// `out = A v` (`v`, `out` of length `m`).
    pub fn mul(&self, v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (idx, block) in self.blocks() {
            for (row, &i) in block.chunks_exact(idx.len().max(1)).zip(idx) {
                let sum = row
                    .iter()
                    .zip(idx)
                    .map(|(a, &j)| a * v.get(j).copied().unwrap_or(f64::NAN))
                    .sum();
                if let Some(o) = out.get_mut(i) {
                    *o = sum;
                }
            }
        }
    }

    /// `out = Aᵀ v` (`v`, `out` of length `m`).
    pub fn mul_transpose(&self, v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (idx, block) in self.blocks() {
            for (row, &i) in block.chunks_exact(idx.len().max(1)).zip(idx) {
                let vi = v.get(i).copied().unwrap_or(f64::NAN);
                for (a, &j) in row.iter().zip(idx) {
                    if let Some(o) = out.get_mut(j) {
                        *o += a * vi;
                    }
                }
            }
        }
    }

    /// Writes the dense row-major `m×m` matrix into `out` (`m²` entries).
    pub fn to_dense(&self, out: &mut [f64]) {
        out.fill(0.0);
        let m = self.m;
        for (idx, block) in self.blocks() {
            for (row, &i) in block.chunks_exact(idx.len().max(1)).zip(idx) {
                for (&a, &j) in row.iter().zip(idx) {
                    if let Some(o) = out.get_mut(i * m + j) {
                        *o = a;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_equal_the_dense_matrix() {
        // Blocks {0, 3} and {2}; unknown 1 in none (zero row and column).
        let mut a = BlockDiagonal::default();
        a.clear(4);
        assert!(a.push_block(&[0, 3], &[1.0, 2.0, 3.0, 4.0]));
        assert!(a.push_block(&[2], &[5.0]));
        assert!(!a.push_block(&[4], &[1.0]), "index out of range");
        assert!(!a.push_block(&[1], &[1.0, 2.0]), "size mismatch");
        let mut dense = vec![f64::NAN; 16];
        a.to_dense(&mut dense);
        #[rustfmt::skip]
        let expect = [1.0, 0.0, 0.0, 2.0,
                      0.0, 0.0, 0.0, 0.0,
                      0.0, 0.0, 5.0, 0.0,
                      3.0, 0.0, 0.0, 4.0];
        assert_eq!(dense, expect);
        let v = [1.0, -2.0, 0.5, 3.0];
        let (mut av, mut atv) = ([0.0; 4], [0.0; 4]);
        a.mul(&v, &mut av);
        a.mul_transpose(&v, &mut atv);
        for i in 0..4 {
            let row: f64 = (0..4).map(|j| expect[i * 4 + j] * v[j]).sum();
            let col: f64 = (0..4).map(|j| expect[j * 4 + i] * v[j]).sum();
            assert_eq!(av[i], row);
            assert_eq!(atv[i], col);
        }
    }
}
