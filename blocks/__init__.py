"""Attitude-estimator blocks: earth-frame filters, their sensor-frame transformation,
the analytic accuracy of Rizun (2008), and the compiled per-sample steps."""
