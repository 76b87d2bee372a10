"""A camera driven or carried forward over the ground: the flow it gives everything standing on the ground.

A pinhole camera over flat ground draws a person at depth Z at a size proportional to 1/Z, with their feet at a row
below the horizon's by the same proportion and their offset across from the image's middle column too. The standing
world's depth factor s(y) = far + (1 - far) y / H (its size factor at feet row y of a world H high) is linear in the
row and zero at the horizon's row y_h = -far H / (1 - far), so it is that 1/Z, with s = 1 at the bottom row. When the
camera moves forward by dZ, a person's 1/Z grows to 1/(Z - dZ): s becomes s / (1 - c s) with c = dZ over the depth of
the bottom row, and their offsets from the focus of expansion (the middle column, the horizon's row) grow by the same
factor, so that they grow, drop toward the bottom and slide out sideways, the faster the nearer they are.

`render.camera_forward` is the rate at which a person at the bottom row grows (d ln height / dt, 1/s): c is it over the
frame rate. The walkers' own motion is unchanged; the flow is the camera's, added to their positions after each step.
Why: on the real MOT15 cameras carried or driven forward, a tracklet's growth explains most of its sideways motion (r
0.66-0.88 between growth times offset and sideways speed; at most 0.39 on the still cameras), which a global image warp
cannot give: it moves near and far people alike.
"""

from __future__ import annotations

import numpy as np

MAX_STEP = 0.5  # 1 - c s is held at this or above: a person within one step of the camera stays where that leaves them


def depth(y: np.ndarray, height: float, far_scale: float) -> np.ndarray:
    """The standing world's depth factor s(y) at feet rows `y` of a world `height` px high: 1 at the bottom row,
    `far_scale` at the top, 0 at the horizon (negative above it)."""
    return far_scale + (1.0 - far_scale) * y / height


def flow(pos: np.ndarray, extent, far_scale: float, per_frame: float) -> np.ndarray:
    """Positions (n, 2) of feet on the ground of a world `extent` (width, height) with `far_scale` < 1, one frame after
    the camera moved forward by `per_frame` (camera_forward over the frame rate)."""
    width, height = extent
    horizon = -far_scale * height / (1.0 - far_scale)
    s = depth(pos[:, 1], height, far_scale)
    grow = 1.0 / np.maximum(1.0 - per_frame * np.maximum(s, 0.0), MAX_STEP)
    focus = np.array([width / 2.0, horizon])
    return focus + (pos - focus) * grow[:, None]
