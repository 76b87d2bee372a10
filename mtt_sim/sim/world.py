"""The pymunk world: targets that move, collide, enter and leave, and static occluders.

Target state lives in numpy arrays (one row per alive target, the "slot"); pymunk only resolves
contacts and joints. Each step reads every body's position and velocity with ``pymunk.batch``,
applies the motion models to all targets at once, writes the velocities back and steps the
space, so no per-target Python object is touched in the steady state.

Coordinates are world pixels, speeds pixels per frame (one frame = one time unit). In the
``standing`` projection the world is the ground plane and a position is the point between a
target's feet; sizes and speeds scale with the depth factor of that point, so a target walking
up the image shrinks and slows down as a real one would.
"""

from __future__ import annotations

import math

import numpy as np
import pymunk
import pymunk.batch as pbatch

from mtt_sim.sim import forward
from mtt_sim.sim.config import MOTIONS, TEXTURES, Scenario
from mtt_sim.sim.spots import SpotGrid
from mtt_sim.sim.walkers import Walkers

WALL_BIT = 1 << 31
_FREE, _FOR_GOOD, _LEFT = 0, -1, -2  # carry_left beside the frames left to ride: free, a carried group's, just left
_FIELDS = pbatch.BodyFields.BODY_ID | pbatch.BodyFields.POSITION | pbatch.BodyFields.VELOCITY
_WALL = 200.0  # wall thickness, px
MIN_DEPTH = 0.02  # the smallest size factor: a far_scale below 0 puts the horizon inside the world
_EXIT_MIN_AGE = 10  # frames a target must have lived before an exit door absorbs it (doors with role "both")


def hue_colors(hues: np.ndarray) -> np.ndarray:
    """Saturated RGB colours for hues in [0, 1) (HSV with S = 0.75, V = 0.9)."""
    h6 = (hues % 1.0) * 6.0
    k = (np.array([5.0, 3.0, 1.0]) + h6[:, None]) % 6.0
    rgb = 0.9 * (1 - 0.75 * np.clip(np.minimum(k, 4 - k), 0, 1))
    return np.round(rgb * 255)


class World:
    """Targets, their motion and their lifecycle for one episode."""

    def __init__(self, scenario: Scenario, rng: np.random.Generator):
        self.sc = scenario
        self.rng = rng
        self.extent = np.array(scenario.world_size)
        self.standing = scenario.world.projection == "standing"
        self.t = 0
        self.next_id = 1
        self.births = 0
        self._hue0 = rng.random()
        self.space = pymunk.Space()
        self._elasticity = {"elastic": 1.0, "soft": 0.2, "none": 0.0}[scenario.world.collision]
        self._add_static()
        self._buf = pbatch.Buffer()
        n_cols = {"ids": np.int64, "group": np.intp, "pos": (np.float64, 2), "vel": (np.float64, 2),
                  "size": (np.float64, 2), "color": (np.uint8, 3), "cruise": np.float64, "phase": np.float64,
                  "goal": (np.float64, 2), "stopped": bool, "born": np.int64, "carrier_id": np.int64,
                  "carry_offset": (np.float64, 2), "carry_left": np.int64, "own_vel": (np.float64, 2),
                  "desired": np.float64, "companion": bool}
        self._cols = list(n_cols)
        for name, spec_ in n_cols.items():
            dtype, width = spec_ if isinstance(spec_, tuple) else (spec_, None)
            setattr(self, name, np.zeros((0, width) if width else 0, dtype))
        self.bodies: list[pymunk.Body] = []
        self._pending: list[dict] = []  # rows of targets spawned but not yet in the state arrays
        g = scenario.groups
        self._motion = np.array([MOTIONS.index(x.motion) for x in g])
        self._present_motions = {x.motion for x in g}
        self._picks_up = scenario.world.carry_frames > 0 and not self.standing  # the carry event (topdown only)
        self._carrying = "carried" in self._present_motions or self._picks_up
        self.texture_of_group = np.array([TEXTURES.index(x.texture) for x in g])
        self.layer_of_group = np.array([x.layer for x in g])
        self.shape_is_rect = np.array([x.shape == "rect" for x in g])
        self._gait = np.array([[x.gait, x.gait_period] for x in g])
        self._param = {k: np.array([getattr(x, k) for x in g], float)
                       for k in ("accel", "speed", "max_speed", "turn_prob", "stop_prob")}
        self._exits = [d for d in scenario.doors if d.role in ("exit", "both")]
        self._walk = Walkers(scenario.walk, scenario.world.frame_rate) if scenario.walk.model == "langevin" else None
        self._forward = scenario.render.camera_forward / scenario.world.frame_rate  # the camera's forward step
        self._populate()
        self._sync_order()

    # ------------------------------------------------------------ geometry

    def depth_scale(self, y: np.ndarray) -> np.ndarray:
        """Size factor of a footprint at world row y: 1 at the bottom, `far_scale` at the top (standing only), and
        never below MIN_DEPTH (at and above a horizon inside the world)."""
        if not self.standing:
            return np.ones_like(y)
        h = self.extent[1]
        return np.maximum(forward.depth(np.clip(y, 0.0, h), h, self.sc.world.far_scale), MIN_DEPTH)

    def boxes(self) -> np.ndarray:
        """Drawn extent of every target, (n, 4) x, y, w, h in world pixels, with the gait applied."""
        s = self.depth_scale(self.pos[:, 1])
        w, h = self.size[:, 0] * s, self.size[:, 1] * s
        if self._gait[:, 0].any():
            amp, period = self._gait[self.group].T
            wave = amp * np.sin(2 * math.pi * self.t / period + self.phase)
            w, h = w * (1 + wave), h * (1 - 0.5 * wave)
        x = self.pos[:, 0] - w / 2
        y = self.pos[:, 1] - (h if self.standing else h / 2)
        return np.stack([x, y, w, h], axis=1)

    def depth(self) -> np.ndarray:
        """Drawing order key of every target: larger is nearer the viewer (drawn later)."""
        if self.standing:
            return self.pos[:, 1].copy()
        return self.layer_of_group[self.group] * 1e9 + self.ids.astype(np.float64)

    @property
    def finished(self) -> bool:
        """No target alive and no birth can happen any more."""
        if len(self.ids):
            return False
        can_spawn = any(g.birth_rate > 0 for g in self.sc.groups) or any(
            d.birth_rate > 0 and d.role != "exit" for d in self.sc.doors)
        cap = self.sc.world.max_births
        return not can_spawn or (cap >= 0 and self.births >= cap)

    # ------------------------------------------------------------ construction

    def _add_static(self):
        """Walls at the world borders and the solid occluders, as static shapes."""
        sb = self.space.static_body
        shapes = []
        if self.sc.world.walls:  # thick slabs just outside the world, so fast bodies cannot tunnel through
            w, h, t = *self.extent, _WALL
            slabs = [(-t, -t, w + t, 0), (-t, h, w + t, h + t), (-t, 0, 0, h), (w, 0, w + t, h)]
            shapes += [pymunk.Poly(sb, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]) for x0, y0, x1, y1 in slabs]
        for occ in self.sc.occluders:
            if occ.solid:
                x, y, w, h = occ.rect
                if self.standing:  # people walk around the base of a pillar, not through its image
                    y, h = y + h - max(4.0, 0.1 * h), max(4.0, 0.1 * h)
                shapes.append(pymunk.Poly(sb, [(x, y), (x + w, y), (x + w, y + h), (x, y + h)]))
        for s in shapes:
            s.elasticity, s.friction = 1.0, 0.0
            s.filter = pymunk.ShapeFilter(categories=WALL_BIT)
        self.space.add(*shapes)

    def _populate(self):
        """Place every group's initial targets, carriers before the targets they carry; linear in their number."""
        order = sorted(range(len(self.sc.groups)), key=lambda i: self.sc.groups[i].motion == "carried")
        grid = SpotGrid(max(max(g.size) for g in self.sc.groups))
        for gi in order:
            g = self.sc.groups[gi]
            if g.motion == "carried":
                self._flush()  # the carriers' rows
                carriers = np.flatnonzero(self.group == self.sc.group(g.carrier))
                for slot in carriers[: g.count]:
                    jitter = self.rng.normal(0, 0.1, 2) * self.size[slot]
                    self._spawn(gi, self.pos[slot] + jitter, np.zeros(2), carrier=int(slot))
                continue
            corners = np.array(g.region) * np.tile(self.extent, 2)
            for _ in range(g.count):
                pos = self._free_spot(g, (corners[:2], corners[2:]), grid)
                size = self._spawn(gi, pos, self._initial_velocity(g), in_view=True)
                grid.add(g.layer, pos, 0.5 * size.max())
        self._place_companions()
        self._flush()

    def _place_companions(self):
        """`render.camera_companions` people of the first group that is not carried, added at reset abreast, a body
        width apart in one row of the group's region and centred on the middle column (where the camera heads),
        standing: as the pair who walk just ahead of ETH-Sunnyday's camera."""
        count = self.sc.render.camera_companions
        gi = next((i for i, g in enumerate(self.sc.groups) if g.motion != "carried"), None)
        if gi is None or not count:
            return
        g, (w, h) = self.sc.groups[gi], self.extent
        y = self.rng.uniform(g.region[1], g.region[3]) * h
        apart = 1.1 * g.size[0] * self.depth_scale(np.array([y]))[0]
        for k in range(count):
            self._spawn(gi, np.array([w / 2 + (k - (count - 1) / 2) * apart, y]), np.zeros(2), in_view=True,
                        companion=True)

    def _free_spot(self, g, region, grid: "SpotGrid", tries: int = 20) -> np.ndarray:
        """A point in `region` (its low and high corners) whose footprint does not overlap a placed target of the same
        layer, if one is found."""
        radius = 0.5 * max(g.size)
        for _ in range(tries):
            p = self.rng.uniform(*region)
            if grid.is_free(g.layer, p, radius):
                return p
        return p

    def _initial_velocity(self, g, heading: float | None = None) -> np.ndarray:
        """Velocity drawn from the group's speed and heading distributions."""
        if heading is None:
            heading = math.radians(g.heading) + self.rng.uniform(-1, 1) * math.radians(g.heading_jitter)
        speed = max(0.0, g.speed * (1 + g.speed_jitter * self.rng.normal()))
        if g.motion == "random_walk":
            return self.rng.normal(0, g.speed, 2)
        return speed * np.array([math.cos(heading), math.sin(heading)])

    def _spawn(self, gi: int, pos: np.ndarray, vel: np.ndarray, carrier: int | None = None,
               in_view: bool = False, companion: bool = False) -> np.ndarray:
        """Add one target of group `gi`: a pymunk body now, a row of every state array at the next `_flush`.
        Returns its size. A walker placed `in_view` at reset stands with the walking model's stationary share (the
        scene opens on people already there, some of them waiting); one entering walks; a `companion` of the camera
        stands (`_place_companions`)."""
        g = self.sc.groups[gi]
        size = np.array(g.size) * np.exp(g.size_jitter * self.rng.normal(size=2))
        hue = self._hue0 + 0.618034 * self.next_id
        color = (1 - g.similarity) * hue_colors(np.array([hue]))[0] + g.similarity * np.array(g.color)
        phase, goal = self.rng.uniform(0, 2 * math.pi), self._pick_goal(pos)
        desired, stopped = 0.0, False
        if self._walk is not None and carrier is None:  # a walker sets off toward its goal at its own speed
            desired = self._walk.desired_speed(self.rng)
            vel = (goal - pos) / max(np.hypot(*(goal - pos)), 1e-9) * desired * size[1] * self._walk.dt
            stopped = companion or (in_view and bool(self.rng.random() < self._walk.standing_share))
            if stopped:
                vel = np.zeros(2)
        self._pending.append(dict(
            ids=self.next_id, group=gi, pos=pos, vel=vel, size=size, color=np.round(color),
            cruise=float(np.hypot(*vel)) or g.speed, phase=phase, goal=goal, stopped=stopped, born=self.t,
            carrier_id=0 if carrier is None else int(self.ids[carrier]),
            carry_offset=np.zeros(2) if carrier is None else pos - self.pos[carrier],
            carry_left=_FREE if carrier is None else _FOR_GOOD, own_vel=vel, desired=desired, companion=companion))
        self.next_id += 1
        self.bodies.append(self._make_body(g, pos, vel, size, carrier))
        return size

    def _flush(self):
        """Append the rows of the targets spawned since the last flush, one concatenation per state array."""
        if self._pending:
            for name in self._cols:
                old = getattr(self, name)
                new = np.array([row[name] for row in self._pending]).astype(old.dtype).reshape(-1, *old.shape[1:])
                setattr(self, name, np.concatenate([old, new]))
            self._pending = []

    def _make_body(self, g, pos, vel, size, carrier):
        body = pymunk.Body(1.0, float("inf"))  # no rotation: boxes stay axis-aligned
        body.position = tuple(pos)
        body.velocity = tuple(vel * self.depth_scale(np.array([pos[1]]))[0])
        if self.standing:
            shape = pymunk.Circle(body, 0.25 * size[0] * self.depth_scale(np.array([pos[1]]))[0])
        elif g.shape == "rect":
            shape = pymunk.Poly.create_box(body, tuple(size))
        else:
            shape = pymunk.Circle(body, 0.5 * min(size))
        shape.elasticity, shape.friction = self._elasticity, 0.0
        # a carried target rides on its carrier (pinned after each step) and touches nothing
        shape.filter = self._collision_filter(1 << g.layer, touching=carrier is None)
        self.space.add(body, shape)
        return body

    def _pick_goal(self, pos: np.ndarray) -> np.ndarray:
        """Where a goal-seeking target heads: a random exit door, else the far side of the world."""
        if self._exits:
            x, y, w, h = self._exits[self.rng.integers(len(self._exits))].rect
            return np.array([x + w / 2, y + h / 2])
        return np.array([self.extent[0] - pos[0], self.rng.uniform(0, self.extent[1])])

    def place(self, positions: np.ndarray, velocities: np.ndarray | None = None):
        """Teleport every target to `positions` (n, 2), optionally with new `velocities`; for tests and demos."""
        positions = np.asarray(positions, float).reshape(len(self.ids), 2)
        self.pos = positions.copy()
        if velocities is not None:
            self.vel = np.asarray(velocities, float).reshape(len(self.ids), 2).copy()
        body_vel = self.vel * self.depth_scale(self.pos[:, 1])[:, None]
        for body, p, v in zip(self.bodies, self.pos.tolist(), body_vel.tolist()):
            body.position, body.velocity = p, v

    # ------------------------------------------------------------ stepping

    def _sync_order(self):
        """Map the rows of pymunk's batch order to our slots (needed after every birth or death).

        The batch also visits the static body that holds the walls; `_rows` picks out the target bodies.
        """
        self._buf.clear()
        pbatch.get_space_bodies(self.space, _FIELDS, self._buf)
        space_ids = np.frombuffer(self._buf.int_buf(), np.int64)
        slot_ids = np.array([b.id for b in self.bodies], np.int64)
        order = np.argsort(slot_ids)
        where = np.searchsorted(slot_ids[order], space_ids).clip(0, max(len(order) - 1, 0))
        self._rows = np.flatnonzero(slot_ids[order][where] == space_ids) if len(order) else np.zeros(0, np.intp)
        self._row_slot = order[where[self._rows]]

    def _read_bodies(self) -> np.ndarray:
        """(rows, 4) position and velocity of every body in pymunk's batch order."""
        self._buf.clear()
        pbatch.get_space_bodies(self.space, _FIELDS, self._buf)
        return np.frombuffer(self._buf.float_buf(), np.float64).reshape(-1, 4).copy()

    def _slot_view(self, data: np.ndarray) -> np.ndarray:
        out = np.empty((len(self.ids), 4))
        out[self._row_slot] = data[self._rows]
        return out

    def step(self):
        """Advance one frame: motion models, physics, exits and births."""
        if len(self.ids):
            data = self._read_bodies()
            state = self._slot_view(data)
            self.pos, body_vel = state[:, :2], state[:, 2:]
            scale = self.depth_scale(self.pos[:, 1])[:, None]
            self.vel = body_vel / scale
            self._apply_motion()
            out = self._carry(self.vel * scale) if self._carrying else self.vel * scale
            vel = data[:, 2:].copy()  # rows that are not targets (the static body) keep their own velocity
            vel[self._rows] = out[self._row_slot]
            buf = pbatch.Buffer()
            buf.set_float_buf(vel.ravel())
            pbatch.set_space_bodies(self.space, pbatch.BodyFields.VELOCITY, buf)
        self.space.step(1.0)
        self.t += 1
        if len(self.ids):
            data = self._read_bodies()
            self.pos = self._slot_view(data)[:, :2]
            if self._carrying:
                self._pin_carried()
            if self._picks_up:
                self._pick_up_and_leave()
            if self._forward:
                self._flow_forward(data)
        self._remove(self._leaving())
        self._spawn_births()

    def _flow_forward(self, data: np.ndarray):
        """Move every target but the camera's companions with the ground as the camera goes forward
        (`mtt_sim.sim.forward`); `data` is this step's read of the bodies, whose rows that are not targets keep their
        place."""
        flowed = forward.flow(self.pos, self.extent, self.sc.world.far_scale, self._forward)
        self.pos = np.where(self.companion[:, None], self.pos, flowed)  # the camera's companions keep their place
        data[self._rows, :2] = self.pos[self._row_slot]
        buf = pbatch.Buffer()
        buf.set_float_buf(data[:, :2].ravel())
        pbatch.set_space_bodies(self.space, pbatch.BodyFields.POSITION, buf)

    def _carried(self) -> tuple[np.ndarray, np.ndarray]:
        """(slots of carried targets whose carrier is alive, their carriers' slots)."""
        carried = np.flatnonzero(self.carrier_id)
        slot = np.searchsorted(self.ids, self.carrier_id[carried]).clip(0, max(len(self.ids) - 1, 0))
        alive = self.ids[slot] == self.carrier_id[carried] if len(carried) else np.zeros(0, bool)
        return carried[alive], slot[alive]

    def _carry(self, out: np.ndarray) -> np.ndarray:
        """Carried targets move with their carrier's new velocity; one whose carrier died drifts on."""
        carried, slot = self._carried()
        out[carried] = out[slot]
        self.vel[carried] = self.vel[slot]
        return out

    def _pin_carried(self):
        """Put each carried target back at its offset from its carrier: walls and contacts change the carrier's
        velocity inside the physics step, which the carried body (touching nothing) would not follow."""
        carried, slot = self._carried()
        self.pos[carried] = self.pos[slot] + self.carry_offset[carried]
        for i in carried.tolist():
            self.bodies[i].position = tuple(self.pos[i])

    def _pick_up_and_leave(self):
        """The carry event: a free target whose box lies wholly inside the box of a moving target drawn over it starts
        to ride with it (touching nothing) for world.carry_frames frames, then is left where it is, going on as it did
        before, and is free again once nothing covers it. Targets of a `carried` group ride for good."""
        riding = self.carry_left > 0
        self.carry_left[riding] -= 1
        for i in np.flatnonzero(riding & (self.carry_left == 0)).tolist():  # left: it goes on as it did before
            self.carrier_id[i], self.vel[i], self.carry_left[i] = 0, self.own_vel[i], _LEFT
            self.bodies[i].velocity = tuple(self.own_vel[i])
            self._set_touching(i, True)
        boxes, depth = self.boxes(), self.depth()
        lo, hi = boxes[:, :2], boxes[:, :2] + boxes[:, 2:]
        moving = (np.hypot(*self.vel.T) > 0.1) & (self.carrier_id == 0)
        covers = ((lo[None] <= lo[:, None]) & (hi[None] >= hi[:, None])).all(axis=2) & (depth[None] > depth[:, None]) \
            & moving[None]
        np.fill_diagonal(covers, False)
        covered = covers.any(axis=1)
        self.carry_left[(self.carry_left == _LEFT) & ~covered] = _FREE  # uncovered since it was left: free again
        for i in np.flatnonzero(covered & (self.carry_left == _FREE)).tolist():
            j = int(np.flatnonzero(covers[i])[np.argmax(depth[covers[i]])])  # the topmost of its covers
            self.carrier_id[i], self.carry_offset[i] = self.ids[j], self.pos[i] - self.pos[j]
            self.carry_left[i], self.own_vel[i] = self.sc.world.carry_frames, self.vel[i]
            self._set_touching(i, False)

    def _set_touching(self, i: int, touching: bool):
        """Let target i collide as its group does, or touch nothing (while it rides)."""
        for shape in self.bodies[i].shapes:
            shape.filter = self._collision_filter(shape.filter.categories, touching)

    def _collision_filter(self, layer_bit: int, touching: bool) -> pymunk.ShapeFilter:
        """A target's filter: it meets the walls and (unless collision is "none") its own layer, or nothing."""
        mask = WALL_BIT | (0 if self.sc.world.collision == "none" else layer_bit) if touching else 0
        return pymunk.ShapeFilter(categories=layer_bit, mask=mask)

    def _apply_motion(self):
        """Update `vel` (ground velocity, px/frame) of every target by its group's motion model, or by the walking
        model where the scene has one (`walk.model`)."""
        if self._walk is not None:
            self.vel, self.stopped = self._walk.step(self.vel, self.pos, self.goal, self.desired, self.size[:, 1],
                                                     self.stopped, self.rng, self.companion)
            return
        g, p = self.group, self._param
        motion = self._motion[g]
        noise = self.rng.normal(size=(len(g), 2))
        vel = self.vel + p["accel"][g][:, None] * noise
        present = self._present_motions
        if "random_walk" in present:
            walk = (motion == MOTIONS.index("random_walk"))[:, None]
            vel = np.where(walk, p["speed"][g][:, None] * noise, vel)
        if "goal" in present:
            to_goal = self.goal - self.pos
            desired = to_goal / np.maximum(np.hypot(*to_goal.T), 1e-9)[:, None] * self.cruise[:, None]
            vel = np.where((motion == MOTIONS.index("goal"))[:, None], vel + 0.1 * (desired - vel), vel)
        if "manoeuvre" in present:
            vel = self._manoeuvre(vel, motion == MOTIONS.index("manoeuvre"))
        speed = np.hypot(*vel.T)
        vel *= np.minimum(1.0, p["max_speed"][g] / np.maximum(speed, 1e-12))[:, None]
        self.vel = vel

    def _manoeuvre(self, vel: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """Sudden turns by 60..180 degrees, stops and restarts for the manoeuvring targets in `mask`; between them a
        target's speed returns toward its cruising speed (10 % a frame), so a bounce off a wall does not slow it for
        good."""
        turn_p, stop_p = self._param["turn_prob"][self.group], self._param["stop_prob"][self.group]
        u = self.rng.random((3, len(vel)))
        angle = np.radians(self.rng.uniform(60, 180, len(vel))) * np.where(u[2] < 0.5, -1, 1)
        turn = mask & (u[0] < turn_p) & ~self.stopped
        c, s = np.cos(angle), np.sin(angle)
        turned = np.stack([c * vel[:, 0] - s * vel[:, 1], s * vel[:, 0] + c * vel[:, 1]], axis=1)
        vel = np.where(turn[:, None], turned, vel)
        speed = np.maximum(np.hypot(*vel.T), 1e-9)
        vel = np.where(mask[:, None], vel * (1 + 0.1 * (self.cruise / speed - 1))[:, None], vel)
        restart = mask & self.stopped & (u[1] < 5 * stop_p)
        stop = mask & ~self.stopped & (u[1] < stop_p)
        heading = self.rng.uniform(0, 2 * math.pi, len(vel))
        vel = np.where(restart[:, None], self.cruise[:, None] * np.stack([np.cos(heading), np.sin(heading)], 1), vel)
        self.stopped = (self.stopped & ~restart) | stop
        return np.where(self.stopped[:, None] & mask[:, None], 0.0, vel)

    def _leaving(self) -> np.ndarray:
        """Slots of targets that left the world (by more than their size) or entered an exit door."""
        margin = self.size.max(axis=1)[:, None]
        out = ((self.pos < -margin) | (self.pos > self.extent + margin)).any(axis=1)
        old = self.t - self.born >= _EXIT_MIN_AGE
        for d in self._exits:
            x, y, w, h = d.rect
            inside = (self.pos[:, 0] >= x) & (self.pos[:, 0] <= x + w) & (self.pos[:, 1] >= y) & (self.pos[:, 1] <= y + h)
            out |= inside & old
        return np.flatnonzero(out)

    def _remove(self, slots: np.ndarray):
        if not len(slots):
            return
        keep = np.ones(len(self.ids), bool)
        keep[slots] = False
        bodies = [self.bodies[s] for s in slots]
        joints = {c for b in bodies for c in b.constraints}
        self.space.remove(*joints, *(s for b in bodies for s in b.shapes), *bodies)
        self.bodies = [b for b, k in zip(self.bodies, keep) if k]
        for name in self._cols:
            setattr(self, name, getattr(self, name)[keep])
        self._sync_order()

    def _spawn_births(self):
        """Poisson births at the world borders (per group) and at entry doors."""
        cap, wcfg = self.sc.world.max_births, self.sc.world
        before = self.births
        events = []
        for gi, g in enumerate(self.sc.groups):
            events += [(gi, None)] * self.rng.poisson(g.birth_rate)
        for d in self.sc.doors:
            if d.role != "exit":
                gi = self.sc.group(d.group) if d.group else 0
                events += [(gi, d)] * self.rng.poisson(d.birth_rate)
        for gi, door in events:
            if len(self.ids) + len(self._pending) >= wcfg.max_alive or (cap >= 0 and self.births >= cap):
                break
            g = self.sc.groups[gi]
            if door is None:
                pos, heading = self._border_entry(g)
            else:
                x, y, w, h = door.rect
                pos = self.rng.uniform((x, y), (x + w, y + h))
                heading = self.rng.uniform(0, 2 * math.pi)
            # under a camera going forward a door is ground coming into view, with people as they are (some waiting)
            self._spawn(gi, pos, self._initial_velocity(g, heading), in_view=door is not None and bool(self._forward))
            self.births += 1
        if self.births != before:
            self._flush()
            self._sync_order()

    def _border_entry(self, g) -> tuple[np.ndarray, float]:
        """A point on a random border (just outside it, or just inside where there are walls) and an inward heading;
        the far border where the camera goes forward (the ground comes from there)."""
        w, h = self.extent
        side = 1 if self._forward else self.rng.choice(4, p=np.array([h, w, h, w]) / (2 * (w + h)))
        inset = 2.0 + 0.5 * max(g.size) if self.sc.world.walls else -0.5 * max(g.size)
        u = self.rng.random()
        pos, inward = [((inset, u * h), 0.0), ((u * w, inset), 90.0),
                       ((w - inset, u * h), 180.0), ((u * w, h - inset), 270.0)][side]
        return np.array(pos), math.radians(inward + self.rng.uniform(-45, 45))
