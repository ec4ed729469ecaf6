"""The stages around the method: gyro offset, heading with its hard-iron fit and magnetometer
delay, sample timing and latency, and delays measured over whole recordings."""
