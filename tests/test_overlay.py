"""The overlay render() draws: colours that stay apart from each other and from the scenes' own, sizes that grow with
the picture, and the observation's frame left as it was."""

from __future__ import annotations

from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest

import mtt_sim
from mtt_sim.show import overlay
from mtt_sim.show.overlay import DET_COLOR, GT_COLOR, GT_HIDDEN_COLOR, TRACK_PALETTE, track_color
from mtt_sim.sim import scenario


def lab(rgb) -> np.ndarray:
    """sRGB (0-255) to CIELAB (D65)."""
    c = np.asarray(rgb, float) / 255
    c = np.where(c > 0.04045, ((c + 0.055) / 1.055) ** 2.4, c / 12.92)
    xyz = c @ np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]).T
    f = xyz / [0.95047, 1.0, 1.08883]
    f = np.where(f > 216 / 24389, np.cbrt(f), (24389 / 27 * f + 16) / 116)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def distance(a, b) -> float:
    """CIE76 colour difference: about 2.3 is just noticeable, 50 and more reads as another colour."""
    return float(np.linalg.norm(lab(a) - lab(b)))


def scene_colours() -> dict[str, tuple]:
    """Every fixed colour a shipped scene paints: its background, its occluders (the poles, the signboard, the trunk)
    and its targets where a group's colour is (nearly) fixed; a group of random hues has no colour of its own."""
    out = {}
    for key in mtt_sim.available():
        sc = scenario.load(key)
        out[f"{key} background"] = sc.render.background_color
        out.update({f"{key} occluder {k}": o.color for k, o in enumerate(sc.occluders)})
        out.update({f"{key} group {k}": g.color for k, g in enumerate(sc.groups) if g.similarity >= 0.5})
    return out


def test_the_lab_distance_by_known_values():
    assert lab((255, 255, 255)) == pytest.approx([100, 0, 0], abs=0.05)
    assert lab((0, 0, 0)) == pytest.approx([0, 0, 0], abs=1e-9)
    assert distance((255, 0, 0), (0, 255, 0)) == pytest.approx(170.6, abs=0.5)


def test_truth_detections_and_every_track_colour_stay_apart():
    assert distance(GT_COLOR, DET_COLOR) >= 100 and distance(GT_HIDDEN_COLOR, DET_COLOR) >= 100
    assert distance(GT_COLOR, GT_HIDDEN_COLOR) >= 30  # the hidden truth darker, still the truth's hue
    for colour in TRACK_PALETTE:
        for other in (GT_COLOR, GT_HIDDEN_COLOR, DET_COLOR):
            assert distance(colour, other) >= 50, (colour, other)
    pairs = [(a, b) for i, a in enumerate(TRACK_PALETTE) for b in TRACK_PALETTE[i + 1:]]
    assert min(distance(a, b) for a, b in pairs) >= 40
    assert len(set(TRACK_PALETTE)) == len(TRACK_PALETTE) >= 6


def test_every_track_id_takes_a_palette_colour_and_neighbouring_ids_differ_most():
    ids = list(range(-3, 60)) + [10**9]
    assert all(track_color(i) in TRACK_PALETTE for i in ids)
    assert track_color(1) == TRACK_PALETTE[0] and track_color(1 + len(TRACK_PALETTE)) == track_color(1)
    assert min(distance(track_color(i), track_color(i + 1)) for i in range(len(TRACK_PALETTE))) >= 60


def test_the_truth_and_detection_colours_are_none_of_the_scenes_own():
    colours = scene_colours()
    assert "crossing occluder 1" in colours and "soccer background" in colours  # the signboard, the pitch
    for name, colour in colours.items():
        for mine in (GT_COLOR, GT_HIDDEN_COLOR, DET_COLOR):
            assert distance(mine, colour) >= 40, (mine, name, colour)
        for track in TRACK_PALETTE:
            assert distance(track, colour) >= 30, (track, name, colour)


def _blank(h: int, w: int) -> np.ndarray:
    return np.full((h, w, 3), 128, np.uint8)


def _thickness(img: np.ndarray, row: int, colour) -> int:
    """How many pixels of `row` are (nearly) `colour`: the width of the vertical lines it crosses."""
    return int((np.abs(img[row].astype(int) - colour).sum(axis=1) < 40).sum())


def _overlay(h: int, w: int, scale: int = 1, box=(0.25, 0.25, 0.5, 0.5)) -> np.ndarray:
    """A track box and a truth box apart on a flat frame, drawn at `scale`; `box` in fractions of the frame."""
    x, y, bw, bh = box[0] * w, box[1] * h, box[2] * w, box[3] * h
    truth = SimpleNamespace(boxes=np.array([[x, y, bw / 2, bh]]), visibility=np.ones(1))  # what the overlay reads
    return overlay.draw_overlay(_blank(h, w), truth, np.zeros((0, 5)), np.array([1]), np.array([[x + bw / 2 + 4, y,
                                                                                                    bw / 2 - 4, bh]]),
                                scale=scale)


def test_line_widths_grow_with_the_frame_and_keep_the_reference_on_small_frames():
    small, big, tiny = _overlay(288, 384), _overlay(576, 768), _overlay(120, 160)
    track = track_color(1)
    lines = {name: (_thickness(img, img.shape[0] // 2, track), _thickness(img, img.shape[0] // 2, GT_COLOR))
             for name, img in (("small", small), ("big", big), ("tiny", tiny))}
    assert lines["big"][0] >= 1.5 * lines["small"][0] and lines["big"][1] >= 1.5 * lines["small"][1], lines
    assert lines["small"][0] > lines["small"][1] >= 2  # the track thicker than the truth; two sides each
    assert lines["tiny"] == lines["small"]  # the floor: never thinner than at the reference size
    enlarged = _overlay(288, 384, scale=2)  # render_scale 2 draws as a frame twice the size does
    assert _thickness(enlarged, 288, track) == lines["big"][0]


def test_a_small_box_keeps_a_thin_outline_on_a_big_frame():
    img = _overlay(576, 768, box=(0.5, 0.5, 0.03, 0.05))  # a 23 x 29 px box: its halves about 10 px wide
    rows = np.arange(img.shape[0])
    widths = [_thickness(img, r, track_color(1)) for r in rows[290:310]]
    assert 0 < max(widths) <= 4  # a 1 px outline each side, not the big frame's 3 px


def test_text_grows_with_the_frame_and_the_banner_fits_its_width():
    def banner_rows(img):
        return int((img[:, 0] < 128).all(axis=1).sum())  # the darkened strip (its left margin has no text)

    text = "frame 40  sort  MOTA 0.724  IDF1 0.784  FP 42  FN 123  IDSW 9"
    small, big, tiny = (overlay.draw_banner(_blank(h, w), text) for h, w in ((288, 384), (576, 768), (120, 200)))
    assert banner_rows(big) >= 1.8 * banner_rows(small) and banner_rows(tiny) <= banner_rows(small)
    assert overlay.label(_blank(576, 768), "12", (100, 100), track_color(1))[1] >= \
        1.8 * overlay.label(_blank(288, 384), "12", (100, 100), track_color(1))[1]
    assert overlay.unit(_blank(100, 100)) == 1.0 and overlay.unit(_blank(540, 960)) == pytest.approx(540 / 288)
    narrow = _blank(576, 300)  # a tall narrow frame: the banner shrinks to stay inside it
    assert overlay.banner_size(narrow, text) < 0.4 * overlay.unit(narrow)
    overlay.draw_banner(narrow, text)
    assert (narrow[: banner_rows(narrow), -3:] < 128).all()  # its right margin holds no white text


def test_render_draws_on_a_copy_and_the_observed_frame_stays_as_it_was():
    env = gym.make("mtt_sim/Mot17Like-v0", render_mode="rgb_array", config={"env.max_steps": 5})
    obs, _ = env.reset(seed=0)
    dets = obs["detections"][: obs["num_detections"]]
    env.unwrapped.remember_tracks(np.arange(1, len(dets) + 1), dets[:, :4])
    obs, *_ = env.step({"ids": np.arange(1, len(dets) + 1), "boxes": dets[:, :4]})
    before = obs["frame"].copy()
    img = env.render()
    np.testing.assert_array_equal(obs["frame"], before)
    assert img.shape == before.shape and not np.array_equal(img, before)
    banner = img[:20, :300].reshape(-1, 3)
    assert (banner.max(axis=1) > 200).sum() > 200  # the banner's text is there, and readable (white)


def test_a_gif_keeps_the_overlay_s_colours_exactly(tmp_path):
    """A GIF has 64 colours: the overlay's few pixels keep theirs instead of merging into a noisy backdrop's."""
    import imageio.v3 as iio

    from mtt_sim.show.video import RESERVED, VideoWriter, gif_palette

    rng = np.random.default_rng(0)
    frames = []
    for k in range(4):
        img = np.clip(rng.normal(140, 30, (120, 160, 3)), 0, 255).astype(np.uint8)
        img[40:90, 100:130] = (180, 170, 60)  # a signboard
        for j, colour in enumerate((GT_COLOR, DET_COLOR, *TRACK_PALETTE)):
            img[10 + 10 * j, 5 + k: 60 + k] = colour  # one-pixel lines, moving
        frames.append(img)
    path = tmp_path / "lines.gif"
    with VideoWriter(path, fps=2) as writer:
        for img in frames:
            writer.write(img)
    back = iio.imread(path, index=None)[..., :3]
    for j, colour in enumerate((GT_COLOR, DET_COLOR, *TRACK_PALETTE)):
        assert (back[0, 10 + 10 * j, 5:60] == colour).all(), colour
    assert np.abs(back[0, 45:85, 105:125].astype(int) - (180, 170, 60)).max() <= 30  # the signboard stays yellow
    palette = gif_palette(frames[0])
    assert len(palette) == 64 and [tuple(c) for c in palette[: len(RESERVED)]] == list(RESERVED)
    np.testing.assert_array_equal(gif_palette(frames[0]), palette)  # the same frame, the same palette
