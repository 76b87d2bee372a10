"""Video files from annotated frames: H.264 MP4 or animated GIF through the ffmpeg that imageio-ffmpeg ships."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from mtt_sim.show.overlay import DET_COLOR, GT_COLOR, GT_HIDDEN_COLOR, TRACK_PALETTE

GIF_COLOURS = 64
# The overlay's colours, kept exact in a GIF: a 64-colour palette fitted to the frame's pixels alone merges these few
# pixels into the backdrop's colours (the detections' cyan came out white).
RESERVED = (GT_COLOR, GT_HIDDEN_COLOR, DET_COLOR, *TRACK_PALETTE, (255, 255, 255), (0, 0, 0))


def gif_palette(rgb: np.ndarray, size: int = GIF_COLOURS) -> np.ndarray:
    """`size` RGB colours for a GIF of frames like `rgb`: the overlay's (`RESERVED`) exactly, and the rest fitted to
    the frame's pixels (a median cut, then k-means steps; deterministic: the same frame, the same palette)."""
    pixels = rgb.reshape(-1, 3)
    boxes = [pixels[:: max(1, len(pixels) // 20000)].astype(np.int32)]  # 20,000 pixels are plenty for a backdrop
    while len(boxes) < size - len(RESERVED):
        spans = [np.ptp(b, axis=0).max() if len(b) > 1 else -1 for b in boxes]
        k = int(np.argmax(spans))
        if spans[k] <= 0:
            break
        box = boxes.pop(k)
        channel = int(np.argmax(np.ptp(box, axis=0)))
        box = box[np.argsort(box[:, channel], kind="stable")]
        boxes += [box[: len(box) // 2], box[len(box) // 2:]]
    free = np.array([b.mean(axis=0) for b in boxes if len(b)])
    pixels, fixed = np.concatenate(boxes).astype(float), np.array(RESERVED, float)
    for _ in range(8):  # k-means steps from the cut: a small patch of its own colour (a signboard) gets a centre
        centres = np.concatenate([fixed, free])
        nearest = ((centres ** 2).sum(axis=1)[None] - 2 * pixels @ centres.T).argmin(axis=1)
        for k in range(len(free)):
            mine = pixels[nearest == len(fixed) + k]
            if len(mine):
                free[k] = mine.mean(axis=0)
    return np.array([*RESERVED, *np.round(free)], np.uint8)


def palette_lut(palette: np.ndarray) -> np.ndarray:
    """(32, 32, 32, 3): the nearest palette colour to the centre of each 5-bit RGB cell."""
    cells = np.stack(np.meshgrid(*[np.arange(32) * 8 + 4] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    centres = palette.astype(np.int64)
    d = (centres ** 2).sum(axis=1)[None] - 2 * cells @ centres.T
    return palette[d.argmin(axis=1)].reshape(32, 32, 32, 3)


class VideoWriter:
    """An H.264 MP4 (plays in browsers, Jupyter and GitHub) or an animated GIF, by the file's extension, from RGB
    frames of one size, through the ffmpeg that imageio-ffmpeg ships in its wheel. The size is taken from the first
    frame; odd sizes are padded by a black row or column (H.264 needs even ones)."""

    def __init__(self, path: str | os.PathLike, fps: float = 25.0):
        suffix = Path(path).suffix.lower()
        if suffix not in (".mp4", ".gif"):
            raise ValueError(f"video file {path}: allowed extensions: .mp4, .gif")
        if not Path(path).resolve().parent.is_dir():
            raise OSError(f"cannot write video file {path}: its folder does not exist")
        if suffix == ".mp4":
            self._kind = {"codec": "libx264", "pix_fmt_out": "yuv420p",
                          "output_params": ["-crf", "23", "-preset", "veryfast"]}
        else:  # every other frame, one 64-colour palette, only each frame's changed rectangle stored: a scene's
            # camera noise changes every pixel, and a GIF has no other way to stay small. The frames come already
            # reduced to those 64 colours (`gif_palette`), so ffmpeg's palette keeps them all, the overlay's too
            self._kind = {"codec": "gif", "pix_fmt_out": "pal8", "output_params": [
                "-filter_complex", f"fps={fps / 2:g},split[a][b];[a]palettegen=max_colors={GIF_COLOURS}:"
                                   "stats_mode=diff[p];[b][p]paletteuse=dither=none:diff_mode=rectangle"]}
        self.path, self.fps, self._gen, self._size = str(path), fps, None, None
        self._lut = None  # a GIF's colour of every 5-bit RGB cell, from its first frame

    def write(self, rgb: np.ndarray):
        h, w = rgb.shape[:2]
        if self._gen is None:
            import imageio_ffmpeg  # imported here: only videos need it

            self._size = (w + w % 2, h + h % 2)
            self._gen = imageio_ffmpeg.write_frames(self.path, self._size, fps=self.fps, macro_block_size=1,
                                                    quality=None, **self._kind)
            self._gen.send(None)
        elif (w + w % 2, h + h % 2) != self._size:
            raise ValueError(f"video frames must keep one size: {self._size}, got {(w, h)}")
        padded = np.zeros((self._size[1], self._size[0], 3), np.uint8)
        padded[:h, :w] = rgb
        if self._kind["codec"] == "gif":
            if self._lut is None:
                self._lut = palette_lut(gif_palette(padded))
            padded = self._lut[padded[..., 0] >> 3, padded[..., 1] >> 3, padded[..., 2] >> 3]
        self._gen.send(padded)

    def close(self):
        if self._gen is not None:
            self._gen.close()
            self._gen = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
