//! `ivt rig record` end to end against the QEMU firmware: its UART1 (one
//! telemetry frame per pulse) on a pty, the recorder on that pty, the PIL
//! link driving pulses. The MCAP must hold exactly the frames the firmware
//! says it sent, on the simulator's channels, with the controller's values.
//!
//! Needs QEMU and the built image: run through `firmware/run-qemu.sh test`.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

use ivt_ctrl::Config;
use ivt_wire::host::{QemuOptions, QemuPil};

#[test]
#[ignore = "needs qemu-system-arm and the firmware image; run by firmware/run-qemu.sh test"]
fn rig_record_captures_every_frame_the_qemu_firmware_sends() {
    let opts = QemuOptions {
        telemetry_serial: "pty".into(),
        ..QemuOptions::from_env()
    };
    let mut pil = QemuPil::start(&opts, 1200).expect("start QEMU");
    let pty = pil.telemetry_pty().expect("pty for UART1").to_path_buf();
    let out = std::env::temp_dir().join(format!("ivt-rig-record-{}.mcap", std::process::id()));
    let mut rec = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(["--json", "rig", "record", "--port"])
        .arg(&pty)
        .arg("--out")
        .arg(&out)
        .args([
            "--f-timer-hz",
            "1e6",
            "--idle-timeout-s",
            "10",
            "--frames",
            "700",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Only drive the firmware once the recorder holds the port: QEMU drops
    // pty output while nobody has the slave side open.
    let mut err = BufReader::new(rec.stderr.take().unwrap());
    let mut line = String::new();
    err.read_line(&mut line).unwrap();
    assert!(line.starts_with("recording from"), "recorder said: {line}");
    // QEMU notices that the pty's slave side is open on a 1 s poll; until
    // then it writes without back-pressure and a full pty drops bytes (lost
    // frames when the recorder is short of CPU). Give it that second.
    std::thread::sleep(std::time::Duration::from_millis(1200));

    let config = Config::default(); // 1 MHz timer
    pil.configure(&config).unwrap();
    pil.update_inputs(8.6, 6.0).unwrap();
    let n = 700u32; // = --frames above
    let mut t = 0u32;
    let mut last = None;
    for k in 0..n {
        t = t.wrapping_add(500 + (k % 40)); // ~100 rpm of θ at PPR 1200
        last = Some(pil.on_pulse(t).unwrap());
    }
    // Let the recorder drain the pty while QEMU still holds it open (closing
    // the master side discards unread bytes); it stops at 700 frames or,
    // if frames were lost, after 10 s idle with fewer.
    let output = rec.wait_with_output().unwrap();
    let report = pil.finish().unwrap();
    assert_eq!(report.telemetry_frames, u64::from(n));
    assert!(output.status.success(), "recorder failed: {output:?}");
    let summary: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(summary["frames"], u64::from(n), "{summary}");
    assert_eq!(summary["bad_frames"], 0, "{summary}");

    let data = std::fs::read(&out).unwrap();
    let mut count: BTreeMap<String, u64> = BTreeMap::new();
    let mut last_control = None;
    for m in mcap::MessageStream::new(&data).unwrap() {
        let m = m.unwrap();
        *count.entry(m.channel.topic.clone()).or_default() += 1;
        if m.channel.topic == "/control" {
            last_control = Some(serde_json::from_slice::<serde_json::Value>(&m.data).unwrap());
        }
    }
    assert_eq!(count["/control"], u64::from(n));
    assert_eq!(count["/stepper"], u64::from(n));
    let (msg, out_last) = (last_control.unwrap(), last.unwrap());
    assert_eq!(msg["ticks"], u64::from(t));
    assert_eq!(msg["omega"].as_f64().unwrap() as f32, out_last.omega);
    assert_eq!(msg["r"].as_f64().unwrap() as f32, out_last.r);
    let _ = std::fs::remove_file(&out);
}
