"""The lab: experiment grids over trackers, scenarios and seeds, the worker pool, benchmarks and plots."""
