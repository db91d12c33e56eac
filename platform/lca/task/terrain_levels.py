"""The terrain-level curriculum (IsaacLab's `terrain_levels_vel`) over a levelled grid.

The grid's rows are difficulty levels, easiest first (`terrain.levels`, `lca.sim.terrain`).
Each env keeps its column; when its episode ends it moves up a row if it walked more than
half a tile, down a row if it covered less than half the distance its commands asked for over
a whole episode, and an env that walks off the top row restarts on a random one, so the
hardest rows never empty.

IsaacLab measures both distances as straight lines (the spawn to the end, the last command
times the episode). Our commands turn (yaw rates up to 0.5 rad/s) and change every 10 s, so a
perfect walker's straight-line distance is mostly under half a tile and under half its last
command's: run T1 (reports/learning.md) sat at level 0.1 of 2 for 2,000 iterations. So here
"walked" is the path, sampled once a second (a gait cycle's sway averages out), and "asked"
is the mean commanded speed over the episode times its length.
"""

from __future__ import annotations

from lca.arrays import Array, device_of, draw, like, namespace


class TerrainLevels:
    """Per-env rows of a levelled grid, moved at each reset; sets the sim's spawn origins."""

    def __init__(self, sim, terrain_cfg, episode_s: float, rng) -> None:
        self.sim = sim
        self.rows, self.cols = int(terrain_cfg.rows), int(terrain_cfg.cols)
        self.tile_size = float(terrain_cfg.tile_size)
        self.episode_s = float(episode_s)
        self.rng = rng
        origin = sim.env_origin
        self.xp = xp = namespace(origin)
        self.centres = like(sim.scene.terrain.tile_centres(), origin)
        n, device = int(origin.shape[0]), device_of(origin)
        self.column = xp.arange(n, device=device) % self.cols
        self.level = self._uniform_rows(terrain_cfg.max_init_level + 1, n)
        self.over = False  # the curriculum has ended: every reset goes to the top row
        self.path, self.asked, self.lived = (
            xp.zeros(n, dtype=origin.dtype, device=device) for _ in range(3)
        )
        self.mark = xp.asarray(origin[:, :2], copy=True)  # where the path was last sampled
        self.place(xp.arange(n, device=device))

    def track(self, base_xy: Array, command_xy: Array, dt: float, sample_s: float = 1.0) -> None:
        """One env step of every env: the commanded distance grows by |command| dt, and the
        path by the distance since the last sample for envs a sample interval on."""
        xp = self.xp
        self.asked += xp.linalg.vector_norm(command_xy, axis=1) * dt
        self.lived += dt
        crossed = xp.floor(self.lived / sample_s) > xp.floor((self.lived - dt) / sample_s)
        due = xp.nonzero(crossed)[0]
        if due.shape[0]:
            self.path[due] += xp.linalg.vector_norm(base_xy[due] - self.mark[due], axis=1)
            self.mark[due] = base_xy[due]

    def update(self, ids: Array, base_xy: Array, command_xy: Array) -> None:
        """Move the envs `ids`, whose episodes just ended at `base_xy` under `command_xy`
        (both (N, 2), every env), and put their next spawns on their new rows."""
        xp = self.xp
        walked = self.path[ids] + xp.linalg.vector_norm(base_xy[ids] - self.mark[ids], axis=1)
        lived = self.lived[ids]
        speed = xp.where(
            lived > 0,
            self.asked[ids] / xp.clip(lived, min=1e-9),
            xp.linalg.vector_norm(command_xy[ids], axis=1),  # untracked: the last command
        )
        asked = speed * self.episode_s
        up = walked > self.tile_size / 2
        down = (walked < asked / 2) & ~up
        level = self.level[ids] + xp.astype(up, xp.int64) - xp.astype(down, xp.int64)
        restart = self._uniform_rows(self.rows, int(ids.shape[0]))
        self.level[ids] = xp.where(level >= self.rows, restart, xp.clip(level, min=0))
        if self.over:
            self.level[ids] = self.rows - 1
        self.place(ids)

    def mean(self) -> float:
        """The mean level as a fraction of the top row (0: all on row 0, 1: all on the top)."""
        return float(self.xp.mean(self.xp.astype(self.level, self.centres.dtype))) / max(
            self.rows - 1, 1
        )

    def _uniform_rows(self, rows: int, n: int) -> Array:
        """`n` row indices uniform in 0..rows - 1."""
        u = draw(self.rng, 0.0, float(rows), n, self.centres)
        return self.xp.clip(self.xp.astype(self.xp.floor(u), self.xp.int64), max=rows - 1)

    def place(self, ids: Array) -> None:
        tile = self.level[ids] * self.cols + self.column[ids]
        self.sim.env_origin[ids] = self.centres[tile]
        self.mark[ids] = self.centres[tile][:, :2]
        self.path[ids], self.asked[ids], self.lived[ids] = 0.0, 0.0, 0.0
