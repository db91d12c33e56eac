"""Practice shares: while the run is before `terrain.practice_end`, the envs are spread over
the grid's tile kinds by `terrain.practice` rather than evenly over its tiles.

Why: a blind policy fails on the climb out of a pit far more than on the walk down a hill
(run G1b, reports/learning.md: 40.6 % against 95.3 %), and more pits under the paper's
objective teach it to end a climb by falling (H1). With falls made expensive (the reward
curriculum's boost), more pits teach the climb (H2). The terrain itself never changes: only
which tile each env respawns on, so the physics costs the same and the run ends on the
grid's even spread, the paper's mixture.
"""

from __future__ import annotations

import numpy as np

from lca.arrays import device_of, like, namespace
from lca.sim.terrain import apportion


def spread(kinds: list[str], n: int, share: dict[str, float] | None = None) -> np.ndarray:
    """The tile index (into `kinds`) of each of `n` envs. Evenly (None): env i on tile
    i % len(kinds). By `share`: each kind's env count in proportion to its share (largest
    remainder, ties in `share`'s order), its envs dealt round-robin over its tiles, the
    kinds interleaved so that any contiguous slice of envs sees every kind."""
    if share is None:
        return np.arange(n) % len(kinds)
    names = [k for k, w in share.items() if w > 0]
    counts = apportion([share[k] for k in names], n)
    tiles = {k: [i for i, kind in enumerate(kinds) if kind == k] for k in names}
    if missing := sorted(k for k in names if not tiles[k]):
        raise ValueError(f"terrain.practice: no tile of {missing} in the grid {sorted(set(kinds))}")
    dealt = [
        (j / count, tiles[k][j % len(tiles[k])])
        for k, count in zip(names, counts, strict=True)
        for j in range(count)
    ]
    return np.array([tile for _, tile in sorted(dealt, key=lambda d: d[0])], dtype=np.int64)


class TerrainPractice:
    """Switches the envs' respawn tiles between the practice shares and the even spread; a
    switch takes effect at each env's next reset."""

    def __init__(self, sim, terrain_cfg, terrain_levels=None) -> None:
        self.sim, self.levels = sim, terrain_levels
        self.share = {k: float(v) for k, v in terrain_cfg.practice.items()}
        kinds = [t.kind for t in sim.scene.terrain.tiles]
        # a levelled grid keeps one kind per column: the practice deals columns
        self.kinds = kinds[: int(terrain_cfg.cols)] if terrain_levels is not None else kinds
        self.centres = sim.scene.terrain.tile_centres()
        self.on = False

    def set(self, on: bool) -> None:
        if bool(on) == self.on:
            return
        self.on = bool(on)
        n = int(self.sim.env_origin.shape[0])
        tile = spread(self.kinds, n, self.share if self.on else None)
        if self.levels is not None:
            self.levels.column[:] = like(tile, self.levels.column)
        else:
            self.sim.env_origin[:] = like(self.centres[tile], self.sim.env_origin)


def practice_for(sim, terrain_cfg, terrain_levels=None) -> TerrainPractice | None:
    """The env's practice, switched on for its first episodes (None when not configured);
    the trainer switches it off at `terrain.practice_end`."""
    if not terrain_cfg.practice:
        return None
    practice = TerrainPractice(sim, terrain_cfg, terrain_levels)
    practice.set(True)
    if terrain_levels is not None:  # its first spawns were placed by column already
        origin = sim.env_origin
        ids = namespace(origin).arange(origin.shape[0], device=device_of(origin))
        terrain_levels.place(ids)
    return practice
