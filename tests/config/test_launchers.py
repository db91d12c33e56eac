"""The launcher presets compose with the project's config, and each job config says what the
preset promises (a joblib pool of 2 here; one SLURM job per run that is requeued); no other
preset ships."""

from __future__ import annotations

from hydra import compose, initialize_config_dir

from lca.config import schema
from lca.paths import conf_dir


def launcher(name: str, *overrides: str):
    schema.register()
    with initialize_config_dir(config_dir=str(conf_dir()), version_base="1.3"):
        cfg = compose("config", [f"hydra/launcher={name}", *overrides], return_hydra_config=True)
    return cfg.hydra.launcher, cfg


def test_local_is_a_joblib_pool_of_two() -> None:
    job, _ = launcher("local")
    assert job._target_.endswith("JoblibLauncher")
    assert job.n_jobs == 2


def test_slurm_requeues_one_job_per_run() -> None:
    job, cfg = launcher("slurm")
    assert job._target_.endswith("submitit_launcher.SlurmLauncher")
    assert (job.nodes, job.tasks_per_node, job.gpus_per_node) == (1, 1, 0)  # device=auto
    assert job.timeout_min == 720 and job.max_num_timeout == 3
    assert (job.cpus_per_task, job.mem_gb, job.partition) == (8, 32, None)
    assert job.submitit_folder == f"{cfg.hydra.sweep.dir}/.submitit/%j"


def test_slurm_asks_for_a_gpu_when_the_run_uses_cuda() -> None:
    job, _ = launcher("slurm", "device=cuda", "hydra.launcher.partition=gpu")
    assert job.gpus_per_node == 1 and job.partition == "gpu"


def test_only_launchers_that_are_tested_ship() -> None:
    """The Ray preset was never run (hydra-ray-launcher's setup() rejects hydra_context,
    facebookresearch/hydra#2725): it is gone rather than shipped untested (issue 29)."""
    presets = sorted(p.stem for p in (conf_dir() / "hydra" / "launcher").glob("*.yaml"))
    assert presets == ["local", "slurm"]
