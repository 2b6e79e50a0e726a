//! The STHB Newton and continuation loops factor with the shared faer LU
//! workspace of the numerics layer.

pub(crate) use ivt_num::LuWorkspace;
