"""Shipped scenario files (TOML), installed as the package data `mtt_sim.scenarios`."""
