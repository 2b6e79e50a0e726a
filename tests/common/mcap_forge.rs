//! MCAP files written byte by byte, so that a test can claim any length in
//! any field (what a hostile recording does): the records of the MCAP
//! specification (magic, header, channel, message, metadata, chunk, data
//! end, footer), little-endian, with no index. Included by
//! `tests/hostile_readers.rs` (`#[path]`).
#![allow(dead_code)]

/// The MCAP magic, at both ends of a file.
pub const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// One record: opcode, body length, body.
pub fn record(op: u8, body: &[u8]) -> Vec<u8> {
    record_claiming(op, body.len() as u64, body)
}

/// A record whose length field claims `len` whatever the body holds.
pub fn record_claiming(op: u8, len: u64, body: &[u8]) -> Vec<u8> {
    let mut r = vec![op];
    r.extend_from_slice(&len.to_le_bytes());
    r.extend_from_slice(body);
    r
}

/// A u32-prefixed string.
pub fn string(s: &[u8]) -> Vec<u8> {
    let mut b = (s.len() as u32).to_le_bytes().to_vec();
    b.extend_from_slice(s);
    b
}

/// A header record (profile, library).
pub fn header() -> Vec<u8> {
    let mut b = string(b"");
    b.extend(string(b"forge"));
    record(0x01, &b)
}

/// A channel record of JSON messages on `topic`.
pub fn channel(id: u16, topic: &str) -> Vec<u8> {
    let mut b = id.to_le_bytes().to_vec();
    b.extend_from_slice(&0u16.to_le_bytes());
    b.extend(string(topic.as_bytes()));
    b.extend(string(b"json"));
    b.extend_from_slice(&0u32.to_le_bytes());
    record(0x04, &b)
}

/// A message record on channel `id` carrying `data`.
pub fn message(id: u16, sequence: u32, data: &[u8]) -> Vec<u8> {
    let mut b = id.to_le_bytes().to_vec();
    b.extend_from_slice(&sequence.to_le_bytes());
    b.extend_from_slice(&0u64.to_le_bytes());
    b.extend_from_slice(&0u64.to_le_bytes());
    b.extend_from_slice(data);
    record(0x05, &b)
}

/// A metadata record `name` with `entries`.
pub fn metadata(name: &str, entries: &[(&str, &str)]) -> Vec<u8> {
    let mut map = vec![];
    for (k, v) in entries {
        map.extend(string(k.as_bytes()));
        map.extend(string(v.as_bytes()));
    }
    let mut b = string(name.as_bytes());
    b.extend(string(&map));
    record(0x0C, &b)
}

/// A chunk record holding `compressed` (compression `"zstd"` or `""`) and
/// declaring `uncompressed_size` and `crc` (0: unchecked).
pub fn chunk(compression: &str, uncompressed_size: u64, crc: u32, compressed: &[u8]) -> Vec<u8> {
    let mut b = vec![];
    b.extend_from_slice(&0u64.to_le_bytes());
    b.extend_from_slice(&0u64.to_le_bytes());
    b.extend_from_slice(&uncompressed_size.to_le_bytes());
    b.extend_from_slice(&crc.to_le_bytes());
    b.extend(string(compression.as_bytes()));
    b.extend_from_slice(&(compressed.len() as u64).to_le_bytes());
    b.extend_from_slice(compressed);
    record(0x06, &b)
}

/// A zstd chunk of `records`, its sizes and CRC true.
pub fn zstd_chunk(records: &[u8]) -> Vec<u8> {
    let data = zstd::bulk::compress(records, 3).unwrap();
    chunk(
        "zstd",
        records.len() as u64,
        crc32fast::hash(records),
        &data,
    )
}

/// A whole file: magic, header, `records`, data end (CRC 0: unchecked),
/// footer (no summary), magic.
pub fn file(records: &[Vec<u8>]) -> Vec<u8> {
    let mut f = MAGIC.to_vec();
    f.extend(header());
    for r in records {
        f.extend_from_slice(r);
    }
    f.extend(record(0x0F, &0u32.to_le_bytes()));
    f.extend(record(0x02, &[0u8; 20]));
    f.extend_from_slice(MAGIC);
    f
}

/// The metadata record of a commissioning recording.
pub fn ivt_metadata() -> Vec<u8> {
    metadata(
        "ivt",
        &[
            ("frame_version", "2"),
            ("ppr", "1200"),
            ("f_timer_hz", "1000000"),
            ("steps_per_rev", "3200"),
        ],
    )
}

/// The channels of a commissioning recording: /pulses 1, /sensors 2,
/// /stepper 3, /sequence 4.
pub fn ivt_channels() -> Vec<Vec<u8>> {
    vec![
        channel(1, "/pulses"),
        channel(2, "/sensors"),
        channel(3, "/stepper"),
        channel(4, "/sequence"),
    ]
}
