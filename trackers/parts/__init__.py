"""What trackers are built from, each part importing only other parts (and `base.Param`): Kalman banks (kalman),
IoU, gates and assignment (assignment), association rounds (rounds), box conversions (boxes), the track table
(track_table), SORT's and ByteTrack's associations without their decisions (associations), decisions as a policy
(management), camera motion (camera_motion), appearance and re-identification (appearance, reid), Gaussian mixtures
(gaussian_mixture), near pairs (near_pairs) and the particle filters' helpers (particles). See
docs/trackers_from_parts.md."""
