"""Finds the packages, so none can be left out by hand (a hand-made list once left out mtt_sim.sim2real). The rest of
the metadata is in pyproject.toml. A setup.py because pyproject.toml alone cannot say this: its packages.find finds
packages under their own folder's name, and the top-level folders trackers/ and scenarios/ install as
mtt_sim.trackers and mtt_sim.scenarios (the top-level name `trackers` is Roboflow's), sub-packages included."""

from setuptools import find_namespace_packages, setup

INSIDE = {"mtt_sim.trackers": "trackers", "mtt_sim.scenarios": "scenarios"}  # package: its top-level folder
SKIP = ["__pycache__", "*.__pycache__"]
packages = find_namespace_packages(include=["mtt_sim", "mtt_sim.*"], exclude=SKIP)  # folders without __init__ too
for name, folder in INSIDE.items():
    packages += [name] + [f"{name}.{sub}" for sub in find_namespace_packages(folder, exclude=SKIP)]
setup(packages=packages, package_dir=INSIDE)
