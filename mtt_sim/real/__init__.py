"""Real data: MOTChallenge sequences and files, the detector's calibration, the sim-to-real validation."""
