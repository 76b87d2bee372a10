"""Simulation against reality: the detector calibrated to real detections, the twin validated against real
tracking results, the baselines and the scoring checked against their reference outputs, and truth statistics."""
