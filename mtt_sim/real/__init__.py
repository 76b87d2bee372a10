"""Real data: a MOTChallenge sequence folder as a source (its frames, detections and ground truth), and the
benchmark's files."""
