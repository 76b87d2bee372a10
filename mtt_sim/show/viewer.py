"""The window of render_mode="human": pygame, as Gymnasium's own classic-control envs use (the [viewer] extra).

opencv-python-headless, the OpenCV this project depends on, has no GUI, so the window is pygame's.
"""

from __future__ import annotations

import importlib.util
import os
import sys

import numpy as np

HOW = ("render_mode='human' opens a window with pygame: pip install 'mtt-sim[viewer]', on a machine with a display. "
       "Without one, use render_mode='rgb_array' (Gymnasium's RecordVideo records it) or `mtt-sim run <scenario> "
       "--video out.mp4`.")


def available() -> bool:
    """Whether a window can be opened here: pygame is installed and there is a display (or SDL is told which video
    driver to use, e.g. SDL_VIDEODRIVER=dummy for tests)."""
    display = sys.platform in ("win32", "darwin") or any(
        os.environ.get(k) for k in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"))
    return display and importlib.util.find_spec("pygame") is not None


class Viewer:
    """A window showing RGB frames at up to `fps` frames per second. pygame has one window per process: envs in
    human mode share it."""

    def __init__(self, title: str, fps: float):
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        import pygame

        self.pg, self.title, self.fps = pygame, title, fps
        self.clock = pygame.time.Clock()
        self.opened = False

    def show(self, rgb: np.ndarray) -> None:
        pg = self.pg
        size = (rgb.shape[1], rgb.shape[0])
        window = pg.display.get_surface() if pg.display.get_init() else None
        if window is None or window.get_size() != size:
            pg.display.init()
            pg.display.set_caption(self.title)
            window = pg.display.set_mode(size)
        self.opened = True
        window.blit(pg.surfarray.make_surface(np.ascontiguousarray(rgb.swapaxes(0, 1))), (0, 0))
        pg.event.pump()
        pg.display.flip()
        self.clock.tick(self.fps)

    def close(self) -> None:
        if self.opened:
            self.pg.display.quit()
            self.opened = False
