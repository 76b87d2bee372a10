"""The simulated tuning routes' record on real video: which route a source takes, the warning a user reads, and the
record computed from hand-made rows."""

import pytest

from helpers import write_sequence
from mtt_sim import cli
from mtt_sim.lab import routes


@pytest.fixture
def sources(tmp_path):
    folder = write_sequence(tmp_path / "seq", [(1, 10.0, 10.0, 20.0, 40.0, 0.9)])
    still, walking, other = tmp_path / "still.toml", tmp_path / "walking.toml", tmp_path / "mine.toml"
    still.write_text(f'{routes.FITTED_HEADER}: a scene\nname = "A"\n[render]\ncamera = "still"\n')
    walking.write_text(f'{routes.FITTED_HEADER}: a scene\nname = "B"\n[render]\ncamera = "walking"\n')
    other.write_text('name = "Mine"\n')
    return folder, still, walking, other


def test_each_source_takes_its_route(sources):
    folder, still, walking, other = sources
    assert routes.route_of(str(folder)) is None  # the sequence's own labels: nothing simulated
    assert routes.route_of(str(folder), {"sensor.model": "synthetic"}) == ("twin", routes.ANY)
    assert routes.route_of(str(still)) == ("scene", "still")
    assert routes.route_of(str(walking)) == ("scene", "walking")
    assert routes.route_of(str(other)) == ("generic", routes.ANY)
    assert routes.route_of("mot17_like") == ("generic", routes.ANY)


def test_a_route_is_doubted_unless_its_record_held(monkeypatch):
    monkeypatch.setattr(routes, "RECORD", {})
    assert "has not been measured" in routes.caution("twin", routes.ANY)
    monkeypatch.setattr(routes, "RECORD", {("twin", routes.ANY, routes.ANY): routes.Record(8, 16, 10, 0.7, 0),
                                           ("generic", routes.ANY, routes.ANY): routes.Record(8, 16, 10, 0.7, 3),
                                           ("scene", "walking", routes.ANY): routes.Record(2, 4, 3, -0.3, 0),
                                           ("scene", "still", routes.ANY): routes.Record(6, 12, 0, None, 1)})
    assert routes.caution("twin", routes.ANY) is None
    assert routes.caution("generic", routes.ANY).startswith("on the shared sequences (8 MOT15 sequences), specs tuned "
                                                            "on a generic scenario kept a median 0.70")
    assert " 3 of 16 lost more than a point of HOTA" in routes.caution("generic", routes.ANY)
    assert "kept a median -0.30" in routes.caution("scene", "walking")
    assert routes.caution("scene", "walking").endswith("the defaults did better there; prefer them unless a few "
                                                       "labelled frames say otherwise")
    assert "fitted scene: 1 of 12 lost" in routes.caution("scene", "still")


def test_the_record_is_computed_from_the_rows():
    def row(sequence, tracker, route, real, defaults=0.40):
        return {"sequence": sequence, "tracker": tracker, "route": route, "defaults": defaults, "real": real}

    rows = [row("A", "sort", "oracle", 0.50), row("A", "sort", "scene", 0.45), row("A", "sort", "twin", 0.48),
            row("B", "sort", "oracle", 0.405), row("B", "sort", "scene", 0.38), row("B", "sort", "twin", 0.40),
            row("C", "sort", "oracle", 0.60), row("C", "sort", "scene", 0.42), row("C", "sort", "twin", 0.30)]
    got = routes.records(rows, {"A": "still", "B": "still", "C": "walking"})
    # A gains 10 points on its labels, the scene keeps 5 of them; B's labels gain half a point (no share), and its
    # scene loses 2 points; C's scene keeps 2 of 20; the twin keeps 8 of 10 on A and loses 10 on C (-0.5 of 20)
    assert got[("scene", "still", "sort")] == routes.Record(sequences=2, pairs=2, gaining=1, share=0.5, losing=1)
    assert got[("scene", "walking", "sort")] == routes.Record(sequences=1, pairs=1, gaining=1, share=0.1, losing=0)
    assert got[("twin", routes.ANY, "sort")] == routes.Record(sequences=3, pairs=3, gaining=2, share=0.15, losing=1)
    # a second tracker (a spec, recorded by its registered name) pooled with the first; routes without a name are left out
    rows += [row("A", "lmb:reid=false", "oracle", 0.50), row("A", "lmb:reid=false", "twin", 0.30),
             row("A", "lmb:reid=false", "generic_clock", 0.30)]
    got = routes.records(rows, {"A": "still", "B": "still", "C": "walking"})
    assert got[("twin", routes.ANY, "lmb")] == routes.Record(sequences=1, pairs=1, gaining=1, share=-1.0, losing=1)
    assert got[("twin", routes.ANY, routes.ANY)] == routes.Record(sequences=3, pairs=4, gaining=3, share=-0.5,
                                                                  losing=2)
    assert {route for route, _, _ in got} == {"scene", "twin"}


def test_a_trackers_own_record_is_told_before_the_pooled_one(monkeypatch):
    monkeypatch.setattr(routes, "RECORD", {("generic", routes.ANY, routes.ANY): routes.Record(8, 48, 40, 0.2, 20),
                                           ("generic", routes.ANY, "sort"): routes.Record(8, 8, 8, 0.6, 0),
                                           ("generic", routes.ANY, "gmphd"): routes.Record(8, 8, 4, -2.9, 8)})
    assert routes.caution("generic", routes.ANY, "sort") is None  # held for SORT
    assert routes.caution("generic", routes.ANY, "gmphd").startswith(
        "on the shared sequences (8 MOT15 sequences), gmphd specs tuned on a generic scenario kept a median -2.90")
    assert "prefer them" in routes.caution("generic", routes.ANY, "gmphd")
    assert "specs of the measured trackers (iou was not measured) tuned on a generic scenario kept a median 0.20" \
        in routes.caution("generic", routes.ANY, "iou")
    assert "20 of 48 lost" in routes.caution("generic", routes.ANY)


def test_tune_warns_once_per_route_that_did_not_hold(monkeypatch, capsys):
    monkeypatch.setattr(routes, "RECORD", {("generic", routes.ANY, routes.ANY): routes.Record(8, 16, 10, 0.2, 5)})
    assert cli.main(["tune", "sort", "--on", "crossing,books", "--trials", "2", "--json",
                     "--config", "env.max_steps=10"]) == 0
    err = capsys.readouterr().err
    assert err.count("warning: on the shared sequences (8 MOT15 sequences), specs of the measured trackers (sort was "
                     "not measured) tuned on a generic scenario kept a median 0.20") == 1
    assert err.count("note: a study's best is flattered by its own seeds; --confirm 4") == 1
    assert cli.main(["tune", "sort", "--on", "crossing", "--trials", "2", "--json", "--confirm", "1",
                     "--config", "env.max_steps=10"]) == 0
    err = capsys.readouterr().err
    assert "warning: on the shared sequences" in err and "--confirm 4" not in err  # asked for already


def test_a_scene_that_moves_or_goes_forward_is_a_walking_camera():
    header = routes.FITTED_HEADER + "\n"
    assert routes.camera_kind(header + '[render]\ncamera = "still"\n') == "still"
    assert routes.camera_kind(header + '[render]\ncamera = "walking"\n') == "walking"
    assert routes.camera_kind(header + '[render]\ncamera = "still"\ncamera_forward = 0.78\n') == "walking"
