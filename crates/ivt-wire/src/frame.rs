//! Byte framing: `SYNC kind len payload[len] crc_lo crc_hi`.
//!
//! The CRC is CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no
//! final xor) over `kind`, `len` and the payload — not over `SYNC`, so a
//! decoder that resynchronises on a stray `0xA5` inside a payload rejects the
//! bogus frame by its CRC and keeps hunting.

/// First byte of every frame.
pub const SYNC: u8 = 0xA5;
/// Largest payload a frame may carry (the length byte is a `u8`).
pub const MAX_PAYLOAD: usize = 255;
/// Bytes a frame adds around its payload: sync, kind, len, two CRC bytes.
pub const OVERHEAD: usize = 5;
/// Size of a buffer that holds any frame.
pub const MAX_FRAME: usize = MAX_PAYLOAD + OVERHEAD;

/// What can go wrong on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WireError {
    /// The received CRC does not match the frame.
    BadCrc,
    /// The output buffer is too small for the frame.
    BufferTooSmall,
    /// The payload is longer than [`MAX_PAYLOAD`].
    PayloadTooLong,
    /// A frame kind this side does not know.
    UnknownKind(u8),
    /// A field that is not a valid value (an enum code out of range).
    BadValue,
    /// A known kind whose version byte this side does not read.
    UnsupportedVersion {
        /// The frame kind.
        kind: u8,
        /// Its version byte.
        version: u8,
    },
    /// A known kind with the wrong payload length.
    BadLength {
        /// The frame kind.
        kind: u8,
        /// Its payload length.
        len: u8,
    },
}

impl core::fmt::Display for WireError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            WireError::BadCrc => write!(f, "frame CRC mismatch"),
            WireError::BufferTooSmall => write!(f, "buffer too small for the frame"),
            WireError::PayloadTooLong => write!(f, "payload longer than {MAX_PAYLOAD} bytes"),
            WireError::BadValue => write!(f, "field value out of range"),
            WireError::UnknownKind(k) => write!(f, "unknown frame kind 0x{k:02x}"),
            WireError::UnsupportedVersion { kind, version } => {
                write!(
                    f,
                    "frame kind 0x{kind:02x} in unsupported version {version}"
                )
            }
            WireError::BadLength { kind, len } => {
                write!(f, "frame kind 0x{kind:02x} with wrong payload length {len}")
            }
        }
    }
}

/// CRC-16/CCITT-FALSE, continued from `crc` over `data` (bitwise: 8 shifts per
/// byte, no table, so it costs no flash on the MCU).
pub fn crc16_update(mut crc: u16, data: &[u8]) -> u16 {
    for &b in data {
        crc ^= (b as u16) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// CRC-16/CCITT-FALSE of `data`.
pub fn crc16(data: &[u8]) -> u16 {
    crc16_update(0xFFFF, data)
}

/// Writes one frame into `out` and returns its length.
///
/// # Errors
/// [`WireError::PayloadTooLong`] or [`WireError::BufferTooSmall`].
pub fn encode(kind: u8, payload: &[u8], out: &mut [u8]) -> Result<usize, WireError> {
    if payload.len() > MAX_PAYLOAD {
        return Err(WireError::PayloadTooLong);
    }
    let n = payload.len() + OVERHEAD;
    // sync, kind, length | payload | CRC (little-endian)
    let Some((head, body, crc_bytes)) = out
        .get_mut(..n)
        .and_then(|out| out.split_first_chunk_mut::<3>())
        .and_then(|(head, rest)| rest.split_last_chunk_mut::<2>().map(|(b, c)| (head, b, c)))
    else {
        return Err(WireError::BufferTooSmall);
    };
    let len = payload.len() as u8;
    *head = [SYNC, kind, len];
    body.copy_from_slice(payload); // n − OVERHEAD = payload.len() bytes
    let crc = crc16_update(crc16(&[kind, len]), payload);
    *crc_bytes = crc.to_le_bytes();
    Ok(n)
}

/// One received frame, borrowed from the [`Decoder`]'s buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawFrame<'a> {
    /// Frame kind.
    pub kind: u8,
    /// Payload bytes.
    pub payload: &'a [u8],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Hunt,
    Kind,
    Len,
    Payload,
    CrcLo,
    CrcHi,
}

/// Streaming frame decoder: feed bytes one at a time with [`Decoder::push`].
/// Bytes before a `SYNC` are skipped; a frame with a bad CRC is reported once
/// and the decoder goes back to hunting for `SYNC`.
#[derive(Clone, Debug)]
pub struct Decoder {
    state: State,
    kind: u8,
    len: u8,
    fill: usize,
    crc_lo: u8,
    /// Bytes pushed so far, and the offset of the current frame's SYNC.
    pos: usize,
    start: usize,
    buf: [u8; MAX_PAYLOAD],
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// A decoder hunting for `SYNC`.
    pub const fn new() -> Self {
        Self {
            state: State::Hunt,
            kind: 0,
            len: 0,
            fill: 0,
            crc_lo: 0,
            pos: 0,
            start: 0,
            buf: [0; MAX_PAYLOAD],
        }
    }

    /// Byte offset (counted from the first byte pushed) of the SYNC of the
    /// frame being read, or of the last one completed.
    #[must_use]
    pub fn frame_start(&self) -> usize {
        self.start
    }

    /// Bytes pushed so far (the offset of the next byte).
    #[must_use]
    pub fn position(&self) -> usize {
        self.pos
    }

    /// True while a frame has started but is not complete (a stream that
    /// ends now is truncated at [`Decoder::frame_start`]).
    #[must_use]
    pub fn in_frame(&self) -> bool {
        self.state != State::Hunt
    }

    /// True if the decoder is between frames and `byte` cannot start one
    /// (a byte that a strict reader calls garbage).
    #[must_use]
    pub fn skips(&self, byte: u8) -> bool {
        self.state == State::Hunt && byte != SYNC
    }

    /// Feeds one byte; returns a frame (or a CRC error) when one is complete.
    pub fn push(&mut self, byte: u8) -> Option<Result<RawFrame<'_>, WireError>> {
        let at = self.pos;
        self.pos = self.pos.wrapping_add(1);
        match self.state {
            State::Hunt => {
                if byte == SYNC {
                    self.start = at;
                    self.state = State::Kind;
                }
            }
            State::Kind => {
                self.kind = byte;
                self.state = State::Len;
            }
            State::Len => {
                self.len = byte;
                self.fill = 0;
                self.state = if byte == 0 {
                    State::CrcLo
                } else {
                    State::Payload
                };
            }
            State::Payload => {
                if let Some(slot) = self.buf.get_mut(self.fill) {
                    *slot = byte;
                }
                self.fill += 1;
                if self.fill >= self.len as usize {
                    self.state = State::CrcLo;
                }
            }
            State::CrcLo => {
                self.crc_lo = byte;
                self.state = State::CrcHi;
            }
            State::CrcHi => {
                self.state = State::Hunt;
                let len = self.len as usize;
                let payload = self.buf.get(..len).unwrap_or(&[]);
                let want = crc16_update(crc16(&[self.kind, self.len]), payload);
                if want != u16::from_le_bytes([self.crc_lo, byte]) {
                    return Some(Err(WireError::BadCrc));
                }
                return Some(Ok(RawFrame {
                    kind: self.kind,
                    payload,
                }));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc_check_value() {
        // The catalogue check value of CRC-16/CCITT-FALSE (a.k.a. CRC-16/IBM-3740).
        assert_eq!(crc16(b"123456789"), 0x29B1);
    }

    #[test]
    fn round_trip_with_garbage_and_corruption() {
        let mut buf = [0u8; 64];
        let mut stream = [0u8; 256];
        let mut n = 0;
        // Leading garbage including a stray SYNC that starts a bogus 2-byte frame.
        for b in [0x00, SYNC, 0x13, 0x02, 0x55, 0x66, 0x01, 0x02] {
            stream[n] = b;
            n += 1;
        }
        let len = encode(0x42, &[1, 2, SYNC, 4], &mut buf).unwrap();
        stream[n..n + len].copy_from_slice(&buf[..len]);
        n += len;
        // A corrupted copy, then an empty-payload frame.
        let len = encode(0x42, &[9, 9], &mut buf).unwrap();
        buf[3] ^= 0x10;
        stream[n..n + len].copy_from_slice(&buf[..len]);
        n += len;
        let len = encode(0x07, &[], &mut buf).unwrap();
        stream[n..n + len].copy_from_slice(&buf[..len]);
        n += len;

        let mut dec = Decoder::new();
        let mut got: [(u8, usize, bool); 8] = [(0, 0, false); 8];
        let mut k = 0;
        for &b in &stream[..n] {
            if let Some(r) = dec.push(b) {
                got[k] = match r {
                    Ok(f) => (f.kind, f.payload.len(), true),
                    Err(_) => (0, 0, false),
                };
                k += 1;
            }
        }
        // Bogus frame rejected, real frame, corrupted frame rejected, empty frame.
        assert_eq!(
            got[..k],
            [
                (0, 0, false),
                (0x42, 4, true),
                (0, 0, false),
                (0x07, 0, true)
            ]
        );
    }

    #[test]
    fn exact_round_trip() {
        let mut buf = [0u8; MAX_FRAME];
        let payload: [u8; MAX_PAYLOAD] = core::array::from_fn(|i| i as u8);
        let n = encode(0x81, &payload, &mut buf).unwrap();
        assert_eq!(n, MAX_FRAME);
        let mut dec = Decoder::new();
        let mut seen = false;
        for &b in &buf[..n] {
            if let Some(r) = dec.push(b) {
                let f = r.unwrap();
                assert_eq!(f.kind, 0x81);
                assert_eq!(f.payload, &payload[..]);
                seen = true;
            }
        }
        assert!(seen);
        assert_eq!(
            encode(1, &payload, &mut buf[..10]),
            Err(WireError::BufferTooSmall)
        );
    }

    #[test]
    fn single_bit_flips_are_detected() {
        let mut buf = [0u8; 32];
        let n = encode(0x01, &[0xde, 0xad, 0xbe, 0xef], &mut buf).unwrap();
        // Flip every bit after SYNC except in the length byte (which changes the
        // framing itself); CRC-16 detects all single-bit errors.
        for i in [1usize, 3, 4, 5, 6, 7, 8] {
            for bit in 0..8 {
                let mut f = buf;
                f[i] ^= 1 << bit;
                let mut dec = Decoder::new();
                let mut res = None;
                for &b in &f[..n] {
                    if let Some(r) = dec.push(b) {
                        res = Some(r.map(|fr| fr.kind));
                    }
                }
                assert_eq!(res, Some(Err(WireError::BadCrc)), "byte {i} bit {bit}");
            }
        }
    }
}
