"""`python -m lca.describe` and `describe_task` against the env they describe."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from lca.config import compose
from lca.task.rewards import REWARD_TERMS
from lca.task.spec import describe_task

GROUPS = ("policy", "height", "critic", "critic_height")


@pytest.fixture(scope="module")
def described() -> dict:
    result = subprocess.run(
        [sys.executable, "-m", "lca.describe", "scale=smoke"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@pytest.fixture(scope="module")
def smoke_env(make_env):
    return make_env("scale=smoke")


def test_cli_lists_every_reward_with_its_weight(described):
    rewards = described["rewards"]
    assert len(rewards) == 24
    assert set(rewards) == set(REWARD_TERMS)
    assert rewards["termination_penalty"] == -200.0
    assert rewards["phase_contact"] == 0.5


def test_cli_group_shapes_equal_the_env_observations(described, smoke_env):
    _, env = smoke_env
    obs = env.get_observations()
    assert set(described["observations"]) == set(GROUPS) == set(obs.keys())
    for group in GROUPS:
        assert described["observations"][group]["shape"] == list(obs[group].shape[1:]), group
    assert described["actions"]["dim"] == env.num_actions == 29
    assert described["policy_dt"] == pytest.approx(env.dt)


def test_cli_term_dims_add_up_to_the_group_shapes(described):
    obs = described["observations"]
    for group in ("policy", "critic"):
        assert sum(t["dim"] for t in obs[group]["terms"]) == obs[group]["shape"][0], group
    for group in ("height", "critic_height"):
        (term,) = obs[group]["terms"]
        assert term["dim"] == obs[group]["shape"][1] * obs[group]["shape"][2]
    policy = {t["name"]: t for t in obs["policy"]["terms"]}
    assert policy["joint_vel"]["noise"] == 1.5 and policy["joint_vel"]["scale"] == 0.05
    assert policy["joint_vel"]["history"] == 5
    assert policy["velocity_commands"]["scale"] == [2.0, 2.0, 0.25]
    critic = {t["name"]: t for t in obs["critic"]["terms"]}
    assert all(t["noise"] == 0.0 for t in critic.values())
    assert "base_lin_vel_world" in critic
    assert obs["height"]["terms"][0]["extent_m"] == pytest.approx([1.0, 1.0])


def test_cli_output_equals_describe_task(described):
    assert json.loads(json.dumps(describe_task(compose(["scale=smoke"])))) == described


@pytest.mark.parametrize(
    ("overrides", "noise", "perception"),
    [
        (["difficulty=hard"], 0.30, True),
        (["difficulty=medium", "task.perception=false"], 0.10, False),
        (["difficulty=hard", "task.observations.noise=false"], 0.0, True),
    ],
)
def test_describe_follows_difficulty_and_switches(overrides, noise, perception):
    d = describe_task(compose(["scale=smoke", *overrides]))
    (height,) = d["observations"]["height"]["terms"]
    assert height["noise"] == pytest.approx(noise)
    assert height["perception"] is perception
    if noise == 0.0:
        assert all(t["noise"] == 0.0 for t in d["observations"]["policy"]["terms"])
