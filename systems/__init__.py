"""What is built around the math, one concern per subpackage: recordings (reading, checks,
axes, writing), simulation (motions, sensor model, diagrams), fmi (building the FMUs, SSP,
co-simulation, verify), evaluation (errors against references, peers, the paper's
experiments, benchmarks) and cli (the attitude command, its plots)."""
