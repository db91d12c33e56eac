"""Entry point: `python run.py [overrides]` trains one run; `-m` sweeps a grid.

python run.py -m actor=mlp,lstm curriculum=one,two
"""

import traceback
from pathlib import Path

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.types import RunMode
from omegaconf import DictConfig

import lca.config
from lca.config.policies import label_policy
from lca.pipeline import run_pipeline

lca.config.schema.register()  # `lca_schema`, assembled from every layer's config groups


@hydra.main(config_path="conf", config_name="config", version_base="1.3")
def main(cfg: DictConfig) -> dict | None:
    lca.config.validate(cfg)
    hydra_cfg = HydraConfig.get()
    label_policy(cfg, hydra_cfg.searchpath)
    run_dir = Path(hydra_cfg.runtime.output_dir)
    try:
        return run_pipeline(
            cfg, run_dir, list(hydra_cfg.overrides.task), dict(hydra_cfg.runtime.choices)
        )
    except Exception as error:
        if hydra_cfg.mode != RunMode.MULTIRUN:
            raise
        # one failed run of a sweep: its FAILED marker says why, the others go on, and the
        # sweep report lists it under "Runs left out" (the sweep then exits non-zero)
        traceback.print_exc()
        print(f"[lca] failed {run_dir}: {type(error).__name__}: {error}")
        return None


if __name__ == "__main__":
    main()
