"""docs/experiments/fresh_contenders.py: the spec each way keeps, and the routes' figures, on hand-made rows."""

import importlib.util
import sys

from helpers import EXPERIMENTS

sys.path.append(str(EXPERIMENTS))  # it imports tune_sim_to_real, beside it
spec = importlib.util.spec_from_file_location("fresh_contenders", EXPERIMENTS / "fresh_contenders.py")
fresh_contenders = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fresh_contenders)


def test_each_way_keeps_its_spec_and_the_figures_follow():
    """One sequence, SORT and IOU, defaults 0.40 on real, each tuned on the real sequence to 0.50 (10 points).
    SORT's study best loses 10 points on real, but its second contender, best on the fresh seeds (the earlier of two
    tied), gains 5. IOU's one contender gains 2, and its defaults beat it on the fresh seeds."""
    rows = [{"sequence": "A", "tracker": t, "route": r, "defaults": 0.40, "real": real, "confirmed_defaults": d}
            for t, r, real, d in (("sort", "oracle", 0.50, None), ("iou", "oracle", 0.50, None),
                                  ("sort", "scene", 0.30, 0.10), ("iou", "scene", 0.42, 0.70))]
    tops = {("A", "sort"): [{"fresh": 0.50, "real": 0.30}, {"fresh": 0.60, "real": 0.45}, {"fresh": 0.60, "real": 0}],
            ("A", "iou"): [{"fresh": 0.65, "real": 0.42}]}
    assert fresh_contenders.chosen(rows[2], tops["A", "sort"], "study") == (0.30, 0.50)
    assert fresh_contenders.chosen(rows[2], tops["A", "sort"], "fresh") == (0.45, 0.60)
    assert fresh_contenders.chosen(rows[3], tops["A", "iou"], "fresh or defaults") == (0.40, 0.70)
    lines = fresh_contenders.table(rows, tops).splitlines()
    # shares: SORT -1.0, 0.5, 0.5; IOU 0.2, 0.2, 0.0. IOU is picked every way (0.65 or 0.70 on the fresh seeds), 8
    # points behind the best tuned (50.0), 10 when its defaults are kept
    assert lines[2] == "| study | -0.40 | 1 of 2 | 0 of 1 | 8.0 | 8.0 |"
    assert lines[3] == "| fresh | 0.35 | 0 of 2 | 0 of 1 | 8.0 | 8.0 |"
    assert lines[4] == "| fresh or defaults | 0.25 | 0 of 2 | 0 of 1 | 10.0 | 10.0 |"


def test_the_twin_route_is_tabled_from_its_own_rows():
    """The same rows as above but SORT's tuned on its twin: the twin's table is the scene's above, and the scene's
    now has IOU alone."""
    rows = [{"sequence": "A", "tracker": t, "route": r, "defaults": 0.40, "real": real, "confirmed_defaults": d}
            for t, r, real, d in (("sort", "oracle", 0.50, None), ("iou", "oracle", 0.50, None),
                                  ("sort", "twin", 0.30, 0.10), ("iou", "scene", 0.42, 0.70))]
    tops = {("A", "sort"): [{"fresh": 0.50, "real": 0.30}, {"fresh": 0.60, "real": 0.45}],
            ("A", "iou"): [{"fresh": 0.65, "real": 0.42}]}
    twin = fresh_contenders.table(rows, tops, "twin").splitlines()
    assert twin[2:] == ["| study | -1.00 | 1 of 1 | 0 of 1 | 20.0 | 20.0 |",
                        "| fresh | 0.50 | 0 of 1 | 0 of 1 | 5.0 | 5.0 |",
                        "| fresh or defaults | 0.50 | 0 of 1 | 0 of 1 | 5.0 | 5.0 |"]
    assert fresh_contenders.table(rows, tops).splitlines()[2] == "| study | 0.20 | 0 of 1 | 0 of 1 | 8.0 | 8.0 |"
