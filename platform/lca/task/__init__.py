"""Task layer: observations, commands, rewards and terminations as an rsl-rl VecEnv."""
