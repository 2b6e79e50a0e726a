//! The lumped bladed disk of pyHarm's tutorial 006 (issue 28): 24 sectors of
//! three DOFs (disk, blade root, blade tip), disks of neighbouring sectors
//! coupled cyclically.

use super::{from_triplets, SparseModel};
use ivt_hb::HbError;

/// The bladed disk and the DOF its force and cubic spring act on.
#[derive(Debug, Clone)]
pub struct BladedDisk {
    /// `M`, `C = 2e-6 K`, `K` on the DOFs `[sector 0: disk, root, tip | sector 1 …]`.
    pub model: SparseModel,
    /// Sector 0's blade tip (DOF 2): `F = 1` and the spring `5e10 x³` act there.
    pub tip: usize,
}

/// Sectors of the disk.
pub const SECTORS: usize = 24;

/// The 72-DOF disk: per sector `M = diag(1.2, 0.35, 0.25)`,
/// `K = [[kg + kb1, −kb1, 0], [−kb1, kb1 + kb2, −kb2], [0, −kb2, kb2]]` with
/// kg = 6e5, kb1 = 1e6, kb2 = 2e6; the disk DOFs of neighbouring sectors joined
/// by springs of 5e7 (cyclically); `C = 2e-6 K`.
///
/// # Errors
/// Never for these sizes (the assembly's error is passed on).
pub fn bladed_disk() -> Result<BladedDisk, HbError> {
    bladed_disk_mistuned(&[1.0; SECTORS])
}

/// The disk of [`bladed_disk`] with sector `s`'s blade springs (kb1, kb2)
/// scaled by `blade_stiffness[s]` (stiffness mistuning; all ones is the tuned
/// disk, entry for entry). `C = 2e-6 K` of the mistuned `K`.
///
/// # Errors
/// [`HbError::Size`] unless there are [`SECTORS`] factors;
/// [`HbError::InvalidInput`] for a factor that is not finite and positive.
pub fn bladed_disk_mistuned(blade_stiffness: &[f64]) -> Result<BladedDisk, HbError> {
    if blade_stiffness.len() != SECTORS {
        return Err(HbError::Size {
            what: "blade_stiffness",
            expected: SECTORS,
            got: blade_stiffness.len(),
        });
    }
    if let Some((s, v)) = blade_stiffness
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(HbError::InvalidInput(format!(
            "blade_stiffness[{s}] = {v} must be finite and > 0"
        )));
    }
    let (kg, kc) = (6e5, 5e7);
    let mass = [1.2, 0.35, 0.25];
    let n = 3 * SECTORS;
    let (mut m, mut k) = (Vec::new(), Vec::new());
    for (s, &factor) in blade_stiffness.iter().enumerate() {
        let (kb1, kb2) = (factor * 1e6, factor * 2e6);
        let sector = [
            [kg + kb1, -kb1, 0.0],
            [-kb1, kb1 + kb2, -kb2],
            [0.0, -kb2, kb2],
        ];
        for (a, (&ma, row)) in mass.iter().zip(&sector).enumerate() {
            m.push((3 * s + a, 3 * s + a, ma));
            for (b, &v) in row.iter().enumerate().filter(|(_, v)| **v != 0.0) {
                k.push((3 * s + a, 3 * s + b, v));
            }
        }
        // The coupling spring between this disk and the next one.
        let (i, j) = (3 * s, 3 * ((s + 1) % SECTORS));
        k.extend([(i, i, kc), (j, j, kc), (i, j, -kc), (j, i, -kc)]);
    }
    let c: Vec<(usize, usize, f64)> = k.iter().map(|&(i, j, v)| (i, j, 2e-6 * v)).collect();
    Ok(BladedDisk {
        model: SparseModel {
            m: from_triplets(n, &m)?,
            c: from_triplets(n, &c)?,
            k: from_triplets(n, &k)?,
        },
        tip: 2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_factors_are_the_tuned_disk_and_a_factor_scales_one_blade() {
        let tuned = bladed_disk().unwrap().model.triplets();
        let mut factors = [1.0; SECTORS];
        factors[5] = 1.5;
        let mistuned = bladed_disk_mistuned(&factors).unwrap().model.triplets();
        // K's entries of sector 5's root-tip coupling: −kb2 = −2e6 → −3e6.
        let entry =
            |t: &[(usize, usize, f64)], i, j| t.iter().find(|e| e.0 == i && e.1 == j).map(|e| e.2);
        assert_eq!(entry(&tuned[2], 16, 17), Some(-2e6));
        assert_eq!(entry(&mistuned[2], 16, 17), Some(-3e6));
        assert_eq!(entry(&mistuned[1], 16, 17), Some(-3e6 * 2e-6));
        // Every other sector is unchanged, entry for entry.
        let others = |t: &[(usize, usize, f64)]| -> Vec<(usize, usize, f64)> {
            t.iter()
                .copied()
                .filter(|e| e.0 / 3 != 5 && e.1 / 3 != 5)
                .collect()
        };
        assert_eq!(others(&tuned[2]), others(&mistuned[2]));
        assert!(bladed_disk_mistuned(&[1.0; 3]).is_err());
        factors[0] = 0.0;
        assert!(bladed_disk_mistuned(&factors).is_err());
    }
}
