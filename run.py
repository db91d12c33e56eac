"""Entry point: `python run.py [overrides]` trains one run; `-m` sweeps a grid.

python run.py -m actor=mlp,lstm curriculum=one,two
"""

from pathlib import Path

import hydra
from hydra.core.hydra_config import HydraConfig
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
    return run_pipeline(
        cfg,
        Path(hydra_cfg.runtime.output_dir),
        list(hydra_cfg.overrides.task),
        dict(hydra_cfg.runtime.choices),
    )


if __name__ == "__main__":
    main()
