"""What both sources speak, below the simulator and the recorded sequences: a frame's truth and detections, and the
configuration tables they share with the validator that builds them."""
