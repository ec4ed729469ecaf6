"""Simulated motion with exact truth, the IMU sensor model, and the closed-loop
python-control diagram motion → sensor → estimator → error."""
