//! Plant integration, sensors and actuators, closed loop with ivt-ctrl, scenes and MCAP logs. Being built under issue 6; nothing here yet.
