//! Little-endian field writer and reader over fixed buffers (no heap, no
//! panic path): every message of the crate is written and read through them.

use crate::frame::WireError;

/// Little-endian field writer over a fixed buffer.
pub(crate) struct Put<const N: usize> {
    buf: [u8; N],
    at: usize,
}

impl<const N: usize> Put<N> {
    pub(crate) fn new() -> Self {
        Self { buf: [0; N], at: 0 }
    }
    pub(crate) fn bytes(&mut self, b: &[u8]) {
        if let Some(dst) = self.buf.get_mut(self.at..self.at + b.len()) {
            dst.copy_from_slice(b);
        }
        self.at += b.len();
    }
    pub(crate) fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    pub(crate) fn u16(&mut self, v: u16) {
        self.bytes(&v.to_le_bytes());
    }
    pub(crate) fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    pub(crate) fn f32s(&mut self, v: &[f32]) {
        for &x in v {
            self.f32(x);
        }
    }
    /// One flag byte: bit i is `bits[i]` (bit 0 first; at most eight).
    pub(crate) fn flags(&mut self, bits: &[bool]) {
        let byte = (0u8..8)
            .zip(bits)
            .fold(0u8, |byte, (i, &on)| byte | u8::from(on) << i);
        self.bytes(&[byte]);
    }
    pub(crate) fn done(&self) -> &[u8] {
        &self.buf[..self.at.min(N)]
    }
}

/// Little-endian field reader; the caller checks the total length first.
pub(crate) struct Get<'a> {
    pub(crate) p: &'a [u8],
}

impl Get<'_> {
    pub(crate) fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        if let (Some(head), Some(rest)) = (self.p.get(..N), self.p.get(N..)) {
            out.copy_from_slice(head);
            self.p = rest;
        }
        out
    }
    pub(crate) fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.take())
    }
    pub(crate) fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    pub(crate) fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take())
    }
    pub(crate) fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    pub(crate) fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    pub(crate) fn f32s<const N: usize>(&mut self) -> [f32; N] {
        core::array::from_fn(|_| self.f32())
    }
    /// The first `N` bits of a flag byte [`Put::flags`] wrote (bit 0 first;
    /// a bit past the eighth reads false).
    pub(crate) fn flags<const N: usize>(&mut self) -> [bool; N] {
        let byte = self.u8();
        let mut bits = [false; N];
        for (i, bit) in (0u8..8).zip(bits.iter_mut()) {
            *bit = byte >> i & 1 != 0;
        }
        bits
    }
}

/// A reader over `payload` after checking that it is `len` bytes long.
///
/// # Errors
/// [`WireError::BadLength`] naming the kind and the received length.
pub(crate) fn expect_len(kind: u8, payload: &[u8], len: usize) -> Result<Get<'_>, WireError> {
    if payload.len() == len {
        Ok(Get { p: payload })
    } else {
        Err(WireError::BadLength {
            kind,
            len: payload.len() as u8,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{Get, Put};

    #[test]
    fn flag_bytes_are_bit_zero_first() {
        let mut p = Put::<3>::new();
        p.flags(&[true, false, true]); // 0b101, the Output flags of msg.rs's table
        p.flags(&[false, true]); // 0b10
        p.flags(&[true; 9]); // a ninth flag has no bit
        assert_eq!(p.done(), &[0b101, 0b10, 0xFF]);
        let mut g = Get { p: p.done() };
        assert_eq!(g.flags::<3>(), [true, false, true]);
        assert_eq!(g.flags::<2>(), [false, true]);
        assert_eq!(
            g.flags::<9>(),
            [true, true, true, true, true, true, true, true, false]
        );
    }
}
