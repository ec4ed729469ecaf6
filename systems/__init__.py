"""What is built around the math, one concern per subpackage: recordings (reading, checks,
axes, writing), simulation (motions, sensor model, diagrams), fmi (building the FMUs, SSP,
co-simulation, verify), evaluation (errors against references, sweeps, peers, the paper's
experiments, benchmarks), cluster (independent jobs in this process or on a Dask cluster)
and cli (the attitude command, its plots)."""
