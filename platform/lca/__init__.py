"""lca: an experiment and ablation platform for learned humanoid locomotion."""

__version__ = "0.1.0"
