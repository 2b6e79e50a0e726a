"""Writes telemetry_v1.bin: 20 telemetry frames in the v1 layout of ivt-wire
0.1 (kind 0x90, 21-byte payload `time_ticks u32, omega, omega_a, r f32,
stepper_position i32, fault u8`), encoded here independently of the Rust
code (struct + a bitwise CRC-16/CCITT-FALSE). Frame k: time_ticks =
0xFFFFF000 + 1000·k (wraps at k = 5), omega = 10 + k/4, omega_a = 10.5,
r = k/1024, stepper_position = 3·k − 7, fault = k % 5 == 4 ? 3 : 0."""
import struct

def crc16(data, crc=0xFFFF):
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc

out = bytearray()
for k in range(20):
    payload = struct.pack("<IfffiB", (0xFFFFF000 + 1000 * k) & 0xFFFFFFFF, 10 + k / 4, 10.5,
                          k / 1024, 3 * k - 7, 3 if k % 5 == 4 else 0)
    assert len(payload) == 21
    body = bytes([0x90, len(payload)]) + payload
    out += bytes([0xA5]) + body + struct.pack("<H", crc16(body))
open("telemetry_v1.bin", "wb").write(out)
