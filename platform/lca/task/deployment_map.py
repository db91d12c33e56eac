"""The actor's map as deployment makes it (`perception.source=deployment`): the robot's depth
cameras fire at `rate_hz`, each frame goes through the paper's filter (`lca.task.perception`),
and between frames the policy reads the last map. A reset env gets a fresh frame at once."""

from __future__ import annotations

import numpy as np

from lca.sim.depth_camera import CameraSpec, DepthCameras
from lca.task import perception


class DeploymentMap:
    def __init__(self, sim, perception_cfg, observations_cfg, rng: np.random.Generator):
        self.cfg = perception_cfg
        self.grid = tuple(observations_cfg.actor_grid)
        self.spacing = float(observations_cfg.actor_spacing)
        specs = [CameraSpec(**vars(c)) for c in perception_cfg.cameras]
        self.cameras = DepthCameras(sim, specs, rng)
        n = sim.num_envs
        self.frame = np.full(n, -1)  # the camera frame each env's map was made from
        self.map = np.zeros((n, self.grid[0] * self.grid[1]))

    @property
    def rng(self) -> np.random.Generator:
        return self.cameras.rng

    @rng.setter
    def rng(self, rng: np.random.Generator) -> None:
        self.cameras.rng = rng

    def restart(self, ids) -> None:
        """`ids` start an episode: their next read takes a frame."""
        self.frame[ids] = -1

    def read(self, episode_s: np.ndarray, base_xy: np.ndarray, yaw: np.ndarray) -> np.ndarray:
        """Each env's latest map, `episode_s` seconds into its episode."""
        # the epsilon keeps t = k / rate on frame k despite float rounding (205 * 0.02 * 30)
        frame = np.floor(episode_s * self.cfg.rate_hz + 1e-9)
        due = frame != self.frame
        if due.any():
            points, valid = self.cameras.capture()
            fresh = perception.deployment_map(
                points,
                valid,
                base_xy,
                yaw,
                self.grid,
                self.spacing,
                self.cfg.outlier_gamma,
                self.cfg.quantum,
            )
            self.map[due] = fresh[due]
            self.frame = np.where(due, frame, self.frame)
        return self.map.copy()
