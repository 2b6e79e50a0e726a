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
    let (kg, kb1, kb2, kc) = (6e5, 1e6, 2e6, 5e7);
    let mass = [1.2, 0.35, 0.25];
    let sector = [
        [kg + kb1, -kb1, 0.0],
        [-kb1, kb1 + kb2, -kb2],
        [0.0, -kb2, kb2],
    ];
    let n = 3 * SECTORS;
    let (mut m, mut k) = (Vec::new(), Vec::new());
    for s in 0..SECTORS {
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
