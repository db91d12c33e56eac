"""The batched simulator of `sim.backend`: mjbatch (MuJoCo C on CPU threads) or MuJoCo-Warp."""

from __future__ import annotations

from lca.sim.batch import BatchedSim
from lca.sim.config import SimConfig
from lca.sim.scene import Scene


def make_sim(scene: Scene, num_envs: int, sim: SimConfig, seed: int = 0, tensors: bool = False):
    """A `BatchedSim` or, with `sim.backend=warp`, a `WarpSim` (imported only then: warp is an
    optional extra). `tensors`: warp's live arrays as torch tensors on its device (what the
    task runs on), else NumPy (host mirrors on a GPU); mjbatch's are NumPy either way."""
    if sim.backend == "warp":
        from lca.sim.warp_batch import WarpSim

        return WarpSim(scene, num_envs, sim.warp_device, seed, sim.nconmax, sim.njmax, tensors)
    return BatchedSim(scene, num_envs, sim.num_threads, seed=seed)
