"""Report rows come from conf/policy/*.yaml: every run is labelled by the policy file whose
`match` fits it, whatever options composed it."""

from __future__ import annotations

import pytest
from omegaconf import OmegaConf

from lca.config import ConfigError, compose
from lca.config.policies import known_policies
from lca.paths import conf_dir
from lca.report.collect import POOLED, load_run, policy_label, row_key


@pytest.mark.parametrize(
    ("overrides", "label", "row"),
    [
        ([], "Two-Stage CNN", 6),
        (["curriculum=blind"], "Blind", 0),
        (["curriculum=blind", "encoder=cnn"], "Blind", 0),  # blind ignores the encoder
        (["policy=one_mlp"], "One-Stage MLP", 1),
        (
            ["policy=two_mlp", "actor=lstm"],
            "Two-Stage LSTM",
            4,
        ),  # the option's block no longer fits
        (["actor=lstm", "encoder=cnn", "curriculum=one"], "One-Stage LSTM-CNN", 7),
        (["policy.label=Mine", "policy.row=3"], "Mine", 3),  # a hand-set block with no match
    ],
)
def test_composition_labels_every_run(overrides: list[str], label: str, row: int) -> None:
    policy = compose(overrides).policy
    assert (policy.label, policy.row) == (label, row)


def test_every_project_policy_file_is_well_formed_and_distinct() -> None:
    policies = known_policies()
    assert set(policies) == {p.stem for p in (conf_dir() / "policy").glob("*.yaml")}
    labels = [p.label for p in policies.values()]
    assert len(set(labels)) == len(labels)
    # each option selects the groups its own block matches
    for name, policy in policies.items():
        chosen = {}
        for entry in OmegaConf.load(conf_dir() / "policy" / f"{name}.yaml").defaults:
            ((key, value),) = OmegaConf.to_container(entry).items()
            chosen[key.removeprefix("override /")] = value
        assert {k: chosen[k] for k in policy.match} == dict(policy.match), name
    assert compose(["policy=two_lstm_cnn"]).policy.label == "Two-Stage LSTM-CNN"


def test_a_bad_match_key_fails_at_composition() -> None:
    with pytest.raises(ConfigError, match=r"^policy.match: unknown keys \['seed'\]"):
        compose(["+policy.match.seed=0"])


def test_the_report_refuses_a_run_no_policy_names(tmp_path) -> None:
    cfg = compose(["policy.label=x"])
    cfg.actor.kind = "gru"  # as a run of an unregistered plugin would read back
    cfg.policy.label = ""
    with pytest.raises(
        ValueError, match=r"some/run: policy: no conf/policy/\*\.yaml matches .*'gru'"
    ):
        policy_label(OmegaConf.create(OmegaConf.to_container(cfg)), "some/run")


def test_rows_order_and_pooled_cnn(tmp_path) -> None:
    cfg = compose(["policy=two_cnn", "encoder.pool=2"])
    assert policy_label(cfg) == ("Two-Stage CNN" + POOLED, 6)
    order = sorted(["Two-Stage CNN", "Blind", "Two-Stage MLP", "Zed"], key=row_key)
    assert order == ["Blind", "Two-Stage MLP", "Two-Stage CNN", "Zed"]  # unknown labels last
    # an old config.yaml without a policy block is matched against conf/policy now
    old = OmegaConf.to_container(compose(["policy=one_lstm"]))
    del old["policy"]
    (tmp_path / "config.yaml").write_text(OmegaConf.to_yaml(old))
    (tmp_path / "provenance.json").write_text("{}")
    assert load_run(tmp_path).label == "One-Stage LSTM"
