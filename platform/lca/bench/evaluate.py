"""The reference report's evaluation, one policy at a time with two threads (the baseline)
against `jobs` policies at a time with one thread each, timed in the same run:

    python -m lca.bench evaluate [shipped=blind,blind] [jobs=2] [hardware=false] \
        [eval.steps=300 eval.videos=false ...]

or, with `baseline=` (overrides joined by `;`), the same `jobs` both times, the first with
those overrides added: what a setting costs against the reference file's, e.g.
`baseline='eval.grid=[4,4]'`.

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

DEFAULTS = {"shipped": "blind,blind", "jobs": "2", "hardware": "false", "baseline": ""}


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
            "seeds": [0],  # each folder ships as its name's seed-0 run
            "shipped": str(shipped),
            "report": str(Path(tmp, "report")),
            "hardware": params["hardware"] == "true",
            "overrides": [*reference["overrides"], *extra],
        }
        for arm, (jobs, added) in _arms(params).items():
            quiet(f"[bench] {arm}: {len(names)} policies, {jobs} at a time {' '.join(added)}")
            t0 = time.perf_counter()
            overrides = [*spec["overrides"], *added]
            evaluate_only(spec, overrides, Path(tmp, f"runs_{arm}"), log=quiet, jobs=jobs)
            result[f"{arm}_s"] = time.perf_counter() - t0
            result.setdefault("arms", {})[arm] = {"jobs": jobs, "overrides": added}
    result["jobs"] = int(params["jobs"])
    result["baseline"] = params["baseline"]
    result["speedup"] = result["baseline_s"] / result["current_s"]
    return result


def _arms(params: dict) -> dict[str, tuple[int, list[str]]]:
    """What is timed: the baseline first, then the reference file's setting."""
    jobs = int(params["jobs"])
    if params["baseline"]:
        return {"baseline": (jobs, params["baseline"].split(";")), "current": (jobs, [])}
    return {"baseline": (1, []), "current": (jobs, [])}


def table(result: dict) -> str:
    jobs = result["jobs"]
    if result["baseline"]:
        first = f"  with {result['baseline']} ({jobs} at a time):"
        second = f"  as the reference file sets it ({jobs} at a time):"
    else:
        first = "  1 at a time, 2 threads:"
        second = f"  {jobs} at a time, 1 thread each:"
    width = max(len(first), len(second))
    return "\n".join(
        [
            f"evaluate-only of {list(result['policies'].values())} {' '.join(result['overrides'])}",
            f"{first:<{width}} {result['baseline_s']:7.1f} s",
            f"{second:<{width}} {result['current_s']:7.1f} s ({result['speedup']:.2f}x)",
        ]
    )
