"""The LMB tracker's re-identification: SILTP codes by hand, LOMO's shape and lighting invariance, XQDA on data with a
known answer, the FIFO pool, and `mtt-sim learn-reid` reproducing the shipped metric's recipe."""

import numpy as np

from mtt_sim import trackers
from mtt_sim import cli
from mtt_sim.trackers.parts import reid


def test_siltp_code_of_a_hand_made_neighbourhood():
    grey = np.full((3, 3), 100.0, np.float32)
    grey[1, 2] = 140.0    # right neighbour brighter than 1.3 x centre: digit 1 at 3^0
    grey[0, 1] = 60.0     # upper neighbour darker than 0.7 x centre: digit 2 at 3^1
    assert reid._siltp(grey[None], 1)[0, 1, 1] == 1 * 1 + 2 * 3


def test_lomo_has_a_fixed_size_unit_parts_and_shrugs_off_lighting():
    rng = np.random.default_rng(0)
    person = np.zeros((60, 24, 3), np.uint8)
    person[:30] = (200, 40, 40)                     # red top
    person[30:] = (40, 40, 160)                     # blue trousers
    person = np.clip(person + rng.normal(0, 6, person.shape), 0, 255).astype(np.uint8)
    other = person[:, :, ::-1].copy()               # the colours swapped
    f, g, d, s = reid.lomo([person, other, (person * 0.6).astype(np.uint8),   # darker: Retinex evens it out
                            np.roll(person, 3, axis=1)])   # shifted sideways: the horizontal maximum absorbs it
    rows = 11 + 5    # rows of 8 x 8 windows, stride 4: 48 x 24 and 24 x 12 (12 x 6 is narrower than a window)
    assert f.shape == g.shape == d.shape == s.shape == (rows * (512 + 2 * 81),)
    colour = rows * 512
    np.testing.assert_allclose([np.linalg.norm(f[:colour]), np.linalg.norm(f[colour:])], 1.0, rtol=1e-5)
    assert max(np.linalg.norm(f - d), np.linalg.norm(f - s)) < 0.5 * np.linalg.norm(f - g)


def test_lomo_of_crops_together_is_lomo_of_each_alone():
    rng = np.random.default_rng(2)
    crops = [rng.integers(0, 256, (h, w, 3), np.uint8) for h, w in ((60, 24), (33, 17), (120, 50), (2, 2))]
    together = reid.lomo(crops)
    assert together.shape == (4, reid._DIM) and reid.lomo([]).shape == (0, reid._DIM)
    assert all(np.array_equal(together[k], reid.lomo([c])[0]) for k, c in enumerate(crops))


def test_xqda_separates_classes_that_differ_only_in_some_directions():
    rng = np.random.default_rng(1)
    centres = rng.normal(0, 1, (30, 40)) * np.r_[np.ones(4) * 3, np.zeros(36)]   # identity lives in 4 dims
    classes = np.repeat(np.arange(30), 6)
    x = centres[classes] + rng.normal(0, 1, (len(classes), 40)) * np.r_[np.ones(4) * 0.3, np.ones(36) * 2]
    metric = reid.Metric(reid.learn_xqda(x, classes, dims=4, pca=40))
    e = metric.embed(x)
    d = metric.distance(e, e)
    np.fill_diagonal(d, np.inf)
    plain = ((x[:, None] - x[None]) ** 2).sum(-1)
    np.fill_diagonal(plain, np.inf)
    assert (classes[d.argmin(1)] == classes).mean() > 0.95 > 0.5 > (classes[plain.argmin(1)] == classes).mean()


def test_pool_is_fifo_skips_labels_in_use_and_respects_the_threshold():
    metric = reid.Metric({"mean": np.zeros(2), "projection": np.eye(2), "kernel": np.eye(2)})
    pool = reid.FeaturePool(3)
    pool.add(np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0], [30.0, 0.0]]), np.array([1, 2, 3, 4]))
    assert [label for _, label in pool.items] == [2, 3, 4]          # the oldest (label 1) fell out
    found = pool.match(metric, np.array([[10.5, 0.0], [20.2, 0.0], [100.0, 0.0]]), exclude={3}, threshold=4.0)
    assert found.tolist() == [2, 0, 0]     # 3 is in use; nothing lies within reach of the third


def test_learn_reid_writes_a_metric_the_tracker_can_load(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    shipped_before = reid.METRIC_FILE.read_bytes()
    assert cli.main(["learn-reid", "--seeds", "1", "--frames", "30", "--every", "10", "--dims", "4"]) == 0
    captured = capsys.readouterr()
    assert "crops" in captured.out and "lmb:reid_metric=xqda.npz" in captured.out and "rendering crops" in captured.err
    assert reid.METRIC_FILE.read_bytes() == shipped_before  # the installed file is replaced only with --install
    metric = reid.Metric.from_file(tmp_path / "xqda.npz")
    assert metric.projection.shape == (len(metric.mean), 4) and metric.kernel.shape == (4, 4)
    assert trackers.make("lmb:reid_metric=xqda.npz").metric.kernel.shape == (4, 4)
    assert reid.Metric.from_file().projection.shape[0] == len(metric.mean)  # the shipped file matches today's feature
    assert cli.main(["learn-reid", "--seeds", "1", "--frames", "30"]) == 2
    assert "'xqda.npz' exists; add --force" in capsys.readouterr().err
