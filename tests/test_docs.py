"""The generated documentation stays in sync with the code."""

from pathlib import Path

from mtt_sim.sim import scenario

ROOT = Path(__file__).resolve().parent.parent


def test_config_reference_is_current():
    text = (ROOT / "docs" / "config.md").read_text()
    assert scenario.reference_table() in text, "regenerate docs/config.md with `mtt-sim config` (see its header)"


def test_readme_lists_every_scenario():
    readme = (ROOT / "README.md").read_text()
    for key in scenario.available():
        assert f"`{key}`" in readme
