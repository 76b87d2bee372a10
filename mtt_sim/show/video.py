"""Video files from annotated frames: H.264 MP4 or animated GIF through the ffmpeg that imageio-ffmpeg ships."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np


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
            # camera noise changes every pixel, and a GIF has no other way to stay small
            self._kind = {"codec": "gif", "pix_fmt_out": "pal8", "output_params": [
                "-filter_complex", f"fps={fps / 2:g},split[a][b];[a]palettegen=max_colors=64:stats_mode=diff[p];"
                                   "[b][p]paletteuse=dither=none:diff_mode=rectangle"]}
        self.path, self.fps, self._gen, self._size = str(path), fps, None, None

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
        self._gen.send(padded)

    def close(self):
        if self._gen is not None:
            self._gen.close()
            self._gen = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
