//! Ordinary least squares with the parameter covariance and Student-t 95 %
//! intervals: the estimator behind the equation-error fit (Eq. 151 in its
//! energy form) and the straight lines of Fig. 47 and Fig. 50.

use super::IdentifyError;
use nalgebra::{DMatrix, DVector};

/// A least-squares fit `y ≈ X p` with its statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct LsFit {
    /// The estimate p̂.
    pub params: Vec<f64>,
    /// Half-widths of the 95 % intervals, `t(0.975, n−p)·√cov_ii`.
    pub half_width: Vec<f64>,
    /// RMS of the residual `y − X p̂`.
    pub residual_rms: f64,
    /// Rows n.
    pub rows: usize,
    /// 1/condition number of the column-scaled ZᵀX (small: nearly collinear).
    pub inverse_condition: f64,
}

/// Least squares `p = (XᵀX)⁻¹Xᵀy` with White's (heteroscedasticity-robust)
/// covariance: [`instrumental_variables`] with Z = X and no lag.
///
/// # Errors
/// As [`instrumental_variables`].
pub fn least_squares(
    x: &DMatrix<f64>,
    y: &DVector<f64>,
    what: &str,
) -> Result<LsFit, IdentifyError> {
    instrumental_variables(x, x, y, 0, what)
}

/// Instrumental-variable estimate `p = (ZᵀX)⁻¹ Zᵀy` with the Newey–West
/// covariance over `lag` rows (Bartlett weights).
///
/// Least squares on regressors with noise shrinks the estimate along its
/// weakly determined directions (errors in variables); when Z is X computed
/// from data whose noise is independent of X's (the other half of the
/// encoder edges and readings), ZᵀX and Zᵀy carry no noise products and the
/// estimate is consistent.
///
/// Columns are scaled by the norms of X's (inertias in kg·m², gains in
/// N·m/V) before ZᵀX is inverted.
///
/// # Errors
/// [`IdentifyError::NotIdentifiable`] when there are fewer rows than
/// columns + 2, a zero column, or an inverse condition number of the scaled
/// ZᵀX below 1e-12 (the data do not excite every parameter), `what` naming
/// the fit.
pub fn instrumental_variables(
    x: &DMatrix<f64>,
    z: &DMatrix<f64>,
    y: &DVector<f64>,
    lag: usize,
    what: &str,
) -> Result<LsFit, IdentifyError> {
    let (n, p) = x.shape();
    let not = |why: String| IdentifyError::NotIdentifiable {
        what: what.to_string(),
        why,
    };
    if n < p + 2 || z.shape() != (n, p) {
        return Err(not(format!("{n} equations for {p} unknowns")));
    }
    let scale: Vec<f64> = x.column_iter().map(|c| c.norm()).collect();
    if let Some(k) = scale.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(not(format!(
            "column {k} of the regression is zero or not finite"
        )));
    }
    let (mut xs, mut zs) = (x.clone(), z.clone());
    for ((mut cx, mut cz), s) in xs.column_iter_mut().zip(zs.column_iter_mut()).zip(&scale) {
        cx /= *s;
        cz /= *s;
    }
    let zx = zs.transpose() * &xs;
    let sv = zx.clone().svd(false, false).singular_values;
    let inverse_condition = sv.min() / sv.max();
    if inverse_condition.is_nan() || inverse_condition <= 1e-12 {
        return Err(not(format!(
            "the regressors are collinear (inverse condition number {inverse_condition:.1e})"
        )));
    }
    let Some(bread) = zx.try_inverse() else {
        return Err(not("ZᵀX is singular".into()));
    };
    let ps = &bread * (zs.transpose() * y);
    let resid = y - &xs * &ps;
    let score: Vec<DVector<f64>> = (zs.row_iter().zip(resid.iter()))
        .map(|(z_i, r_i)| z_i.transpose() * *r_i)
        .collect();
    let mut meat = DMatrix::<f64>::zeros(p, p);
    for (i, si) in score.iter().enumerate() {
        meat += si * si.transpose();
        // score[i − l] for l = 1..=min(lag, i)
        for (l, s_back) in (1..=lag.min(i)).zip(score.iter().take(i).rev()) {
            let w = 1.0 - l as f64 / (lag + 1) as f64;
            let c = si * s_back.transpose() * w;
            meat += &c + c.transpose();
        }
    }
    let dof = (n - p) as f64;
    let cov = &bread * meat * bread.transpose() * (n as f64 / dof);
    let t = student_t_975(dof);
    Ok(LsFit {
        params: ps.iter().zip(&scale).map(|(p, s)| p / s).collect(),
        half_width: (cov.diagonal().iter().zip(&scale))
            .map(|(c, s)| t * c.max(0.0).sqrt() / s)
            .collect(),
        residual_rms: (resid.norm_squared() / n as f64).sqrt(),
        rows: n,
        inverse_condition,
    })
}

/// The 97.5 % quantile of Student's t with `dof` degrees of freedom, by the
/// Cornish–Fisher expansion about z = 1.959964 (Abramowitz & Stegun
/// 26.7.5): 2.2281 at dof 10 (table: 2.2281), 2.0423 at 30 (2.0423).
pub fn student_t_975(dof: f64) -> f64 {
    let z: f64 = 1.959_963_984_540_054;
    let (z3, z5, z7) = (z.powi(3), z.powi(5), z.powi(7));
    let g1 = (z3 + z) / 4.0;
    let g2 = (5.0 * z5 + 16.0 * z3 + 3.0 * z) / 96.0;
    let g3 = (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / 384.0;
    z + g1 / dof + g2 / (dof * dof) + g3 / (dof * dof * dof)
}

/// A straight line `y = a + b x` fitted to points, with 95 % intervals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// Intercept a.
    pub intercept: f64,
    /// Slope b.
    pub slope: f64,
    /// 95 % half-width of the slope.
    pub slope_half_width: f64,
    /// RMS residual.
    pub residual_rms: f64,
}

/// [`least_squares`] of `y = a + b x`.
///
/// # Errors
/// Fewer than 4 points, or all x equal.
pub fn fit_line(points: &[(f64, f64)], what: &str) -> Result<Line, IdentifyError> {
    let x = DMatrix::from_fn(points.len(), 2, |i, j| match (j, points.get(i)) {
        (0, Some(_)) => 1.0,
        (_, Some(p)) => p.0,
        _ => f64::NAN,
    });
    let y = DVector::from_iterator(points.len(), points.iter().map(|p| p.1));
    let f = least_squares(&x, &y, what)?;
    let get = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(f64::NAN);
    Ok(Line {
        intercept: get(&f.params, 0),
        slope: get(&f.params, 1),
        slope_half_width: get(&f.half_width, 1),
        residual_rms: f.residual_rms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Table values of t(0.975, ν) (Abramowitz & Stegun Table 26.10).
    #[test]
    fn student_t_matches_the_table() {
        for (dof, table) in [(10.0, 2.2281), (30.0, 2.0423), (120.0, 1.9799)] {
            assert!((student_t_975(dof) - table).abs() < 2e-4, "{dof}");
        }
    }

    /// An exact line is recovered exactly; with known ±e alternating noise
    /// the slope's interval covers the truth, and a constant x is refused.
    #[test]
    fn line_fit_recovers_and_refuses() {
        let pts: Vec<_> = (0..20).map(|k| (k as f64, 3.0 - 0.5 * k as f64)).collect();
        let l = fit_line(&pts, "line").unwrap();
        assert!((l.slope + 0.5).abs() < 1e-12 && (l.intercept - 3.0).abs() < 1e-12);
        let noisy: Vec<_> = pts
            .iter()
            .enumerate()
            .map(|(k, p)| (p.0, p.1 + if k % 2 == 0 { 0.1 } else { -0.1 }))
            .collect();
        let l = fit_line(&noisy, "line").unwrap();
        assert!((l.slope + 0.5).abs() < l.slope_half_width, "{l:?}");
        let flat: Vec<_> = (0..20).map(|k| (1.0, k as f64)).collect();
        assert!(matches!(
            fit_line(&flat, "flat"),
            Err(IdentifyError::NotIdentifiable { .. })
        ));
    }
}
