"""Trackers from elsewhere: any object with `update(detections)` (external), Roboflow's `trackers` package
(roboflow), and tracker classes named by location or installed as plugins (plugins)."""
