"""`python -m lca.hardware run_dir=<dir>`: the paper's four hardware tasks in simulation."""
