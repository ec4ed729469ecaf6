"""Independent jobs (a recording, a Table 1 cell, a co-simulation) run in this process or
through dask.distributed: a local cluster of worker processes or an existing cluster
(jobs), and how a Dask worker that ran FMUs ends (worker_exit). docs/distributed.md says
how to start a cluster."""
