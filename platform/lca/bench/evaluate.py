"""The reference report's evaluation, one policy at a time with two threads (the baseline)
against `jobs` policies at a time with one thread each, timed in the same run:

    python -m lca.bench evaluate [shipped=blind,blind] [jobs=2] [hardware=false] \
        [eval.steps=300 eval.videos=false ...]

`shipped` names folders under assets/policies/; each is evaluated under the next policy name
of experiments/reference.yaml (the same folder twice measures two equal policies). The rest
are overrides of the experiment (`--evaluate-only`'s), e.g. a shorter episode.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from omegaconf import OmegaConf

from lca.bench.timing import split_params
from lca.paths import assets_dir, root
from lca.shipped import evaluate_only

DEFAULTS = {"shipped": "blind,blind", "jobs": "2", "hardware": "false"}


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    params, extra = split_params(overrides, DEFAULTS)
    reference = OmegaConf.to_container(OmegaConf.load(root() / "experiments" / "reference.yaml"))
    sources = params["shipped"].split(",")
    names = reference["policies"][: len(sources)]
    if len(names) < len(sources):
        raise ValueError(f"shipped: at most {len(reference['policies'])} folders")
    quiet = (lambda _: None) if log is None else log
    result = {"policies": dict(zip(names, sources, strict=True)), "overrides": extra}
    with tempfile.TemporaryDirectory() as tmp:
        shipped = Path(tmp, "shipped")
        for name, source in zip(names, sources, strict=True):
            shutil.copytree(assets_dir() / "policies" / source, shipped / name)
        spec = {
            **reference,
            "policies": names,
            "shipped": str(shipped),
            "report": str(Path(tmp, "report")),
            "hardware": params["hardware"] == "true",
            "overrides": [*reference["overrides"], *extra],
        }
        for jobs in (1, int(params["jobs"])):
            quiet(f"[bench] {len(names)} policies, {jobs} at a time")
            t0 = time.perf_counter()
            evaluate_only(spec, spec["overrides"], Path(tmp, f"runs{jobs}"), log=quiet, jobs=jobs)
            result[f"jobs{jobs}_s"] = time.perf_counter() - t0
    result["jobs"] = int(params["jobs"])
    result["speedup"] = result["jobs1_s"] / result[f"jobs{result['jobs']}_s"]
    return result


def table(result: dict) -> str:
    jobs = result["jobs"]
    return "\n".join(
        [
            f"evaluate-only of {list(result['policies'].values())} {' '.join(result['overrides'])}",
            f"  1 at a time, 2 threads:      {result['jobs1_s']:7.1f} s",
            f"  {jobs} at a time, 1 thread each: {result[f'jobs{jobs}_s']:7.1f} s "
            f"({result['speedup']:.2f}x)",
        ]
    )
