"""The locomotion task as an rsl-rl-lib 5.x `VecEnv` over the batched MuJoCo simulation.

Observation groups (TensorDict, batch [N]):
  policy         K-frame noisy proprioception history, command, last action, gait phase
  height         (N, 1, 11, 11) noisy, sparse actor map; exactly zero when perception is off
  critic         the same proprioception without noise, plus world-frame base velocity
  critic_height  (N, 1, 16, 16) noiseless privileged map
"""

from __future__ import annotations

import mujoco
import numpy as np
import torch
from omegaconf import DictConfig, OmegaConf
from rsl_rl.env import VecEnv
from tensordict import TensorDict

from lca.arrays import Array, as_float, draw, generator, like, namespace, zeros
from lca.config.runtime import resolve_device
from lca.sim.backend import make_sim
from lca.sim.scene import Scene, build_scene
from lca.task import heightmap, observations
from lca.task.actions import action_scales, joint_ids
from lca.task.commands import VelocityCommand, gait_phase
from lca.task.deployment_map import DeploymentMap
from lca.task.reward_manager import RewardManager
from lca.task.rewards import RewardContext
from lca.task.state import (
    ContactAccumulator,
    RobotState,
    read_state,
    replace_rows,
    yaw_of,
    zero_rows,
)
from lca.task.step_metrics import step_metrics
from lca.task.terminations import fell, non_finite
from lca.task.terrain_levels import TerrainLevels
from lca.task.terrain_practice import practice_for

_W = mujoco.mjtWarning
BAD_STATE_WARNINGS = [int(w) for w in (_W.mjWARN_BADQPOS, _W.mjWARN_BADQVEL, _W.mjWARN_BADQACC)]


class EnvConfig:
    """The composed config, readable like a DictConfig, with the `to_dict()` rsl-rl wants."""

    def __init__(self, cfg: DictConfig):
        self._cfg = cfg

    def __getattr__(self, name: str):
        return getattr(self._cfg, name)

    def to_dict(self) -> dict:
        return OmegaConf.to_container(self._cfg, resolve=True)


class LocomotionEnv(VecEnv):
    def __init__(self, cfg: DictConfig, scene: Scene | None = None):
        self.cfg = EnvConfig(cfg)  # rsl-rl's loggers call cfg.to_dict()
        # a plain dataclass: OmegaConf attribute reads cost ~10 us each on the hot path
        task = OmegaConf.to_object(cfg.task)
        self.task_cfg = task
        self.device = torch.device(resolve_device(cfg.device))
        self.num_envs = int(task.num_envs)
        self.scene = scene if scene is not None else build_scene(cfg)
        self.sim = make_sim(self.scene, self.num_envs, cfg.sim, seed=cfg.seed, tensors=True)
        # the task's arrays live where the physics does: NumPy float64 on the host (mjbatch,
        # and warp's CPU device), torch tensors on the physics device where the sim hands
        # them; `ref` gives their type, dtype and device
        live = self.sim.qpos
        self._ref = ref = np.zeros(0) if isinstance(live, np.ndarray) else live
        self.xp = namespace(ref)
        self.rng = generator(cfg.seed + 1, ref)
        self.decimation = int(cfg.sim.decimation)
        self.dt = cfg.sim.timestep * self.decimation
        self.max_episode_length = int(round(task.episode_length_s / self.dt))
        names = self.scene.joint_names
        self.num_actions = len(names)
        self.default_joint_pos = like(self.scene.home_joint_pos.copy(), ref)
        self.action_scale = like(action_scales(self.scene.model, task), ref)
        self.hip_ids = self._ids(joint_ids(names, "hip_roll", "hip_yaw"))
        self.arm_ids = self._ids(joint_ids(names, "shoulder", "elbow", "wrist"))
        self.torso_ids = self._ids(joint_ids(names, "waist"))
        lower, upper = self.scene.model.jnt_range[1 : 1 + self.num_actions].T
        mid, half = (lower + upper) / 2, (upper - lower) / 2 * task.reward_params.soft_limit_factor
        self.joint_lower, self.joint_upper = like(mid - half, ref), like(mid + half, ref)
        self._bad_warning_ids = self._ids(BAD_STATE_WARNINGS)
        self.reward_manager = RewardManager(task, self.num_envs, ref)
        self.perception = bool(task.perception)
        # evaluation turns it off: only the actor's observations (no critic map, no history)
        self.observe_critic = True
        # the worlds the physics steps (None: all): a test freezes the units it no longer
        # counts, so they cost no physics (`lca.evaluate.rollout.step_only`)
        self.stepping: np.ndarray | None = None
        self.height_noise = float(cfg.difficulty.height_noise) if task.observations.noise else 0.0

        obs = task.observations
        self.history_terms = observations.history_terms(obs, self.num_actions)
        self.current_terms = observations.current_terms(obs, self.num_actions)
        frame_dim = sum(t.dim for t in self.history_terms)
        self.history = observations.History(self.num_envs, obs.history, frame_dim, ref)
        self.critic_history = observations.History(self.num_envs, obs.history, frame_dim, ref)
        self.actor_grid = tuple(obs.actor_grid)
        self.critic_grid = tuple(obs.critic_grid)
        self.actor_offsets = heightmap.grid_offsets(self.actor_grid, obs.actor_spacing)
        self.critic_offsets = heightmap.grid_offsets(self.critic_grid, obs.critic_spacing)
        # both grids' points, queried in one call each step (the actor's first)
        self.map_offsets = np.concatenate([self.actor_offsets, self.critic_offsets])

        self.commands = VelocityCommand(task.commands, self.num_envs, self.dt, self.rng, ref)
        self.perception_cfg = OmegaConf.to_object(cfg.perception)
        self.camera_map = None
        if self.perception_cfg.source == "deployment":
            self.camera_map = DeploymentMap(self.sim, self.perception_cfg, obs, self.rng)
        self.contacts = ContactAccumulator(self.sim)
        self.warnings = self.sim.warnings
        self.episode_length_buf = torch.zeros(self.num_envs, dtype=torch.long, device=self.device)
        self._episode_steps = self._zeros(self.num_envs, dtype=self.xp.int64)
        self.action = self._zeros((self.num_envs, self.num_actions))
        self.last_action = self._zeros((self.num_envs, self.num_actions))
        self.nonfinite_resets = 0  # envs reset from a non-finite state (actions included)
        self.nonfinite_actions = 0  # env steps whose action held a NaN or inf
        self._push_steps = (
            int(round(task.randomization.push_interval_s / self.dt))
            if task.randomization.enabled
            else 0
        )
        if task.randomization.enabled:
            mass = draw(self.rng, *task.randomization.added_base_mass, self.num_envs, ref)
            self.sim.set_added_base_mass(self._all_ids(), mass)
        self.terrain_levels = None
        if cfg.terrain.levels:
            self.terrain_levels = TerrainLevels(
                self.sim, cfg.terrain, task.episode_length_s, self.rng
            )
        self.terrain_practice = practice_for(self.sim, cfg.terrain, self.terrain_levels)
        self._reset_envs(self._all_ids())
        self._obs = self._observe(read_state(self.sim, self.contacts))

    # ---- rsl-rl VecEnv -------------------------------------------------------------------
    def get_observations(self) -> TensorDict:
        return self._obs

    def step(self, actions: torch.Tensor) -> tuple[TensorDict, torch.Tensor, torch.Tensor, dict]:
        xp, clip = self.xp, self.task_cfg.action_clip
        self.last_action = self.action
        raw = self._from_policy(actions)
        finite = xp.isfinite(raw)
        bad_action = ~xp.all(finite, axis=1)  # NaN / inf from the policy: counted, zeroed
        self.action = xp.clip(xp.where(finite, raw, like(0.0, raw)), min=-clip, max=clip)
        self.sim.ctrl[:] = self.default_joint_pos + self.action_scale * self.action
        bad_before = ~self._finite_rows(self.sim.qpos) | ~self._finite_rows(self.sim.qvel)
        warnings_before = self._bad_state_warnings()
        self.contacts.clear()
        for _ in range(self.decimation):
            self.sim.step(ids=self.stepping)
            self.contacts.update()
        self._episode_steps += 1
        if self.terrain_levels is not None:
            self.terrain_levels.track(self.sim.qpos[:, :2], self.commands.value[:, :2], self.dt)
        self._maybe_push()
        self.commands.update()

        state = read_state(self.sim, self.contacts)
        broken = bad_before | bad_action | (self._bad_state_warnings() > warnings_before)
        broken |= non_finite(state, self.task_cfg.terminations.max_joint_vel)
        state = zero_rows(state, broken)
        fallen = fell(state, self.task_cfg.terminations) & ~broken
        terminated = fallen | broken
        time_out = (self._episode_steps >= self.max_episode_length) & ~terminated

        reward = self.reward_manager.compute(self._reward_context(state, terminated), self.dt)

        done = terminated | time_out
        strike = self.task_cfg.reward_params.strike_threshold
        extras = {
            "time_outs": torch.as_tensor(time_out, device=self.device),
            "log": {},
            "metrics": step_metrics(state, self.commands.value, terminated, time_out, strike),
        }
        done_ids = xp.nonzero(done)[0]
        if done_ids.shape[0]:
            extras["log"] = self._episode_log(done_ids, fallen, time_out)
        # counts and logged means stay in the sim's array type: no host sync per step on a GPU
        self.nonfinite_resets = self.nonfinite_resets + xp.sum(xp.astype(broken, xp.int64))
        self.nonfinite_actions = self.nonfinite_actions + xp.sum(xp.astype(bad_action, xp.int64))
        log = extras["log"]
        log["Episode_Termination/nonfinite_total"] = as_float(self.nonfinite_resets, self._ref)
        log["Episode_Termination/nonfinite_actions_total"] = as_float(
            self.nonfinite_actions, self._ref
        )
        log["Sim/buffer_overflows_total"] = as_float(xp.sum(self.sim.overflows), self._ref)
        extras["metrics"]["fell"] = fallen
        extras["metrics"]["nonfinite"] = broken
        extras["metrics"]["nonfinite_action"] = bad_action
        log |= self.reward_manager.curriculum_log()
        log["Curriculum/command_floor"] = self.commands.min_speed
        self._reset_envs(done_ids)
        if done_ids.shape[0]:
            state = replace_rows(state, read_state(self.sim, self.contacts, done_ids), done_ids)
        self._obs = self._observe(state, reset_ids=done_ids)
        self.episode_length_buf = torch.as_tensor(self._episode_steps, device=self.device)
        return (
            self._obs,
            torch.as_tensor(reward, dtype=torch.float32, device=self.device),
            torch.as_tensor(done, dtype=torch.long, device=self.device),
            extras,
        )

    # ---- internals -----------------------------------------------------------------------
    def _zeros(self, shape, dtype=None) -> Array:
        return zeros(shape, self._ref, dtype)

    def _ids(self, ids) -> Array:
        return self.xp.asarray(np.asarray(ids, dtype=np.int64), device=self._ref.device)

    def _all_ids(self) -> Array:
        return self.xp.arange(self.num_envs, device=self._ref.device)

    def _from_policy(self, actions: torch.Tensor) -> Array:
        """The policy's actions in the physics' array type and float dtype."""
        if isinstance(self._ref, np.ndarray):
            return actions.detach().cpu().numpy().astype(np.float64)
        return actions.detach().to(device=self._ref.device, dtype=self._ref.dtype)

    def _finite_rows(self, values: Array) -> Array:
        return self.xp.all(self.xp.isfinite(values), axis=1)

    def _bad_state_warnings(self) -> Array:
        # warning[:, w] = [lastinfo, number]
        return self.xp.sum(self.warnings[:, self._bad_warning_ids, 1], axis=1)

    def _reset_envs(self, ids: Array) -> None:
        n = int(ids.shape[0])
        if n == 0:
            return
        if self.terrain_levels is not None:  # episodes that ran: their rows move first
            ended = ids[self._episode_steps[ids] > 0]
            self.terrain_levels.update(ended, self.sim.qpos[:, :2], self.commands.value[:, :2])
        self.sim.reset(ids, self.task_cfg.reset)
        rand = self.task_cfg.randomization
        if rand.enabled:
            self.sim.set_friction_scale(ids, draw(self.rng, *rand.friction, n, self._ref))
        self.commands.resample(ids)
        self._episode_steps[ids] = 0
        if self.camera_map is not None:
            self.camera_map.restart(ids)
        self.action[ids] = 0.0
        self.last_action[ids] = 0.0
        self.reward_manager.reset(ids)

    def _maybe_push(self) -> None:
        if self._push_steps <= 0:
            return
        due = self.xp.nonzero((self._episode_steps % self._push_steps) == 0)[0]
        if due.shape[0]:
            v = self.task_cfg.randomization.push_velocity
            qvel = self.sim.qvel[due]
            qvel[:, :2] += draw(self.rng, -v, v, (int(due.shape[0]), 2), self._ref)
            self.sim.qvel[due] = qvel

    def _phase(self) -> Array:
        period = self.task_cfg.reward_params.gait_period
        return gait_phase(as_float(self._episode_steps, self._ref) * self.dt, period)

    def _reward_context(self, state: RobotState, terminated: Array) -> RewardContext:
        return RewardContext(
            state=state,
            command=self.commands.value,
            standing=self.commands.standing,
            phase=self._phase(),
            action=self.action,
            last_action=self.last_action,
            default_joint_pos=self.default_joint_pos,
            joint_lower=self.joint_lower,
            joint_upper=self.joint_upper,
            hip_ids=self.hip_ids,
            arm_ids=self.arm_ids,
            torso_ids=self.torso_ids,
            terminated=terminated,
            params=self.reward_manager.params,
            sim=self.sim,
        )

    def _episode_log(self, ids: Array, fallen: Array, time_out: Array) -> dict:
        mean = self.xp.mean
        log = self.reward_manager.episode_log(ids)
        log["Episode_Termination/fall"] = mean(as_float(fallen[ids], self._ref))
        log["Episode_Termination/time_out"] = mean(as_float(time_out[ids], self._ref))
        return log

    def _observe(self, state: RobotState, reset_ids: Array | None = None) -> TensorDict:
        n, xp = self.num_envs, self.xp
        inputs = observations.ObsInputs(
            state,
            self.default_joint_pos,
            self.commands.value,
            self.action,
            self._phase(),
            self.commands.standing,
        )
        noisy = self.task_cfg.observations.noise
        clean = observations.build(inputs, self.history_terms, None)
        frame = observations.build(inputs, self.history_terms, self.rng) if noisy else clean
        fresh = self._all_ids() if reset_ids is None else reset_ids
        self.history.push(frame)
        self.history.fill(fresh, frame)
        if self.observe_critic:
            self.critic_history.push(clean)
            self.critic_history.fill(fresh, clean)
        current = observations.build(inputs, self.current_terms, None)
        if noisy and any(t.noise > 0 for t in self.current_terms):
            actor_current = observations.build(inputs, self.current_terms, self.rng)
        else:
            actor_current = current
        self._state = state
        yaw = yaw_of(state.base_quat)
        # the actor's points only when its map is read from the terrain (not blind, no cameras)
        split = self.actor_offsets.shape[0] if self.perception and self.camera_map is None else 0
        if self.observe_critic:
            offsets = self.map_offsets if split else self.critic_offsets
            raw = heightmap.sample_heights(self.scene.terrain, state.base_pos[:, :2], yaw, offsets)
        else:
            raw = None
        actor_map = self._actor_map(
            state, yaw, raw[:, :split] if split and raw is not None else None
        )
        groups = {
            "policy": xp.concat([self.history.flat(), actor_current], axis=1),
            "height": actor_map.reshape(n, 1, *self.actor_grid),
        }
        if self.observe_critic:
            groups["critic"] = xp.concat(
                [self.critic_history.flat(), current, state.base_lin_vel_world], axis=1
            )
            critic_map = heightmap.normalise(raw[:, split:])
            groups["critic_height"] = critic_map.reshape(n, 1, *self.critic_grid)
        return TensorDict(
            {
                k: torch.as_tensor(v, dtype=torch.float32, device=self.device)
                for k, v in groups.items()
            },
            batch_size=[n],
            device=self.device,
        )

    @property
    def state(self) -> RobotState:
        """The state the latest observation was made from (reset envs: their new state)."""
        return self._state

    def reseed(self, seed: int) -> None:
        """Restart every random stream (resets, noise, commands) from `seed`."""
        self.rng = generator(seed, self._ref)
        self.commands.rng = self.rng
        if self.camera_map is not None:
            self.camera_map.rng = self.rng
        self.sim.rng = generator(seed + 1, self._ref)

    def reset_all(self) -> TensorDict:
        """Reset every environment (each steps again) and return fresh observations."""
        self.stepping = None
        self._reset_envs(self._all_ids())
        self.contacts.clear()
        self.history.buffer[:] = 0.0
        self.critic_history.buffer[:] = 0.0
        self._obs = self._observe(read_state(self.sim, self.contacts))
        return self._obs

    def set_perception(self, on: bool) -> None:
        """Curriculum switch: when off the actor's map is exactly zero; the critic keeps its map.
        The current observation's `height` group is recomputed, so the next action sees it."""
        if bool(on) == self.perception:
            return
        self.perception = bool(on)
        self._obs["height"] = torch.as_tensor(
            self._actor_map(self._state, yaw_of(self._state.base_quat)).reshape(
                self.num_envs, 1, *self.actor_grid
            ),
            dtype=torch.float32,
            device=self.device,
        )

    def _actor_map(self, state: RobotState, yaw: Array, raw: Array | None = None) -> Array:
        """The actor's map; `raw`: the terrain heights under its grid, if already sampled."""
        if not self.perception:
            return self._zeros((self.num_envs, self.actor_offsets.shape[0]))
        if self.camera_map is not None:
            episode_s = self._episode_steps * self.dt
            return self.camera_map.read(episode_s, state.base_pos[:, :2], yaw)
        if raw is None:
            raw = heightmap.sample_heights(
                self.scene.terrain, state.base_pos[:, :2], yaw, self.actor_offsets
            )
        drop = self.task_cfg.observations.height_dropout
        return heightmap.actor_map(raw, self.height_noise, drop, self.rng)
