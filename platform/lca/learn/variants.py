"""Actor and encoder kinds: what `actor.kind` and `encoder.kind` may name.

An actor kind is the rsl-rl model class the runner resolves by name, how the paper's tables
label it, and whether the platform can export it (ONNX + TorchScript). A new kind is one
model class plus one `ACTORS.register(...)` call and one `conf/actor/<kind>.yaml`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lca.config.registry import ACTORS, ENCODERS


@dataclass(frozen=True)
class ActorSpec:
    class_path: str  # "module:Class", resolved by rsl-rl's runner
    recurrent: bool = False
    exports: bool = True  # False: training skips exported/ and says so up front
    model_kwargs: dict = field(default_factory=dict)  # extra model-class arguments


def actor_spec(kind: str) -> ActorSpec:
    return ACTORS.entry(kind, "actor.kind").value


ACTORS.register("mlp", label="MLP")(ActorSpec("lca.learn.models:PerceptiveMLPModel"))
ACTORS.register("lstm", label="LSTM")(
    ActorSpec(
        "lca.learn.models:PerceptiveRNNModel", recurrent=True, model_kwargs={"rnn_type": "lstm"}
    )
)
# The encoder kinds HeightmapEncoder builds; the label names the paper's rows.
ENCODERS.register("mlp", label="MLP")("mlp")
ENCODERS.register("cnn", label="CNN")("cnn")
