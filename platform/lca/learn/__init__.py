"""Learning layer: actor/critic models, curricula, and the training loop around rsl-rl PPO."""
