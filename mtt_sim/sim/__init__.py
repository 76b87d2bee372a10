"""The simulator: a scenario's configuration, the pymunk world, the renderer, the ground truth and the detectors."""
