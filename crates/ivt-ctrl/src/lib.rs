//! The rig controller (no_std, f32, no heap): angle-sampled averaging, open-loop law, time-delay feedback, actuator output. Being built under issue 5; nothing here yet.
#![no_std]
