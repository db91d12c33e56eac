"""Benchmarks: `python -m lca.bench sim|env|train [--json] [hydra overrides]`."""
