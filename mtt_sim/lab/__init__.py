"""The lab: episodes run for a purpose: the one episode runner, experiment grids over trackers, scenarios and seeds,
the worker pool, benchmarks, plots, exports and the documentation site's stills."""
