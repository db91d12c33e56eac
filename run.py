"""Entry point: `python run.py [overrides]` composes one run; `-m` sweeps a grid."""

import hydra
from omegaconf import DictConfig, OmegaConf

import lca.config  # noqa: F401  registers the structured schema


@hydra.main(config_path="conf", config_name="config", version_base="1.3")
def main(cfg: DictConfig) -> None:
    lca.config.validate(cfg)
    print(OmegaConf.to_yaml(cfg))


if __name__ == "__main__":
    main()
