"""The math: earth-frame filters and their accuracy (filters), the estimator methods
(methods), the stages around them (stages: gyro offset, heading, hard iron, magnetometer
delay, timing) and the causal pipeline that chains them, driven over arrays or per sample
(pipeline). Nothing here imports attitude_fmu.systems."""
