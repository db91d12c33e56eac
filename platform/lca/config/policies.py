"""The report's policy rows, declared in `conf/policy/*.yaml` (label, row, match).

A run composed with `policy=<name>` carries that file's `policy` block. Any other run gets it
here, at composition, from the one policy file whose `match` equals the run's curriculum,
actor kind and encoder kind, looked up in the project's `conf/` and in every
`hydra.searchpath` folder (where a plugin keeps its own). A run that matches none keeps an
empty label, and the report refuses it by name rather than pooling it into another row.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import cache
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from lca.config.errors import ConfigValueError
from lca.config.schema import MATCH_KEYS, PolicyConfig
from lca.paths import conf_dir


def search_dirs(searchpath: Iterable[str] = ()) -> list[Path]:
    """The project's conf folder, then the `file://` folders of a Hydra searchpath."""
    extra = [Path(p.removeprefix("file://")) for p in searchpath if str(p).startswith("file://")]
    return [conf_dir(), *extra]


def known_policies(searchpath: Iterable[str] = ()) -> dict[str, PolicyConfig]:
    """{option name: its policy block} over every `policy/*.yaml` in the search folders."""
    return dict(_read_policies(tuple(search_dirs(searchpath))))


@cache  # every composition asks; the files are read once per set of folders
def _read_policies(folders: tuple[Path, ...]) -> dict[str, PolicyConfig]:
    found = {}
    for folder in folders:
        for path in sorted((folder / "policy").glob("*.yaml")):
            block = OmegaConf.load(path).get("policy")
            if block is None:
                raise ConfigValueError(f"policy: {path} has no `policy:` block (label, row, match)")
            policy = OmegaConf.to_object(OmegaConf.merge(OmegaConf.structured(PolicyConfig), block))
            policy.check()
            found[path.stem] = policy
    return found


def run_choices(cfg: DictConfig) -> dict[str, str]:
    """The values a policy's `match` is compared with: {curriculum, actor, encoder}."""
    return {key: str(OmegaConf.select(cfg, dotted)) for key, dotted in MATCH_KEYS.items()}


def matching_policy(cfg: DictConfig, searchpath: Iterable[str] = ()) -> PolicyConfig | None:
    """The policy whose match is the most specific one that fits the run; two equally
    specific matches are a config error naming both files."""
    choices = run_choices(cfg)
    found = [
        (len(p.match), name, p)
        for name, p in known_policies(searchpath).items()
        if fits(p, choices)
    ]
    if not found:
        return None
    found.sort(key=lambda f: -f[0])
    if len(found) > 1 and found[0][0] == found[1][0] and found[0][2].label != found[1][2].label:
        raise ConfigValueError(
            f"policy: {choices} matches both conf/policy/{found[0][1]}.yaml and "
            f"{found[1][1]}.yaml equally; make one `match` more specific"
        )
    return found[0][2]


def fits(policy: DictConfig | PolicyConfig, choices: dict[str, str]) -> bool:
    """Whether the policy's `match` holds for a run's `run_choices`."""
    return all(choices[k] == v for k, v in policy.match.items())


def label_policy(cfg: DictConfig, searchpath: Iterable[str] = ()) -> None:
    """Set `cfg.policy` to the matching policy file's block. A block already there (from a
    `policy=` option or set by hand) stays if it still fits the run: `policy=two_mlp
    actor=lstm` is labelled as the LSTM it is. No match leaves the label empty."""
    if cfg.policy.label and fits(cfg.policy, run_choices(cfg)):
        return
    policy = matching_policy(cfg, searchpath) or PolicyConfig()
    cfg.policy = OmegaConf.structured(policy)


def unlabelled_error(where: str, cfg: DictConfig, searchpath: Iterable[str] = ()) -> str:
    known = {name: p.label for name, p in known_policies(searchpath).items()}
    return (
        f"{where}: policy: no conf/policy/*.yaml matches {run_choices(cfg)}; known: {known}. "
        "Add one with `policy: {label, row, match}` (a plugin keeps it in its own conf folder "
        "on hydra.searchpath)"
    )
