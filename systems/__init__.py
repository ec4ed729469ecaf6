"""Systems around the estimator blocks: motions, sensor model, diagrams, batch runs, CLI."""
