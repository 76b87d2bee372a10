"""Trackers from elsewhere: any object with `update(detections)` (external) and Roboflow's `trackers` package
(roboflow). Tracker classes named by location or installed as plugins are found by the registry (../plugins.py)."""
