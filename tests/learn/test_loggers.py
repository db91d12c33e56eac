"""The default logger writes TensorBoard event files with the training scalars, one point per
iteration, under the run's logs/ folder; `logger=none` writes none."""

from __future__ import annotations

import pytest
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

from .helpers import make_trainer, smoke_cfg

pytestmark = pytest.mark.slow  # trains twice


def test_tensorboard_gets_a_point_per_iteration(smoke_scene, tmp_path) -> None:
    cfg = smoke_cfg("logger=tensorboard", "scale.max_iterations=3")
    make_trainer(cfg, tmp_path / "run", smoke_scene).train()
    events = list((tmp_path / "run" / "logs").rglob("events.out.tfevents.*"))
    assert events, "no TensorBoard event file"
    acc = EventAccumulator(str(events[0].parent))
    acc.Reload()
    tags = acc.Tags()["scalars"]
    losses = [t for t in tags if t.startswith("Loss/")]
    assert losses, tags
    assert [e.step for e in acc.Scalars(losses[0])] == [0, 1, 2]


def test_no_logger_writes_no_events(smoke_scene, tmp_path) -> None:
    cfg = smoke_cfg("logger=none", "scale.max_iterations=1")
    make_trainer(cfg, tmp_path / "run", smoke_scene).train()
    assert not list(tmp_path.rglob("events.out.tfevents.*"))
