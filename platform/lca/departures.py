"""What a run's config departs from the paper, derived rather than hand-listed: the config is
compared leaf by leaf with the paper profile of the same policy (the same actor, encoder and
curriculum at `scale=paper` with the paper's CNN) over the groups that decide how a policy is
trained. Every difference is a departure, named by its key, with both values."""

from __future__ import annotations

from typing import Any

from omegaconf import DictConfig, OmegaConf

PAPER_PROFILE = ["scale=paper", "encoder.pool=0"]
# the groups that decide what is trained and how; eval, logging, paths and seeds do not
TRAINING_GROUPS = ("sim", "robot", "terrain", "difficulty", "task", "algo", "actor", "encoder")
TRAINING_GROUPS += ("curriculum", "scale", "perception")
# bookkeeping inside those groups: how often to log or save, names, worker threads
BOOKKEEPING = {
    "scale.name",
    "scale.log_interval",
    "scale.checkpoint_interval",
    "sim.num_threads",
    "sim.backend",
    "sim.warp_device",
    "sim.nconmax",
    "sim.njmax",
}
WHOLE = {"terrain.mixture", "terrain.practice"}  # compared as one value


def departures(cfg: DictConfig) -> list[str]:
    """`key=value (paper: value)` for every training setting of `cfg` that is not the
    paper's, sorted by key."""
    from lca.config import compose

    axes = [f"{group}={cfg[group].name}" for group in ("actor", "encoder", "curriculum")]
    try:
        paper = compose([*axes, *PAPER_PROFILE])
    except Exception as error:  # a plugin's option the package cannot compose on its own
        return [f"not derived: the paper profile for {axes} does not compose ({error})"]
    ours, theirs = _leaves(cfg), _leaves(paper)
    out = []
    for key in sorted(set(ours) | set(theirs)):
        if key.split(".")[0] not in TRAINING_GROUPS or key in BOOKKEEPING:
            continue
        mine, its = ours.get(key, "(unset)"), theirs.get(key, "(unset)")
        if mine != its:
            out.append(f"{key}={_text(mine)} (paper: {_text(its)})")
    return out


def _leaves(cfg: DictConfig) -> dict[str, Any]:
    data = OmegaConf.to_container(cfg, resolve=True)
    out: dict[str, Any] = {}

    def walk(prefix: str, value: Any) -> None:
        if isinstance(value, dict) and prefix not in WHOLE:
            for k, v in value.items():
                walk(f"{prefix}.{k}" if prefix else str(k), v)
        else:
            out[prefix] = value

    walk("", data)
    return out


def _text(value: Any) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_text(v)}" for k, v in value.items()) + "}"
    if isinstance(value, float):
        return f"{value:g}"
    if value == "":
        return "none"  # e.g. algo.init_from: from scratch
    return str(value)
